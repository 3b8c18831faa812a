// The one plan of emulated runs (study, sweep, diagnosis' navigation gain):
// n whole IMU intervals from the trajectory start, record epochs on the IMU
// grid at the record rate and denser inside each outage, each outage end an
// epoch, outages shifted to filter time, P0 from the initial sigmas; an
// outage past the trajectory refused naming it; a run emulated from the plan
// records one epoch per planned epoch. IMU rate, outages and record rates are
// drawn at random over wide ranges (seeded, printed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include "navimpact/analysis/run_plan.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace an = navimpact::analysis;
using navimpact::Outage;

namespace {

an::RunPlanOptions options(double end_s) {
  an::RunPlanOptions o;
  o.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  o.trajectory.end_s = end_s;
  return o;
}

}  // namespace

TEST(RunPlan, EpochsOnTheImuGridDenserInOutagesEachOutageEndAnEpoch) {
  const std::uint64_t seed = 20261125;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int trial = 0; trial < 4; ++trial) {
    an::RunPlanOptions o = options(60.0);
    o.imu_rate_hz = 20.0 + 380.0 * U(g);
    o.record_rate_hz = 0.2 + 2.0 * U(g);
    o.outage_record_rate_hz = 2.0 + 18.0 * U(g);
    const double a0 = 1.0 + 15.0 * U(g), d0 = 0.5 + 10.0 * U(g);
    const double a1 = a0 + d0 + 1.0 + 10.0 * U(g), d1 = 0.5 + 15.0 * U(g);
    o.outages = {Outage::fromStartDuration(a0, d0), Outage::fromStartDuration(a1, d1)};
    o.initial_sigma << 1, 2, 3, 0.1, 0.2, 0.3, 0.01, 0.02, 0.03;
    std::printf("seed %llu trial %d: IMU %.3f Hz, records %.3f / %.3f Hz, outages %s %s\n",
                static_cast<unsigned long long>(seed), trial, o.imu_rate_hz, o.record_rate_hz,
                o.outage_record_rate_hz, navimpact::outageText(o.outages[0]).c_str(),
                navimpact::outageText(o.outages[1]).c_str());
    const an::RunPlan p = an::planRuns(o);
    const double rate = o.imu_rate_hz;
    // n whole intervals of the trajectory span, t1 = t0 + n / rate.
    const double span = p.traj->tEnd() - p.traj->tBegin();
    EXPECT_EQ(p.samples(), static_cast<std::size_t>(std::floor(span * rate + 1e-9)));
    EXPECT_DOUBLE_EQ(p.t0, p.traj->tBegin());
    EXPECT_NEAR(p.duration_s(), double(p.samples()) / rate, 1e-9);
    EXPECT_NEAR(p.perfect.back().t, p.t1, 1e-6);
    // Epochs: increasing, on the IMU grid, the first at t0.
    ASSERT_EQ(p.truth.t.size(), p.truth.x.size());
    EXPECT_DOUBLE_EQ(p.truth.t.front(), p.t0);
    for (std::size_t e = 0; e < p.truth.t.size(); ++e) {
      const double k = (p.truth.t[e] - p.t0) * rate;
      EXPECT_NEAR(k, std::round(k), 1e-6) << e;
      if (e > 0) {
        EXPECT_GT(p.truth.t[e], p.truth.t[e - 1]);
      }
    }
    const double step_out = std::max(1.0, std::round(rate / o.record_rate_hz)) / rate;
    const double step_in = std::max(1.0, std::round(rate / o.outage_record_rate_hz)) / rate;
    ASSERT_EQ(p.outage_end_epoch.size(), 2u);
    ASSERT_EQ(p.nav.outages.size(), 2u);
    for (std::size_t q = 0; q < 2; ++q) {
      const Outage& w = o.outages[q];
      // shifted to filter time, the end an epoch within half an IMU interval
      EXPECT_DOUBLE_EQ(p.nav.outages[q].start_s, p.t0 + w.start_s);
      EXPECT_DOUBLE_EQ(p.nav.outages[q].end_s, p.t0 + w.end_s);
      EXPECT_LE(std::abs(p.truth.t[p.outage_end_epoch[q]] - (p.t0 + w.end_s)), 0.5 / rate + 1e-9);
      // inside the outage no gap longer than the outage record step
      for (std::size_t e = 1; e < p.truth.t.size(); ++e)
        if (p.truth.t[e - 1] >= p.t0 + w.start_s - 0.5 / rate && p.truth.t[e] <= p.t0 + w.end_s + 0.5 / rate) {
          EXPECT_LE(p.truth.t[e] - p.truth.t[e - 1], step_in + 1e-9);
        }
    }
    // outside: no gap longer than the record step
    for (std::size_t e = 1; e < p.truth.t.size(); ++e) EXPECT_LE(p.truth.t[e] - p.truth.t[e - 1], step_out + 1e-9);
    for (int i = 0; i < 9; ++i) EXPECT_DOUBLE_EQ(p.nav.P0_nav(i, i), o.initial_sigma(i) * o.initial_sigma(i));
  }
}

