// The start of a real run: levelling against its closed form, the static
// detector's false-alarm rate and power, and the coarse aligner on emulated
// ground-vehicle and airborne starts drawn at random (seeded; the draws are
// printed), judged against the truth with the sigmas it reports.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/filter/alignment.hpp"

using namespace navimpact;
using namespace ftest;

namespace {
double logUniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng));
}
}  // namespace

// At rest f_B = -C_NtoB g_N: levelling returns the attitude's roll and pitch
// for any heading (Groves 5.101) exactly when gravity is along the ellipsoid
// normal, and to within the deflection of normal gravity from the normal
// (a few microradians) with WGS84 normal gravity; an accelerometer bias b tilts it by
// d roll = -b_y/g, d pitch = b_x/g at level, to second order in |b|/g.
TEST(Alignment, LevellingMatchesClosedForms) {
  const std::uint64_t seed = 7031;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    ins::NavState x = staticState();
    const double r = 80.0 * kDeg * U(rng), p = 80.0 * kDeg * U(rng), y = M_PI * U(rng);
    x.setRollPitchYaw(r, p, y);
    const Vector3d g_N = earth::gravity_N(x.lat, x.h);
    const Vector3d f = -(x.C_BtoN().transpose() * Vector3d(0.0, 0.0, g_N.norm()));
    const Eigen::Vector2d rp = filter::levelRollPitch(f);
    EXPECT_NEAR(rp[0], r, 1e-12) << "seed " << seed << " draw " << k;
    EXPECT_NEAR(rp[1], p, 1e-12) << "seed " << seed << " draw " << k;
    const Eigen::Vector2d rp_wgs = filter::levelRollPitch(-(x.C_BtoN().transpose() * g_N));
    const double defl = std::atan2(g_N.head<2>().norm(), g_N.z());  // deflection of normal gravity
    EXPECT_LT(defl, 1e-5);
    // a tilt of the gravity vector by defl moves roll by up to defl / cos(pitch)
    EXPECT_NEAR(rp_wgs[0], r, 2.0 * defl / std::cos(p) + 1e-12) << "seed " << seed << " draw " << k;
    EXPECT_NEAR(rp_wgs[1], p, 2.0 * defl + 1e-12) << "seed " << seed << " draw " << k;
  }
  for (int k = 0; k < 200; ++k) {
    ins::NavState x = staticState();
    x.setRollPitchYaw(0.0, 0.0, M_PI * U(rng));
    const Vector3d b = 0.05 * Vector3d(U(rng), U(rng), U(rng));  // up to 5 mg
    const double g = earth::gravity_N(x.lat, x.h).norm();
    const Vector3d f = -(x.C_BtoN().transpose() * Vector3d(0.0, 0.0, g)) + b;
    const Eigen::Vector2d rp = filter::levelRollPitch(f);
    const double second = std::pow(b.norm() / g, 2);
    EXPECT_NEAR(rp[0], -b.y() / g, 2.0 * second + 1e-12) << "seed " << seed << " draw " << k;
    EXPECT_NEAR(rp[1], b.x() / g, 2.0 * second + 1e-12) << "seed " << seed << " draw " << k;
  }
  EXPECT_THROW(filter::levelRollPitch(Vector3d(0.1, 0.0, 0.2)), Error);
}

namespace {
/// White-noise samples of a body at rest with per-axis sigmas, plus a constant bias.
std::vector<ins::ImuSample> restSamples(int n, double rate, const Vector3d& sw, const Vector3d& sf,
                                        std::mt19937_64& rng, double t0 = 0.0) {
  std::normal_distribution<double> N01;
  const ins::NavState x = staticState();
  Vector3d w, f;
  staticRates(x, w, f);
  std::vector<ins::ImuSample> out(n);
  const double dt = 1.0 / rate;
  for (int k = 0; k < n; ++k) {
    Vector3d ew, ef;
    for (int a = 0; a < 3; ++a) {
      ew(a) = sw(a) * N01(rng);
      ef(a) = sf(a) * N01(rng);
    }
    out[k] = ins::ImuSample::fromRates(t0 + (k + 1) * dt, dt, w + ew + Vector3d(3e-4, -2e-4, 1e-4), f + ef);
  }
  return out;
}
}  // namespace

