// Replay of emulated rawlogs: time base, outage bookkeeping, bad input.
#include <algorithm>
#include <cstdio>
#include <random>

#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/report/replay_report.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;
namespace an = navimpact::analysis;

namespace {

navimpact::Recording emulate60(const std::string& errors) {
  emu::EmulationConfig c;
  c.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  c.trajectory.end_s = 60.0;
  c.imu_errors = errors;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  return emu::runEmulation(c, "test");
}

std::string errorOf(const an::ReplayConfig& c) {
  try {
    an::runReplay(c);
  } catch (const navimpact::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Replay, PerfectImuStaysWithinItsPredictedSigmaThroughAnOutage) {
  const auto dir = navimpact::test::tempDir();
  const auto path = (dir / "perfect.rawlog").string();
  navimpact::rawlog::writeRawlog(path, emulate60("none"));
  an::ReplayConfig c;
  c.rawlog = path;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  c.outages.push_back(navimpact::Outage::fromStartDuration(30.0, 20.0));
  const auto r = an::runReplay(c);
  ASSERT_EQ(r.run.epochs.size(), 601u);  // GT at 10 Hz over 60 s
  EXPECT_NEAR(r.run.epochs.front().t - r.t_zero, 0.0, 1e-9);
  ASSERT_EQ(r.run.outages.size(), 1u);
  const auto& e = r.run.epochs.at(static_cast<std::size_t>(r.run.outages[0].end_epoch));
  EXPECT_NEAR(e.t - r.t_zero, 50.0, 1e-9);
  // GNSS fixes at 0..60 s, those in (30, 50] dropped.
  EXPECT_EQ(r.run.gnss_updates, 61u - 20u);
  // An error-free IMU coasts better than the Ref-model filter expects.
  EXPECT_LT(e.err.head<2>().norm(), 3.0 * e.sigma.head<2>().norm());
  EXPECT_LT(std::abs(e.err[2]), 3.0 * e.sigma[2]);
  const std::string csv = navimpact::report::solutionCsv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 602);
  EXPECT_NE(navimpact::report::summaryJson(r).find("\"horizontal_error_end_m\""), std::string::npos);
}

TEST(Replay, BadInputIsAClearError) {
  const auto dir = navimpact::test::tempDir();
  auto d = emulate60("none");
  const auto ok = (dir / "ok.rawlog").string();
  navimpact::rawlog::writeRawlog(ok, d);
  an::ReplayConfig c;
  c.rawlog = ok;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  c.outages.push_back(navimpact::Outage::fromStartDuration(50.0, 20.0));
  EXPECT_NE(errorOf(c).find("outage 50:20 ends at 70 s, after the data"), std::string::npos) << errorOf(c);
  c.outages.clear();
  c.model_spec.clear();
  // no model recorded (errors: none) and none given
  EXPECT_NE(errorOf(c).find("--model"), std::string::npos) << errorOf(c);
  d.imu.clear();
  const auto noImu = (dir / "noimu.rawlog").string();
  navimpact::rawlog::writeRawlog(noImu, d);
  c.rawlog = noImu;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  EXPECT_NE(errorOf(c).find("no IMU data"), std::string::npos) << errorOf(c);
  EXPECT_THROW(navimpact::parseOutage("200"), navimpact::Error);
  EXPECT_THROW(navimpact::parseOutage("-1:5"), navimpact::Error);
  EXPECT_DOUBLE_EQ(navimpact::parseOutage("200:60").duration_s(), 60.0);
}

// An IMU gap (samples missing in a block at a random place and of a random
// length from 2 samples to 1 s; seed logged) is an error naming the rawlog and
// the time unless max_imu_gap_s allows it; then the filter propagates across
// it, says so in the notices, and a perfect IMU stays within 3 sigma at the end.
TEST(Replay, ImuGapIsAnErrorUnlessAllowedThenPropagatedAcross) {
  const std::uint64_t seed = 1511;
  std::mt19937_64 rng(seed);
  auto d = emulate60("none");
  const double dt = d.imu[1].t - d.imu[0].t;
  const std::size_t n = d.imu.size();
  const std::size_t missing = 2 + rng() % static_cast<std::size_t>(std::llround(1.0 / dt) - 1);
  const std::size_t first = static_cast<std::size_t>(10.0 / dt) + rng() % static_cast<std::size_t>(35.0 / dt);
  const double gap = d.imu[first + missing].t - d.imu[first - 1].t;
  std::printf("seed %llu: %zu IMU samples removed from %.3f s (gap %.4f s, nominal step %.4f s)\n",
              static_cast<unsigned long long>(seed), missing, d.imu[first].t, gap, dt);
  d.imu.erase(d.imu.begin() + static_cast<std::ptrdiff_t>(first), d.imu.begin() + static_cast<std::ptrdiff_t>(first + missing));
  ASSERT_EQ(d.imu.size(), n - missing);
  const auto path = (navimpact::test::tempDir() / "gap.rawlog").string();
  navimpact::rawlog::writeRawlog(path, d);
  an::ReplayConfig c;
  c.rawlog = path;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  const std::string m = errorOf(c);
  EXPECT_NE(m.find(path + ": IMU gap of "), std::string::npos) << m;
  EXPECT_NE(m.find("max_imu_gap_s"), std::string::npos) << m;
  c.max_imu_gap_s = 0.99 * gap;  // shorter than the gap: still refused
  EXPECT_NE(errorOf(c).find("IMU gap of "), std::string::npos);
  c.max_imu_gap_s = 1.01 * gap;
  const auto r = an::runReplay(c);
  EXPECT_EQ(r.imu_gaps, 1u);
  EXPECT_EQ(r.run.steps, n);  // propagated across the gap in nominal steps
  ASSERT_EQ(r.run.epochs.size(), 601u);
  bool said = false;
  for (const auto& s : r.notices) said = said || s.find("1 IMU gap(s)") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_NE(navimpact::report::summaryJson(r).find("IMU gap(s)"), std::string::npos);
  const auto& e = r.run.epochs.back();
  EXPECT_TRUE(e.err.allFinite());
  EXPECT_LT(e.err.head<2>().norm(), 3.0 * e.sigma.head<2>().norm());
}

// A GNSS fix recorded twice (a random one; seed logged) is refused by the
// reader, naming the entry and the earlier one, instead of being applied twice.
TEST(Replay, DuplicatedGnssRecordIsAnError) {
  const std::uint64_t seed = 1512;
  std::mt19937_64 rng(seed);
  auto d = emulate60("none");
  const std::size_t i = rng() % d.gnss.size();
  std::printf("seed %llu: GNSS fix %zu of %zu (t = %.3f s) recorded twice\n", static_cast<unsigned long long>(seed), i,
              d.gnss.size(), d.gnss[i].t);
  d.gnss.insert(d.gnss.begin() + static_cast<std::ptrdiff_t>(i), d.gnss[i]);
  const auto path = (navimpact::test::tempDir() / "dup.rawlog").string();
  navimpact::rawlog::writeRawlog(path, d);
  an::ReplayConfig c;
  c.rawlog = path;
  c.model_spec = navimpact::test::sourcePath("config/models/navchip_table1.yaml:ref");
  const std::string m = errorOf(c);
  EXPECT_NE(m.find(path + ": entry "), std::string::npos) << m;
  EXPECT_NE(m.find("(label GNSS"), std::string::npos) << m;
  EXPECT_NE(m.find("same time as GNSS entry"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}
