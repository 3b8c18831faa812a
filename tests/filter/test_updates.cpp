// Measurement updates against hand-computed examples (9 navigation states,
// perfect sensors), the chi-square gate, error reporting and the layout.
#include <gtest/gtest.h>

#include <cmath>

#include "filter_test_util.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "test_support.hpp"

using namespace navimpact;
using namespace ftest;

namespace {
filter::Matrix9d diagP(double p, double v, double a) {
  filter::Vector9d d;
  d << p, p, p, v, v, v, a, a, a;
  return d.asDiagonal();
}
}  // namespace

// Baro: P_DD = 16, sigma = 2, h_est = 100, h_meas = 102.
//  dz = 100 - 102 = -2, H = [0 0 -1 ...], S = 16 + 4 = 20, K_D = -16/20 = -0.8,
//  dx_D = K dz = 1.6 -> h = 100 + 1.6 = 101.6; P_DD' = 16*4/20 = 3.2; NIS = 4/20.
TEST(Updates, BaroHandExample) {
  ins::NavState x = staticState();
  x.h = 100.0;
  filter::Matrix9d P0 = diagP(1.0, 1.0, 1e-4);
  P0(2, 2) = 16.0;
  filter::ErrorStateEkf ekf(x, P0, stochastic::ImuModel{});
  const filter::UpdateResult r = ekf.updateBaro(102.0, 2.0);
  EXPECT_TRUE(r.accepted);
  EXPECT_NEAR(r.innovation(0), -2.0, 1e-12);
  EXPECT_NEAR(r.S(0, 0), 20.0, 1e-12);
  EXPECT_NEAR(r.nis, 0.2, 1e-12);
  EXPECT_NEAR(ekf.state().h, 101.6, 1e-9);
  EXPECT_NEAR(ekf.P()(2, 2), 3.2, 1e-12);
  EXPECT_NEAR(ekf.P()(0, 0), 1.0, 1e-15);  // other states untouched (no correlation)
  EXPECT_NEAR(ekf.state().lat, x.lat, 1e-15);
}

// GNSS position with lever arm l = [2 0 0] m, level, heading north (C = I):
//  H_pos = I, H_psi = -[(C l) x] = [[0 0 0], [0 0 2], [0 -2 0]].
//  P = diag(pos 1, vel 1, att 0.01), R = I:
//  S = diag(2, 1 + 4*0.01 + 1, 2.04). Measurement 0.5 m north of the predicted
//  antenna: dz = [-0.5 0 0] -> dx_N = -0.25 (the estimate moves 0.25 m north),
//  P_NN' = 0.5, P_EE' = 1 - 1/2.04, P(pos_E, psi_D)' = -0.02/2.04,
//  P(psi_D)' = 0.01 - 0.0004/2.04.
TEST(Updates, GnssPositionWithLeverArmHandExample) {
  ins::NavState x = staticState();
  x.setRollPitchYaw(0, 0, 0);
  filter::ErrorStateEkf ekf(x, diagP(1.0, 1.0, 0.01), stochastic::ImuModel{});
  const Vector3d lever(2.0, 0.0, 0.0);
  const earth::Radii rr = earth::radii(x.lat);
  // C = I: forward = north, the predicted antenna is 2 m north of the IMU;
  // the measurement is 0.5 m further north
  earth::Geodetic z{x.lat + (2.0 + 0.5) / (rr.R_N + x.h), x.lon, x.h};
  const filter::UpdateResult r = ekf.updateGnssPosition(z, Vector3d(1, 1, 1), lever);
  EXPECT_NEAR(r.innovation(0), -0.5, 1e-6);
  EXPECT_NEAR(r.innovation(1), 0.0, 1e-9);
  EXPECT_NEAR(r.S(0, 0), 2.0, 1e-12);
  EXPECT_NEAR(r.S(1, 1), 2.04, 1e-12);  // lever along N: psi_D moves the antenna east
  EXPECT_NEAR(r.S(2, 2), 2.04, 1e-12);  // and psi_E moves it down
  const Vector3d dp = earth::curvilinearDiffNed(ekf.state().geodetic(), x.geodetic());
  EXPECT_NEAR(dp.x(), 0.25, 1e-6);
  EXPECT_NEAR(ekf.P()(0, 0), 0.5, 1e-12);
  EXPECT_NEAR(ekf.P()(1, filter::kAtt + 2), -0.02 / 2.04, 1e-12);
  EXPECT_NEAR(ekf.P()(filter::kAtt + 2, filter::kAtt + 2), 0.01 - 0.0004 / 2.04, 1e-12);
}

