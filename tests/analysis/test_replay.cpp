// Replay of emulated rawlogs: time base, outage bookkeeping, bad input.
#include <algorithm>

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