TEST(RunPlan, OutagePastTheTrajectoryIsRefusedNamingIt) {
  an::RunPlanOptions o = options(60.0);
  o.imu_rate_hz = 100.0;
  o.outages = {Outage::fromStartDuration(50.0, 20.0)};
  o.outage_name = "--outage";
  try {
    an::planRuns(o);
    ADD_FAILURE() << "accepted";
  } catch (const navimpact::Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("--outage 50:20 ends at 70 s, after the end of the trajectory ", 0), 0u) << m;
    EXPECT_NE(m.find("uav_flight_260s.csv.gz"), std::string::npos) << m;
  }
  o.imu_rate_hz = 0.0;
  o.outages.clear();
  EXPECT_THROW(an::planRuns(o), navimpact::Error);
}

TEST(RunPlan, AnEmulatedRunRecordsEveryPlannedEpoch) {
  an::RunPlanOptions o = options(30.0);
  o.imu_rate_hz = 100.0;
  o.outages = {Outage::fromStartDuration(10.0, 15.0)};
  o.use_baro = false;
  const an::RunPlan p = an::planRuns(o);
  navimpact::stochastic::ImuModel m;
  m.rate_hz = o.imu_rate_hz;
  std::array<std::vector<double>, 6> err;
  for (int c = 0; c < 6; ++c) {
    m.axis[c].rate_hz = o.imu_rate_hz;
    m.axis[c].terms = {navimpact::stochastic::Process::wn(c < 3 ? 1e-3 : 1e-2)};
    err[c] = navimpact::stochastic::simulate(m.axis[c], p.samples(), navimpact::stochastic::deriveSeed(7, c));
    err[c].resize(p.samples());
  }
  const an::EmulatedRun run = p.emulate(err, 7);
  const an::NavRunInput in = p.input(run);
  EXPECT_EQ(in.baro, nullptr);  // use_baro false
  EXPECT_EQ(in.truth, &p.truth);
  const an::NavRunResult r = an::runNav(in, m, p.nav);
  ASSERT_EQ(r.epochs.size(), p.truth.t.size());
  EXPECT_EQ(r.baro_updates, 0u);
  ASSERT_EQ(r.outages.size(), 1u);
  EXPECT_EQ(r.outages[0].end_epoch, static_cast<int>(p.outage_end_epoch[0]));
}

// A plan along a trajectory already smoothed (a run diagnosis plans along the
// replayed run's own), from a later start, without record epochs: t0 is the
// start, n the whole IMU intervals to the trajectory's end, the perfect IMU
// that of the span, no epoch but the outage ends, and a start past the end is
// refused. Start, rate and outage drawn at random (seeded, printed).
TEST(RunPlan, AlongASmoothedTrajectoryFromALaterStartWithOnlyTheOutageEnds) {
  const std::uint64_t seed = 20261126;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const an::RunPlanOptions file = options(60.0);
  const auto tr = std::make_shared<const navimpact::emulation::SmoothTrajectory>(
      navimpact::emulation::readTrajectoryCsv(file.trajectory), file.smoothing);
  for (int trial = 0; trial < 3; ++trial) {
    an::RunPlanOptions o;
    o.smoothed = tr;
    o.start_s = tr->tBegin() + 20.0 * U(g);
    o.imu_rate_hz = 50.0 + 200.0 * U(g);
    o.record_rate_hz = 0.0;
    o.outage_record_rate_hz = 0.0;
    o.outages = {Outage::fromStartDuration(5.0 + 10.0 * U(g), 1.0 + 10.0 * U(g))};
    std::printf("seed %llu trial %d: start %.3f s, IMU %.3f Hz, outage %s\n", static_cast<unsigned long long>(seed),
                trial, *o.start_s, o.imu_rate_hz, navimpact::outageText(o.outages[0]).c_str());
    const an::RunPlan p = an::planRuns(o);
    EXPECT_EQ(p.traj, tr);  // shared, not read again
    EXPECT_EQ(p.t0, *o.start_s);
    EXPECT_EQ(p.samples(), an::imuSamples(p.t0, tr->tEnd(), o.imu_rate_hz));
    EXPECT_EQ(p.samples(), static_cast<std::size_t>(std::floor((tr->tEnd() - p.t0) * o.imu_rate_hz + 1e-9)));
    const auto perfect = navimpact::emulation::perfectImu(*tr, o.imu_rate_hz, p.t0, p.t1);
    ASSERT_EQ(perfect.size(), p.perfect.size());
    for (std::size_t k = 0; k < perfect.size(); k += 97) {
      EXPECT_EQ(perfect[k].t, p.perfect[k].t);
      EXPECT_EQ(perfect[k].dv_B, p.perfect[k].dv_B);
    }
    ASSERT_EQ(p.truth.t.size(), 1u);
    ASSERT_EQ(p.outage_end_epoch, std::vector<std::size_t>{0});
    EXPECT_NEAR(p.truth.t[0], p.t0 + o.outages[0].end_s, 0.5 / o.imu_rate_hz + 1e-9);
  }
  an::RunPlanOptions late;
  late.smoothed = tr;
  late.imu_rate_hz = 100.0;
  late.start_s = tr->tEnd() + 1.0;
  EXPECT_EQ(an::imuSamples(*late.start_s, tr->tEnd(), 100.0), 0u);
  EXPECT_THROW(an::planRuns(late), navimpact::Error);
}
