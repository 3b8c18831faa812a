// Datasheet figures and state-space blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/state_space.hpp"
#include "stochastic_test_util.hpp"

using namespace navimpact::stochastic;
using navimpact::units::Quantity;
using navimpact::test::model;

TEST(Datasheet, ArwOfWhiteNoiseByHand) {
  // Table 1 gyro WN 9.788e-4 rad/s per sample at 200 Hz:
  // N = 9.788e-4 * sqrt(1/200) rad/sqrt(s) = 6.92116e-5; * 180/pi * 60 = 0.23793 deg/sqrt(h).
  const auto f = datasheetFigures(model(200, {Process::wn(9.788e-4)}));
  ASSERT_TRUE(f.noise_density.has_value());
  EXPECT_NEAR(*f.noise_density, 6.921161174e-5, 1e-13);
  EXPECT_FALSE(f.bias_instability.has_value());  // WN alone: ADEV decreases monotonically
  EXPECT_FALSE(f.random_walk.has_value());
  const std::string s = formatDatasheet(f, Quantity::AngularRate);
  EXPECT_NE(s.find("ARW"), std::string::npos);
  EXPECT_NE(s.find("0.2379 deg/sqrt(h)"), std::string::npos) << s;
  // Accelerometer: VRW = N * 60 m/s/sqrt(h); 5.521e-3 * sqrt(0.005) * 60 = 0.023424
  const auto fa = datasheetFigures(model(200, {Process::wn(5.521e-3)}));
  EXPECT_NE(formatDatasheet(fa, Quantity::SpecificForce).find("0.02342 m/s/sqrt(h)"),
            std::string::npos);
}

TEST(Datasheet, RandomWalkDriftAndBiasInstabilityOfWnPlusRw) {
  // ADEV^2 = N^2/tau + K^2 tau/3 (IEEE 952): minimum sqrt(2 N K / sqrt(3)) at
  // tau* = sqrt(3) N / K. The grid has 50 points/decade (4.7 % steps), so the
  // minimum value is within 0.1 % and its place within 5 %.
  const double rate = 100, sigma = 1e-3, gamma = 1e-6;
  const auto f = datasheetFigures(model(rate, {Process::wn(sigma), Process::rw(gamma),
                                               Process::dr(2e-8), Process::qn(1e-5)}));
  const double N = sigma * std::sqrt(1 / rate), K = gamma * std::sqrt(rate);
  ASSERT_TRUE(f.random_walk && f.drift_rate && f.quantization && f.bias_instability);
  EXPECT_NEAR(*f.random_walk, K, 1e-18);
  EXPECT_NEAR(*f.drift_rate, 2e-6, 1e-19);
  EXPECT_NEAR(*f.quantization, 1e-7, 1e-20);
  const double tau_star = std::sqrt(3.0) * N / K;
  const double adev_min = std::sqrt(2 * N * K / std::sqrt(3.0));
  // The value check uses WN + RW alone (DR and QN would shift the minimum).
  const auto g = datasheetFigures(model(rate, {Process::wn(sigma), Process::rw(gamma)}));
  ASSERT_TRUE(g.bias_instability.has_value());
  EXPECT_NEAR(*g.bias_instability * 0.664, adev_min, 1e-3 * adev_min);
  EXPECT_NEAR(*g.bias_instability_tau_s, tau_star, 0.05 * tau_star);
  EXPECT_LT(*f.bias_instability_tau_s, 0.8 * tau_star);  // the drift pulls the minimum earlier
}

TEST(Datasheet, GaussMarkovBumpGivesFloorBeforeIt) {
  // WN + GM with a strong, long GM: the ADEV falls (WN), then rises to the GM hump.
  const auto f = datasheetFigures(model(200, {Process::wn(9.788e-4), Process::gm(7.555e-5, 2008)}));
  ASSERT_TRUE(f.bias_instability.has_value());
  EXPECT_GT(*f.bias_instability_tau_s, 1.0);
  EXPECT_LT(*f.bias_instability_tau_s, 2008.0);
  const std::string s = formatDatasheet(f, Quantity::AngularRate);
  EXPECT_NE(s.find("deg/h"), std::string::npos);
  EXPECT_EQ(formatDatasheet(datasheetFigures(model(200, {})), Quantity::AngularRate), "(no error)\n");
}

