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

TEST(CovarianceReport, WritesAllOutputsOrNothing) {
  // The paper's static covariance configuration (60 s, 8 models).
  const analysis::CovarianceStudyConfig cfg =
      analysis::loadCovarianceStudyConfig(test::sourcePath("config/paper/covariance_static.yaml"));
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

  // summary.json: the sigmas at every summary time, per run.
  std::ifstream js(dir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  ASSERT_EQ(j["runs"].size(), r.runs.size());
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    const auto& run = r.runs[k];
    EXPECT_EQ(j["runs"][k]["filter_states"].get<int>(), run.states);
    ASSERT_EQ(j["runs"][k]["at"].size(), cfg.summary_times_s.size());
    for (std::size_t q = 0; q < cfg.summary_times_s.size(); ++q) {
      const double ts = cfg.summary_times_s[q];
      const auto& at = j["runs"][k]["at"][q];
      std::size_t i = 0;
      for (std::size_t m = 1; m < run.t.size(); ++m)
        if (std::abs(run.t[m] - ts) < std::abs(run.t[i] - ts)) i = m;
      EXPECT_EQ(at["t_s"].get<double>(), run.t[i]);
      EXPECT_EQ(at["sigma_pos_N_m"].get<double>(), run.sigma[i][0]);
      EXPECT_EQ(at["sigma_vel_E_mps"].get<double>(), run.sigma[i][4]);
      EXPECT_EQ(at["sigma_yaw_rad"].get<double>(), run.sigma[i][8]);
    }
  }
  EXPECT_NE(report::covarianceSummary(r).find(r.runs.back().model), std::string::npos);
}
