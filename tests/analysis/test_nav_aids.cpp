// Ground-vehicle aids in the navigation loop: an IMU at rest without GNSS
// coasts (velocity sigma grows with the accelerometer noise and the tilt),
// with zero-velocity updates from the static detector the velocity stays
// within the ZUPT sigma and its error within its predicted sigma.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/core/earth.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace an = navimpact::analysis;
using namespace navimpact;
using Eigen::Vector3d;

TEST(NavAids, ZuptHoldsAStaticImuThatWouldOtherwiseCoast) {
  const std::uint64_t seed = 3141;
  constexpr double kDeg = M_PI / 180.0;
  const double rate = 100.0;
  const int n = static_cast<int>(60.0 * rate);
  ins::NavState x;
  x.lat = 52.2 * kDeg;
  x.lon = 4.4 * kDeg;
  x.h = 10.0;
  x.setRollPitchYaw(1.0 * kDeg, -2.0 * kDeg, 30.0 * kDeg);
  stochastic::ImuModel m;
  m.rate_hz = rate;
  for (int c = 0; c < 6; ++c) {
    m.axis[c].rate_hz = rate;
    m.axis[c].terms = {c < 3 ? stochastic::Process::wn(2e-3) : stochastic::Process::wn(2e-2)};
  }
  const Eigen::Matrix3d C_NtoB = x.C_BtoN().transpose();
  const Vector3d f = -(C_NtoB * earth::gravity_N(x.lat, x.h)), w = C_NtoB * earth::w_IE_N(x.lat);
  std::array<std::vector<double>, 6> err;
  Vector3d sw, sf;
  for (int c = 0; c < 6; ++c) {
    err[c] = stochastic::simulate(m.axis[c], n, stochastic::deriveSeed(seed, c));
    double s2 = 0.0;
    for (double e : err[c]) s2 += e * e;
    (c < 3 ? sw : sf)(c % 3) = std::sqrt(s2 / n);  // the at-rest level the detector is told
  }
  std::vector<ins::ImuSample> imu(n);
  for (int k = 0; k < n; ++k)
    imu[k] = ins::ImuSample::fromRates((k + 1) / rate, 1.0 / rate,
                                       w + Vector3d(err[0][k], err[1][k], err[2][k]),
                                       f + Vector3d(err[3][k], err[4][k], err[5][k]));
  an::TruthSeries truth;
  for (int s = 0; s <= 60; ++s) {
    ins::NavState xs = x;
    xs.t = s;
    truth.t.push_back(s);
    truth.x.push_back(xs);
  }
  an::NavRunInput in;
  in.x0 = x;
  in.imu = &imu;
  in.truth = &truth;
  an::NavRunOptions opt;
  opt.P0_nav.diagonal() << 1, 1, 1, 1e-4, 1e-4, 1e-4, 1e-6, 1e-6, 1e-6;
  const an::NavRunResult coast = an::runNav(in, m, opt);
  opt.zupt = true;
  opt.zupt_detector.gyro_sigma_rad_s = sw;
  opt.zupt_detector.acc_sigma_mps2 = sf;
  opt.zupt_sigma_mps = 0.01;
  opt.zupt_interval_s = 0.1;
  const an::NavRunResult held = an::runNav(in, m, opt);
  const auto& c = coast.epochs.back();
  const auto& h = held.epochs.back();
  std::printf("seed %llu: coasting 60 s: velocity sigma %.3f m/s, error %.3f m/s; with %zu ZUPTs: sigma %.4f m/s, "
              "error %.4f m/s, position error %.3f m\n",
              static_cast<unsigned long long>(seed), c.sigma.segment<3>(3).norm(), c.err.segment<3>(3).norm(),
              held.zupt_updates, h.sigma.segment<3>(3).norm(), h.err.segment<3>(3).norm(), h.err.head<3>().norm());
  EXPECT_EQ(coast.zupt_updates, 0u);
  // a window is called moving at the detector's level (1 %): nearly every 0.1 s has a ZUPT
  EXPECT_GE(held.zupt_updates, 550u);
  EXPECT_LE(held.zupt_updates, 600u);
  EXPECT_GT(c.sigma[3], 10.0 * opt.zupt_sigma_mps);
  for (int i = 3; i < 6; ++i) {
    EXPECT_LT(h.sigma[i], 1.5 * opt.zupt_sigma_mps) << i;  // an update leaves P_vv below R, then 0.1 s of growth
    EXPECT_LT(std::abs(h.err[i]), 4.0 * h.sigma[i]) << i;
  }
  EXPECT_LT(h.err.head<3>().norm(), c.err.head<3>().norm());
}