// Same, lever arm along body right (east): H_psi = -[(0,2,0) x] couples psi_D
// into north and psi_N into down: S_NN = 1 + 4*0.01 + 1 = 2.04.
TEST(Updates, GnssPositionLeverArmCouplesAttitude) {
  ins::NavState x = staticState();
  x.setRollPitchYaw(0, 0, 0);
  filter::ErrorStateEkf ekf(x, diagP(1.0, 1.0, 0.01), stochastic::ImuModel{});
  const Vector3d lever(0.0, 2.0, 0.0);
  const Eigen::MatrixXd H = ekf.H_gnssPosition(lever);
  // -[(0,2,0) x] = [[0 0 -2], [0 0 0], [2 0 0]] on psi
  EXPECT_DOUBLE_EQ(H(0, filter::kAtt + 2), -2.0);
  EXPECT_DOUBLE_EQ(H(2, filter::kAtt + 0), 2.0);
  const earth::Geodetic z = earth::nedToGeodetic(x.geodetic(), Vector3d(0.0, 2.0, 0.0));
  const filter::UpdateResult r = ekf.updateGnssPosition(z, Vector3d(1, 1, 1), lever);
  EXPECT_NEAR(r.S(0, 0), 2.04, 1e-12);
  EXPECT_NEAR(r.S(1, 1), 2.0, 1e-12);
  EXPECT_NEAR(r.S(2, 2), 2.04, 1e-12);
  EXPECT_NEAR(r.innovation.norm(), 0.0, 1e-6);
  // P(pos_N, psi_D)' = 0 - (1 * -2 * 0.01)... K = P H' S^-1: cov(pos_N, psi_D) = -(1)(-0.02)/2.04
  EXPECT_NEAR(ekf.P()(0, filter::kAtt + 2), 0.02 / 2.04, 1e-12);
  EXPECT_NEAR(ekf.P()(filter::kAtt + 2, filter::kAtt + 2), 0.01 - 0.0004 / 2.04, 1e-12);
  EXPECT_NEAR(ekf.P()(0, 0), 1.0 - 1.0 / 2.04, 1e-12);
}