namespace {
/// Independent reference for Qd: composite Simpson quadrature of
/// exp(F s) Qc exp(F s)^T over [0, dt].
Eigen::MatrixXd qdSimpson(const Eigen::MatrixXd& F, const Eigen::MatrixXd& Qc, double dt) {
  const int K = 2000;
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(F.rows(), F.cols());
  for (int i = 0; i <= K; ++i) {
    const double s = dt * i / K;
    const Eigen::MatrixXd E = (F * s).exp();
    const double w = (i == 0 || i == K) ? 1 : (i % 2 ? 4 : 2);
    S += w * E * Qc * E.transpose();
  }
  return S * dt / (3.0 * K);
}
/// Van Loan in the test (independent of the library's branch choice).
void vanLoanRef(const Eigen::MatrixXd& F, const Eigen::MatrixXd& Qc, double dt, Eigen::MatrixXd& Phi,
                Eigen::MatrixXd& Qd) {
  const auto n = F.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  M.topLeftCorner(n, n) = -F * dt;
  M.topRightCorner(n, n) = Qc * dt;
  M.bottomRightCorner(n, n) = F.transpose() * dt;
  const Eigen::MatrixXd E = M.exp();
  Phi = E.bottomRightCorner(n, n).transpose();
  Qd = Phi * E.topRightCorner(n, n);
}
}  // namespace

TEST(StateSpace, ClosedFormsMatchVanLoan) {
  const double rate = 200;
  for (const Process& p : {Process::gm(4.811e-4, 3.22), Process::gm(7.555e-5, 2008.0),
                           Process::rw(3e-7), Process::dr(9.3e-10), Process::sin(0.1, 1.3)}) {
    const StateSpaceBlock b = stateSpace(p, rate);
    ASSERT_EQ(b.names.size(), static_cast<std::size_t>(b.n));
    for (double dt : {0.005, 0.1, 1.0}) {
      Eigen::MatrixXd Phi, Qd;
      vanLoanRef(b.F, b.Qc, dt, Phi, Qd);
      EXPECT_LT((b.Phi(dt) - Phi).norm(), 1e-12 * (1 + Phi.norm())) << kindName(p.kind);
      EXPECT_LT((b.Qd(dt) - Qd).norm(), 1e-10 * (Qd.norm() + 1e-300) + 1e-30) << kindName(p.kind);
    }
  }
}

TEST(StateSpace, GeneralFallbackMatchesQuadrature) {
  // A block that is none of the closed forms exercises the Van Loan fallback.
  StateSpaceBlock b;
  b.n = 2;
  b.F.resize(2, 2);
  b.F << -0.5, 1.0, -0.3, -0.2;
  b.Qc.resize(2, 2);
  b.Qc << 2.0, 0.3, 0.3, 1.0;
  const double dt = 0.7;
  const Eigen::MatrixXd Qd = b.Qd(dt), ref = qdSimpson(b.F, b.Qc, dt);
  EXPECT_LT((Qd - ref).norm(), 1e-9 * ref.norm());
  EXPECT_LT((b.Phi(dt) - (b.F * dt).exp()).norm(), 1e-13);
  // and the scalar GM closed form against quadrature too
  const StateSpaceBlock g = stateSpace(Process::gm(2.0, 0.8), 100);
  EXPECT_NEAR(g.Qd(0.3)(0, 0), qdSimpson(g.F, g.Qc, 0.3)(0, 0), 1e-10);
}

