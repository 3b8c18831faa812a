// Perfect IMU against textbook closed forms (Groves 2013 ch. 5): at rest on the
// ellipsoid, constant velocity along a meridian and along a parallel, and a
// level coordinated turn. The expected values below use their own WGS84 radii
// and the explicit Coriolis / centripetal terms, not the code under test;
// only normal gravity is taken from the earth model (it is the model, not the
// kinematics, that is being checked).
#include <cmath>
#include <functional>

#include <Eigen/Geometry>

#include "navimpact/core/earth.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace earth = navimpact::earth;
using Eigen::Vector3d;

namespace {

constexpr double kA = 6378137.0, kF = 1.0 / 298.257223563, kE2 = kF * (2 - kF);
constexpr double kOmega = 7.292115e-5;
double R_N(double lat) { return kA * (1 - kE2) / std::pow(1 - kE2 * std::sin(lat) * std::sin(lat), 1.5); }
double R_E(double lat) { return kA / std::sqrt(1 - kE2 * std::sin(lat) * std::sin(lat)); }

struct Sample { earth::Geodetic p; Vector3d rpy; };

// Samples at 100 Hz for [0, dur] from a function of time.
emu::SampledTrajectory sampled(double dur, const std::function<Sample(double)>& f) {
  emu::SampledTrajectory s;
  s.source = "analytic";
  s.origin = f(0.0).p;
  for (int i = 0; i <= int(dur * 100); ++i) {
    const double t = i / 100.0;
    const Sample x = f(t);
    s.t.push_back(t);
    s.p_L.push_back(earth::geodeticToNed(s.origin, x.p));
    s.rpy.push_back(x.rpy);
  }
  return s;
}

double gMaxRel[2] = {0.0, 0.0};  // largest |got - want| / |want| seen for f_B and w_IB_B

void expectClose(const Vector3d& got, const Vector3d& want, const char* what, double t) {
  const double tol = 1e-7 * want.norm();
  double& m = gMaxRel[what[0] == 'f' ? 0 : 1];
  m = std::max(m, (got - want).norm() / want.norm());
  EXPECT_LE((got - want).norm(), tol) << what << " at t=" << t << "\n got  " << got.transpose()
                                      << "\n want " << want.transpose();
}

const double lat0 = 46.57 * M_PI / 180, lon0 = 6.54 * M_PI / 180, h0 = 600.0;

struct Report : ::testing::EmptyTestEventListener {
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (std::string(info.test_suite_name()) != "ClosedForms") return;
    std::printf("  max relative error: f_B %.2e, w_IB_B %.2e\n", gMaxRel[0], gMaxRel[1]);
    gMaxRel[0] = gMaxRel[1] = 0.0;
  }
};
const bool kReportInstalled = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new Report);
  return true;
}();

}  // namespace

TEST(ClosedForms, AtRestOnTheEllipsoid) {
  const Vector3d rpy(0.1, -0.2, 1.0);
  emu::SmoothTrajectory tr(sampled(20.0, [&](double) { return Sample{{lat0, lon0, h0}, rpy}; }), {});
  const Eigen::Matrix3d C_NtoB = emu::eulerToC_NtoB(rpy[0], rpy[1], rpy[2]);
  const Vector3d w_IE(kOmega * std::cos(lat0), 0, -kOmega * std::sin(lat0));
  for (double t : {0.0, 3.3, 10.0, 20.0}) {
    const auto s = tr.at(t);
    expectClose(s.f_B, -(C_NtoB * earth::gravity_N(lat0, h0)), "f_B", t);
    expectClose(s.w_IB_B, C_NtoB * w_IE, "w_IB_B", t);
    EXPECT_LT(s.v_N.norm(), 1e-9);
  }
}

