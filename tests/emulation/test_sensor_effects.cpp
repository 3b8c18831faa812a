// Sensor effects of an emulated run (sensor_effects.hpp): each effect against
// its definition, with parameters drawn at random over the documented range
// (seeds and values printed).
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace ins = navimpact::ins;
namespace lim = navimpact::limits;
using Eigen::Vector3d;

namespace {

constexpr double kRate = 200.0, kDt = 1.0 / kRate;

double uniform(std::mt19937_64& g, const lim::Range& r) {
  return std::uniform_real_distribution<double>(r.lo, r.hi)(g);
}
Vector3d uniform3(std::mt19937_64& g, const lim::Range& r) { return {uniform(g, r), uniform(g, r), uniform(g, r)}; }

// Rates of axis a: amp_a sin(2 pi f_a t + ph_a) + offset_a; exact increments
// over (t - dt, t] from the closed-form integral.
struct Sinusoids {
  std::array<double, 6> amp{}, f{}, ph{}, off{};
  double integral(int a, double t) const {
    const double w = 2 * M_PI * f[a];
    return -amp[a] / w * std::cos(w * t + ph[a]) + off[a] * t;
  }
  double rate(int a, double t) const { return amp[a] * std::sin(2 * M_PI * f[a] * t + ph[a]) + off[a]; }
  ins::ImuSample sample(double ta, double tb) const {
    ins::ImuSample s;
    s.t = tb;
    s.dt = tb - ta;
    for (int a = 0; a < 3; ++a) {
      s.dtheta_B(a) = integral(a, tb) - integral(a, ta);
      s.dv_B(a) = integral(3 + a, tb) - integral(3 + a, ta);
    }
    return s;
  }
  std::vector<ins::ImuSample> imu(double t0, std::size_t n) const {
    std::vector<ins::ImuSample> v(n);
    for (std::size_t k = 0; k < n; ++k) v[k] = sample(t0 + double(k) * kDt, t0 + double(k + 1) * kDt);
    return v;
  }
};

Sinusoids randomSinusoids(std::mt19937_64& g) {
  Sinusoids s;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int a = 0; a < 6; ++a) {
    s.amp[a] = a < 3 ? 0.1 + 1.9 * u(g) : 0.5 + 9.5 * u(g);  // rad/s, m/s^2
    s.f[a] = 0.05 + 2.95 * u(g);                            // Hz
    s.ph[a] = 2 * M_PI * u(g);
    s.off[a] = a == 5 ? -9.81 : 0.0;
  }
  return s;
}

std::array<std::vector<double>, 6> randomErrors(std::size_t n, std::uint64_t seed) {
  std::array<std::vector<double>, 6> e;
  for (int a = 0; a < 6; ++a) {
    e[a] = emu::standardNormal(n, navimpact::stochastic::deriveSeed(seed, a));
    for (double& v : e[a]) v *= a < 3 ? 1e-3 : 1e-2;
  }
  return e;
}

using navimpact::test::errorOf;

/// Random sinusoids (@p n samples from @p g) before and after an effect on
/// both triads, each axis uniform over @p range (the effect printed with @p seed).
struct TriadApplied {
  std::vector<ins::ImuSample> perfect, out;
  emu::SensorEffects fx;
};
TriadApplied applyTriadEffect(std::mt19937_64& g, std::uint64_t seed, std::size_t n, Vector3d emu::SensorEffects::*gyro,
                              Vector3d emu::SensorEffects::*acc, const lim::Range& range) {
  TriadApplied r;
  r.perfect = randomSinusoids(g).imu(0.0, n);
  r.fx.*gyro = uniform3(g, range);
  r.fx.*acc = uniform3(g, range);
  std::printf("seed %llu: %s\n", (unsigned long long)seed, emu::describeEffects(r.fx).c_str());
  r.out = emu::applySensorEffects(r.perfect, {}, r.fx, {}, 1).imu;
  return r;
}

}  // namespace