// GNSS velocity, no lever arm: P_v = 0.04, sigma = 0.2 -> K = 0.5;
// v_est = 0, z = [1, -2, 0.4] -> v = [0.5, -1, 0.2], P_v' = 0.02.
TEST(Updates, GnssVelocityHandExample) {
  ins::NavState x = staticState();
  filter::ErrorStateEkf ekf(x, diagP(1.0, 0.04, 1e-4), stochastic::ImuModel{});
  const filter::UpdateResult r =
      ekf.updateGnssVelocity(Vector3d(1.0, -2.0, 0.4), Vector3d(0.2, 0.2, 0.2));
  EXPECT_NEAR((ekf.state().v_N - Vector3d(0.5, -1.0, 0.2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(ekf.P()(3, 3), 0.02, 1e-12);
  EXPECT_NEAR(r.nis, (1.0 + 4.0 + 0.16) / 0.08, 1e-9);
}

TEST(Updates, ChiSquareGateRejectsOutlierAndCounts) {
  ins::NavState x = staticState();
  filter::EkfConfig cfg;
  cfg.gate_probability = 0.999;
  filter::ErrorStateEkf ekf(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{}, cfg);
  // 50 m off with S = 2 m^2: NIS = 1250 >> chi2_3(0.999) = 16.27
  const earth::Geodetic far = earth::nedToGeodetic(x.geodetic(), Vector3d(50, 0, 0));
  const filter::UpdateResult r = ekf.updateGnssPosition(far, Vector3d(1, 1, 1));
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(ekf.rejections(), 1);
  EXPECT_NEAR(ekf.state().lat, x.lat, 0.0);
  EXPECT_NEAR(ekf.P()(0, 0), 1.0, 0.0);
  // 1 m off: NIS = 0.5, accepted
  const earth::Geodetic near = earth::nedToGeodetic(x.geodetic(), Vector3d(1, 0, 0));
  EXPECT_TRUE(ekf.updateGnssPosition(near, Vector3d(1, 1, 1)).accepted);
  EXPECT_EQ(ekf.rejections(), 1);
  // gate off (default): the outlier is used
  filter::ErrorStateEkf ekf2(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{});
  EXPECT_TRUE(ekf2.updateGnssPosition(far, Vector3d(1, 1, 1)).accepted);
}

// Lock-out and re-admission (EkfConfig::gate_readmit_after, Simon 2006 §7.4).
// Baro, P_DD = 1, sigma = 1, h_est = 100, the true height 110: dz = -10,
// S = 2, NIS = 50 > g = chi2_1^-1(0.999) = 10.83 every time.
//  readmit_after = 0: every fix rejected, the filter never moves (lock-out).
//  readmit_after = 2: fixes 1 and 2 rejected; fix 3 applied with P scaled by
//  lambda = 50 / g: P_DD = lambda, K = lambda / (lambda + 1),
//  h = 100 + 10 K, P_DD' = lambda / (lambda + 1), P_NN' = lambda (uncorrelated);
//  fix 4 then has NIS = (10 - 10 K)^2 / (P_DD' + 1) < g and is accepted.
TEST(Updates, GateReadmitsAfterARunOfRejections) {
  ins::NavState x = staticState();
  x.h = 100.0;
  filter::EkfConfig cfg;
  cfg.gate_probability = 0.999;
  const double g = 10.827566170662733;  // chi2_1 quantile at 0.999
  cfg.gate_readmit_after = 0;
  filter::ErrorStateEkf locked(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{}, cfg);
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(locked.updateBaro(110.0, 1.0).accepted);
  EXPECT_EQ(locked.rejections(), 10);
  EXPECT_EQ(locked.state().h, 100.0);

  cfg.gate_readmit_after = 2;
  filter::ErrorStateEkf ekf(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{}, cfg);
  EXPECT_FALSE(ekf.updateBaro(110.0, 1.0).accepted);
  EXPECT_FALSE(ekf.updateBaro(110.0, 1.0).accepted);
  const filter::UpdateResult r = ekf.updateBaro(110.0, 1.0);
  const double lambda = 50.0 / g, K = lambda / (lambda + 1.0);
  EXPECT_TRUE(r.accepted);
  EXPECT_TRUE(r.readmitted);
  EXPECT_NEAR(r.nis, 50.0, 1e-9);
  EXPECT_NEAR(r.gate, g, 1e-9);
  EXPECT_NEAR(r.inflation, lambda, 1e-9);
  EXPECT_NEAR(ekf.state().h, 100.0 + 10.0 * K, 1e-6);
  EXPECT_NEAR(ekf.P()(2, 2), lambda / (lambda + 1.0), 1e-9);
  EXPECT_NEAR(ekf.P()(0, 0), lambda, 1e-9);
  EXPECT_EQ(ekf.rejections(), 2);
  const filter::UpdateResult r4 = ekf.updateBaro(110.0, 1.0);
  EXPECT_TRUE(r4.accepted);
  EXPECT_FALSE(r4.readmitted);
  EXPECT_NEAR(r4.nis, std::pow(10.0 - 10.0 * K, 2) / (lambda / (lambda + 1.0) + 1.0), 1e-6);
  EXPECT_LT(r4.nis, g);
  // an isolated outlier after an accepted fix starts a new count: rejected
  EXPECT_FALSE(ekf.updateBaro(200.0, 1.0).accepted);
  EXPECT_EQ(ekf.rejections(), 3);
  // the range is checked
  cfg.gate_readmit_after = -1;
  EXPECT_THROW(filter::ErrorStateEkf(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{}, cfg), Error);
}

TEST(Updates, NanDataThrowsNamingTheTime) {
  ins::NavState x = staticState();
  filter::ErrorStateEkf ekf(x, diagP(1.0, 1.0, 1e-4), stochastic::ImuModel{});
  Vector3d w, f;
  staticRates(x, w, f);
  ekf.predict(ins::ImuSample::fromRates(0.005, 0.005, w, f));
  f.x() = std::nan("");
  try {
    ekf.predict(ins::ImuSample::fromRates(0.010, 0.005, w, f));
    FAIL() << "expected navimpact::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("t = 0.01 s"), std::string::npos) << e.what();
  }
}

TEST(Layout, RefModelStatesAreNamedAndCounted) {
  const stochastic::ImuModel m =
      stochastic::loadImuModel(test::sourcePath("config/models/navchip_table1.yaml") + ":ref");
  const filter::StateLayout L = filter::StateLayout::build(m);
  // gyro: 3 GM per axis; acc: 3 GM + DR (2) per axis -> 9 + 15 = 24 IMU states
  EXPECT_EQ(L.imuSize(), 24);
  EXPECT_EQ(L.size(), 33);
  EXPECT_EQ(L.names()[9], "gyro_x.GM1(T=59.22s)");
  bool found = false;
  for (const auto& n : L.names()) found |= (n == "acc_x.GM1(T=3.22s)");
  EXPECT_TRUE(found) << L.describe();
  EXPECT_NEAR(L.whitePsd()[0], 9.788e-4 * 9.788e-4 / 200.0, 1e-20);
  EXPECT_NEAR(L.whitePsd()[5], 5.521e-3 * 5.521e-3 / 200.0, 1e-18);
  // sensor rows pick exactly that axis' states
  EXPECT_DOUBLE_EQ(L.sensorRow(0).sum(), 3.0);
  EXPECT_DOUBLE_EQ(L.sensorRow(3).sum(), 4.0);  // 3 GM + DR bias (DR rate has H = 0)
  filter::ImuErrorOptions opt;
  opt.turn_on_bias = true;
  opt.turn_on_sigma = {1e-4, 1e-4, 1e-4, 1e-2, 1e-2, 1e-2};
  EXPECT_EQ(filter::StateLayout::build(m, opt).imuSize(), 30);
  opt.turn_on_sigma[4] = 0.0;
  EXPECT_THROW(filter::StateLayout::build(m, opt), Error);
}

// GMWM fits of quantised sensors put the first-scale noise into GMs with T of a
// few ms (config/models/adis16405_fitted.yaml:model2, T = 3-6 ms at 100 Hz). Over a
// propagation interval of k = 5 samples (50 ms) such a state is white at the
// filter's resolution; it must enter as white noise of the same long-run
// variance, and the filter must keep P positive definite through a long
// GNSS-free coast (with the GM as a state the truncated-series coupling made P
// indefinite within 0.1 s).
TEST(Layout, GaussMarkovShorterThanThePropagationIntervalEntersAsWhiteNoise) {
  using stochastic::Process;
  const double rate = 100.0, T = 0.005, sigma = 6e-3;
  const stochastic::ImuModel m =
      ftest::model({Process::wn(1e-12), Process::gm(sigma, T), Process::gm(2e-4, 40.0)},
                   {Process::wn(1e-12), Process::gm(0.035, 0.006)}, rate);
  filter::EkfConfig cfg;
  cfg.propagate_every = 5;
  const filter::StateLayout L = filter::StateLayout::build(m, filter::effectiveImuOptions(m, cfg));
  EXPECT_EQ(L.imuSize(), 3);              // only the 40 s gyro GMs stay states
  EXPECT_EQ(L.notes().size(), 6u) << L.describe();
  const double phi = std::exp(-1.0 / (rate * T));
  const double wn2 = 1e-24 + sigma * sigma * (1.0 + phi) / (1.0 - phi);
  EXPECT_NEAR(L.whitePsd()[0], wn2 / rate, 1e-9 * wn2 / rate);
  // Every sample: k dt = 10 ms still exceeds T = 5-6 ms, so the same conversion.
  cfg.propagate_every = 1;
  EXPECT_EQ(filter::StateLayout::build(m, filter::effectiveImuOptions(m, cfg)).imuSize(), 3);
  // Without the option the GMs are states (the layout itself does not decide).
  EXPECT_EQ(filter::StateLayout::build(m).imuSize(), 9);

  // 20 s with GNSS and baro, then 60 s with baro only: P stays positive definite.
  cfg.propagate_every = 5;
  const ins::NavState x0 = ftest::staticState();
  filter::ErrorStateEkf ekf(x0, filter::Matrix9d::Identity() * 1e-2, m, cfg);
  const auto imu = ftest::simulateStatic(x0, m, 8000, 17);
  for (std::size_t k = 0; k < imu.size(); ++k) {
    ekf.predict(imu[k]);
    if ((k + 1) % 100 == 0 && k < 2000)
      ekf.updateGnssPosition({x0.lat, x0.lon, x0.h}, Eigen::Vector3d(2.0, 2.0, 4.0));
    if ((k + 1) % 10 == 0) ekf.updateBaro(x0.h, 0.5);
  }
  ekf.flushPropagation();
  const Eigen::MatrixXd P = ekf.P();
  EXPECT_TRUE(P.allFinite());
  EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(P).info(), Eigen::Success);
}
