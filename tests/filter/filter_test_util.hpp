// Helpers shared by the filter tests: small models and a static-IMU simulator.
#pragma once

#include <random>
#include <vector>

#include "../ins/ins_test_util.hpp"
#include "navimpact/filter/ekf.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace ftest {

using namespace navimpact;
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using instest::kDeg;
using instest::navState;

/// Same model on the three axes of each sensor ("" = perfect sensor).
inline stochastic::ImuModel model(const std::vector<stochastic::Process>& gyro,
                                  const std::vector<stochastic::Process>& acc, double rate_hz) {
  stochastic::ImuModel m;
  m.rate_hz = rate_hz;
  for (int c = 0; c < 6; ++c) {
    m.axis[c].rate_hz = rate_hz;
    m.axis[c].terms = c < 3 ? gyro : acc;
  }
  return m;
}

inline ins::NavState staticState() { return navState(46.57, 7.65, 550.0, Eigen::Vector3d::Zero(), 2.0, -1.5, 60.0); }

/// Perfect rates of a vehicle at rest (f_B = -C_NtoB g_N, w_IB_B = C_NtoB w_IE_N).
inline void staticRates(const ins::NavState& x, Eigen::Vector3d& w_B, Eigen::Vector3d& f_B) {
  const Eigen::Matrix3d C_NtoB = x.C_BtoN().transpose();
  f_B = -(C_NtoB * earth::gravity_N(x.lat, x.h));
  w_B = C_NtoB * earth::w_IE_N(x.lat);
}

/// Raw IMU samples at rest, corrupted by the model (rates per sample).
inline std::vector<ins::ImuSample> simulateStatic(const ins::NavState& x,
                                                  const stochastic::ImuModel& m, int n,
                                                  std::uint64_t seed) {
  Eigen::Vector3d w, f;
  staticRates(x, w, f);
  const double dt = 1.0 / m.rate_hz;
  std::vector<std::vector<double>> err(6);
  for (int c = 0; c < 6; ++c)
    err[c] = m.axis[c].empty() ? std::vector<double>(n, 0.0)
                               : stochastic::simulate(m.axis[c], n, stochastic::deriveSeed(seed, c));
  std::vector<ins::ImuSample> out(n);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d ew(err[0][k], err[1][k], err[2][k]);
    const Eigen::Vector3d ea(err[3][k], err[4][k], err[5][k]);
    out[k] = ins::ImuSample::fromRates(x.t + (k + 1) * dt, dt, w + ew, f + ea);
  }
  return out;
}

}  // namespace ftest
