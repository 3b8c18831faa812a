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
#include "navimpact/emulation/sensor_effects.hpp"
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
  c.trajectory.end_s = 240.0;
  c.imu_errors = "model";
  c.model_spec = model_spec;
  c.imu_seed = imu_seed;
  c.gnss.seed = imu_seed + 11;
  c.baro.seed = imu_seed + 12;
  const auto path = (navimpact::test::tempDir() / (name + ".rawlog")).string();
  navimpact::rawlog::writeRawlog(path, emu::runEmulation(c, "test"));
  return path;
}

/// The same run with sensor effects applied to its IMU (the model's errors are already in it).
std::string emulateWithEffects(const std::string& name, std::uint64_t imu_seed, const emu::SensorEffects& fx) {
  emu::EmulationConfig c;
  c.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  c.trajectory.end_s = 240.0;
  c.imu_errors = "model";
  c.model_spec = navimpact::test::sourcePath(kModel);
  c.imu_seed = imu_seed;
  c.gnss.seed = imu_seed + 11;
  c.baro.seed = imu_seed + 12;
  const Eigen::Vector3d told = c.gnss.lever_arm_B;
  c.gnss = emu::gnssWithEffects(c.gnss, fx);  // GNSS of the true antenna; the rawlog states the told one
  navimpact::Recording d = emu::runEmulation(c, "test");
  d.lever_arm_B = told;
  const double dt = 1.0 / c.imu_rate_hz;
  std::vector<navimpact::ins::ImuSample> s;
  for (const auto& r : d.imu) s.push_back(navimpact::ins::ImuSample::fromRates(r.t, dt, r.w_IB_B, r.f_B));
  const auto ws = emu::whiteNoiseSigma(st::loadImuModel(c.model_spec), c.imu_rate_hz);
  const auto e = emu::applySensorEffects(s, {}, fx, ws, imu_seed + 13);
  std::cout << "effects: " << e.description << "\n";
  for (std::size_t k = 0; k < d.imu.size(); ++k) {
    d.imu[k].w_IB_B = e.imu[k].dtheta_B / e.imu[k].dt;
    d.imu[k].f_B = e.imu[k].dv_B / e.imu[k].dt;
  }
  const auto path = (navimpact::test::tempDir() / (name + ".rawlog")).string();
  navimpact::rawlog::writeRawlog(path, d);
  return path;
}