// Null: a body at rest with white noise of the stated sigmas (drawn log-uniform
// over three decades, rate 50-1000 Hz, window 0.1-1 s) is called "moving" in
// a fraction alpha of disjoint windows (binomial 4-sigma band), and the mean
// statistic is the chi-square dof 6 (W - 1).
TEST(Alignment, StaticDetectorFalseAlarmRateIsItsLevel) {
  const std::uint64_t seed = 4411;
  std::mt19937_64 rng(seed);
  long windows = 0, alarms = 0;
  double sum_ratio = 0.0;
  const double alpha = 0.05;
  for (int rec = 0; rec < 12; ++rec) {
    filter::StaticDetectorOptions o;
    const double rate = logUniform(rng, 50.0, 1000.0);
    o.window_s = logUniform(rng, 0.1, 1.0);
    for (int a = 0; a < 3; ++a) {
      o.gyro_sigma_rad_s(a) = logUniform(rng, 1e-5, 1e-2);
      o.acc_sigma_mps2(a) = logUniform(rng, 1e-4, 1e-1);
    }
    o.false_alarm = alpha;
    filter::StaticDetector det(o, rate);
    const int W = det.window();
    const auto s = restSamples(W * 60, rate, o.gyro_sigma_rad_s, o.acc_sigma_mps2, rng);
    for (std::size_t k = 0; k < s.size(); ++k) {
      const bool st = det.push(s[k]);
      if ((k + 1) % W == 0) {  // disjoint windows
        ++windows;
        alarms += st ? 0 : 1;
        sum_ratio += det.statistic() / det.dof();
      }
    }
    std::printf("  record %d: rate %.1f Hz, window %d samples, gyro sigma %.2e rad/s, acc sigma %.2e m/s^2\n",
                rec, rate, W, o.gyro_sigma_rad_s(0), o.acc_sigma_mps2(0));
  }
  const double rate = double(alarms) / windows;
  const double band = 4.0 * std::sqrt(alpha * (1 - alpha) / windows);
  std::printf("seed %llu: %ld of %ld windows at rest called moving (%.3f, level %.2f +- %.3f); mean T/dof %.4f\n",
              static_cast<unsigned long long>(seed), alarms, windows, rate, alpha, band, sum_ratio / windows);
  EXPECT_NEAR(rate, alpha, band);
  EXPECT_NEAR(sum_ratio / windows, 1.0, 0.02);
}

// Power: vibration (white, of the at-rest size: variance doubled) or a steady
// turn of 0.1 rad/s without extra noise is "moving" in every full window.
TEST(Alignment, StaticDetectorSeesVibrationAndSteadyTurns) {
  const std::uint64_t seed = 4412;
  std::mt19937_64 rng(seed);
  filter::StaticDetectorOptions o;
  o.gyro_sigma_rad_s.setConstant(2e-3);
  o.acc_sigma_mps2.setConstant(2e-2);
  const double rate = 200.0;
  filter::StaticDetector vib(o, rate), turn(o, rate);
  const auto a = restSamples(4000, rate, o.gyro_sigma_rad_s * std::sqrt(2.0), o.acc_sigma_mps2 * std::sqrt(2.0), rng);
  auto b = restSamples(4000, rate, o.gyro_sigma_rad_s, o.acc_sigma_mps2, rng);
  for (auto& s : b) s.dtheta_B.z() += 0.1 * s.dt;
  int vib_static = 0, turn_static = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    vib_static += vib.push(a[k]) ? 1 : 0;
    turn_static += turn.push(b[k]) ? 1 : 0;
  }
  EXPECT_EQ(vib_static, 0) << "seed " << seed;
  EXPECT_EQ(turn_static, 0) << "seed " << seed;
  EXPECT_THROW(filter::StaticDetector(o, 2.0), Error);  // window of 1 sample
}