TEST(StateSpace, GaussMarkovIsStationary) {
  const StateSpaceBlock b = stateSpace(Process::gm(4.811e-4, 3.22), 200);
  for (double dt : {0.005, 1.0, 100.0}) {
    const Eigen::MatrixXd P = b.Phi(dt) * b.P0 * b.Phi(dt).transpose() + b.Qd(dt);
    EXPECT_NEAR(P(0, 0), b.P0(0, 0), 1e-15 * b.P0(0, 0));
  }
  EXPECT_DOUBLE_EQ(b.Phi(0.005)(0, 0), std::exp(-0.005 / 3.22));
  EXPECT_EQ(b.H(0), 1.0);
}

TEST(StateSpace, WhiteParts) {
  EXPECT_EQ(stateSpace(Process::wn(1e-3), 200).n, 0);
  EXPECT_DOUBLE_EQ(stateSpace(Process::wn(1e-3), 200).white_psd, 1e-6 / 200);
  EXPECT_DOUBLE_EQ(stateSpace(Process::qn(1e-3), 200).white_psd, 2e-6 / 200);
}

TEST(StateSpace, RandomWalkVarianceGrowthMatchesSimulation) {
  // 4000 simulated paths of RW(gamma) at 100 Hz: var(x_k) = gamma^2 (k+1),
  // and the state space predicts P_{k+1} = P_k + Qd(dt) from P_0 = 0.
  const double gamma = 2e-3, rate = 100;
  const StateSpaceBlock b = stateSpace(Process::rw(gamma), rate);
  const int paths = 4000, n = 60;
  std::vector<double> s2(n, 0.0);
  Model m;
  m.rate_hz = rate;
  m.terms = {Process::rw(gamma)};
  for (int i = 0; i < paths; ++i) {
    const auto x = simulate(m, n, deriveSeed(77, i));
    for (int k = 0; k < n; ++k) s2[k] += x[k] * x[k];
  }
  double P = b.P0(0, 0);
  for (int k = 0; k < n; ++k) {
    P = b.Phi(1 / rate)(0, 0) * P * b.Phi(1 / rate)(0, 0) + b.Qd(1 / rate)(0, 0);
    const double v = s2[k] / paths;  // known zero mean
    EXPECT_NEAR(v, P, 5 * P * std::sqrt(2.0 / paths)) << k;
  }
  EXPECT_NEAR(P, gamma * gamma * n, 1e-18);
}

TEST(StateSpace, DriftAndSinusoid) {
  const double rate = 200, omega = 9.3e-10;
  const StateSpaceBlock d = stateSpace(Process::dr(omega), rate);
  // bias' = rate: after t seconds bias = b0 + r t
  Eigen::Vector2d x(0.1, omega * rate);
  const Eigen::VectorXd y = d.Phi(10.0) * x;
  EXPECT_NEAR(y[0], 0.1 + omega * rate * 10.0, 1e-18);
  EXPECT_EQ(y[1], x[1]);
  EXPECT_DOUBLE_EQ(d.P0(1, 1), std::pow(omega * rate, 2));
  // bias variance grows as (omega/dt)^2 t^2 from the rate prior
  const Eigen::MatrixXd P = d.Phi(50.0) * d.P0 * d.Phi(50.0).transpose();
  EXPECT_NEAR(P(0, 0), std::pow(omega * rate * 50.0, 2), 1e-12 * P(0, 0));

  // SIN: H Phi(k dt) x0 reproduces amp sin(w k dt + theta) for x0 = amp [sin theta, cos theta]
  const double A = 0.2, f = 1.3, th = 0.7, w = 2 * 3.14159265358979323846 * f;
  const StateSpaceBlock s = stateSpace(Process::sin(A, f), rate);
  Eigen::Vector2d z(A * std::sin(th), A * std::cos(th));
  for (int k = 1; k <= 400; ++k) {
    z = s.Phi(1 / rate) * z;
    EXPECT_NEAR((s.H * z)(0), A * std::sin(w * k / rate + th), 1e-12);
  }
  EXPECT_TRUE(s.Qd(0.01).isZero(0.0));
}
