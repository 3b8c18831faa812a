// Strapdown mechanization: a perfect IMU at rest stays at rest; a turn with
// known rates reaches the known attitude; a constant acceleration in a level
// frame gives the expected velocity.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "ins_test_util.hpp"
#include "navimpact/ins/mechanization.hpp"
#include "navimpact/core/error.hpp"

using namespace navimpact;
using Eigen::Vector3d;
using instest::kDeg;

namespace {
ins::NavState restState() { return instest::navState(46.57, 7.65, 550.0, Vector3d::Zero(), 3.0, -2.0, 130.0); }
}  // namespace

// Required by issue 3: one hour at 200 Hz of perfect static IMU data.
TEST(Mechanization, PerfectStaticImuStaysPutForOneHour) {
  const ins::NavState x0 = restState();
  const Eigen::Matrix3d C_NtoB = x0.C_BtoN().transpose();
  const Vector3d f_B = -(C_NtoB * earth::gravity_N(x0.lat, x0.h));
  const Vector3d w_B = C_NtoB * earth::w_IE_N(x0.lat);
  const double dt = 1.0 / 200.0;
  ins::Mechanization mech(x0);
  const int n = 3600 * 200;
  for (int k = 1; k <= n; ++k) mech.step(ins::ImuSample::fromRates(k * dt, dt, w_B, f_B));
  const ins::NavState& x = mech.state();
  const Vector3d dp = earth::curvilinearDiffNed(x.geodetic(), x0.geodetic());
  EXPECT_LT(dp.norm(), 1e-3) << dp.transpose();
  EXPECT_LT(x.v_N.norm(), 1e-6);
  const Eigen::AngleAxisd da(x.q_BtoN * x0.q_BtoN.conjugate());
  EXPECT_LT(std::abs(da.angle()), 1e-7);
  EXPECT_NEAR(x.t, 3600.0, 1e-6);
  std::cout << "1 h static drift: position " << dp.norm() << " m, velocity " << x.v_N.norm()
            << " m/s, attitude " << std::abs(da.angle()) << " rad\n";
}

// A sign error in the Earth-rate or gravity terms fails the static test; a
// sign error in the body-rate use fails this one: rotate 90 deg about body
// down at a constant rate on top of the Earth rate, yaw must advance by 90 deg.
TEST(Mechanization, ConstantYawRateTurnReachesKnownHeading) {
  ins::NavState x0 = restState();
  x0.setRollPitchYaw(0.0, 0.0, 10.0 * kDeg);
  const double rate = 9.0 * kDeg, dt = 0.005, T = 10.0;
  ins::Mechanization mech(x0);
  const int n = static_cast<int>(std::lround(T / dt));
  ins::NavState truth = x0;
  for (int k = 1; k <= n; ++k) {
    truth.setRollPitchYaw(0.0, 0.0, 10.0 * kDeg + rate * k * dt);
    // level, yawing: w_IB_B = C_NtoB w_IE_N + [0 0 rate]; f_B = -C_NtoB g_N
    const double yaw_mid = 10.0 * kDeg + rate * (k - 0.5) * dt;
    const Eigen::Matrix3d C_NtoB =
        ins::quatFromRollPitchYaw(0, 0, yaw_mid).toRotationMatrix().transpose();
    const Vector3d w_B = C_NtoB * earth::w_IE_N(x0.lat) + Vector3d(0, 0, rate);
    const Vector3d f_B = -(C_NtoB * earth::gravity_N(x0.lat, x0.h));
    mech.step(ins::ImuSample::fromRates(k * dt, dt, w_B, f_B));
  }
  const Vector3d rpy = mech.state().rollPitchYaw();
  EXPECT_NEAR(ins::wrapAngle(rpy.z() - (10.0 * kDeg + rate * T)), 0.0, 1e-6);
  EXPECT_NEAR(rpy.x(), 0.0, 1e-6);
  EXPECT_NEAR(rpy.y(), 0.0, 1e-6);
  // The approximate midpoint f_B sampling leaves only a tiny velocity error.
  EXPECT_LT(mech.state().v_N.norm(), 1e-4);
}

// Level, heading north, a specific force of 1 m/s^2 forward on top of the
// gravity reaction accelerates north; after 10 s: v_N ~ 10 m/s, moved ~50 m.
TEST(Mechanization, ForwardAccelerationMovesNorth) {
  ins::NavState x0 = restState();
  x0.setRollPitchYaw(0.0, 0.0, 0.0);
  const double dt = 0.005;
  ins::Mechanization mech(x0);
  for (int k = 1; k <= 2000; ++k) {
    const ins::NavState& x = mech.state();
    const Eigen::Matrix3d C_NtoB = x.C_BtoN().transpose();
    // cancel gravity and Coriolis/transport so that the N-frame acceleration is [1 0 0]
    const Vector3d w_ie = earth::w_IE_N(x.lat), w_en = earth::w_EN_N(x.lat, x.h, x.v_N);
    const Vector3d a_N(1.0, 0.0, 0.0);
    const Vector3d f_N = a_N - earth::gravity_N(x.lat, x.h) + (2 * w_ie + w_en).cross(x.v_N);
    const Vector3d w_B = C_NtoB * (w_ie + w_en);
    mech.step(ins::ImuSample::fromRates(k * dt, dt, w_B, C_NtoB * f_N));
  }
  const ins::NavState& x = mech.state();
  EXPECT_NEAR(x.v_N.x(), 10.0, 1e-3);
  EXPECT_NEAR(x.v_N.y(), 0.0, 1e-3);
  EXPECT_NEAR(x.v_N.z(), 0.0, 1e-3);
  const Vector3d dp = earth::curvilinearDiffNed(x.geodetic(), x0.geodetic());
  EXPECT_NEAR(dp.x(), 50.0, 0.05);
  EXPECT_NEAR(dp.y(), 0.0, 0.01);
}