TEST(SensorEffects, NoEffectGivesExactlyPerfectPlusErrors) {
  std::mt19937_64 g(11);
  const auto perfect = randomSinusoids(g).imu(3.0, 4000);
  const auto err = randomErrors(perfect.size(), 5);
  emu::SensorEffects fx;
  ASSERT_TRUE(fx.none());
  fx.gyro_motion_noise_factor = 1.0;
  const auto out = emu::applySensorEffects(perfect, err, fx, {1, 1, 1, 1, 1, 1}, 9);
  ASSERT_EQ(out.imu.size(), perfect.size());
  for (std::size_t k = 0; k < perfect.size(); ++k) {
    ins::ImuSample s = perfect[k];  // what analysis::emulateRun does
    for (int a = 0; a < 3; ++a) {
      s.dtheta_B(a) += err[a][k] * s.dt;
      s.dv_B(a) += err[3 + a][k] * s.dt;
    }
    ASSERT_EQ(out.imu[k].t, s.t);
    ASSERT_EQ(out.imu[k].dt, s.dt);
    ASSERT_EQ(out.imu[k].dtheta_B, s.dtheta_B) << k;
    ASSERT_EQ(out.imu[k].dv_B, s.dv_B) << k;
  }
  EXPECT_EQ(out.description, "none");
}

TEST(SensorEffects, ScaleFactorAddsScaleTimesTrue) {
  const std::uint64_t seed = 21;
  std::mt19937_64 g(seed);
  const auto [perfect, out, fx] =
      applyTriadEffect(g, seed, 2000, &emu::SensorEffects::gyro_scale, &emu::SensorEffects::acc_scale, lim::kScaleFactor);
  for (std::size_t k = 0; k < perfect.size(); ++k) {
    const Vector3d dg = out[k].dtheta_B - perfect[k].dtheta_B, da = out[k].dv_B - perfect[k].dv_B;
    const Vector3d eg = fx.gyro_scale.cwiseProduct(perfect[k].dtheta_B), ea = fx.acc_scale.cwiseProduct(perfect[k].dv_B);
    for (int a = 0; a < 3; ++a) {
      ASSERT_NEAR(dg(a), eg(a), 4e-16 * std::abs(perfect[k].dtheta_B(a)) + 1e-300) << k;
      ASSERT_NEAR(da(a), ea(a), 4e-16 * std::abs(perfect[k].dv_B(a)) + 1e-300) << k;
    }
  }
}

TEST(SensorEffects, MisalignmentAndNonOrthogonalityAreTheDocumentedMatrix) {
  const std::uint64_t seed = 22;
  std::mt19937_64 g(seed);
  const auto [perfect, out, fx] = applyTriadEffect(g, seed, 1000, &emu::SensorEffects::gyro_misalignment_rad,
                                                   &emu::SensorEffects::acc_misalignment_rad, lim::kMisalignmentRad);
  for (std::size_t k = 0; k < perfect.size(); ++k) {
    // measured - true = m x true (a rotation of the triad by -m, to first order)
    const Vector3d eg = fx.gyro_misalignment_rad.cross(perfect[k].dtheta_B);
    const Vector3d ea = fx.acc_misalignment_rad.cross(perfect[k].dv_B);
    ASSERT_LT((out[k].dtheta_B - perfect[k].dtheta_B - eg).norm(), 1e-15 * perfect[k].dtheta_B.norm() + 1e-300);
    ASSERT_LT((out[k].dv_B - perfect[k].dv_B - ea).norm(), 1e-15 * perfect[k].dv_B.norm() + 1e-300);
  }
  // Non-orthogonality: symmetric off-diagonal, zero trace, no rotation part.
  emu::SensorEffects no;
  no.gyro_nonorthogonality_rad = uniform3(g, lim::kMisalignmentRad);
  const Eigen::Matrix3d D = no.gyroMatrix() - Eigen::Matrix3d::Identity();
  EXPECT_EQ(D, D.transpose());
  EXPECT_EQ(D.diagonal(), Vector3d::Zero());
  EXPECT_EQ(D(1, 2), no.gyro_nonorthogonality_rad.x());
  EXPECT_EQ(D(0, 2), no.gyro_nonorthogonality_rad.y());
  EXPECT_EQ(D(0, 1), no.gyro_nonorthogonality_rad.z());
}

