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
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "navimpact/rawlog/reader.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/report/run_diagnosis_report.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace an = navimpact::analysis;
namespace st = navimpact::stochastic;

namespace {

const std::string kModel = "config/models/navchip_table1.yaml:ref";

/// The emulation of the first @p end_s of the UAV trajectory with the sensor
/// errors of @p model_spec, IMU, GNSS and baro seeds from @p imu_seed.
emu::EmulationConfig uavEmulation(double end_s, const std::string& model_spec, std::uint64_t imu_seed) {
  emu::EmulationConfig c;
  c.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  c.trajectory.end_s = end_s;
  c.imu_errors = "model";
  c.model_spec = model_spec;
  c.imu_seed = imu_seed;
  c.gnss.seed = imu_seed + 11;
  c.baro.seed = imu_seed + 12;
  return c;
}

/// A 240 s emulated run of the UAV trajectory with the sensor errors of @p model_spec.
std::string emulateRun(const std::string& name, const std::string& model_spec, std::uint64_t imu_seed) {
  const emu::EmulationConfig c = uavEmulation(240.0, model_spec, imu_seed);
  const auto path = (navimpact::test::tempDir() / (name + ".rawlog")).string();
  navimpact::rawlog::writeRawlog(path, emu::runEmulation(c, "test"));
  return path;
}

/// The same run with sensor effects applied to its IMU (the model's errors are already in it).
std::string emulateWithEffects(const std::string& name, std::uint64_t imu_seed, const emu::SensorEffects& fx) {
  emu::EmulationConfig c = uavEmulation(240.0, navimpact::test::sourcePath(kModel), imu_seed);
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

// The held-out replays score an extension on the measured run's outage
// windows, paired by window: an extension whose aligning phase ends later (here
// larger GNSS sigmas, as the gnss_noise cause fits on the Katwijk run: the
// heading from a chord course needs a longer chord) would lay its own outages
// later from its own filter start (replay --outages-every), so pairing by
// order would compare other outages. Outage
// period and duration drawn at random (seeded, printed).
TEST(RunDiagnosis, AnExtensionThatAlignsLaterIsScoredOnTheMeasuredOutageWindows) {
  const std::uint64_t seed = std::random_device{}();
  std::mt19937_64 rng(seed);
  const double duration = std::uniform_real_distribution<double>(2.0, 15.0)(rng);
  const double reconverge = std::uniform_real_distribution<double>(5.0, 15.0)(rng);
  std::cout << "seed " << seed << ": outages of " << duration << " s after " << reconverge << " s of GNSS\n";
  navimpact::Recording d = emu::runEmulation(uavEmulation(120.0, navimpact::test::sourcePath(kModel), seed), "test");
  for (auto& g : d.reference) g.v_N.reset();  // no velocity: the filter starts after an aligning phase
  const auto path = (navimpact::test::tempDir() / "aligns_later.rawlog").string();
  navimpact::rawlog::writeRawlog(path, d);
  const navimpact::rawlog::RawlogRecords data = navimpact::rawlog::readRawlogRecords(path);

  an::ReplayConfig c;
  c.rawlog = path;
  c.model_spec = navimpact::test::sourcePath(kModel);
  c.outages_every = navimpact::OutagePattern{duration + reconverge, duration};
  c.use_gnss_velocity = false;              // heading from the course of a chord between fixes
  c.alignment_yaw_from_reference = false;
  an::ReplayConfig ext = c;
  // the gnss_noise extension: larger GNSS sigmas (3 x the fixes'), so a longer chord for the course
  ext.sigma_pos_h_m = 3.0 * std::sqrt((*d.gnss.front().cov_pos_N)(0, 0));
  const an::ReplayResult measured = an::runReplay(c, data);
  ASSERT_TRUE(measured.alignment && measured.score);
  ASSERT_GE(measured.score->outages.size(), 3u);
  const an::ReplayResult laid = an::runReplay(ext, data);  // its outages laid from its own start
  std::cout << "filter start: measured " << measured.aided_from_s << " s (heading " << measured.alignment->heading
            << "), extension " << laid.aided_from_s << " s (heading " << laid.alignment->heading << ")\n";
  ASSERT_GT(laid.aided_from_s, measured.aided_from_s + 1e-3);
  ASSERT_TRUE(laid.score && !laid.score->outages.empty());
  EXPECT_NE(laid.score->outages.front().start_s, measured.score->outages.front().start_s);

  const an::PairedOutageScores p = an::replayOnMeasuredOutages(ext, measured, data);
  // GNSS is dropped in the measured windows also while aligning: a window inside
  // the extension's aligning phase delays it further
  bool windowWhileAligning = false;
  for (const auto& o : measured.cfg.outages) windowWhileAligning = windowWhileAligning || o.start_s < laid.aided_from_s;
  std::cout << "extension's filter start on the measured windows " << p.aided_from_s << " s\n";
  if (windowWhileAligning) EXPECT_GE(p.aided_from_s, laid.aided_from_s);
  else EXPECT_EQ(p.aided_from_s, laid.aided_from_s);
  ASSERT_EQ(p.outages.size(), measured.score->outages.size());
  ASSERT_EQ(p.ends.size(), measured.score->outages.size());
  // the same windows scored by the extension in a full replay given them explicitly
  an::ReplayConfig explicitWindows = ext;
  explicitWindows.outages = measured.cfg.outages;
  explicitWindows.outages_every.reset();
  const an::ReplayResult full = an::runReplay(explicitWindows, data);
  std::size_t paired = 0;
  for (std::size_t k = 0; k < p.outages.size(); ++k) {
    const navimpact::analysis::OutageScore& m = measured.score->outages[k];
    SCOPED_TRACE("outage " + std::to_string(k) + " at " + std::to_string(m.start_s) + " s");
    // an outage that starts before the extension's filter is not the same outage: unpaired
    ASSERT_EQ(p.outages[k].has_value(), m.start_s > p.aided_from_s);
    if (!p.outages[k]) continue;
    ++paired;
    EXPECT_NEAR(p.outages[k]->start_s, m.start_s, 1e-9);
    EXPECT_NEAR(p.outages[k]->duration_s, m.duration_s, 1e-9);
    EXPECT_EQ(p.outages[k]->end_s, m.end_s);
    const navimpact::analysis::OutageScore* o = nullptr;
    for (const auto& f : full.score->outages)
      if (std::abs(f.start_s - m.start_s) <= 1e-9) o = &f;
    ASSERT_NE(o, nullptr);
    EXPECT_EQ(p.outages[k]->err_N, o->err_N);
    EXPECT_EQ(p.outages[k]->nees, o->nees);
    EXPECT_EQ(p.ends[k].first.head<3>(), o->err_N);
  }
  EXPECT_GE(paired + 2, measured.score->outages.size());
  EXPECT_GE(paired, 1u);
  // today's configuration on its own windows is today's replay, bit for bit
  const an::PairedOutageScores same = an::replayOnMeasuredOutages(c, measured, data);
  for (std::size_t k = 0; k < same.outages.size(); ++k) {
    ASSERT_TRUE(same.outages[k].has_value());
    EXPECT_EQ(same.outages[k]->err_N, measured.score->outages[k].err_N);
    EXPECT_EQ(same.outages[k]->sigma_N, measured.score->outages[k].sigma_N);
    EXPECT_EQ(same.outages[k]->nees, measured.score->outages[k].nees);
  }
  // stopped: the windows that end by the stop, as in the full replay
  const double stop = 0.5 * (p.aided_from_s + measured.run.epochs.back().t - measured.t_zero);
  const an::PairedOutageScores cut = an::replayOnMeasuredOutages(ext, measured, data, stop);
  for (std::size_t k = 0; k < cut.outages.size(); ++k) {
    const auto& m = measured.score->outages[k];
    ASSERT_EQ(cut.outages[k].has_value(), p.outages[k].has_value() && m.start_s + m.duration_s <= stop);
    if (cut.outages[k]) {
      EXPECT_EQ(cut.outages[k]->err_N, p.outages[k]->err_N);
    }
  }
}

// ---- Hidden effects -------------------------------------------------------
// Each effect alone in an emulated 240 s UAV run whose IMU errors are the
// model's: the filter and the simulation lack the effect. Its size is drawn at
// random (seeded, printed) over the whole documented range: log-uniform
// magnitude over the range's top three decades (two for the motion-noise
// factor, [1, 100]), random signs per axis; far below the detection limit
// the same holds a fortiori. Each draw:
//  - a named cause (findings) other than the hidden one is a false alarm, an
//    event of probability <= alpha = 0.05 per run (the family-wise level; the
//    limits script measured 1 in 100 null and below-limit runs, 2 in 40 at
//    0.5 and 1 ms time offsets, the same noise seed both times): a test allows it in one of its two runs, not both
//    (probability <= alpha^2 = 0.25 % at the nominal level), so a cause that
//    is named in place of the hidden one systematically still fails;
//  - above the detection limit of this run length (README) the hidden cause
//    is named (the best significant one) with a positive held-out gain;
//  - its 95 % intervals cover the truth on the affected components (at most
//    one miss of three, a 0.7 % event for calibrated intervals).
// Short runs (one 10 s duration, 8 realisations, 3 folds) keep CI small.
namespace {

namespace limits = navimpact::limits;

// Detection limits on this run (240 s of the UAV flight, 1 Hz GNSS 2 m / 4 m,
// 10 s outages every 20 s, 8 realisations, 3 folds, alpha 0.05 over the seven
// causes), README "Run diagnosis": sizes where the hidden cause was named in
// all 4 runs of `bash bench/run_diagnosis_limits.sh 4` (4 seeds per size, every
// axis of the triad at that magnitude); in brackets what it measured there and
// below.
constexpr double kLimitGyroScale = 2e-3;           // [ratio] (named in 4/4 runs; 1/4 at 5e-4, 0/4 at 2e-4)
constexpr double kLimitAccScale = 1e-2;            // [ratio] (4/4; 3/4 at 5e-3, 2/4 at 2e-3 and 5e-4, 0/4 at 2e-4:
                                                   // a bias random walk explains it nearly as well, undecided)
constexpr double kLimitGyroMisalignment = 1e-2;    // [rad] (4/4; 4/4 at 3e-3, 3/4 at 1e-3, 0/4 at 3e-4)
constexpr double kLimitAccMisalignment = 5e-3;     // [rad] (4/4; 4/4 at 1e-2, 3/4 at 2e-3, 0/4 at 1e-3)
constexpr double kLimitTimeOffset = 0.01;          // [s] (4/4; 4/4 at 0.005, 1/4 at 0.002)
constexpr double kLimitBiasRandomWalk = 3e-3;      // [m/s^2/sqrt(s)] (4/4; 4/4 at 1e-3, 1/4 at 3e-4)
constexpr double kLimitLeverArm = 0.5;             // [m per axis] (4/4; 4/4 at 0.2, 0/4 at 0.1)
constexpr double kLimitGyroMotionNoise = 30.0;     // factor (4/4; 4/4 at 10, 0/4 at 3)
constexpr double kLimitAccMotionNoise = 100.0;     // factor (4/4, the end of the range; 3/4 at 30, 0/4 at 10)

struct Hidden {
  std::string cause;                     // the cause that carries the effect
  double size = 0.0, limit = 0.0;        // drawn size and the stated detection limit (same unit)
  struct Truth {
    std::string channel, param;
    double value;
  };
  std::vector<Truth> truth;              // true values of the cause's parameters
};

/// The seeds of a hidden-effect test: @p a and @p b, or with
/// NAVIMPACT_RUN_DIAGNOSIS_SEED=S (S > 0), two others derived from S: draws
/// the suite has never seen, printed with the draw.
std::vector<std::uint64_t> seeds(std::uint64_t a, std::uint64_t b) {
  const std::uint64_t root = navimpact::test::envOr("NAVIMPACT_RUN_DIAGNOSIS_SEED", 0);
  if (root == 0) return {a, b};
  return {st::deriveSeed(root, a), st::deriveSeed(root, b)};
}

/// Magnitude log-uniform over [hi / 10^decades, hi] with a random sign.
double drawSigned(std::mt19937_64& rng, double hi, double decades) {
  const double m = hi * std::pow(10.0, -decades * std::uniform_real_distribution<double>(0.0, 1.0)(rng));
  return (rng() & 1u) ? m : -m;
}

an::RunDiagnosisOptions hiddenOptions(const std::string& rawlog, std::uint64_t seed) {
  an::RunDiagnosisOptions o = options(rawlog, seed);
  o.durations_s = {10.0};
  o.realisations = 8;
  o.folds = 3;
  return o;
}

/// Checks one run; returns whether another cause than the hidden one was named (a false alarm).
bool checkHidden(const an::RunDiagnosis& d, const Hidden& h) {
  std::cout << navimpact::report::runDiagnosisSummary(d);
  bool wrong = false;
  for (const auto& f : d.findings)
    if (f.cause != h.cause) {
      std::cout << "false alarm: " << f.cause << " " << f.channel << " named (hidden: " << h.cause << ")\n";
      wrong = true;
    }
  const an::CauseResult* c = nullptr;
  for (const auto& x : d.causes)
    if (x.cause == h.cause) c = &x;
  EXPECT_NE(c, nullptr);
  if (c == nullptr) return wrong;
  std::cout << h.cause << ": size " << h.size << " (detection limit " << h.limit << "), held-out gain " << c->gain
            << ", p = " << c->p_value << (c->significant ? ", significant" : "") << "\n";
  if (h.size >= h.limit) {
    EXPECT_GE(d.best, 0) << "above the detection limit but nothing named";
    if (d.best >= 0) {
      EXPECT_EQ(d.causes[static_cast<std::size_t>(d.best)].cause, h.cause);
    }
    EXPECT_GT(c->gain, 0.0);
    EXPECT_TRUE(c->significant);
    // the finding and the gain reach the output contract
    const std::string js = navimpact::report::runDiagnosisJson(d, "{}");
    EXPECT_NE(js.find("\"cause\": \"" + h.cause + "\""), std::string::npos);
    EXPECT_NE(js.find("\"significant\": true"), std::string::npos);
  }
  int misses = 0, checked = 0;
  for (const auto& t : h.truth)
    for (const auto& f : c->findings) {
      if (f.channel != t.channel) continue;
      for (std::size_t k = 0; k < f.interval.size(); ++k) {
        if (f.interval[k].first != t.param) continue;
        double est = NAN;
        for (const auto& p : f.params)
          if (p.first == t.param) est = p.second;
        const auto& iv = f.interval[k].second;
        const bool in = iv.first <= t.value && t.value <= iv.second;
        std::cout << "  " << t.channel << " " << t.param << " " << est << " [" << iv.first << ", " << iv.second
                  << "] truth " << t.value << (in ? "" : "  MISS") << "\n";
        misses += in ? 0 : 1;
        ++checked;
      }
    }
  EXPECT_EQ(checked, static_cast<int>(h.truth.size()));
  EXPECT_LE(misses, 1);
  return wrong;
}

/// At most one of a test's runs may name a wrong cause (see above).
void expectAtMostOneFalseAlarm(int runs_with_wrong_cause) {
  EXPECT_LE(runs_with_wrong_cause, 1) << "both runs named a cause other than the hidden one: probability <= alpha^2 "
                                         "= 0.25 % if each is a false alarm at the family-wise level";
}

/// The triad of one sensor that an effect acts on: the gyro's or the accelerometer's vector.
struct TriadEffect {
  const char* cause;  ///< the cause the diagnosis must name
  const char* param;  ///< its parameter per channel
  const char* what;   ///< in the log line
  const char* unit;   ///< suffix of the magnitude in the log line
  double range_hi;    ///< documented range [-hi, hi]
  double limit_gyro, limit_acc;  ///< detection limits
  Eigen::Vector3d emu::SensorEffects::*gyro;
  Eigen::Vector3d emu::SensorEffects::*acc;
};

/// The effect on one triad (drawn: gyro or accelerometer), one magnitude
/// log-uniform over three decades below its range's end with a random sign
/// per axis, emulated, diagnosed and checked.
bool checkHiddenTriad(const TriadEffect& e, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const bool gyro = (rng() & 1u) != 0;
  const double m = std::abs(drawSigned(rng, e.range_hi, 3.0));
  emu::SensorEffects fx;
  Hidden h{e.cause, m, gyro ? e.limit_gyro : e.limit_acc, {}};
  for (int i = 0; i < 3; ++i) {
    const double v = (rng() & 1u) ? m : -m;
    (fx.*(gyro ? e.gyro : e.acc))(i) = v;
    h.truth.push_back({navimpact::kChannelNames[(gyro ? 0 : 3) + i], e.param, v});
  }
  std::cout << "hidden " << e.what << ": seed " << seed << ", " << (gyro ? "gyro" : "acc") << " " << m << e.unit << "\n";
  return checkHidden(an::diagnoseRun(hiddenOptions(emulateWithEffects(e.cause, seed, fx), seed + 1)), h);
}

}  // namespace

// White noise k times the model's while moving (k log-uniform over the
// documented [1, 100]; gyro or accelerometers drawn): the factor's 99 %
// interval covers k on the affected channels and stays near 1 on the others.
TEST(RunDiagnosisHidden, InMotionNoise) {
  int wrong = 0;
  for (std::uint64_t seed : seeds(41003u, 41004u)) {
    std::mt19937_64 rng(seed);
    const bool gyro = (rng() & 1u) != 0;
    const double k = std::pow(10.0, 2.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng));
    emu::SensorEffects fx;
    (gyro ? fx.gyro_motion_noise_factor : fx.acc_motion_noise_factor) = k;
    std::cout << "hidden in-motion noise: seed " << seed << ", " << (gyro ? "gyro" : "acc") << " factor " << k << "\n";
    Hidden h{"in_motion_noise", k, gyro ? kLimitGyroMotionNoise : kLimitAccMotionNoise, {}};
    for (int i = 0; i < 3; ++i) h.truth.push_back({navimpact::kChannelNames[(gyro ? 0 : 3) + i], "factor", k});
    const an::RunDiagnosis d = an::diagnoseRun(hiddenOptions(emulateWithEffects("motion", seed, fx), seed + 1));
    wrong += checkHidden(d, h) ? 1 : 0;
    for (const auto& c : d.causes)
      if (c.cause == "in_motion_noise")
        for (const auto& f : c.findings)
          if ((f.channel.rfind("gyro", 0) == 0) != gyro) {
            EXPECT_LT(f.interval.front().second.first, 1.5) << f.channel;  // unaffected channels near 1
          }
  }
  expectAtMostOneFalseAlarm(wrong);
}

// Scale factors of one triad (drawn: gyro or accelerometer), one magnitude
// log-uniform over [5e-5, 0.05] with a random sign per axis.
TEST(RunDiagnosisHidden, ScaleFactor) {
  const TriadEffect e{"scale_factor", "scale", "scale factor", "", limits::kScaleFactor.hi,
                      kLimitGyroScale, kLimitAccScale, &emu::SensorEffects::gyro_scale, &emu::SensorEffects::acc_scale};
  int wrong = 0;
  for (std::uint64_t seed : seeds(41101u, 41102u)) wrong += checkHiddenTriad(e, seed) ? 1 : 0;
  expectAtMostOneFalseAlarm(wrong);
}

// Misalignment of one triad (drawn), one magnitude log-uniform over [5e-5, 0.05] rad.
TEST(RunDiagnosisHidden, Misalignment) {
  const TriadEffect e{"misalignment", "angle", "misalignment", " rad", limits::kMisalignmentRad.hi,
                      kLimitGyroMisalignment, kLimitAccMisalignment, &emu::SensorEffects::gyro_misalignment_rad,
                      &emu::SensorEffects::acc_misalignment_rad};
  int wrong = 0;
  for (std::uint64_t seed : seeds(41201u, 41202u)) wrong += checkHiddenTriad(e, seed) ? 1 : 0;
  expectAtMostOneFalseAlarm(wrong);
}

// IMU-GNSS time offset, magnitude log-uniform over [1e-4, 0.1] s, random sign.
TEST(RunDiagnosisHidden, TimeOffset) {
  int wrong = 0;
  for (std::uint64_t seed : seeds(41301u, 41302u)) {
    std::mt19937_64 rng(seed);
    const double d = drawSigned(rng, limits::kTimeOffsetS.hi, 3.0);
    emu::SensorEffects fx;
    fx.time_offset_s = d;
    std::cout << "hidden time offset: seed " << seed << ", " << d << " s\n";
    const Hidden h{"time_offset", std::abs(d), kLimitTimeOffset, {{"all", "time_offset", d}}};
    wrong += checkHidden(an::diagnoseRun(hiddenOptions(emulateWithEffects("offset", seed, fx), seed + 1)), h) ? 1 : 0;
  }
  expectAtMostOneFalseAlarm(wrong);
}

// Antenna lever-arm error, one magnitude log-uniform over [0.01, 10] m, random sign per axis.
TEST(RunDiagnosisHidden, LeverArm) {
  int wrong = 0;
  for (std::uint64_t seed : seeds(41401u, 41402u)) {
    std::mt19937_64 rng(seed);
    const double m = std::abs(drawSigned(rng, limits::kLeverArmErrorM.hi, 3.0));
    emu::SensorEffects fx;
    Hidden h{"lever_arm", m, kLimitLeverArm, {}};
    const char* ax[3] = {"error_x", "error_y", "error_z"};
    for (int i = 0; i < 3; ++i) {
      fx.lever_arm_error_B_m(i) = (rng() & 1u) ? m : -m;
      h.truth.push_back({"gnss", ax[i], fx.lever_arm_error_B_m(i)});
    }
    std::cout << "hidden lever-arm error: seed " << seed << ", " << m << " m per axis\n";
    wrong += checkHidden(an::diagnoseRun(hiddenOptions(emulateWithEffects("lever", seed, fx), seed + 1)), h) ? 1 : 0;
  }
  expectAtMostOneFalseAlarm(wrong);
}

// An accelerometer bias random walk the model lacks (all three axes), density
// log-uniform over [1e-5, 1e-2] m/s^2/sqrt(s): bias_instability. The horizontal
// (acc_x, acc_y: one estimate, so its miss counts twice) and vertical (acc_z)
// intervals cover the truth, at most one miss. (Scaled as q T^5/20, a bias known at the outage start, they
// read 2-6x high and missed at most seeds: the filter that lacks the random walk
// starts each outage with a bias that has wandered since it last estimated it.)
TEST(RunDiagnosisHidden, BiasInstability) {
  int wrong = 0;
  for (std::uint64_t seed : seeds(41501u, 41502u)) {
    std::mt19937_64 rng(seed);
    const double q = std::abs(drawSigned(rng, 1e-2, 3.0));
    st::ImuModel m = st::loadImuModel(navimpact::test::sourcePath(kModel));
    for (int c = 3; c < 6; ++c)
      m.axis[c].terms.push_back(st::Process::rw(q / std::sqrt(m.axis[c].rate_hz > 0 ? m.axis[c].rate_hz : m.rate_hz)));
    const auto mfile = (navimpact::test::tempDir() / ("bias_" + std::to_string(seed) + ".yaml")).string();
    std::ofstream(mfile) << st::toYaml(m);
    std::cout << "hidden accelerometer bias random walk: seed " << seed << ", " << q << " m/s^2/sqrt(s)\n";
    const auto path = emulateRun("bias_" + std::to_string(seed), mfile, seed);
    const Hidden h{"bias_instability", q, kLimitBiasRandomWalk,
                   {{"acc_x", "rw_density", q}, {"acc_y", "rw_density", q}, {"acc_z", "rw_density", q}}};
    wrong += checkHidden(an::diagnoseRun(hiddenOptions(path, seed + 1)), h) ? 1 : 0;
  }
  expectAtMostOneFalseAlarm(wrong);
}
