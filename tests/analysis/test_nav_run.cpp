// The navigation run where its measurements meet its clock and its start, on
// a perfect IMU and GNSS of centimetres: what the filter must get right there
// cannot hide behind noise. The first 120 s of the UAV flight at 100 Hz; the
// antenna and the IMU-GNSS time offset drawn at random over their documented
// ranges (seeded, printed).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/analysis/run_plan.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "test_support.hpp"

namespace an = navimpact::analysis;
namespace lim = navimpact::limits;

namespace {

constexpr double kSigmaPos = 0.02;   // GNSS position, each axis [m]
constexpr double kSigmaVel = 0.002;  // GNSS velocity, each axis [m/s]

/// The plan of a run with the antenna at @p lever_B: GNSS 1 Hz and baro 10 Hz
/// of (nearly) no noise, an initial error of millimetres, P0 to match.
an::RunPlan plan(const Eigen::Vector3d& lever_B) {
  an::RunPlanOptions o;
  o.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  o.trajectory.end_s = 120.0;
  o.imu_rate_hz = 100.0;
  o.record_rate_hz = 10.0;
  o.gnss.sigma_pos_h_m = o.gnss.sigma_pos_v_m = kSigmaPos;
  o.gnss.sigma_vel_h_mps = o.gnss.sigma_vel_v_mps = kSigmaVel;
  o.gnss.lever_arm_B = lever_B;
  o.baro.sigma_m = 0.05;
  o.initial_sigma << 0.01, 0.01, 0.01, 0.001, 0.001, 0.001, 1e-4, 1e-4, 1e-4;
  return an::planRuns(o);
}

/// The filter's model: the NavChip Table 1 Ref errors at the run's rate.
navimpact::stochastic::ImuModel model() {
  return navimpact::stochastic::convertRate(
      navimpact::stochastic::loadImuModel(navimpact::test::sourcePath("config/models/navchip_table1.yaml") + ":ref"),
      100.0);
}

/// One run of @p p on a perfect IMU whose sample stamped t holds the motion of
/// t - @p d (IMU-GNSS time offset), through a filter with @p nav.
an::NavRunResult run(const an::RunPlan& p, double d, const an::NavRunOptions& nav, std::uint64_t seed) {
  std::array<std::vector<double>, 6> zero;
  for (auto& z : zero) z.assign(p.samples(), 0.0);
  an::EmulatedRun r = p.emulate(zero, seed);
  r.imu = navimpact::emulation::shiftImuTime(r.imu, d);
  return an::runNav(p.input(r), model(), nav);
}

double uniform(std::mt19937_64& g, const lim::Range& r) {
  return std::uniform_real_distribution<double>(r.lo, r.hi)(g);
}

}  // namespace

// A GNSS velocity at the first epoch with a lever arm l: the antenna moves at
// v + C (w x l), so the update at x0.t needs the body rate before any IMU
// step: the first sample's (ErrorStateEkf::primeRates). With zero rates it set
// the velocity off by about |w x l| (0.5-0.8 m/s at the first epoch for the
// antennas of the default seed, up to 32 m/s later in the transient). Told
// the true antenna, the first epoch's velocity error stays below a tenth of
// |w0 x l| plus 2 cm/s, and the run's below 3 cm/s per metre of lever arm
// (measured: at most 0.016 m/s per metre, the start's transient; 10 m: 0.03-0.05
// m/s at the first epoch).
TEST(NavRun, AGnssVelocityAtTheStartWithALeverArmUsesTheBodyRate) {
  std::mt19937_64 g(navimpact::test::envOr("NAVIMPACT_NAV_RUN_SEED", 61001));
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Vector3d l(uniform(g, lim::kLeverArmM), uniform(g, lim::kLeverArmM), uniform(g, lim::kLeverArmM));
    const an::RunPlan p = plan(l);
    const an::NavRunResult r = run(p, 0.0, p.nav, 71 + trial);
    ASSERT_FALSE(r.epochs.empty());
    EXPECT_NEAR(r.epochs.front().t, p.t0, 1e-9);
    const double wl = (p.perfect.front().dtheta_B / p.perfect.front().dt).cross(l).norm();
    double worst = 0.0;
    for (const auto& e : r.epochs) worst = std::max(worst, e.err.segment<3>(3).norm());
    const double first = r.epochs.front().err.segment<3>(3).norm();
    std::printf("trial %d: antenna at [%.3f, %.3f, %.3f] m, |w0 x l| %.3f m/s: velocity error at the first epoch "
                "%.2e m/s, worst %.2e m/s\n", trial, l.x(), l.y(), l.z(), wl, first, worst);
    EXPECT_LT(first, 0.1 * wl + 0.02);
    EXPECT_LT(worst, 0.03 * l.norm());
  }
}

