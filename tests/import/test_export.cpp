// Export then import: a random recording comes back (IMU and times exactly,
// positions to 1e-9 m, attitude to 1e-12 rad), and the same time base.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "navimpact/core/earth.hpp"
#include "navimpact/import/export_run.hpp"
#include "navimpact/import/manifest.hpp"
#include "recording_checks.hpp"
#include "test_support.hpp"

namespace navimpact {
namespace {

TEST(ExportRun, ImportOfTheExportIsTheRecording) {
  for (std::uint64_t seed = 7100; seed < 7106; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N(0.0, 1.0);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    Recording d;
    d.source = "random";
    d.origin = {(-80 + 160 * U(rng)) * M_PI / 180, (-180 + 360 * U(rng)) * M_PI / 180, 1000 * U(rng)};
    d.start_unix_s = 1700000000 + static_cast<long long>(1e6 * U(rng));
    d.lever_arm_B = Eigen::Vector3d(N(rng), N(rng), N(rng));
    const double rate = 50 + 950 * U(rng);
    const bool withVel = seed % 2, withCov = seed % 3 != 0;
    std::printf("seed %llu: rate %.2f Hz, GNSS velocity %d, covariance %d\n", (unsigned long long)seed, rate, withVel, withCov);
    for (int k = 0; k < 300; ++k)
      d.imu.push_back({0.5 + k / rate, Eigen::Vector3d(N(rng), N(rng), N(rng)), Eigen::Vector3d(N(rng), N(rng), 9.8 + N(rng))});
    for (int k = 0; k < 10; ++k) {
      GnssFix f;
      f.t = 0.1 + 0.13 * k;
      f.pos = earth::nedToGeodetic(d.origin, Eigen::Vector3d(100 * N(rng), 100 * N(rng), N(rng)));
      if (withVel && k != 3) f.v_N = Eigen::Vector3d(N(rng), N(rng), N(rng));
      if (withCov) f.cov_pos_N = Eigen::Vector3d(1 + U(rng), 1 + U(rng), 2 + U(rng)).asDiagonal();
      if (withCov && f.v_N) f.cov_vel_N = Eigen::Vector3d(0.1, 0.1, 0.2).asDiagonal();
      d.gnss.push_back(f);
      d.baro.push_back({f.t + 0.01, 200 + N(rng), std::nullopt});
      ReferenceRecord r;
      r.t = f.t + 0.05;
      r.p_L = Eigen::Vector3d(100 * N(rng), 100 * N(rng), N(rng));
      r.v_N = Eigen::Vector3d(N(rng), N(rng), N(rng));
      r.q_BtoN = Eigen::Quaterniond(Eigen::AngleAxisd(3 * U(rng), Eigen::Vector3d(N(rng), N(rng), N(rng)).normalized()));
      d.reference.push_back(r);
    }
    const auto dir = test::tempDir();
    const auto notes = import::exportRun(d, dir);
    const Recording b = import::importManifest((dir / "manifest.yaml").string());
    EXPECT_EQ(b.start_unix_s, d.start_unix_s);
    ASSERT_NO_FATAL_FAILURE(test::expectSameImu(b.imu, d.imu));
    ASSERT_EQ(b.gnss.size(), d.gnss.size());
    for (std::size_t k = 0; k < d.gnss.size(); ++k) {
      EXPECT_EQ(b.gnss[k].t, d.gnss[k].t);
      EXPECT_LT(earth::geodeticToNed(d.gnss[k].pos, b.gnss[k].pos).norm(), 1e-8);
      ASSERT_EQ(b.gnss[k].v_N.has_value(), d.gnss[k].v_N.has_value());
      if (d.gnss[k].v_N) { EXPECT_EQ(*b.gnss[k].v_N, *d.gnss[k].v_N); }
      ASSERT_EQ(b.gnss[k].cov_pos_N.has_value(), withCov);
      if (withCov) { EXPECT_LT((*b.gnss[k].cov_pos_N - *d.gnss[k].cov_pos_N).norm(), 1e-14); }
      ASSERT_EQ(b.gnss[k].cov_vel_N.has_value(), d.gnss[k].cov_vel_N.has_value());
    }
    ASSERT_EQ(b.baro.size(), d.baro.size());
    EXPECT_EQ(b.baro[4].h, d.baro[4].h);
    ASSERT_EQ(b.reference.size(), d.reference.size());
    for (std::size_t k = 0; k < d.reference.size(); ++k) {
      EXPECT_LT((b.reference[k].p_L - d.reference[k].p_L).norm(), 1e-8) << k;
      EXPECT_EQ(*b.reference[k].v_N, *d.reference[k].v_N);
      EXPECT_LT(b.reference[k].q_BtoN->angularDistance(*d.reference[k].q_BtoN), 1e-12);
    }
    EXPECT_EQ(*b.lever_arm_B, *d.lever_arm_B);
    EXPECT_NEAR(b.origin.lat, d.origin.lat, 1e-15);
  }
}

}  // namespace
}  // namespace navimpact