// A reference record becomes the navigation state it describes: the NED
// offset from the origin goes to geodetic and back to the same offset, and a
// reference without velocity or attitude is refused (never a zero state).
TEST(NavState, OfAReferenceRecord) {
  const earth::Geodetic o{46.57 * kDeg, 7.65 * kDeg, 550.0};
  ReferenceRecord r;
  r.t = 12.5;
  r.p_L = Vector3d(1234.5, -678.25, -31.0);
  r.v_N = Vector3d(20.0, -3.0, 0.5);
  r.q_BtoN = Eigen::Quaterniond(2.0, 0.2, -0.1, 0.4);  // not normalised on purpose
  const ins::NavState x = ins::navStateOf(r, o);
  EXPECT_EQ(x.t, 12.5);
  EXPECT_LT((earth::geodeticToNed(o, x.geodetic()) - r.p_L).norm(), 1e-6);
  EXPECT_EQ(x.v_N, *r.v_N);
  EXPECT_NEAR(x.q_BtoN.norm(), 1.0, 1e-15);
  EXPECT_LT(x.q_BtoN.angularDistance(*r.q_BtoN), 1e-12);
  ReferenceRecord noAtt = r;
  noAtt.q_BtoN.reset();
  EXPECT_THROW(ins::navStateOf(noAtt, o), Error);
  ReferenceRecord noVel = r;
  noVel.v_N.reset();
  EXPECT_THROW(ins::navStateOf(noVel, o), Error);
}

// Mechanization::step carries the latitude terms (trigonometry, radii) of the
// end of one step into the next: the states must be bit for bit those of the
// free function, which computes everything from the latitude, also across
// setState() (a filter update) and at latitude -0 / +0. Random rates and forces
// (seed printed).
TEST(Mechanization, CarriedLatitudeTermsGiveTheSameBits) {
  const std::uint64_t seed = std::random_device{}();
  std::cout << "seed " << seed << "\n";
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double lat0 : {46.57 * kDeg, -0.0, 0.0, -71.3 * kDeg}) {
    ins::NavState x0 = restState();
    x0.lat = lat0;
    x0.v_N = Vector3d(40.0 * u(rng), 40.0 * u(rng), 2.0 * u(rng));
    const double dt = 1.0 / 200.0;
    ins::Mechanization mech(x0);
    ins::NavState ref = x0;
    ins::ImuSample last, last2;
    earth::LocalGravity gravity;  // the same sequence of gravity calls as inside mech
    for (int k = 1; k <= 2000; ++k) {
      const Vector3d w(0.3 * u(rng), 0.3 * u(rng), 0.5 * u(rng)), f(2.0 * u(rng), 2.0 * u(rng), -9.8 + u(rng));
      const ins::ImuSample s = ins::ImuSample::fromRates(k * dt, dt, w, f);
      mech.step(s);
      ref = ins::mechanize(ref, s, k > 1 ? &last : nullptr, k > 2 ? &last2 : nullptr, {}, &gravity);
      last2 = last;
      last = s;
      if (k % 97 == 0) {  // an update moves the state
        ins::NavState x = mech.state();
        x.lat += 1e-7 * u(rng);
        x.v_N.x() += 0.01 * u(rng);
        mech.setState(x);
        ref = x;
      }
      const ins::NavState& a = mech.state();
      ASSERT_TRUE(a.lat == ref.lat && a.lon == ref.lon && a.h == ref.h && a.v_N == ref.v_N &&
                  a.q_BtoN.coeffs() == ref.q_BtoN.coeffs())
          << "step " << k << " from latitude " << lat0;
    }
  }
  for (const double lat : {0.0, -0.0, 0.3, -1.2, 1.5}) {
    const earth::LatitudeTerms l(lat);
    const earth::Radii r = earth::radii(lat);
    EXPECT_TRUE(l.r.R_N == r.R_N && l.r.R_E == r.R_E && l.r.dR_N_dlat == r.dR_N_dlat && l.r.dR_E_dlat == r.dR_E_dlat);
    const Vector3d v(12.0, -7.0, 1.0);
    EXPECT_TRUE(earth::w_IE_N(l) == earth::w_IE_N(lat));
    EXPECT_TRUE(earth::w_EN_N(l, 300.0, v) == earth::w_EN_N(lat, 300.0, v));
    double a_lat = 0, a_h = 0, b_lat = 0, b_h = 0;
    earth::gravityGradient(l, 300.0, a_lat, a_h);
    earth::gravityGradient(lat, 300.0, b_lat, b_h);
    EXPECT_TRUE(a_lat == b_lat && a_h == b_h);
  }
}