TEST(SensorEffects, TimeOffsetShiftsAKnownSinusoid) {
  const std::uint64_t seed = 23;
  std::mt19937_64 g(seed);
  for (int trial = 0; trial < 8; ++trial) {
    const Sinusoids s = randomSinusoids(g);
    const double d = uniform(g, lim::kTimeOffsetS);
    const double t0 = 10.0;
    const std::size_t n = 4000;  // 20 s
    const auto perfect = s.imu(t0, n);
    emu::SensorEffects fx;
    fx.time_offset_s = d;
    const auto out = emu::applySensorEffects(perfect, {}, fx, {}, 1).imu;
    std::printf("seed %llu trial %d: time offset %.6f s\n", (unsigned long long)seed, trial, d);
    std::size_t checked = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const double ta = perfect[k].t - perfect[k].dt - d, tb = perfect[k].t - d;
      if (ta < t0 || tb > t0 + double(n) * kDt) continue;  // ends: held rate, below
      const ins::ImuSample want = s.sample(ta, tb);
      for (int a = 0; a < 6; ++a) {
        const double w = 2 * M_PI * s.f[a];
        // 4-point Lagrange of the cumulative integral C: |error| <= |C''''| h^4 / 4!
        // at each end of the interval (C'''' = amp w^3), plus round-off of C.
        const double tol = 2.0 * s.amp[a] * w * w * w * std::pow(kDt, 4) / 24.0 +
                           1e-14 * (s.amp[a] / w + std::abs(s.off[a]) * 40.0);
        const double got = a < 3 ? out[k].dtheta_B(a) : out[k].dv_B(a - 3);
        const double exp = a < 3 ? want.dtheta_B(a) : want.dv_B(a - 3);
        ASSERT_NEAR(got, exp, tol) << "trial " << trial << " sample " << k << " axis " << a;
      }
      ++checked;
    }
    EXPECT_GT(checked, n - std::size_t(std::ceil(std::abs(d) * kRate)) - 2);
    // Beyond the record the first (d > 0) or last (d < 0) sample's rate is held.
    const ins::ImuSample& edge = d > 0 ? out.front() : out.back();
    const ins::ImuSample& src = d > 0 ? perfect.front() : perfect.back();
    if (std::abs(d) > 2 * kDt) {
      EXPECT_NEAR((edge.dtheta_B - src.dtheta_B).norm(), 0.0, 1e-12);
      EXPECT_NEAR((edge.dv_B - src.dv_B).norm(), 0.0, 1e-11);
    }
  }
}

TEST(SensorEffects, TimeOffsetOfWholeSamplesMovesTheSamples) {
  std::mt19937_64 g(24);
  const auto perfect = randomSinusoids(g).imu(0.0, 1000);
  for (int j : {1, 3, -7}) {
    const auto out = emu::shiftImuTime(perfect, j * kDt);
    for (std::size_t k = 20; k < 980; ++k) {
      const auto& src = perfect[std::size_t(long(k) - j)];
      ASSERT_LT((out[k].dtheta_B - src.dtheta_B).norm(), 1e-13) << j << " " << k;
      ASSERT_LT((out[k].dv_B - src.dv_B).norm(), 1e-12) << j << " " << k;
    }
  }
}

TEST(SensorEffects, MotionNoiseInflatesTheWhiteNoiseOnlyWhileMoving) {
  const std::uint64_t seed = 25;
  std::mt19937_64 g(seed);
  // 50 s at rest (level: f = (0, 0, -g)), then 50 s turning at 0.3 rad/s.
  const std::size_t half = 10000, n = 2 * half;
  std::vector<ins::ImuSample> perfect(n);
  for (std::size_t k = 0; k < n; ++k)
    perfect[k] = ins::ImuSample::fromRates(double(k + 1) * kDt, kDt, Vector3d(0, 0, k < half ? 0.0 : 0.3),
                                           Vector3d(0, 0, -9.80665));
  emu::SensorEffects fx;
  fx.gyro_motion_noise_factor = uniform(g, lim::kMotionNoiseFactor);
  fx.acc_motion_noise_factor = uniform(g, lim::kMotionNoiseFactor);
  const std::array<double, 6> sigma{1e-3, 2e-3, 3e-3, 1e-2, 2e-2, 3e-2};
  std::array<std::vector<double>, 6> err;
  for (int a = 0; a < 6; ++a) {
    err[a] = emu::standardNormal(n, navimpact::stochastic::deriveSeed(seed + 1, a));
    for (double& v : err[a]) v *= sigma[a];
  }
  std::printf("seed %llu: %s\n", (unsigned long long)seed, emu::describeEffects(fx).c_str());
  const auto out = emu::applySensorEffects(perfect, err, fx, sigma, seed + 2);
  EXPECT_EQ(out.moving_samples, half);
  for (int a = 0; a < 6; ++a) {
    const double k = a < 3 ? fx.gyro_motion_noise_factor : fx.acc_motion_noise_factor;
    for (int part = 0; part < 2; ++part) {
      double ss = 0;
      for (std::size_t i = part * half; i < (part + 1) * half; ++i) {
        const double r = a < 3 ? (out.imu[i].dtheta_B(a) - perfect[i].dtheta_B(a)) / kDt
                               : (out.imu[i].dv_B(a - 3) - perfect[i].dv_B(a - 3)) / kDt;
        ss += r * r;
      }
      const double sd = std::sqrt(ss / double(half)), want = sigma[a] * (part ? k : 1.0);
      // sample std of N normal values: relative standard error 1/sqrt(2N); 4.5 of them.
      EXPECT_NEAR(sd / want, 1.0, 4.5 / std::sqrt(2.0 * half)) << "axis " << a << " part " << part;
    }
  }
  // Seeded: the same seed repeats, another seed differs.
  const auto again = emu::applySensorEffects(perfect, err, fx, sigma, seed + 2);
  const auto other = emu::applySensorEffects(perfect, err, fx, sigma, seed + 3);
  EXPECT_EQ(again.imu.back().dtheta_B, out.imu.back().dtheta_B);
  EXPECT_NE(other.imu.back().dtheta_B, out.imu.back().dtheta_B);
}