// An IMU-GNSS time offset d = t_IMU - t_true over its documented range, the
// filter's time-offset state on (prior 50 ms). With the antenna at the IMU it
// reads d within 0.5 % of |d| plus 3 sigma (measured: at most 0.2 %); with an
// antenna over the lever-arm range within 10 % (measured: 0.03-0.2 % for
// positive offsets, 0.6-4.6 % for negative ones at seeds 5-7: a bias not
// explained). What had to hold: the initial state (on the true clock) carried
// to the IMU's and coupled to the offset's error
// (ErrorStateEkf::carryInitialStateToImuClock); each GNSS fix and baro sample
// applied at the IMU epoch of its true time, t + d (NavRunner), where a
// first-order carry over the whole offset read 84 ms as 81.3 ms and 20 ms as
// 19.65 ms (sigma 0.035 ms); the barometer on the true clock as GNSS; the
// antenna's acceleration (rotation terms of the lever arm) and the body rate
// at the sample's end (ErrorStateEkf::antennaAcceleration). Before: 5.5-6.5 %
// short without a lever arm, 6-82 % off with one.
TEST(NavRun, ATimeOffsetIsReadAcrossItsRange) {
  std::mt19937_64 g(navimpact::test::envOr("NAVIMPACT_NAV_RUN_SEED", 61001) + 1);
  for (int trial = 0; trial < 6; ++trial) {
    const double d = uniform(g, lim::kTimeOffsetS);
    const bool lever = trial % 2 == 1;
    Eigen::Vector3d l = Eigen::Vector3d::Zero();
    if (lever) l << uniform(g, lim::kLeverArmErrorM), uniform(g, lim::kLeverArmErrorM), uniform(g, lim::kLeverArmErrorM);
    const an::RunPlan p = plan(l);
    an::NavRunOptions nav = p.nav;
    nav.ekf.imu.extra.time_offset_sigma_s = 0.05;
    const an::NavRunResult r = run(p, d, nav, 81 + trial);
    const double est = r.extra_estimates.time_offset_s, sd = r.extra_sigmas.time_offset_s;
    std::printf("trial %d: offset %.6f s, antenna [%.2f, %.2f, %.2f] m: read %.6f s, sigma %.2e s (%+.3f %%)\n", trial,
                d, l.x(), l.y(), l.z(), est, sd, 100.0 * (est - d) / std::abs(d));
    ASSERT_GT(sd, 0.0);
    EXPECT_LE(std::abs(est - d), (lever ? 0.1 : 0.005) * std::abs(d) + 3.0 * sd);
  }
}


// With a time-offset estimate d > 0 the truth of true time t is scored with the
// state at IMU time t + d; for the last truth epochs that time lies past the
// last sample, where a carry over up to d beyond the data is first order (its
// (dw/dt) d^2 / 2 gave a perfect IMU attitude NEES of 200-1,700 there alone).
// Such epochs are counted, not scored: every truth epoch of the span is one or
// the other, those past the IMU clock are exactly the ones after t1 - d_est, and
// without the state there are none. Offset drawn over the positive half of its
// documented range (seeded, printed).
TEST(NavRun, TruthEpochsPastTheImuClockAreCountedNotExtrapolated) {
  std::mt19937_64 g(navimpact::test::envOr("NAVIMPACT_NAV_RUN_SEED", 61001) + 2);
  const an::RunPlan p = plan(Eigen::Vector3d::Zero());
  const double half = 0.5 / p.rate_hz;
  std::size_t inSpan = 0;
  for (const double t : p.truth.t) inSpan += t <= p.t1 + half ? 1 : 0;
  {
    const an::NavRunResult r = run(p, 0.0, p.nav, 71);
    EXPECT_EQ(r.epochs_past_imu_clock, 0u);
    EXPECT_EQ(r.epochs.size(), inSpan);
  }
  for (int trial = 0; trial < 2; ++trial) {
    const double d = std::uniform_real_distribution<double>(0.0, lim::kTimeOffsetS.hi)(g);
    an::NavRunOptions nav = p.nav;
    nav.ekf.imu.extra.time_offset_sigma_s = 0.05;
    const an::NavRunResult r = run(p, d, nav, 72 + trial);
    const double est = r.extra_estimates.time_offset_s;
    std::size_t past = 0;
    for (const double t : p.truth.t) past += (t <= p.t1 + half && t + est > p.t1 + half) ? 1 : 0;
    std::printf("trial %d: offset %.6f s read %.6f s: %zu scored, %zu past the IMU clock\n", trial, d, est,
                r.epochs.size(), r.epochs_past_imu_clock);
    EXPECT_EQ(r.epochs.size() + r.epochs_past_imu_clock, inSpan);
    EXPECT_EQ(r.epochs_past_imu_clock, past);
    ASSERT_FALSE(r.epochs.empty());
    EXPECT_LE(r.epochs.back().t + est, p.t1 + half * (1.0 + 1e-6));
  }
}
