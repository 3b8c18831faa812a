// The covariance stays symmetric positive (semi-)definite (filter::PdCheck):
// covariance-only runs with models, rates, propagation intervals, aiding and
// horizons drawn at random over their documented ranges (seed printed), and a
// covariance that is not positive definite is refused naming time and state.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/model_text.hpp"

using namespace navimpact;
using stochastic::Process;

namespace {

/// Smallest eigenvalue of P on the floored correlation scale of PdCheck.
double floorCorrelationMin(const Eigen::MatrixXd& P, const Eigen::VectorXd& floor) {
  const Eigen::VectorXd inv = P.diagonal().cwiseMax(floor).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Pc = inv.asDiagonal() * P * inv.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Pc).eigenvalues()(0);
}

/// IMU rate from which the truncated series form must never be refused.
constexpr double kSeriesAlwaysRate = 50.0;

double logUniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng));
}

/// A random model at @p rate: WN always; GM, RW, DR each with probability 1/2
/// (GM up to three terms), continuous-time figures drawn log-uniformly over
/// consumer to navigation grade, converted to the per-sample parameters.
std::vector<Process> randomTerms(std::mt19937_64& rng, double rate, bool gyro) {
  const double dt = 1.0 / rate, s = gyro ? 1.0 : 10.0;
  std::vector<Process> t = {Process::wn(logUniform(rng, 1e-5, 1e-2) * s / std::sqrt(dt))};
  std::bernoulli_distribution half(0.5);
  const int gms = std::uniform_int_distribution<int>(0, 3)(rng);
  for (int i = 0; i < gms; ++i) t.push_back(Process::gm(logUniform(rng, 1e-6, 1e-3) * s, logUniform(rng, 0.1, 5000.0)));
  if (half(rng)) t.push_back(Process::rw(logUniform(rng, 1e-8, 1e-5) * s * std::sqrt(dt)));
  if (half(rng)) t.push_back(Process::dr(logUniform(rng, 1e-10, 1e-6) * s * dt));
  return t;
}

}  // namespace