namespace {

/// A smooth ground-vehicle or airborne trajectory built in code: at rest for
/// t_rest, then accelerating to `speed` along a heading that turns at `turn`.
struct Scenario {
  double rate = 100.0;           // IMU [Hz]
  double t_rest = 0.0;           // [s]
  double speed = 1.0;            // [m/s]
  double accel_time = 3.0;       // [s] to reach speed
  double yaw0 = 0.0, turn = 0.0; // [rad], [rad/s] once moving
  double roll = 0.0, pitch = 0.0;
  double duration = 60.0;        // [s]
  double climb = 0.0;            // [m/s] vertical speed once moving (up)
};

emulation::SmoothTrajectory makeTrajectory(const Scenario& sc) {
  emulation::SampledTrajectory s;
  s.origin = {52.2 * kDeg, 4.4 * kDeg, 45.0};
  double dist = 0.0, yaw = sc.yaw0;
  Vector3d p = Vector3d::Zero();
  const double h = 0.02;
  for (double t = -2.0; t <= sc.duration + 2.0 + 1e-9; t += h) {
    const double tm = t - sc.t_rest;
    double v = 0.0;
    if (tm > 0.0) {
      const double u = std::min(tm / sc.accel_time, 1.0);
      v = sc.speed * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);  // smooth 0 -> speed
    }
    if (tm > 0.0) yaw += sc.turn * (v / sc.speed) * h;
    p += Vector3d(std::cos(yaw), std::sin(yaw), -sc.climb / sc.speed) * v * h;
    dist += v * h;
    s.t.push_back(t);
    s.p_L.push_back(p);
    s.rpy.push_back(Vector3d(sc.roll, sc.pitch, yaw));
  }
  emulation::SmoothingOptions so;
  so.position_cutoff_hz = 2.0;
  so.attitude_cutoff_hz = 2.0;
  return emulation::SmoothTrajectory(s, so);
}

struct AlignOutcome {
  bool done = false;
  filter::Vector9d err, sigma;
  filter::AlignmentReport rep;
};

/// Run the aligner over an emulated start: IMU with white noise and constant
/// biases, GNSS fixes every gnss_dt from a random phase (never on an IMU
/// sample), antenna at the lever arm, position noise sigma_p, optional velocity.
AlignOutcome runAligner(const Scenario& sc, filter::AlignmentOptions opt, double gnss_dt, double sigma_p,
                        bool with_velocity, double sigma_v, const Vector3d& bw, const Vector3d& bf,
                        double noise_w, double noise_f, std::mt19937_64& rng) {
  const emulation::SmoothTrajectory tr = makeTrajectory(sc);
  std::normal_distribution<double> N01;
  const double dt = 1.0 / sc.rate;
  const double phase = std::uniform_real_distribution<double>(0.1, 0.9)(rng) * gnss_dt;
  double t_fix = phase;
  filter::CoarseAligner al(opt, 0.0, sc.rate);
  AlignOutcome out;
  const int n = static_cast<int>(sc.duration * sc.rate);
  for (int k = 1; k <= n && !al.done(); ++k) {
    const double ta = (k - 1) * dt, tb = k * dt;
    Vector3d dv, dth;
    tr.increments(ta, tb, dv, dth);
    for (int a = 0; a < 3; ++a) {
      dth(a) += (bw(a) + noise_w * N01(rng)) * dt;
      dv(a) += (bf(a) + noise_f * N01(rng)) * dt;
    }
    al.addImu(ins::ImuSample{tb, dt, dth, dv});
    while (t_fix <= tb && !al.done()) {
      const emulation::TruthState ts = tr.at(t_fix);
      filter::AlignmentFix f;
      f.t = t_fix;
      Vector3d e(sigma_p * N01(rng), sigma_p * N01(rng), sigma_p * N01(rng));
      f.pos = earth::nedToGeodetic(ts.pos, ts.C_BtoN * opt.lever_arm_B + e);
      f.sigma_pos_N.setConstant(sigma_p);
      if (with_velocity) {
        f.v_N = ts.v_N + ts.C_BtoN * (ts.w_IB_B - ts.C_BtoN.transpose() * ts.w_IE_N).cross(opt.lever_arm_B) +
                sigma_v * Vector3d(N01(rng), N01(rng), N01(rng));
        f.sigma_vel_N.setConstant(sigma_v);
      }
      al.addFix(f);
      t_fix += gnss_dt;
    }
  }
  out.done = al.done();
  if (!out.done) return out;
  out.rep = al.report();
  out.err = filter::navError(al.state(), emulation::truthNavState(tr, al.state().t));
  out.sigma = al.P0().diagonal().cwiseSqrt();
  return out;
}

