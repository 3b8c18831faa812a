// Covariance study outputs: all or nothing, and the files hold the sigmas of the result.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/filter/ekf.hpp"
#include "navimpact/report/covariance_report.hpp"
#include "navimpact/stochastic/model_file.hpp"
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
    // how the model entered the filter, where it was changed
    EXPECT_EQ(j["runs"][k].contains("notes"), !run.notes.empty());
    if (!run.notes.empty()) { EXPECT_EQ(j["runs"][k]["notes"].get<std::vector<std::string>>(), run.notes); }
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

TEST(CovarianceReport, TheSummaryListsHowEachModelEnteredTheFilter) {
  // A Gauss-Markov term with T below the covariance propagation interval
  // enters the filter as white noise (filter::layoutFor): the console summary says so.
  const auto dir = test::tempDir();
  const std::string models = (dir / "m.yaml").string(), cfgFile = (dir / "cov.yaml").string();
  std::ofstream(models) << "rate_hz: 200\nmodels:\n  short_gm:\n    gyroscope: \"WN(sigma=1e-3) + GM(sigma=1e-4, T=0.01)\"\n"
                           "  plain:\n    gyroscope: \"WN(sigma=1e-3)\"\n";
  std::ofstream(cfgFile) << "model_file: m.yaml\nduration_s: 2\nimu_rate_hz: 200\noutput_rate_hz: 1\n"
                            "summary_times_s: [1, 2]\n"
                            "static_state: {lat_deg: 46.52, lon_deg: 6.57, h_m: 400, roll_deg: 0, pitch_deg: 0, yaw_deg: 0}\n"
                            "initial_sigma: {position_m: 0, velocity_mps: 0, attitude_deg: 0}\n"
                            "baro: {rate_hz: 10, sigma_m: 0.001}\n"
                            "filter: {discretization: series, propagate_every: 10}\n"
                            "model_sets:\n  - {name: gyro, title: short GM, models: [short_gm, plain]}\n";
  const analysis::CovarianceStudyConfig cfg = analysis::loadCovarianceStudyConfig(cfgFile);
  const analysis::CovarianceStudyResult r = analysis::runCovarianceStudy(cfg);
  ASSERT_EQ(r.runs.size(), 2u);
  ASSERT_FALSE(r.runs[0].notes.empty());
  EXPECT_TRUE(r.runs[1].notes.empty());
  const std::string s = report::covarianceSummary(r);
  EXPECT_NE(s.find("note (gyro / short_gm): " + r.runs[0].notes.front()), std::string::npos) << s;
  EXPECT_EQ(s.find("note (gyro / plain)"), std::string::npos) << s;
}

// --print-states lists what the filter builds: per model, the state count and
// layout of the ErrorStateEkf its run uses, with the notes, at a propagation
// interval drawn at random (seeded, printed): a GM too fast for it enters as
// white noise and is not listed as a state.
TEST(CovarianceReport, PrintStatesListTheLayoutTheFilterBuilds) {
  const std::uint64_t seed = 20261125;
  std::mt19937_64 g(seed);
  analysis::CovarianceStudyConfig cfg =
      analysis::loadCovarianceStudyConfig(test::sourcePath("config/paper/covariance_static.yaml"));
  for (int trial = 0; trial < 4; ++trial) {
    cfg.filter.propagate_every = std::uniform_int_distribution<int>(1, 400)(g);
    std::cout << "seed " << seed << " trial " << trial << ": propagate_every " << cfg.filter.propagate_every << "\n";
    const auto models = analysis::covarianceModels(cfg);
    std::size_t expected = 0;
    for (const auto& s : cfg.model_sets) expected += s.models.size();
    ASSERT_EQ(models.size(), expected);
    const std::string text = report::covarianceStateLayouts(models);
    std::size_t at = 0;
    for (const auto& m : models) {
      const filter::ErrorStateEkf ekf(cfg.nominal, filter::Matrix9d::Identity(),
                                      stochastic::loadImuModel(cfg.model_file + ":" + m.model), cfg.filter);
      EXPECT_EQ(m.entry.layout.size(), ekf.size()) << m.model;
      const std::string head = "# " + m.model_set + " / " + m.model + ": " + std::to_string(ekf.size()) + " states\n";
      const std::size_t h = text.find(head, at);
      ASSERT_NE(h, std::string::npos) << head << text;
      at = h + head.size();
      for (const auto& n : m.entry.notes) {
        const std::string line = "# note: " + n + "\n";
        ASSERT_EQ(text.compare(at, line.size(), line), 0) << text.substr(at, 200);
        at += line.size();
      }
      const std::string layout = m.entry.layout.describe();
      ASSERT_EQ(text.compare(at, layout.size(), layout), 0) << m.model;
      at += layout.size();
    }
    EXPECT_EQ(at, text.size());
  }
}
