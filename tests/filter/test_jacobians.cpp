// Jacobian checks in the style of manif's common_tester: perturb the truth by
// a small error, run the nonlinear model (mechanization / measurement), and
// compare the resulting error with the filter's linearised prediction
// (Phi for F blocks, H for measurement blocks), block by block.
#include <gtest/gtest.h>

#include <cmath>

#include "filter_test_util.hpp"

using namespace navimpact;
using namespace ftest;

namespace {

// A moving, turning, accelerating vehicle: every F term is exercised.
ins::NavState movingState() { return navState(46.57, 7.65, 1200.0, Vector3d(35.0, -22.0, 3.0), 12.0, -7.0, 130.0); }
const Vector3d kW(0.05, -0.03, 0.12);   // body rate [rad/s]
const Vector3d kF(1.5, -0.8, -9.2);     // specific force [m/s^2]

stochastic::ImuModel richModel() {
  using P = stochastic::Process;
  return model({P::wn(1e-3), P::gm(5e-5, 60.0), P::rw(1e-6)},
               {P::wn(5e-3), P::gm(5e-4, 3.0), P::dr(1e-9), P::sin(1e-3, 0.7)}, 200.0);
}

// Full-state error propagation through the nonlinear mechanization over dt:
// the estimate starts at truth (+) dx0 and is driven by the truth's IMU output
// corrupted by the IMU-error-state error (estimate minus truth => corrected
// output minus true output = -H dx_imu).
VectorXd propagateError(const filter::ErrorStateEkf& ekf, const ins::NavState& truth,
                        const VectorXd& dx0, const MatrixXd& Dii, double dt) {
  const filter::StateLayout& L = ekf.layout();
  const ins::ImuSample s_true = ins::ImuSample::fromRates(truth.t + dt, dt, kW, kF);
  ins::ImuSample s_est = s_true;
  const VectorXd dimu = dx0.tail(L.imuSize());
  // mean IMU-error-state error over the interval (trapezoid; exact for a drift)
  const VectorXd dimu_mean = 0.5 * (dimu + Dii * dimu);
  for (int c = 0; c < 6; ++c) {
    const double de = -L.sensorRow(c).dot(dimu_mean) * dt;
    if (c < 3) s_est.dtheta_B(c) += de; else s_est.dv_B(c - 3) += de;
  }
  const ins::NavState est0 = filter::applyNavError(truth, dx0.head<9>());
  const ins::NavState t1 = ins::mechanize(truth, s_true, nullptr);
  const ins::NavState e1 = ins::mechanize(est0, s_est, nullptr);
  VectorXd dx1(dx0.size());
  dx1.head<9>() = filter::navError(e1, t1);
  dx1.tail(L.imuSize()) = Dii * dimu;
  return dx1;
}

}  // namespace

// Every block of Phi (from F of Groves 14.63-14.71 plus the IMU coupling)
// against central differences of the nonlinear error propagation.
TEST(Jacobians, TransitionBlocksMatchNonlinearPropagation) {
  const ins::NavState truth = movingState();
  filter::EkfConfig cfg;
  cfg.discretization = filter::Discretization::VanLoan;
  filter::ErrorStateEkf ekf(truth, filter::Matrix9d::Identity(), richModel(), cfg);
  // 20 ms: long enough that second-order position changes stand well above the
  // rounding of latitude (about 6e-10 m), short enough for O(dt^2) to be negligible.
  const double dt = 0.02;
  // linearise at the interval midpoint of the truth
  const ins::NavState mid = ins::mechanize(truth, ins::ImuSample::fromRates(truth.t + dt / 2, dt / 2, kW, kF), nullptr);
  ekf.predictCovariance(mid, kW, kF, dt);
  MatrixXd Phi, Qd;
  ekf.discretize(dt, Phi, Qd);
  const int N = ekf.size(), m = ekf.layout().imuSize();
  const MatrixXd Dii = Phi.bottomRightCorner(m, m);

  // step sizes per state kind: metres, m/s, rad, sensor units
  MatrixXd J(N, N);
  VectorXd eps(N);
  for (int j = 0; j < N; ++j) eps(j) = j < 3 ? 1.0 : j < 6 ? 1e-2 : j < 9 ? 1e-3 : 1e-2;
  // rounding floor of a central difference: ~1e-9 m of latitude/longitude rounding / eps
  auto floorOf = [&](int j) { return 1e-9 / eps(j); };
  for (int j = 0; j < N; ++j) {
    VectorXd d = VectorXd::Zero(N);
    d(j) = eps[j];
    J.col(j) = (propagateError(ekf, truth, d, Dii, dt) - propagateError(ekf, truth, -d, Dii, dt)) /
               (2.0 * eps(j));
  }
  // Compare the change over dt (Phi - I) block by block: the discrete
  // mechanization and the exact exponential of F agree to O(dt^2) relative.
  const MatrixXd I = MatrixXd::Identity(N, N);
  const char* names[] = {"pos", "vel", "att"};
  for (int bi = 0; bi < 3; ++bi) {
    for (int bj = 0; bj < 3; ++bj) {
      const MatrixXd lin = (Phi - I).block<3, 3>(3 * bi, 3 * bj);
      const MatrixXd nl = (J - I).block<3, 3>(3 * bi, 3 * bj);
      const double scale = std::max(lin.norm(), nl.norm());
      EXPECT_LE((lin - nl).norm(), 2e-3 * scale + floorOf(3 * bj))
          << names[bi] << "/" << names[bj] << "\nlinear:\n" << lin << "\nnonlinear:\n" << nl;
    }
    // coupling to every IMU error state; position responds to gyro errors and
    // to drift rates / oscillator second states only at third order in dt
    // (state -> attitude or bias -> velocity -> position), where the discrete
    // mechanization and the exact exponential legitimately differ by O(dt^3):
    // those chains are products of blocks tested here, so they are skipped.
    // The mechanization rotates the velocity increment with the body over the
    // interval (Groves 5.84, exact constant-rate form), while F freezes C_BtoN:
    // a sensor error reaching velocity through that rotation differs by
    // O(|w_IB_B| dt) relative, which is added to the tolerance.
    const MatrixXd Fc = ekf.F();
    const double rot_rel = kW.norm() * dt;
    for (int j = 9; j < N; ++j) {
      if (bi == 0 && Fc.block(3, j, 3, 1).norm() == 0.0) continue;
      const Vector3d lin = Phi.block<3, 1>(3 * bi, j), nl = J.block<3, 1>(3 * bi, j);
      const double scale = std::max(lin.norm(), nl.norm());
      EXPECT_LE((lin - nl).norm(), (2e-3 + rot_rel) * scale + floorOf(j))
          << names[bi] << "/" << ekf.layout().names()[j] << "\nlinear: " << lin.transpose()
          << "\nnonlinear: " << nl.transpose();
    }
  }
  // relative size of the largest mismatch, for the report
  // A wrong sign anywhere in the big blocks would fail above; make sure they are not trivially zero.
  EXPECT_GT((Phi - I).block(3, 6, 3, 3).norm(), 1e-2);   // tilt -> velocity (f x)
  EXPECT_GT((Phi - I).block(0, 3, 3, 3).norm(), 1e-3);   // velocity -> position
  EXPECT_GT((Phi - I).block(6, 3, 3, 3).norm(), 1e-10);  // velocity -> attitude (transport)
}