TEST(SensorEffects, LeverArmErrorMovesTheTrueAntenna) {
  const std::uint64_t seed = 26;
  std::mt19937_64 g(seed);
  emu::GnssOptions told;
  told.lever_arm_B = Vector3d(0.5, -0.2, -1.0);
  emu::SensorEffects fx;
  fx.lever_arm_error_B_m = uniform3(g, lim::kLeverArmErrorM);
  std::printf("seed %llu: %s\n", (unsigned long long)seed, emu::describeEffects(fx).c_str());
  const auto truth = emu::gnssWithEffects(told, fx);
  // estimate minus truth: told - true = error
  EXPECT_LT((told.lever_arm_B - truth.lever_arm_B - fx.lever_arm_error_B_m).norm(), 1e-15);
  EXPECT_EQ(truth.seed, told.seed);
  EXPECT_EQ(truth.sigma_pos_h_m, told.sigma_pos_h_m);
}

TEST(SensorEffects, WhiteNoiseSigmaAtTheImuRate) {
  navimpact::stochastic::ImuModel m;
  m.rate_hz = 100.0;
  for (int a = 0; a < 6; ++a) m.axis[a].rate_hz = 100.0;
  m.axis[0].terms = {navimpact::stochastic::Process::wn(3e-3), navimpact::stochastic::Process::gm(1e-4, 10.0),
                     navimpact::stochastic::Process::wn(4e-3)};
  m.axis[4].terms = {navimpact::stochastic::Process::gm(1e-4, 10.0)};
  const auto s = emu::whiteNoiseSigma(m, 200.0);
  EXPECT_NEAR(s[0], 5e-3 * std::sqrt(2.0), 1e-15);  // same noise density at twice the rate
  EXPECT_EQ(s[1], 0.0);
  EXPECT_EQ(s[4], 0.0);
}

TEST(SensorEffects, OutOfRangeValuesAreErrorsNamingTheKey) {
  emu::SensorEffects fx;
  fx.gyro_scale.y() = 0.06;
  EXPECT_EQ(errorOf([&] { emu::validateEffects(fx, "cfg.yaml", "effects."); }),
            "cfg.yaml: key 'effects.gyro_scale[1]': must be in [-0.05, 0.05] (ratio), got 0.06");
  fx = {};
  fx.time_offset_s = std::nan("");
  EXPECT_NE(errorOf([&] { emu::validateEffects(fx, "x"); }).find("time_offset_s"), std::string::npos);
  fx = {};
  fx.acc_motion_noise_factor = 0.5;
  EXPECT_NE(errorOf([&] { emu::applySensorEffects({}, {}, fx, {}, 1); }).find("acc_motion_noise_factor"),
            std::string::npos);
  fx = {};
  std::array<std::vector<double>, 6> err;
  err[2].assign(3, 0.0);
  std::vector<ins::ImuSample> four(4, ins::ImuSample::fromRates(1, 1, Vector3d::Zero(), Vector3d::Zero()));
  EXPECT_NE(errorOf([&] { emu::applySensorEffects(four, err, fx, {}, 1); }).find("axis 2 has 3 values"),
            std::string::npos);
}
