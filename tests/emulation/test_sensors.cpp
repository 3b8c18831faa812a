// Sensor outputs: simulated and measured IMU errors, GNSS (noise, lever arm), baro.
#include <cmath>
#include <functional>
#include <numeric>

#include "navimpact/core/error.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace st = navimpact::stochastic;

namespace {

double stdev(const std::vector<double>& x) {
  const double m = std::accumulate(x.begin(), x.end(), 0.0) / x.size();
  double s = 0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / (x.size() - 1));
}

st::ImuModel wnModel(double rate, double sg, double sa) {
  st::ImuModel m;
  m.source = "test";
  m.rate_hz = rate;
  for (int i = 0; i < 6; ++i) {
    m.axis[i].rate_hz = rate;
    m.axis[i].terms.push_back(st::Process::wn(i < 3 ? sg : sa));
  }
  return m;
}

emu::StaticRecordingSpec adis() {
  emu::StaticRecordingSpec s;
  s.file = navimpact::test::sourcePath("datasets/adis16405_static_excerpt.csv.gz");
  s.csv.rate_hz = 100.0;
  s.csv.gyro_unit = "deg/s";
  s.csv.acc_unit = "g";
  return s;
}

using navimpact::test::errorOf;

// A trajectory at rest (level, heading east) for GNSS/baro checks.
emu::SmoothTrajectory rest(double dur) {
  emu::SampledTrajectory s;
  s.source = "rest";
  s.origin = {0.8, 0.1, 500.0};
  for (int i = 0; i <= int(dur * 100); ++i) {
    s.t.push_back(i / 100.0);
    s.p_L.push_back(Eigen::Vector3d::Zero());
    s.rpy.push_back(Eigen::Vector3d(0, 0, M_PI / 2));
  }
  return emu::SmoothTrajectory(s, {});
}

}  // namespace

TEST(ImuErrors, ModelWhiteNoiseHasItsSigmaAndIsSeeded) {
  const auto m = wnModel(200.0, 1e-3, 5e-3);
  const auto a = emu::modelImuErrors(m, 200.0, 100000, 42);
  EXPECT_TRUE(a.notices.empty());
  EXPECT_NEAR(stdev(a.axis[0]), 1e-3, 1e-3 * 0.02);
  EXPECT_NEAR(stdev(a.axis[5]), 5e-3, 5e-3 * 0.02);
  EXPECT_NE(a.axis[0][10], a.axis[1][10]);  // independent axis streams
  const auto b = emu::modelImuErrors(m, 200.0, 1000, 42);
  EXPECT_EQ(b.axis[3][999], a.axis[3][999]);  // same seed, same stream
}

TEST(ImuErrors, ModelAtAnotherRateIsConvertedWithANotice) {
  // WN at 100 Hz with sigma s has the density of WN at 200 Hz with sigma s*sqrt(2).
  const auto a = emu::modelImuErrors(wnModel(100.0, 1e-3, 1e-3), 200.0, 100000, 7);
  ASSERT_EQ(a.notices.size(), 1u);
  EXPECT_NE(a.notices[0].find("100 Hz"), std::string::npos);
  EXPECT_NEAR(stdev(a.axis[2]), 1e-3 * std::sqrt(2.0), 1e-3 * std::sqrt(2.0) * 0.02);
}

TEST(ImuErrors, StaticRecordingWindowMeanRemovedSi) {
  auto s = adis();
  s.offset_s = 100.0;
  const auto e = emu::staticImuErrors(s, 100.0, 5000);
  const auto rec = navimpact::readImuCsv(s.file, s.csv);
  for (int i = 0; i < 6; ++i) {
    const double mean = std::accumulate(e.axis[i].begin(), e.axis[i].end(), 0.0) / 5000;
    EXPECT_NEAR(mean, 0.0, 1e-12);
  }
  // differences between samples are the recording's (SI), unchanged
  const auto& gz = rec.channel("gyro_z").x;
  EXPECT_NEAR(e.axis[2][7] - e.axis[2][3], gz[10000 + 7] - gz[10000 + 3], 1e-15);
  const auto& az = rec.channel("acc_z").x;
  EXPECT_NEAR(e.axis[5][20] - e.axis[5][0], az[10020] - az[10000], 1e-15);
}