an::RunDiagnosisOptions options(const std::string& rawlog, std::uint64_t seed) {
  an::RunDiagnosisOptions o;
  o.replay.rawlog = rawlog;
  o.replay.model_spec = navimpact::test::sourcePath(kModel);
  o.durations_s = {10.0, 20.0};
  o.reconverge_s = 10.0;
  o.realisations = 12;
  o.seed = seed;
  o.alpha = 0.05;
  o.folds = 4;
  o.replay.lever_arm_B = Eigen::Vector3d::Zero();  // the antenna the filter is told (true = told - lever-arm error)
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
  // no cause has a significant held-out gain (each tested at alpha / 3)
  EXPECT_TRUE(d.findings.empty());
  EXPECT_EQ(d.best, -1);
  ASSERT_EQ(d.causes.size(), 7u);
  ASSERT_EQ(d.durations.size(), 2u);
  // the reference has velocity and attitude: four quantities per duration, NEES per duration
  EXPECT_EQ(d.comparisons.size(), 8u);
  EXPECT_EQ(d.tests, 10u);
  for (const auto& c : d.comparisons) {
    EXPECT_GT(c.measured.size(), 0u);
    EXPECT_EQ(c.predicted.size(), 12u * c.measured.size());
    EXPECT_LE(c.ratio_lo, c.ratio);
    EXPECT_GE(c.ratio_hi, c.ratio);
  }
  // identical inputs give identical results (the comparison; the causes' replays are deterministic too)
  an::RunDiagnosisOptions o2 = options(path, seed + 1);
  o2.causes = false;
  const an::RunDiagnosis d2 = an::diagnoseRun(o2);
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
  an::RunDiagnosisOptions o = options(path, seed + 1);
  o.causes = false;  // the verdict only
  const an::RunDiagnosis d = an::diagnoseRun(o);
  std::cout << navimpact::report::runDiagnosisSummary(d);
  EXPECT_EQ(d.verdict, "inadequate");
  bool above = false;
  for (const auto& c : d.comparisons) above = above || c.ratio_lo > 1.0;
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

// White noise k times the model's while moving (k drawn over [3, 30]; gyro or
// accelerometers drawn at random). Always: the factor's 99 % interval covers k
// on the three affected channels and stays near 1 on the others. Gyro noise:
// in_motion_noise is ranked first with a significant held-out gain (the
// extension helps). Accelerometer noise of this model, even 30 times larger,
// hardly changes the outage errors of this run (GNSS sigma 2 m, outages up to
// 20 s): its gain is printed, not required.
TEST(RunDiagnosis, InMotionNoiseIsNamedWithItsFactor) {
  const std::uint64_t seed = 41003;
  std::mt19937_64 rng(seed);
  const double k = std::uniform_real_distribution<double>(3.0, 30.0)(rng);
  const bool gyro = (rng() & 1u) != 0;
  emu::SensorEffects fx;
  (gyro ? fx.gyro_motion_noise_factor : fx.acc_motion_noise_factor) = k;
  std::cout << "in-motion noise: seed " << seed << ", " << (gyro ? "gyro" : "acc") << " factor " << k << "\n";
  const auto path = emulateWithEffects("motion", seed, fx);
  const an::RunDiagnosis d = an::diagnoseRun(options(path, seed + 1));
  std::cout << navimpact::report::runDiagnosisSummary(d);
  const an::CauseResult* motion = nullptr;
  for (const auto& c : d.causes)
    if (c.cause == "in_motion_noise") motion = &c;
  ASSERT_NE(motion, nullptr);
  int covered = 0;
  for (const auto& f : motion->findings) {
    const bool affected = (f.channel.rfind("gyro", 0) == 0) == gyro;
    const auto& iv = f.interval.front().second;
    std::cout << f.channel << " factor " << f.params.front().second << " [" << iv.first << ", " << iv.second << "]\n";
    if (affected && iv.first <= k && k <= iv.second) ++covered;
    if (!affected) EXPECT_LT(iv.first, 1.5) << f.channel;  // unaffected channels near 1
  }
  EXPECT_EQ(covered, 3);
  if (gyro) {
    ASSERT_GE(d.best, 0);
    EXPECT_EQ(d.causes[static_cast<std::size_t>(d.best)].cause, "in_motion_noise");
    EXPECT_EQ(d.causes.front().cause, "in_motion_noise");
    EXPECT_GT(motion->gain, 0.0);
    EXPECT_TRUE(motion->significant);
  }
}

// The same with the gyroscopes always (k drawn over [3, 30], another seed).
TEST(RunDiagnosis, InMotionGyroNoiseIsNamedAndHelps) {
  const std::uint64_t seed = 41004;
  std::mt19937_64 rng(seed);
  const double k = std::uniform_real_distribution<double>(3.0, 30.0)(rng);
  emu::SensorEffects fx;
  fx.gyro_motion_noise_factor = k;
  std::cout << "in-motion gyro noise: seed " << seed << ", factor " << k << "\n";
  const an::RunDiagnosis d = an::diagnoseRun(options(emulateWithEffects("gyro", seed, fx), seed + 1));
  std::cout << navimpact::report::runDiagnosisSummary(d);
  ASSERT_GE(d.best, 0);
  const auto& b = d.causes[static_cast<std::size_t>(d.best)];
  EXPECT_EQ(b.cause, "in_motion_noise");
  EXPECT_GT(b.gain, 0.0);
  for (const auto& f : b.findings)
    if (f.channel.rfind("gyro", 0) == 0) {
      const auto& iv = f.interval.front().second;
      std::cout << f.channel << " factor " << f.params.front().second << " [" << iv.first << ", " << iv.second << "]\n";
      EXPECT_LE(iv.first, k);
      EXPECT_GE(iv.second, k);
    }
  // the finding and the gain reach the output contract
  const std::string js = navimpact::report::runDiagnosisJson(d, "{}");
  EXPECT_NE(js.find("\"cause\": \"in_motion_noise\""), std::string::npos);
  EXPECT_NE(js.find("\"significant\": true"), std::string::npos);
}