// Draws: IMU rate 1 Hz - 1 kHz (log-uniform), propagate_every 1..100, gyroscopes
// or accelerometers perfect in a third of the draws each,
// discretization series or Van Loan, initial navigation sigmas zero or up to
// 10 m / 1 m/s / 1 deg, barometer 0.001-10 m at 1-10 Hz, GNSS position fixes
// (0.01-10 m) at 1 Hz during a drawn first part of the run and then a coast,
// 2,000-20,000 IMU steps (up to 5.5 h at 1 Hz). After every draw: P finite,
// symmetric, and on the floored correlation scale no eigenvalue below
// -PdCheck::tolerance; the run never stops. Repairs are counted and printed.
TEST(PositiveDefinite, StaysPositiveDefiniteOverDrawnModelsRatesAndAiding) {
  const std::uint64_t seed = 20261125;
  std::mt19937_64 rng(seed);
  const int draws = 32;
  std::printf("seed %llu: %d draws\n", static_cast<unsigned long long>(seed), draws);
  int repairs = 0, repaired_runs = 0, refused = 0;
  for (int it = 0; it < draws; ++it) {
    const double rate = std::round(logUniform(rng, 1.0, 1000.0));
    filter::EkfConfig cfg;
    cfg.propagate_every = std::uniform_int_distribution<int>(1, 100)(rng);
    cfg.discretization = std::bernoulli_distribution(0.25)(rng) ? filter::Discretization::VanLoan
                                                                  : filter::Discretization::Series;
    // one sensor perfect in a third of the draws each (the paper's static analysis:
    // states then decouple from every noise and keep variances at rounding level)
    const int perfect = std::uniform_int_distribution<int>(0, 2)(rng);
    std::vector<Process> gyro = randomTerms(rng, rate, true), acc = randomTerms(rng, rate, false);
    if (perfect == 1) gyro.clear();
    if (perfect == 2) acc.clear();
    const stochastic::ImuModel m = ftest::model(gyro, acc, rate);
    const bool zero_p0 = std::bernoulli_distribution(0.5)(rng);
    filter::Vector9d s0;
    s0 << Eigen::Vector3d::Constant(logUniform(rng, 1e-3, 10.0)), Eigen::Vector3d::Constant(logUniform(rng, 1e-4, 1.0)),
        Eigen::Vector3d::Constant(logUniform(rng, 1e-5, 1.0) * ftest::kDeg);
    if (zero_p0) s0.setZero();
    const double baro_sigma = logUniform(rng, 1e-3, 10.0), gnss_sigma = logUniform(rng, 1e-2, 10.0);
    const int baro_every = std::max(1, static_cast<int>(std::lround(rate / logUniform(rng, 1.0, 10.0))));
    const int gnss_every = std::max(1, static_cast<int>(std::lround(rate)));
    const int n = std::uniform_int_distribution<int>(2000, 20000)(rng);
    const int gnss_until = std::uniform_int_distribution<int>(0, n)(rng);
    char what[400];
    std::snprintf(what, sizeof what,
                  "draw %d: %.0f Hz, propagate_every %d, %s, P0 %s, baro %.3g m every %d, GNSS %.3g m for %d of %d "
                  "steps, gyro %s, acc %s",
                  it, rate, cfg.propagate_every, cfg.discretization == filter::Discretization::VanLoan ? "vanloan" : "series",
                  zero_p0 ? "zero" : "drawn", baro_sigma, baro_every, gnss_sigma, gnss_until, n,
                  gyro.empty() ? "perfect" : stochastic::formatTerms(gyro).c_str(),
                  acc.empty() ? "perfect" : stochastic::formatTerms(acc).c_str());
    SCOPED_TRACE(what);
    std::printf("%s\n", what);
    // One run: P stays positive semi-definite on the floored correlation scale
    // (repairs counted), or the run is refused with one line naming time and state.
    auto run = [&](filter::EkfConfig c, std::string& refusal) -> int {
      ins::NavState x = ftest::staticState();
      Eigen::Vector3d w, f;
      ftest::staticRates(x, w, f);
      filter::ErrorStateEkf ekf(x, s0.cwiseAbs2().asDiagonal(), m, c);
      const Eigen::MatrixXd Hb = ekf.H_baro();
      const Eigen::MatrixXd Rb = Eigen::MatrixXd::Constant(1, 1, baro_sigma * baro_sigma);
      const Eigen::MatrixXd Hg = ekf.H_gnssPosition(Eigen::Vector3d::Zero());
      const Eigen::MatrixXd Rg = Eigen::MatrixXd::Identity(3, 3) * gnss_sigma * gnss_sigma;
      try {
        for (int k = 1; k <= n; ++k) {
          x.t = k / rate;
          ekf.predictCovariance(x, w, f, 1.0 / rate);
          if (k % baro_every == 0) ekf.update(Eigen::VectorXd::Zero(1), Hb, Rb, false);
          if (k <= gnss_until && k % gnss_every == 0) ekf.update(Eigen::VectorXd::Zero(3), Hg, Rg, false);
        }
        ekf.update(Eigen::VectorXd::Zero(1), Hb, Rb, false);
      } catch (const Error& e) {
        refusal = e.what();
        return -1;
      }
      const Eigen::MatrixXd& P = ekf.P();
      EXPECT_TRUE(P.allFinite());
      EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);  // the update mirrors its lower triangle
      const double lmin = floorCorrelationMin(P, ekf.varianceFloor());
      EXPECT_GE(lmin, -filter::PdCheck::tolerance);
      EXPECT_GE(ekf.pdWorstRepaired(), -filter::PdCheck::repair_limit);
      std::printf("  %d states, smallest eigenvalue %.3g, %d repairs (worst %.3g)\n", ekf.size(), lmin,
                  ekf.pdRepairs(), ekf.pdWorstRepaired());
      return ekf.pdRepairs();
    };
    std::string refusal;
    const int r = run(cfg, refusal);
    if (r >= 0) {
      repairs += r;
      repaired_runs += r > 0;
      continue;
    }
    // A refusal: one line naming the time and the state. Only the truncated
    // series may be refused (its Qd is indefinite when dt is long); Van Loan's
    // exact discretization of the same draw must run.
    std::printf("  refused: %s\n", refusal.c_str());
    ++refused;
    EXPECT_EQ(refusal.find('\n'), std::string::npos);
    EXPECT_NE(refusal.find("not positive definite at t = "), std::string::npos) << refusal;
    EXPECT_NE(refusal.find("mostly state "), std::string::npos) << refusal;
    EXPECT_EQ(cfg.discretization, filter::Discretization::Series) << refusal;
    EXPECT_LT(rate, kSeriesAlwaysRate) << "the series form must run at this rate: " << refusal;
    filter::EkfConfig exact = cfg;
    exact.discretization = filter::Discretization::VanLoan;
    std::string again;
    EXPECT_GE(run(exact, again), 0) << "Van Loan refused too: " << again;
  }
  std::printf("%d repairs in %d of %d runs, %d runs refused (series form at long IMU intervals)\n", repairs,
              repaired_runs, draws, refused);
}