TEST(ImuErrors, StaticRecordingDecimatesByExactIntegerFactor) {
  auto s = adis();
  s.offset_s = 0.0;
  const auto e = emu::staticImuErrors(s, 50.0, 1000);
  ASSERT_FALSE(e.notices.empty());
  const auto rec = navimpact::readImuCsv(s.file, s.csv);
  const auto& gx = rec.channel("gyro_x").x;
  const double d = 0.5 * (gx[2] + gx[3]) - 0.5 * (gx[0] + gx[1]);
  EXPECT_NEAR(e.axis[0][1] - e.axis[0][0], d, 1e-15);
}

TEST(ImuErrors, StaticRecordingBadRateOrLengthIsAClearError) {
  auto s = adis();
  EXPECT_NE(errorOf([&] { emu::staticImuErrors(s, 200.0, 10); }).find("static recording is at 100 Hz, emulation at 200 Hz"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { emu::staticImuErrors(s, 100.0, 300000); }).find("too short"), std::string::npos);
  s.offset_s = 2600.0;
  EXPECT_NE(errorOf([&] { emu::staticImuErrors(s, 100.0, 5000); }).find("offset 2600 s leaves"), std::string::npos);
  // window from the seed: reproducible, and a notice says where
  s.offset_s.reset();
  s.seed = 11;
  const auto a = emu::staticImuErrors(s, 100.0, 100), b = emu::staticImuErrors(s, 100.0, 100);
  EXPECT_EQ(a.axis[4], b.axis[4]);
  EXPECT_NE(a.notices.at(0).find("seed 11"), std::string::npos);
}

TEST(Gnss, NoiseMatchesSigmasAndLeverArmIsRotated) {
  const auto tr = rest(200.0);
  emu::GnssOptions o;
  o.rate_hz = 10.0;
  o.seed = 3;
  const auto fixes = emu::simulateGnss(tr, o, 0.0, 200.0);
  ASSERT_EQ(fixes.size(), 2001u);
  std::vector<double> n, d, ve, vd;
  for (const auto& f : fixes) {
    const auto dp = navimpact::earth::geodeticToNed(tr.origin(), f.pos);
    n.push_back(dp[0]);
    d.push_back(dp[2]);
    ASSERT_TRUE(f.v_N && f.cov_pos_N && f.cov_vel_N);
    ve.push_back((*f.v_N)[1]);
    vd.push_back((*f.v_N)[2]);
  }
  EXPECT_NEAR(stdev(n), 2.0, 2.0 * 0.05);
  EXPECT_NEAR(stdev(d), 4.0, 4.0 * 0.05);
  EXPECT_NEAR(stdev(ve), 0.05, 0.05 * 0.05);
  EXPECT_NEAR(stdev(vd), 0.10, 0.10 * 0.05);
  EXPECT_DOUBLE_EQ((*fixes[5].cov_pos_N)(2, 2), 16.0);
  // Heading east: an antenna 1 m forward is 1 m east of the IMU.
  emu::GnssOptions l;
  l.sigma_pos_h_m = l.sigma_pos_v_m = l.sigma_vel_h_mps = l.sigma_vel_v_mps = 1e-12;
  l.lever_arm_B = Eigen::Vector3d(1.0, 0.0, 0.0);
  const auto f = emu::simulateGnss(tr, l, 10.0, 10.0).at(0);
  const auto dp = navimpact::earth::geodeticToNed(tr.origin(), f.pos);
  EXPECT_NEAR(dp[0], 0.0, 1e-6);
  EXPECT_NEAR(dp[1], 1.0, 1e-6);
}

TEST(Baro, NoiseMatchesSigma) {
  const auto tr = rest(200.0);
  const auto b = emu::simulateBaro(tr, emu::BaroOptions{10.0, 0.5, 9}, 0.0, 200.0);
  ASSERT_EQ(b.size(), 2001u);
  std::vector<double> h;
  for (const auto& s : b) h.push_back(s.h - 500.0);
  EXPECT_NEAR(stdev(h), 0.5, 0.5 * 0.05);
  EXPECT_NEAR(std::accumulate(h.begin(), h.end(), 0.0) / h.size(), 0.0, 0.05);
}