TEST(ClosedForms, ConstantVelocityAlongAMeridian) {
  const double v = 25.0;
  // lat(t) from dlat/dt = v / (R_N + h), RK4 with a fine step.
  std::vector<double> lat(1 + 30 * 1000);
  lat[0] = lat0;
  const double dt = 1e-3;
  auto fl = [&](double la) { return v / (R_N(la) + h0); };
  for (std::size_t i = 1; i < lat.size(); ++i) {
    const double x = lat[i - 1];
    const double k1 = fl(x), k2 = fl(x + 0.5 * dt * k1), k3 = fl(x + 0.5 * dt * k2), k4 = fl(x + dt * k3);
    lat[i] = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  const Vector3d rpy(0.0, 0.05, 0.0);
  emu::SmoothTrajectory tr(sampled(30.0, [&](double t) {
    return Sample{{lat[std::size_t(std::lround(t * 1000))], lon0, h0}, rpy}; }), {});
  const Eigen::Matrix3d C_NtoB = emu::eulerToC_NtoB(rpy[0], rpy[1], rpy[2]);
  for (double t : {5.0, 12.34, 25.0}) {
    const double la = lat[std::size_t(std::lround(t * 1000))];
    const auto s = tr.at(t);
    EXPECT_NEAR(s.pos.lat, la, 1e-12);
    const Vector3d w_IE(kOmega * std::cos(la), 0, -kOmega * std::sin(la));
    const Vector3d w_EN(0, -v / (R_N(la) + h0), 0);
    // Coriolis (0, -2 Omega v sin lat, 0) and centripetal (0, 0, v^2/(R_N+h)).
    const Vector3d f_N = -earth::gravity_N(la, h0) +
                         Vector3d(0, -2 * kOmega * v * std::sin(la), v * v / (R_N(la) + h0));
    expectClose(s.f_B, C_NtoB * f_N, "f_B", t);
    expectClose(s.w_IB_B, C_NtoB * (w_IE + w_EN), "w_IB_B", t);
    EXPECT_NEAR((s.v_N - Vector3d(v, 0, 0)).norm(), 0.0, 1e-7);
  }
}

TEST(ClosedForms, ConstantVelocityAlongAParallel) {
  const double v = 25.0;
  const double lonRate = v / ((R_E(lat0) + h0) * std::cos(lat0));
  const Vector3d rpy(0.0, 0.0, M_PI / 2);
  emu::SmoothTrajectory tr(sampled(30.0, [&](double t) {
    return Sample{{lat0, lon0 + lonRate * t, h0}, rpy}; }), {});
  const Eigen::Matrix3d C_NtoB = emu::eulerToC_NtoB(rpy[0], rpy[1], rpy[2]);
  const double Re = R_E(lat0) + h0;
  const Vector3d w_IE(kOmega * std::cos(lat0), 0, -kOmega * std::sin(lat0));
  const Vector3d w_EN(v / Re, 0, -v * std::tan(lat0) / Re);
  const Vector3d f_N = -earth::gravity_N(lat0, h0) +
                       Vector3d(2 * kOmega * v * std::sin(lat0) + v * v * std::tan(lat0) / Re, 0,
                                2 * kOmega * v * std::cos(lat0) + v * v / Re);
  for (double t : {5.0, 15.0, 25.0}) {
    const auto s = tr.at(t);
    expectClose(s.f_B, C_NtoB * f_N, "f_B", t);
    expectClose(s.w_IB_B, C_NtoB * (w_IE + w_EN), "w_IB_B", t);
  }
}

TEST(ClosedForms, LevelCoordinatedTurn) {
  const double V = 20.0, wt = 0.1, g0 = 9.80665;
  const double bank = std::atan(V * wt / g0);
  // Integrate lat, lon from v_N = V (cos psi, sin psi, 0), psi = wt t (RK4, 1 ms).
  const double dt = 1e-3;
  const int n = 40 * 1000;
  std::vector<double> la(n + 1), lo(n + 1);
  la[0] = lat0;
  lo[0] = lon0;
  auto rate = [&](double t, double x, double& dla, double& dlo) {
    dla = V * std::cos(wt * t) / (R_N(x) + h0);
    dlo = V * std::sin(wt * t) / ((R_E(x) + h0) * std::cos(x));
  };
  for (int i = 1; i <= n; ++i) {
    const double t = (i - 1) * dt;
    double a1, b1, a2, b2, a3, b3, a4, b4;
    rate(t, la[i - 1], a1, b1);
    rate(t + dt / 2, la[i - 1] + dt / 2 * a1, a2, b2);
    rate(t + dt / 2, la[i - 1] + dt / 2 * a2, a3, b3);
    rate(t + dt, la[i - 1] + dt * a3, a4, b4);
    la[i] = la[i - 1] + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    lo[i] = lo[i - 1] + dt / 6 * (b1 + 2 * b2 + 2 * b3 + b4);
  }
  emu::SmoothTrajectory tr(sampled(40.0, [&](double t) {
    const auto i = std::size_t(std::lround(t * 1000));
    return Sample{{la[i], lo[i], h0}, Vector3d(bank, 0.0, wt * t)}; }), {});
  for (double t : {10.0, 17.77, 30.0}) {
    const auto i = std::size_t(std::lround(t * 1000));
    const double psi = wt * t, lat = la[i];
    const Vector3d v_N(V * std::cos(psi), V * std::sin(psi), 0);
    const Vector3d a_N(-V * wt * std::sin(psi), V * wt * std::cos(psi), 0);
    const double Rn = R_N(lat) + h0, Re = R_E(lat) + h0;
    const Vector3d w_IE(kOmega * std::cos(lat), 0, -kOmega * std::sin(lat));
    const Vector3d w_EN(v_N[1] / Re, -v_N[0] / Rn, -v_N[1] * std::tan(lat) / Re);  // Groves 5.44
    const Eigen::Matrix3d C_NtoB = emu::eulerToC_NtoB(bank, 0.0, psi);
    const Vector3d f_B = C_NtoB * (a_N - earth::gravity_N(lat, h0) + (2 * w_IE + w_EN).cross(v_N));
    const Vector3d w_NB_B(0, wt * std::sin(bank), wt * std::cos(bank));
    const auto s = tr.at(t);
    expectClose(s.f_B, f_B, "f_B", t);
    expectClose(s.w_IB_B, w_NB_B + C_NtoB * (w_IE + w_EN), "w_IB_B", t);
    // Coordinated: almost no lateral specific force (only Earth-rate terms remain).
    EXPECT_LT(std::abs(s.f_B[1]), 5e-3);
    // Increments over one 200 Hz interval equal the integral of the closed form.
    Vector3d dv, dth;
    tr.increments(t, t + 0.005, dv, dth);
    Vector3d dvRef = Vector3d::Zero(), dthRef = Vector3d::Zero();
    const int m = 50;  // Simpson on the closed form (smooth; error ~1e-16)
    for (int k = 0; k <= m; ++k) {
      const double tk = t + 0.005 * k / m, w = (k == 0 || k == m) ? 1 : (k % 2 ? 4 : 2);
      const auto sk = tr.at(tk);
      dvRef += w * sk.f_B;
      dthRef += w * sk.w_IB_B;
    }
    dvRef *= 0.005 / (3 * m);
    dthRef *= 0.005 / (3 * m);
    EXPECT_LE((dv - dvRef).norm(), 1e-12 * dvRef.norm());
    EXPECT_LE((dth - dthRef).norm(), 1e-12 * dthRef.norm());
  }
}