void expectWithin(const AlignOutcome& o, double k, const std::string& what) {
  ASSERT_TRUE(o.done) << what;
  for (int i = 0; i < 9; ++i)
    EXPECT_LE(std::abs(o.err(i)), k * o.sigma(i))
        << what << ": state " << i << " error " << o.err(i) << " sigma " << o.sigma(i);
}

}  // namespace

// A rover at rest, then driving slowly (0.1-2 m/s) with gentle turns;
// position-only GNSS every 0.2-3 s (1 cm - 0.5 m), lever arm up to 1.6 m,
// heading unknown: static levelling, heading from the GNSS chord course, the
// start at the first fix that gives a velocity. Every error within 4 reported sigmas.
TEST(Alignment, RoverAtRestThenDrivingWithPositionOnlyGnss) {
  const std::uint64_t seed = 5150;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    Scenario sc;
    sc.rate = logUniform(rng, 50.0, 400.0);
    sc.t_rest = 5.0 + 15.0 * std::abs(U(rng));
    sc.speed = logUniform(rng, 0.1, 2.0);
    sc.yaw0 = M_PI * U(rng);
    sc.turn = 0.02 * U(rng);
    sc.roll = 4.0 * kDeg * U(rng);
    sc.pitch = 4.0 * kDeg * U(rng);
    sc.duration = sc.t_rest + 90.0;
    filter::AlignmentOptions opt;
    opt.lever_arm_B = Vector3d(0.5 * U(rng), 0.2 * U(rng), -1.6 * std::abs(U(rng)));
    const double noise_w = 1e-3, noise_f = 1e-2;
    opt.detector.gyro_sigma_rad_s.setConstant(noise_w);
    opt.detector.acc_sigma_mps2.setConstant(noise_f);
    const Vector3d bf = 0.01 * Vector3d(U(rng), U(rng), U(rng));
    const Vector3d bw = 2e-4 * Vector3d(U(rng), U(rng), U(rng));
    opt.acc_bias_sigma_mps2 = 0.01;
    opt.gyro_bias_sigma_rad_s = 1e-5;  // after the at-rest mean is removed: its noise only
    const double gnss_dt = logUniform(rng, 0.2, 3.0), sigma_p = logUniform(rng, 0.01, 0.5);
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "seed %llu trial %d: rate %.1f Hz, rest %.1f s, speed %.2f m/s, yaw0 %.1f deg, turn %.3f rad/s, "
                  "GNSS every %.2f s sigma %.3f m, lever [%.2f %.2f %.2f] m",
                  static_cast<unsigned long long>(seed), trial, sc.rate, sc.t_rest, sc.speed, sc.yaw0 / kDeg,
                  sc.turn, gnss_dt, sigma_p, opt.lever_arm_B.x(), opt.lever_arm_B.y(), opt.lever_arm_B.z());
    const AlignOutcome o = runAligner(sc, opt, gnss_dt, sigma_p, false, 0.0, bw, bf, noise_w, noise_f, rng);
    std::printf("%s\n", buf);
    ASSERT_TRUE(o.done) << buf;
    std::printf("  -> %s / %s, aligned at %.2f s, yaw error %.3f deg (sigma %.3f), tilt error %.3f %.3f deg (sigma %.3f)\n",
                o.rep.levelling.c_str(), o.rep.heading.c_str(), o.rep.t_end, o.err(8) / kDeg, o.sigma(8) / kDeg,
                o.err(6) / kDeg, o.err(7) / kDeg, o.sigma(6) / kDeg);
    EXPECT_EQ(o.rep.levelling, "static") << buf;
    EXPECT_EQ(o.rep.heading, "gnss_chord_course") << buf;
    EXPECT_GE(o.rep.level_span_s, sc.t_rest - 1.0) << buf;
    EXPECT_GT(o.rep.t_end, sc.t_rest) << buf;
    expectWithin(o, 4.0, buf);
  }
}

