// Outputs of `fit` and `wv`: the model file reads back to the fitted models,
// fit.json / wv.json / wv.csv hold the estimates exactly, figures are PNGs,
// nothing is left when the output set is not committed.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/report/fit_report.hpp"
#include "navimpact/report/wv_report.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "test_support.hpp"

using namespace navimpact;

namespace {

/// The committed ADIS16405 excerpt (real static data, 2^18 samples at 100 Hz), cut to @p n samples.
ImuSeries adisExcerpt(std::size_t n) {
  CsvImuOptions o;
  o.rate_hz = 100.0;
  o.gyro_unit = "deg/s";
  o.acc_unit = "g";
  ImuSeries s = readImuCsv(test::sourcePath("datasets/adis16405_static_excerpt.csv.gz"), o);
  for (auto& c : s.channels) c.x.resize(n);
  return s;
}

bool isPng(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  char b[8] = {};
  f.read(b, 8);
  return f && std::string(b + 1, 3) == "PNG";
}

std::vector<double> vec(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

}  // namespace

TEST(FitReport, ModelFileAndJsonHoldTheFit) {
  const ImuSeries s = adisExcerpt(1u << 16);
  gmwm::RecordingFitOptions o;
  o.structure = "WN+GM";
  o.intervals = "asymptotic";
  o.channels = {"gyro_y", "acc_x", "acc_z"};
  const gmwm::RecordingFit f = gmwm::fitRecording(s, o);
  const std::string input = R"({"file": "adis16405_static_excerpt.csv.gz", "format": "csv"})";
  const auto dir = test::tempDir() / "fit";
  {
    OutputSet out(dir);
    report::writeFitOutputs(f, input, "9.9.9", out);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "model.yaml")) << "output left without commit";
  OutputSet out(dir);
  report::writeFitOutputs(f, input, "9.9.9", out);
  out.commit();

  // model.yaml reads back to the fitted models; channels not fitted are none.
  const stochastic::ImuModel back = stochastic::loadImuModel((dir / "model.yaml").string());
  EXPECT_EQ(back.rate_hz, 100.0);
  for (const char* n : kChannelNames)
    EXPECT_EQ(stochastic::formatTerms(back.forChannel(n).terms, 17),
              stochastic::formatTerms(f.model.forChannel(n).terms, 17))
        << n;
  std::ifstream yaml(dir / "model.yaml");
  std::string first;
  std::getline(yaml, first);
  EXPECT_NE(first.find("navimpact 9.9.9 of " + s.source + ", structure WN+GM"), std::string::npos) << first;

