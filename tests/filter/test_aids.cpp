// Aiding measurements for real runs: GNSS at any timestamp (the predicted
// antenna carried to the fix epoch), zero-velocity updates, the
// non-holonomic constraint of a ground vehicle and the NIS gate's report.
// Jacobians against central differences of the nonlinear residuals (as in
// test_jacobians.cpp), updates against hand-computed examples.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/core/error.hpp"

using namespace navimpact;
using namespace ftest;

namespace {

ins::NavState movingState() { return navState(-33.9, 151.2, 80.0, Vector3d(12.0, -7.0, 0.4), 4.0, -3.0, -150.0); }
const Vector3d kW(0.02, -0.04, 0.25);  // body rate [rad/s]
const Vector3d kF(0.9, 1.3, -9.6);     // specific force [m/s^2]

stochastic::ImuModel richModel() {
  using P = stochastic::Process;
  return model({P::wn(1e-3), P::gm(5e-5, 60.0), P::rw(1e-6)},
               {P::wn(5e-3), P::gm(5e-4, 3.0), P::dr(1e-9)}, 100.0);
}

/// A filter whose estimate is truth (+) dx: navigation error applied, corrected
/// IMU output = true output - H dx_imu (the IMU-error estimate is off by dx_imu).
filter::ErrorStateEkf perturbed(const ins::NavState& truth, const VectorXd& dx) {
  filter::ErrorStateEkf e(truth, filter::Matrix9d::Identity(), richModel());
  const int m = e.layout().imuSize();
  Vector3d w = kW, f = kF;
  for (int c = 0; c < 3; ++c) {
    w(c) -= e.layout().sensorRow(c).dot(dx.tail(m));
    f(c) -= e.layout().sensorRow(3 + c).dot(dx.tail(m));
  }
  e.predictCovariance(filter::applyNavError(truth, dx.head<9>()), w, f, 0.01);
  return e;
}

int stateSize() { return filter::ErrorStateEkf(movingState(), filter::Matrix9d::Identity(), richModel()).size(); }

/// Central-difference Jacobian of @p r at the truth, per error-state kind.
template <class R>
MatrixXd numericJacobian(int rows, int N, R r) {
  MatrixXd J(rows, N);
  for (int j = 0; j < N; ++j) {
    const double eps = j < 3 ? 1.0 : j < 6 ? 1e-2 : j < 9 ? 1e-4 : 1e-3;
    VectorXd d = VectorXd::Zero(N);
    d(j) = eps;
    J.col(j) = (r(d) - r(-d)) / (2.0 * eps);
  }
  return J;
}

void expectColumnsClose(const MatrixXd& H, const MatrixXd& J, const filter::StateLayout& L, double rel,
                        double abs) {
  for (int j = 0; j < H.cols(); ++j) {
    const double scale = std::max(H.col(j).norm(), J.col(j).norm());
    EXPECT_LE((H.col(j) - J.col(j)).norm(), rel * scale + abs)
        << L.names()[j] << "\nH: " << H.col(j).transpose() << "\nnonlinear: " << J.col(j).transpose();
  }
}

}  // namespace

// A fix taken dt_meas after the filter time: the residual carries the predicted
// antenna to the fix epoch with its velocity (position) or the IMU acceleration
// (velocity); H = H_pos + dt_meas H_vel and H_vel + dt_meas F_vel.
TEST(Aids, GnssAtAnyTimestampJacobiansMatchNonlinearResiduals) {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const ins::NavState truth = movingState();
  for (int trial = 0; trial < 4; ++trial) {
    const double tau = 0.01 * U(rng);  // up to one IMU interval at 100 Hz, either side
    const Vector3d lever(2.0 * U(rng), U(rng), -1.5 + 0.5 * U(rng));
    SCOPED_TRACE("dt_meas = " + std::to_string(tau) + " s, seed 20261124 trial " + std::to_string(trial));
    filter::ErrorStateEkf ekf = perturbed(truth, VectorXd::Zero(stateSize()));
    const int N = ekf.size();
    const earth::Geodetic z_pos{truth.lat, truth.lon, truth.h};
    const Vector3d z_vel(1.0, 2.0, 3.0);
    auto resid = [&](const VectorXd& d) {
      filter::ErrorStateEkf e = perturbed(truth, d);
      VectorXd r(6);
      r.head<3>() = e.residualGnssPosition(z_pos, lever, tau);
      r.tail<3>() = e.residualGnssVelocity(z_vel, lever, tau);
      return r;
    };
    MatrixXd H(6, N);
    H << ekf.H_gnssPosition(lever, tau), ekf.H_gnssVelocity(lever, tau);
    const MatrixXd J = numericJacobian(6, N, resid);
    // position rows: the velocity term is exact in tau; velocity rows: F
    // linearises the acceleration (Groves 14.65-14.69), rounding floor 1e-9
    expectColumnsClose(H, J, ekf.layout(), 1e-4, 1e-8);
    // the epoch correction is really there
    const VectorXd r0 = resid(VectorXd::Zero(N));
    filter::ErrorStateEkf e0 = perturbed(truth, VectorXd::Zero(N));
    const Vector3d v_ant = truth.v_N + truth.C_BtoN() * kW.cross(lever) -
                           earth::w_IE_N(truth.lat).cross(truth.C_BtoN() * lever);
    EXPECT_NEAR((r0.head<3>() - e0.residualGnssPosition(z_pos, lever)).norm(), (v_ant * tau).norm(), 1e-9);
  }
}