// Airborne start: moving from the first sample (8-25 m/s, climbing, turning),
// GNSS position and velocity at 1-5 Hz: levelling by the GNSS velocity change,
// heading from the velocity course, over the first two GNSS intervals.
TEST(Alignment, MovingStartWithGnssVelocity) {
  const std::uint64_t seed = 5151;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    Scenario sc;
    sc.rate = logUniform(rng, 100.0, 400.0);
    sc.t_rest = -10.0;  // already at speed
    sc.speed = 8.0 + 17.0 * std::abs(U(rng));
    sc.yaw0 = M_PI * U(rng);
    sc.turn = 0.05 * U(rng);
    sc.roll = 10.0 * kDeg * U(rng);
    sc.pitch = 5.0 * kDeg * U(rng);
    sc.climb = 1.0 * U(rng);
    sc.duration = 20.0;
    filter::AlignmentOptions opt;
    opt.lever_arm_B = Vector3d(0.5 * U(rng), 0.2 * U(rng), -0.3 * std::abs(U(rng)));
    opt.acc_bias_sigma_mps2 = 0.01;
    opt.gyro_bias_sigma_rad_s = 2e-4;
    const Vector3d bf = 0.01 * Vector3d(U(rng), U(rng), U(rng));
    const Vector3d bw = 2e-4 * Vector3d(U(rng), U(rng), U(rng));
    const double gnss_dt = 1.0 / (1.0 + 4.0 * std::abs(U(rng)));
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "seed %llu trial %d: rate %.1f Hz, speed %.1f m/s, yaw0 %.1f deg, turn %.3f rad/s, roll %.1f deg, "
                  "GNSS every %.2f s",
                  static_cast<unsigned long long>(seed), trial, sc.rate, sc.speed, sc.yaw0 / kDeg, sc.turn,
                  sc.roll / kDeg, gnss_dt);
    const AlignOutcome o = runAligner(sc, opt, gnss_dt, 0.5, true, 0.05, bw, bf, 1e-3, 1e-2, rng);
    std::printf("%s\n", buf);
    ASSERT_TRUE(o.done) << buf;
    std::printf("  -> %s / %s, aligned at %.2f s, yaw error %.3f deg (sigma %.3f), tilt error %.3f %.3f deg (sigma %.3f)\n",
                o.rep.levelling.c_str(), o.rep.heading.c_str(), o.rep.t_end, o.err(8) / kDeg, o.sigma(8) / kDeg,
                o.err(6) / kDeg, o.err(7) / kDeg, o.sigma(6) / kDeg);
    EXPECT_EQ(o.rep.levelling, "gnss_velocity") << buf;
    EXPECT_EQ(o.rep.heading, "gnss_velocity_course") << buf;
    EXPECT_LE(o.rep.t_end, 3.0 * gnss_dt + 0.1) << buf;  // two intervals after the first fix
    expectWithin(o, 4.0, buf);
  }
}

