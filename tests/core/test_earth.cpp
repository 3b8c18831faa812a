// WGS84 earth model: published normal-gravity values, radii, conversions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "navimpact/core/earth.hpp"

namespace e = navimpact::earth;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

TEST(Earth, NormalGravityAtEquatorAndPole) {
  // WGS84 normal gravity on the ellipsoid (NIMA TR8350.2 table 3.4).
  EXPECT_NEAR(e::gravity_N(0.0, 0.0).z(), 9.7803253359, 1e-9);
  EXPECT_NEAR(e::gravity_N(90.0 * kDeg - 1e-12, 0.0).z(), 9.8321849379, 1e-9);
  EXPECT_NEAR(e::gravity_N(0.0, 0.0).x(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(e::gravity_N(30 * kDeg, 100.0).y(), 0.0);
}

TEST(Earth, GravityGradientMatchesFiniteDifferences) {
  for (double latd : {0.0, 20.0, 46.57, 75.0}) {
    const double lat = latd * kDeg, h = 500.0;
    double dlat = 0, dh = 0;
    e::gravityGradient(lat, h, dlat, dh);
    const double fd_h = (e::gravity_N(lat, h + 1.0).z() - e::gravity_N(lat, h - 1.0).z()) / 2.0;
    const double fd_lat =
        (e::gravity_N(lat + 1e-5, h).z() - e::gravity_N(lat - 1e-5, h).z()) / 2e-5;
    EXPECT_NEAR(dh, fd_h, 1e-4 * std::abs(fd_h)) << latd;
    EXPECT_NEAR(dlat, fd_lat, 1e-3 * 0.05 + 1e-3 * std::abs(fd_lat)) << latd;
  }
}

TEST(Earth, RadiiAtEquatorAndPole) {
  const auto r0 = e::radii(0.0);
  EXPECT_NEAR(r0.R_N, e::kA * (1 - e::kE2), 1e-6);
  EXPECT_NEAR(r0.R_E, e::kA, 1e-6);
  const auto r90 = e::radii(90 * kDeg);
  EXPECT_NEAR(r90.R_N, r90.R_E, 1e-6);
  // derivatives by finite differences
  const double lat = 40 * kDeg;
  const auto rp = e::radii(lat + 1e-6), rm = e::radii(lat - 1e-6), r = e::radii(lat);
  EXPECT_NEAR(r.dR_N_dlat, (rp.R_N - rm.R_N) / 2e-6, 1e-3);
  EXPECT_NEAR(r.dR_E_dlat, (rp.R_E - rm.R_E) / 2e-6, 1e-3);
}

TEST(Earth, RatesAndFrames) {
  const double lat = 46.57 * kDeg;
  EXPECT_NEAR(e::w_IE_N(lat).norm(), 7.292115e-5, 1e-15);
  // omega_IE_N equals C_EtoN * [0 0 Omega].
  const Eigen::Vector3d w = e::C_EtoN(lat, 0.3) * Eigen::Vector3d(0, 0, e::kOmegaIE);
  EXPECT_NEAR((w - e::w_IE_N(lat)).norm(), 0.0, 1e-18);
  // Going east at 100 m/s: transport rate about north = v_E / (R_E + h).
  const Eigen::Vector3d wen = e::w_EN_N(lat, 0.0, Eigen::Vector3d(0, 100, 0));
  EXPECT_NEAR(wen.x(), 100.0 / e::radii(lat).R_E, 1e-15);
}

TEST(Earth, ConversionsRoundTrip) {
  const e::Geodetic p{46.57 * kDeg, 7.65 * kDeg, 432.1};
  const e::Geodetic q = e::ecefToGeodetic(e::geodeticToEcef(p));
  EXPECT_NEAR(q.lat, p.lat, 1e-12);
  EXPECT_NEAR(q.lon, p.lon, 1e-12);
  EXPECT_NEAR(q.h, p.h, 1e-6);
  const Eigen::Vector3d ned(120.0, -35.0, 7.0);
  const e::Geodetic r = e::nedToGeodetic(p, ned);
  EXPECT_NEAR((e::geodeticToNed(p, r) - ned).norm(), 0.0, 1e-6);
  // North is north: positive N displacement increases latitude, D lowers h.
  EXPECT_GT(r.lat, p.lat);
  EXPECT_LT(r.lon, p.lon);
  EXPECT_NEAR(r.h, p.h - 7.0, 0.01);
  // Curvilinear difference agrees with the exact local Cartesian within mm at 100 m.
  EXPECT_NEAR((e::curvilinearDiffNed(r, p) - ned).norm(), 0.0, 5e-3);
}

// The local gravity cache stays within its documented 1e-9 m/s^2 of the
// GeographicLib field along a wandering path (climbs, descents, latitude drift)
// that crosses many boxes, and it really caches (far fewer refreshes than queries).
TEST(Earth, LocalGravityMatchesGeographicLibAlongAPath) {
  e::LocalGravity g;
  double worst = 0.0;
  long queries = 0;
  for (int i = 0; i < 20000; ++i) {
    const double t = 0.05 * i;  // 1000 s at 20 Hz
    const double lat = 0.81 + 2e-4 * std::sin(0.01 * t) + 3e-6 * t;  // drifts over ~5 boxes
    const double h = 430.0 + 150.0 * std::sin(0.02 * t) + 0.5 * std::sin(3.0 * t);
    const Eigen::Vector3d d = g(lat, h) - e::gravity_N(lat, h);
    worst = std::max(worst, d.cwiseAbs().maxCoeff());
    ++queries;
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(worst, 0.0);  // it is an approximation, not a second call of gravity_N
  EXPECT_GT(g.refreshes(), 10);
  EXPECT_LT(g.refreshes(), queries / 20);
  // A box that is too large is visibly worse: the bound is the box, not luck.
  e::LocalGravity coarse(2000.0, 0.05);
  double worst_coarse = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double lat = 0.81 + 2.5e-4 * i, h = 10.0 * i;
    worst_coarse = std::max(worst_coarse, (coarse(lat, h) - e::gravity_N(lat, h)).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(worst_coarse, 1e-8);
}
