// Run diagnosis (navimpact diagnose --run): emulated runs whose sensor is, or
// is not, the model the simulation uses. Parameters are drawn at random over
// their documented ranges; seeds and values are printed.
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "navimpact/analysis/run_diagnosis.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/report/run_diagnosis_report.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace an = navimpact::analysis;
namespace st = navimpact::stochastic;

namespace {

const std::string kModel = "config/models/navchip_table1.yaml:ref";

/// A 120 s emulated run of the UAV trajectory with the sensor errors of @p model_spec.
std::string emulateRun(const std::string& name, const std::string& model_spec, std::uint64_t imu_seed) {
  emu::EmulationConfig c;
  c.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  c.trajectory.end_s = 120.0;
  c.imu_errors = "model";
  c.model_spec = model_spec;
  c.imu_seed = imu_seed;
  c.gnss.seed = imu_seed + 11;
  c.baro.seed = imu_seed + 12;
  const auto path = (navimpact::test::tempDir() / (name + ".rawlog")).string();
  navimpact::rawlog::writeRawlog(path, emu::runEmulation(c, "test"));
  return path;
}

an::RunDiagnosisOptions options(const std::string& rawlog, std::uint64_t seed) {
  an::RunDiagnosisOptions o;
  o.replay.rawlog = rawlog;
  o.replay.model_spec = navimpact::test::sourcePath(kModel);
  o.durations_s = {10.0, 20.0};
  o.reconverge_s = 20.0;
  o.realisations = 8;
  o.seed = seed;
  o.alpha = 0.01;
  return o;
}

}  // namespace

// Sensor = model: the verdict is "adequate" unless one of the Bonferroni tests
// fires, which happens with probability <= alpha = 1 % per run.
TEST(RunDiagnosis, NullRunIsAdequate) {
  const std::uint64_t seed = 41001;
  std::cout << "null run: imu seed " << seed << "\n";
  const auto path = emulateRun("null", navimpact::test::sourcePath(kModel), seed);
  const an::RunDiagnosis d = an::diagnoseRun(options(path, seed + 1));
  std::cout << navimpact::report::runDiagnosisSummary(d);
  EXPECT_EQ(d.verdict, "adequate");
  ASSERT_EQ(d.durations.size(), 2u);
  // the reference has velocity and attitude: four quantities per duration, NEES per duration
  EXPECT_EQ(d.comparisons.size(), 8u);
  EXPECT_EQ(d.tests, 10u);
  for (const auto& c : d.comparisons) {
    EXPECT_GT(c.measured.size(), 0u);
    EXPECT_EQ(c.predicted.size(), 8u * c.measured.size());
    EXPECT_LE(c.ratio_lo, c.ratio);
    EXPECT_GE(c.ratio_hi, c.ratio);
  }
  // identical inputs give identical results
  const an::RunDiagnosis d2 = an::diagnoseRun(options(path, seed + 1));
  for (std::size_t k = 0; k < d.comparisons.size(); ++k)
    EXPECT_EQ(d.comparisons[k].predicted_rms, d2.comparisons[k].predicted_rms);
  const std::string js = navimpact::report::runDiagnosisJson(d, "{}");
  for (const char* key : {"\"verdict\"", "\"findings\"", "\"gain\"", "\"outage_error_before_m\"", "\"ratio_interval\"",
                          "\"anees_band\""})
    EXPECT_NE(js.find(key), std::string::npos) << key;
}

// A sensor whose every noise term is k times the model's (k drawn in [3, 10],
// the documented range of in-motion noise inflation): inadequate, the
// measured/predicted ratio's interval above 1 for the position at the longer outage.
TEST(RunDiagnosis, NoisierSensorIsInadequate) {
  const std::uint64_t seed = 41002;
  std::mt19937_64 rng(seed);
  const double k = std::uniform_real_distribution<double>(3.0, 10.0)(rng);
  std::cout << "noisier sensor: imu seed " << seed << ", noise factor " << k << "\n";
  st::ImuModel m = st::loadImuModel(navimpact::test::sourcePath(kModel));
  for (auto& ax : m.axis)
    for (auto& p : ax.terms) {
      p.sigma *= k;
      p.gamma *= k;
      p.Q *= k;
      p.omega *= k;
      p.amp *= k;
    }
  const auto mfile = (navimpact::test::tempDir() / "noisier.yaml").string();
  std::ofstream(mfile) << st::toYaml(m);
  const auto path = emulateRun("noisier", mfile, seed);
  const an::RunDiagnosis d = an::diagnoseRun(options(path, seed + 1));
  std::cout << navimpact::report::runDiagnosisSummary(d);
  EXPECT_EQ(d.verdict, "inadequate");
  bool above = false;
  for (const auto& c : d.comparisons)
    if (c.duration_s == 20.0 && c.quantity == "horizontal_position") above = c.ratio_lo > 1.0;
  EXPECT_TRUE(above);
}

TEST(RunDiagnosis, BadInputIsAClearError) {
  an::RunDiagnosisOptions o = options(navimpact::test::sourcePath("datasets/uav_flight_260s_ref.rawlog"), 1);
  o.durations_s = {500.0};  // longer than the run
  try {
    an::diagnoseRun(o);
    FAIL() << "no error";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find("no outage of 500 s"), std::string::npos) << e.what();
  }
  o = options("", 1);
  o.realisations = 1;
  EXPECT_THROW(an::diagnoseRun(o), navimpact::Error);
}