// A given heading (configuration or reference): static levelling, then the
// start at the next fix; the yaw is the given one, carried by the gyros.
TEST(Alignment, GivenHeadingAndNoMotionNeeded) {
  const std::uint64_t seed = 5152;
  std::mt19937_64 rng(seed);
  Scenario sc;
  sc.rate = 125.0;
  sc.t_rest = 1e9;  // never moves
  sc.yaw0 = -20.0 * kDeg;
  sc.roll = 0.65 * kDeg;
  sc.pitch = -2.5 * kDeg;
  sc.duration = 80.0;
  filter::AlignmentOptions opt;
  opt.yaw_rad = -19.0 * kDeg;  // 1 deg off
  opt.yaw_sigma_rad = 2.0 * kDeg;
  opt.max_level_s = 30.0;
  opt.acc_bias_sigma_mps2 = 0.01;
  const AlignOutcome o = runAligner(sc, opt, 1.0, 0.01, false, 0.0, Vector3d::Zero(), Vector3d(0.003, -0.002, 0.0),
                                    1e-3, 1e-2, rng);
  ASSERT_TRUE(o.done);
  EXPECT_EQ(o.rep.heading, "configuration");
  EXPECT_EQ(o.rep.levelling, "static");
  EXPECT_NEAR(o.rep.level_span_s, 30.0, 0.5);  // whole detector windows
  EXPECT_LE(o.rep.t_end, 31.5);
  EXPECT_TRUE(o.rep.static_at_end);
  EXPECT_NEAR(o.err(8), 1.0 * kDeg, 0.01 * kDeg);  // the given yaw's error, kept
  // tilt error = accelerometer bias / g (closed form), within 4 sigma of the
  // mean's noise (1e-2 m/s^2 per sample over the levelling span) and of the
  // gyro noise integrated from the levelling to the end (1e-3 rad/s per sample)
  const double n_level = o.rep.level_span_s * sc.rate;
  const double t_gyro = o.rep.t_end - o.rep.level_span_s;
  const double tol = 4.0 * std::sqrt(std::pow(1e-2 / 9.81, 2) / n_level + 1e-6 * t_gyro / sc.rate);
  std::printf("tilt tolerance %.2e rad (levelled over %.2f s, gyro-carried %.2f s)\n", tol, o.rep.level_span_s, t_gyro);
  EXPECT_NEAR(o.rep.rpy[0] - sc.roll, 0.002 / 9.81, tol);   // d roll = -b_y / g
  EXPECT_NEAR(o.rep.rpy[1] - sc.pitch, 0.003 / 9.81, tol);  // d pitch = b_x / g
  expectWithin(o, 4.0, "given heading");
}