// ZUPT and the non-holonomic constraint (with a point away from the IMU, so
// that the attitude, Earth-rate and gyro-error terms are exercised).
TEST(Aids, ZeroVelocityAndNonHolonomicJacobiansMatchNonlinearResiduals) {
  const ins::NavState truth = movingState();
  const Vector3d point(-1.4, 0.3, 0.6);
  filter::ErrorStateEkf ekf = perturbed(truth, VectorXd::Zero(stateSize()));
  const int N = ekf.size();
  auto resid = [&](const VectorXd& d) {
    filter::ErrorStateEkf e = perturbed(truth, d);
    VectorXd r(5);
    r.head<3>() = e.state().v_N;
    r.tail<2>() = e.residualNonHolonomic(point);
    return r;
  };
  MatrixXd H(5, N);
  H << ekf.H_zeroVelocity(), ekf.H_nonHolonomic(point);
  const MatrixXd J = numericJacobian(5, N, resid);
  expectColumnsClose(H, J, ekf.layout(), 1e-5, 1e-9);
  // the constraint sees heading through the velocity: a sideways velocity of
  // |v| psi_D per radian
  EXPECT_GT(H.block(3, filter::kAtt, 2, 3).norm(), 10.0);
  // and the gyro errors through the point's offset
  EXPECT_GT(H.block(3, filter::kNav, 2, N - filter::kNav).norm(), 0.1);
}

// ZUPT: P_vv = 0.04 I, sigma = 0.1, v_est = (0.2, 0, 0):
//  dz = 0.2, S = 0.05, K = 0.8, v' = 0.2 - 0.16 = 0.04, P_NN' = 0.04*0.01/0.05 = 0.008, NIS = 0.8.
TEST(Aids, ZeroVelocityHandExample) {
  ins::NavState x = staticState();
  x.v_N = Vector3d(0.2, 0.0, 0.0);
  filter::Vector9d d;
  d << 1, 1, 1, 0.04, 0.04, 0.04, 1e-4, 1e-4, 1e-4;
  filter::ErrorStateEkf ekf(x, d.asDiagonal(), stochastic::ImuModel{});
  const filter::UpdateResult r = ekf.updateZeroVelocity(0.1);
  EXPECT_TRUE(r.accepted);
  EXPECT_NEAR(r.nis, 0.8, 1e-12);
  EXPECT_NEAR(ekf.state().v_N.x(), 0.04, 1e-12);
  EXPECT_NEAR(ekf.P()(3, 3), 0.008, 1e-12);
  EXPECT_THROW(ekf.updateZeroVelocity(0.0), Error);
}

// Non-holonomic constraint, level, heading north, v_N = (1, 0.5, 0): the body
// sees 0.5 m/s to the right. P_vv = I, attitude known exactly, sigma_lat = 1:
//  S_yy = 1 + 1 = 2, K(v_E) = 1/2, v_E' = 0.5 - 0.25 = 0.25, P_EE' = 0.5;
//  the forward velocity is unconstrained (v_N stays 1).
TEST(Aids, NonHolonomicHandExample) {
  ins::NavState x = staticState();
  x.setRollPitchYaw(0.0, 0.0, 0.0);
  x.v_N = Vector3d(1.0, 0.5, 0.0);
  filter::Vector9d d;
  d << 1, 1, 1, 1, 1, 1, 0, 0, 0;
  filter::ErrorStateEkf ekf(x, d.asDiagonal(), stochastic::ImuModel{});
  const Eigen::Vector2d z = ekf.residualNonHolonomic(Vector3d::Zero());
  EXPECT_NEAR(z(0), 0.5, 1e-12);
  EXPECT_NEAR(z(1), 0.0, 1e-12);
  const filter::UpdateResult r = ekf.updateNonHolonomic(1.0, 0.1);
  EXPECT_NEAR(r.S(0, 0), 2.0, 1e-12);
  EXPECT_NEAR(ekf.state().v_N.y(), 0.25, 1e-12);
  EXPECT_NEAR(ekf.state().v_N.x(), 1.0, 1e-12);
  EXPECT_NEAR(ekf.P()(4, 4), 0.5, 1e-12);
}

// The gate reports its threshold, rejects a gross outlier without touching the
// state and counts it; an ordinary fix passes.
TEST(Aids, GateReportsThresholdAndRejection) {
  ins::NavState x = staticState();
  filter::EkfConfig cfg;
  cfg.gate_probability = 0.999;
  filter::Vector9d d;
  d << 1, 1, 1, 0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4;
  filter::ErrorStateEkf ekf(x, d.asDiagonal(), stochastic::ImuModel{}, cfg);
  const double q = boost::math::quantile(boost::math::chi_squared(3), 0.999);
  const earth::Geodetic far = earth::nedToGeodetic(x.geodetic(), Vector3d(100.0, 0.0, 0.0));
  const filter::UpdateResult bad = ekf.updateGnssPosition(far, Vector3d::Ones());
  EXPECT_FALSE(bad.accepted);
  EXPECT_NEAR(bad.gate, q, 1e-9);
  EXPECT_GT(bad.nis, q);
  EXPECT_EQ(ekf.rejections(), 1);
  EXPECT_NEAR(ekf.state().lat, x.lat, 0.0);
  const earth::Geodetic near = earth::nedToGeodetic(x.geodetic(), Vector3d(0.5, 0.0, 0.0));
  const filter::UpdateResult ok = ekf.updateGnssPosition(near, Vector3d::Ones());
  EXPECT_TRUE(ok.accepted);
  EXPECT_EQ(ekf.rejections(), 1);
}