  // fit.json: input copied, per channel the model, objective, flags and WV exactly.
  std::ifstream js(dir / "fit.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["input"], nlohmann::json::parse(input));
  EXPECT_EQ(j["structure"], "WN+GM");
  EXPECT_EQ(j["weights"], "r");
  ASSERT_EQ(j["channels"].size(), f.channels.size());
  for (std::size_t i = 0; i < f.channels.size(); ++i) {
    const auto& c = f.channels[i];
    const auto& jc = j["channels"][i];
    EXPECT_EQ(jc["name"], c.name);
    EXPECT_EQ(jc["model"], stochastic::formatTerms(c.fit.model.terms, 17));
    EXPECT_EQ(jc["objective"].get<double>(), c.fit.objective);
    EXPECT_EQ(jc["wv"]["wv"].get<std::vector<double>>(), vec(c.wv.wv));
    EXPECT_EQ(jc["wv"]["ci_high"].get<std::vector<double>>(), vec(c.wv.ci_high));
    ASSERT_EQ(jc["terms"].size(), c.fit.model.terms.size());
    for (std::size_t t = 0; t < c.fit.model.terms.size(); ++t)
      EXPECT_EQ(jc["terms"][t]["negligible"].get<bool>(), static_cast<bool>(c.negligible[t]));
    EXPECT_EQ(jc["terms"][1]["T"].get<double>(), c.fit.model.terms[1].T);
    EXPECT_DOUBLE_EQ(jc["terms"][1]["phi"].get<double>(), std::exp(-1.0 / (100.0 * c.fit.model.terms[1].T)));
    EXPECT_FALSE(jc.contains("selection"));  // only with auto
  }
  EXPECT_TRUE(isPng(dir / "fit_gyroscope.png"));
  EXPECT_TRUE(isPng(dir / "fit_accelerometer.png"));

  // The console summary names every fitted channel with its model.
  const std::string sum = report::fitSummary(f);
  for (const auto& c : f.channels)
    EXPECT_NE(sum.find(c.name + ": " + stochastic::formatTerms(c.fit.model.terms)), std::string::npos) << sum;
}

// A model that misses the data (WN only on the real ADIS excerpt) is warned
// about on the console and in fit.json, with the scales it leaves the CI at.
TEST(FitReport, ModelOutsideTheCiIsWarnedAbout) {
  const ImuSeries s = adisExcerpt(1u << 16);
  gmwm::RecordingFitOptions o;
  o.structure = "WN";
  o.intervals = "asymptotic";
  o.channels = {"gyro_x", "acc_y"};
  const gmwm::RecordingFit f = gmwm::fitRecording(s, o);
  const auto dir = test::tempDir() / "fit";
  OutputSet out(dir);
  report::writeFitOutputs(f, "{}", "v", out);
  out.commit();
  std::ifstream js(dir / "fit.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  const std::string sum = report::fitSummary(f);
  for (std::size_t i = 0; i < f.channels.size(); ++i) {
    const auto& c = f.channels[i];
    const auto& jc = j["channels"][i];
    EXPECT_EQ(c.outside_ci, gmwm::scalesOutsideCi(c.fit.model, c.wv));
    ASSERT_GT(c.outside_ci.size(), 3u) << c.name;
    ASSERT_EQ(jc["scales_outside_ci"].size(), c.outside_ci.size());
    for (std::size_t k = 0; k < c.outside_ci.size(); ++k)
      EXPECT_EQ(jc["scales_outside_ci"][k]["tau_s"].get<double>(), c.wv.tau[c.outside_ci[k]] / c.wv.rate_hz);
    EXPECT_LT(jc["scales_outside_ci_chance"].get<double>(), 0.05);
    ASSERT_GE(jc["warnings"].size(), 1u);
    EXPECT_NE(jc["warnings"][0].get<std::string>().find("does not describe the data"), std::string::npos);
    EXPECT_TRUE(c.white_noise_note.empty());  // no GM
  }
  std::size_t warnings = 0;
  for (std::size_t p = sum.find("warning: model WV outside the 95 % CI"); p != std::string::npos;
       p = sum.find("warning: model WV outside the 95 % CI", p + 1))
    ++warnings;
  EXPECT_EQ(warnings, 2u) << sum;
}

TEST(FitReport, OneSensorGivesOneFigure) {
  const ImuSeries s = adisExcerpt(1u << 12);
  gmwm::RecordingFitOptions o;
  o.structure = "WN";
  o.intervals = "asymptotic";
  o.channels = {"gyro_x"};
  const gmwm::RecordingFit f = gmwm::fitRecording(s, o);
  const auto dir = test::tempDir() / "fit";
  OutputSet out(dir);
  report::writeFitOutputs(f, "{}", "v", out);
  out.commit();
  EXPECT_TRUE(isPng(dir / "fit_gyroscope.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "fit_accelerometer.png"));
}

TEST(WvReport, CsvAndJsonHoldTheEstimatesExactly) {
  const ImuSeries s = adisExcerpt(3000);
  const gmwm::RecordingWv w = gmwm::recordingWv(s, {}, true);
  const auto dir = test::tempDir() / "wv";
  {
    OutputSet out(dir);
    report::writeWvOutputs(w, R"({"file": "x"})", out);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "wv.csv")) << "output left without commit";
  OutputSet out(dir);
  report::writeWvOutputs(w, R"({"file": "x"})", out);
  out.commit();

  std::ifstream csv(dir / "wv.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "channel,j,tau_s,wv,ci_low,ci_high");
  for (const auto& c : w.channels)
    for (int i = 0; i < c.wv.scales(); ++i) {
      ASSERT_TRUE(std::getline(csv, line));
      std::stringstream ss(line);
      std::string name, jj, tau, v, lo, hi;
      std::getline(ss, name, ',');
      std::getline(ss, jj, ',');
      std::getline(ss, tau, ',');
      std::getline(ss, v, ',');
      std::getline(ss, lo, ',');
      std::getline(ss, hi, ',');
      EXPECT_EQ(name, c.name);
      EXPECT_EQ(std::stoi(jj), i + 1);
      EXPECT_EQ(std::stod(tau), c.wv.tau[i] / 100.0);
      EXPECT_EQ(std::stod(v), c.wv.wv[i]);  // 17 digits: exact
      EXPECT_EQ(std::stod(lo), c.wv.ci_low[i]);
      EXPECT_EQ(std::stod(hi), c.wv.ci_high[i]);
    }
  EXPECT_FALSE(std::getline(csv, line)) << "extra row: " << line;

  std::ifstream js(dir / "wv.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["input"]["file"], "x");
  EXPECT_EQ(j["estimator"]["type"], "classical (mean of squares)");
  ASSERT_EQ(j["channels"].size(), 6u);
  for (std::size_t c = 0; c < 6; ++c) {
    EXPECT_EQ(j["channels"][c]["name"], w.channels[c].name);
    EXPECT_EQ(j["channels"][c]["wv"].get<std::vector<double>>(), vec(w.channels[c].wv.wv));
    EXPECT_EQ(j["channels"][c]["allan"]["adev"].get<std::vector<double>>(), w.channels[c].adev);
  }
  EXPECT_TRUE(isPng(dir / "wv_gyroscope.png"));
  EXPECT_TRUE(isPng(dir / "wv_accelerometer.png"));
  EXPECT_NE(report::wvSummary(w).find("3000 samples at 100 Hz"), std::string::npos) << report::wvSummary(w);
}