// Measurement Jacobians: residual of the filter at a perturbed estimate,
// measured by the true antenna, against H dx.
TEST(Jacobians, MeasurementBlocksMatchNonlinearResiduals) {
  const ins::NavState truth = movingState();
  const Vector3d lever(0.8, -0.3, -1.2);
  const stochastic::ImuModel mdl = richModel();
  // true antenna position and velocity (exact local Cartesian for the lever arm)
  const Eigen::Matrix3d C = truth.C_BtoN();
  const earth::Geodetic z_pos = earth::nedToGeodetic(truth.geodetic(), C * lever);
  const Vector3d z_vel = truth.v_N + C * kW.cross(lever) - earth::w_IE_N(truth.lat).cross(C * lever);

  auto residuals = [&](const VectorXd& dx) {
    filter::ErrorStateEkf e(truth, filter::Matrix9d::Identity(), mdl);
    // corrected gyro output of the estimate = true rate - H dx_imu
    Vector3d w = kW;
    for (int c = 0; c < 3; ++c) w(c) -= e.layout().sensorRow(c).dot(dx.tail(e.layout().imuSize()));
    e.predictCovariance(filter::applyNavError(truth, dx.head<9>()), w, kF, 0.005);
    VectorXd r(7);
    r.head<3>() = e.residualGnssPosition(z_pos, lever);
    r.segment<3>(3) = e.residualGnssVelocity(z_vel, lever);
    r(6) = e.state().h - truth.h;
    return r;
  };
  filter::ErrorStateEkf ekf(truth, filter::Matrix9d::Identity(), mdl);
  ekf.predictCovariance(truth, kW, kF, 0.005);
  const int N = ekf.size();
  MatrixXd H(7, N);
  H << ekf.H_gnssPosition(lever), ekf.H_gnssVelocity(lever), ekf.H_baro();
  EXPECT_LT(residuals(VectorXd::Zero(N)).norm(), 1e-6);  // truth predicts the measurement
  MatrixXd J(7, N);
  for (int j = 0; j < N; ++j) {
    const double eps = j < 3 ? 1.0 : j < 6 ? 1e-2 : j < 9 ? 1e-4 : 1e-3;
    VectorXd d = VectorXd::Zero(N);
    d(j) = eps;
    J.col(j) = (residuals(d) - residuals(-d)) / (2.0 * eps);
  }
  for (int j = 0; j < N; ++j) {
    const double scale = std::max(H.col(j).norm(), J.col(j).norm());
    EXPECT_LE((H.col(j) - J.col(j)).norm(), 1e-5 * scale + 1e-9)
        << ekf.layout().names()[j] << "\nH: " << H.col(j).transpose()
        << "\nnonlinear: " << J.col(j).transpose();
  }
  EXPECT_GT(H.block(0, filter::kAtt, 3, 3).norm(), 1.0);  // lever arm makes attitude observable
}
