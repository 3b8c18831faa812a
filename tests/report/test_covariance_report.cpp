// Covariance study outputs: all or nothing, and the files hold the sigmas of the result.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/report/covariance_report.hpp"
#include "test_support.hpp"

using namespace navimpact;

namespace {
analysis::CovarianceStudyConfig shortConfig(double T) {
  const std::string path = (test::tempDir() / "cov.yaml").string();
  std::ofstream(path) << "model_file: " << test::sourcePath("config/models/navchip_table1.yaml")
                      << "\nduration_s: " << T
                      << "\nsummary_times_s: [1]\n"
                         "static_state: {lat_deg: 46.52, lon_deg: 6.57, h_m: 400, yaw_deg: 20}\n"
                         "baro: {rate_hz: 0, sigma_m: 1}\n"
                         "model_sets:\n"
                         "  - {name: accelerometer, models: [acc_model1, acc_model2, acc_model3, acc_ref]}\n"
                         "  - {name: gyroscope, models: [gyro_model1, gyro_ref]}\n";
  return analysis::loadCovarianceStudyConfig(path);
}
}  // namespace

TEST(CovarianceReport, WritesAllOutputsOrNothing) {
  const analysis::CovarianceStudyConfig cfg = shortConfig(2.0);
  const analysis::CovarianceStudyResult r = analysis::runCovarianceStudy(cfg);
  const auto dir = test::tempDir() / "out";
  {
    OutputSet out(dir);
    report::writeCovarianceStudy(cfg, r, out);
    // not committed: nothing may appear
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "covariance.csv"));
  OutputSet out(dir);
  report::writeCovarianceStudy(cfg, r, out);
  out.commit();
  for (const char* f : {"covariance.csv", "summary.json", "covariance_accelerometer.png",
                        "covariance_gyroscope.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;

  // covariance.csv: one row per run and time, the sigmas to 9 digits.
  std::ifstream csv(dir / "covariance.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("time_s,model_set,model,sigma_pos_N_m,", 0), 0u) << line;
  for (const auto& run : r.runs)
    for (std::size_t i = 0; i < run.t.size(); ++i) {
      ASSERT_TRUE(std::getline(csv, line));
      std::stringstream ss(line);
      std::string tok;
      std::getline(ss, tok, ',');
      EXPECT_NEAR(std::stod(tok), run.t[i], 1e-6 * std::max(1.0, run.t[i]));
      std::getline(ss, tok, ',');
      EXPECT_EQ(tok, run.model_set);
      std::getline(ss, tok, ',');
      EXPECT_EQ(tok, run.model);
      for (int c = 0; c < 9; ++c) {
        ASSERT_TRUE(std::getline(ss, tok, ','));
        EXPECT_NEAR(std::stod(tok), run.sigma[i][c], 1e-8 * std::abs(run.sigma[i][c]) + 1e-300);
      }
    }
  EXPECT_FALSE(std::getline(csv, line)) << "extra row: " << line;

  // summary.json: the sigmas at the summary time (1 s), per run.
  std::ifstream js(dir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  ASSERT_EQ(j["runs"].size(), r.runs.size());
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    const auto& run = r.runs[k];
    const auto& at = j["runs"][k]["at"][0];
    std::size_t i = 0;
    for (std::size_t m = 1; m < run.t.size(); ++m)
      if (std::abs(run.t[m] - 1.0) < std::abs(run.t[i] - 1.0)) i = m;
    EXPECT_EQ(at["t_s"].get<double>(), run.t[i]);
    EXPECT_EQ(at["sigma_pos_N_m"].get<double>(), run.sigma[i][0]);
    EXPECT_EQ(at["sigma_yaw_rad"].get<double>(), run.sigma[i][8]);
    EXPECT_EQ(j["runs"][k]["filter_states"].get<int>(), run.states);
  }
}