// The check can say no: an indefinite covariance (a correlation of 2 between
// north position and velocity, drawn sign) is refused at the first update,
// naming the time and the state, and a semi-definite one within rounding is
// repaired (counted) rather than refused.
TEST(PositiveDefinite, AnIndefiniteCovarianceIsRefusedNamingTimeAndState) {
  const stochastic::ImuModel m = ftest::model({Process::wn(1e-4)}, {Process::wn(1e-3)}, 100.0);
  const ins::NavState x0 = ftest::staticState();
  filter::Matrix9d P0 = filter::Matrix9d::Identity();
  P0(0, 3) = P0(3, 0) = 2.0;  // |correlation| 2: eigenvalue -1 on the correlation scale
  filter::ErrorStateEkf bad(x0, P0, m, filter::EkfConfig{});
  try {
    bad.updateBaro(x0.h, 1.0);
    FAIL() << "expected a refusal";
  } catch (const Error& e) {
    const std::string s = e.what();
    EXPECT_NE(s.find("not positive definite at t = 0 s after update"), std::string::npos) << s;
    EXPECT_NE(s.find("mostly state"), std::string::npos) << s;
  }
  // correlation 1 + 1e-7: eigenvalue -1e-7, inside the repair limit
  P0(0, 3) = P0(3, 0) = 1.0 + 1e-7;
  filter::ErrorStateEkf near(x0, P0, m, filter::EkfConfig{});
  near.updateBaro(x0.h, 1.0);
  EXPECT_EQ(near.pdRepairs(), 1);
  EXPECT_NEAR(near.pdWorstRepaired(), -1e-7, 1e-9);
  EXPECT_EQ(near.pdFirstRepairTime(), x0.t);
  EXPECT_GE(floorCorrelationMin(near.P(), near.varianceFloor()), -1e-12);
}

// Sensor noise the model does not hold (samples of an IMU gap): after the
// pending propagation, P_psi grows by psd_w dt and P_v by psd_f dt on each axis
// (Qd = C diag(psd) C' dt = psd dt I), nothing else changes; bad values refused.
TEST(PositiveDefinite, AddedSensorNoiseIsPsdTimesDtOnAttitudeAndVelocity) {
  const stochastic::ImuModel m = ftest::model({Process::wn(1e-4), Process::rw(1e-6)}, {Process::wn(1e-3)}, 100.0);
  const ins::NavState x0 = ftest::staticState();
  filter::EkfConfig c;
  c.propagate_every = 7;  // a propagation is pending when the noise comes
  filter::ErrorStateEkf a(x0, 0.01 * filter::Matrix9d::Identity(), m, c), b = a;
  for (const auto& s : ftest::simulateStatic(x0, m, 13, 5)) {
    a.predict(s);
    b.predict(s);
  }
  const double dt = 0.01, pw = 3e-7, pf = 2e-4;
  a.addSensorNoise(dt, pw, pf);
  b.flushPropagation();
  Eigen::MatrixXd added = Eigen::MatrixXd::Zero(a.size(), a.size());
  for (int i = 0; i < 3; ++i) {
    added(3 + i, 3 + i) = pf * dt;
    added(6 + i, 6 + i) = pw * dt;
  }
  EXPECT_LE((a.P() - b.P() - added).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_THROW(a.addSensorNoise(0.0, pw, pf), Error);
  EXPECT_THROW(a.addSensorNoise(dt, -1.0, pf), Error);
  EXPECT_THROW(a.addSensorNoise(dt, pw, NAN), Error);
}