// A heading given at a later time t_y (a reference whose attitude starts after
// the IMU data): the aligner waits for it and carries it to the start through
// the gyros, also when the vehicle turns in between (up to 0.05 rad/s: a yaw
// taken as the start's would be off by up to 0.05 t_y rad). Rovers at rest
// then driving (position-only GNSS; t_y at rest or while driving) and airborne
// starts (GNSS velocity, a course available before t_y), drawn at random
// (seeded, printed); the given yaw is the true one at t_y plus an error drawn
// from its stated sigma. Every error within 4 reported sigmas, the heading
// from the given yaw, the phase ending at or after t_y.
TEST(Alignment, HeadingGivenLaterIsCarriedToTheStart) {
  const std::uint64_t seed = 5154;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::normal_distribution<double> N01;
  for (int trial = 0; trial < 8; ++trial) {
    const bool airborne = trial % 2 == 1;
    Scenario sc;
    sc.rate = logUniform(rng, 100.0, 400.0);
    sc.yaw0 = M_PI * U(rng);
    sc.turn = 0.05 * U(rng);
    sc.roll = 4.0 * kDeg * U(rng);
    sc.pitch = 4.0 * kDeg * U(rng);
    if (airborne) {
      sc.t_rest = -10.0;
      sc.speed = 8.0 + 17.0 * std::abs(U(rng));
    } else {
      sc.t_rest = 5.0 + 15.0 * std::abs(U(rng));
      sc.speed = logUniform(rng, 0.5, 2.0);
    }
    const double t_y = airborne ? 0.5 + 14.5 * std::abs(U(rng)) : 1.0 + (sc.t_rest + 29.0) * std::abs(U(rng));
    sc.duration = std::max(t_y, std::max(sc.t_rest, 0.0)) + 60.0;
    filter::AlignmentOptions opt;
    opt.lever_arm_B = Vector3d(0.5 * U(rng), 0.2 * U(rng), -0.5 * std::abs(U(rng)));
    opt.acc_bias_sigma_mps2 = 0.01;
    opt.gyro_bias_sigma_rad_s = airborne ? 2e-4 : 1e-5;
    opt.detector.gyro_sigma_rad_s.setConstant(1e-3);
    opt.detector.acc_sigma_mps2.setConstant(1e-2);
    opt.yaw_sigma_rad = 1.0 * kDeg;
    const ins::NavState truth_y = emulation::truthNavState(makeTrajectory(sc), t_y);
    const double yaw_true_y = truth_y.rollPitchYaw()[2], yaw_true_0 = emulation::truthNavState(makeTrajectory(sc), 0.0).rollPitchYaw()[2];
    const double yaw_err = opt.yaw_sigma_rad * N01(rng);
    opt.yaw_rad = yaw_true_y + yaw_err;
    opt.yaw_t_s = t_y;
    opt.yaw_source = "reference";
    const Vector3d bf = 0.01 * Vector3d(U(rng), U(rng), U(rng));
    const Vector3d bw = (airborne ? 2e-4 : 1e-5) * Vector3d(U(rng), U(rng), U(rng));
    const double gnss_dt = airborne ? 1.0 / (1.0 + 4.0 * std::abs(U(rng))) : logUniform(rng, 0.2, 3.0);
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "seed %llu trial %d (%s): rate %.1f Hz, rest %.1f s, speed %.2f m/s, turn %.3f rad/s, yaw given at "
                  "%.2f s (true yaw there %.2f deg, at the start %.2f deg), GNSS every %.2f s",
                  static_cast<unsigned long long>(seed), trial, airborne ? "airborne" : "rover", sc.rate, sc.t_rest,
                  sc.speed, sc.turn, t_y, yaw_true_y / kDeg, yaw_true_0 / kDeg, gnss_dt);
    const AlignOutcome o =
        runAligner(sc, opt, gnss_dt, airborne ? 0.5 : 0.05, airborne, 0.05, bw, bf, 1e-3, 1e-2, rng);
    std::printf("%s\n", buf);
    ASSERT_TRUE(o.done) << buf;
    std::printf("  -> %s / %s at %.3f s, aligned at %.2f s, yaw error %.3f deg (sigma %.3f; given yaw's error %.3f), tilt "
                "error %.3f %.3f deg (sigma %.3f)\n",
                o.rep.levelling.c_str(), o.rep.heading.c_str(), o.rep.heading_t, o.rep.t_end, o.err(8) / kDeg,
                o.sigma(8) / kDeg, yaw_err / kDeg, o.err(6) / kDeg, o.err(7) / kDeg, o.sigma(6) / kDeg);
    EXPECT_EQ(o.rep.heading, "reference") << buf;
    EXPECT_NEAR(o.rep.heading_t, t_y, 0.5 / sc.rate + 1e-9) << buf;
    EXPECT_GE(o.rep.t_end, t_y) << buf;
    EXPECT_EQ(o.rep.levelling, airborne ? "gnss_velocity" : "static") << buf;
    expectWithin(o, 4.0, buf);
  }
  // a heading given later than max_align_s after the start is refused; one
  // not reached yet is what the aligner says it misses
  filter::AlignmentOptions opt;
  opt.yaw_rad = 0.3;
  opt.yaw_t_s = 700.0;
  EXPECT_THROW(filter::CoarseAligner(opt, 0.0, 100.0), Error);
  opt.yaw_t_s = 20.0;
  const filter::CoarseAligner al(opt, 0.0, 100.0);
  EXPECT_NE(al.missing().find("waiting for the configuration's yaw at t = 20 s"), std::string::npos) << al.missing();
}

// A vehicle that never moves and no heading: the aligner keeps aligning and
// says what is missing; after max_align_s it throws naming it.
TEST(Alignment, NoMotionNoHeadingSaysWhatIsMissing) {
  std::mt19937_64 rng(5153);
  Scenario sc;
  sc.t_rest = 1e9;
  sc.duration = 30.0;
  filter::AlignmentOptions opt;
  opt.max_level_s = 5.0;
  const AlignOutcome o = runAligner(sc, opt, 1.0, 0.01, false, 0.0, Vector3d::Zero(), Vector3d::Zero(), 1e-3,
                                    1e-2, rng);
  EXPECT_FALSE(o.done);
  opt.max_align_s = 10.0;
  try {
    runAligner(sc, opt, 1.0, 0.01, false, 0.0, Vector3d::Zero(), Vector3d::Zero(), 1e-3, 1e-2, rng);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("heading"), std::string::npos) << e.what();
  }
}
