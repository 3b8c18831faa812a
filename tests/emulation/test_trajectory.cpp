// Trajectory CSV import: the real UAV flight, the synthetic lemniscate, units,
// and bad input.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "test_support.hpp"

namespace emu = navimpact::emulation;

namespace {
std::string writeCsv(const std::string& name, const std::string& body) {
  const auto p = navimpact::test::tempDir() / name;
  std::ofstream(p) << body;
  return p.string();
}
std::string errorOf(const emu::TrajectorySpec& s) {
  return navimpact::test::errorOf([&] { emu::readTrajectoryCsv(s); });
}
emu::TrajectorySpec nedSpec(const std::string& file) {
  emu::TrajectorySpec s;
  s.file = file;
  s.system = "ned";
  s.col_time = "t"; s.col_north = "n"; s.col_east = "e"; s.col_down = "d";
  s.col_roll = "r"; s.col_pitch = "p"; s.col_yaw = "y";
  s.attitude_unit = "deg";
  s.origin = navimpact::earth::Geodetic{0.8, 0.1, 500};
  return s;
}
std::string nedRows(int n, double dt = 0.01) {
  std::string s = "t,n,e,d,r,p,y\n";
  for (int i = 0; i < n; ++i)
    s += std::to_string(i * dt) + "," + std::to_string(i * 0.1) + ",0,0,1,2," + std::to_string(170 + i * 2) + "\n";
  return s;
}
}  // namespace

TEST(Trajectory, ReadsLocalNedWithDegreesAndUnwrapsYaw) {
  const auto f = writeCsv("a.csv", nedRows(20));
  auto s = emu::readTrajectoryCsv(nedSpec(f));
  ASSERT_EQ(s.t.size(), 20u);
  EXPECT_NEAR(s.rpy[0][0], 1.0 * M_PI / 180, 1e-12);
  EXPECT_NEAR(s.p_L[5][0], 0.5, 1e-12);
  // yaw passes 180 deg: stays continuous after unwrapping (it is continuous already)
  EXPECT_NEAR(s.rpy[19][2], (170 + 38) * M_PI / 180, 1e-12);
}

TEST(Trajectory, UnwrapsWrappedYaw) {
  std::string body = "t,n,e,d,r,p,y\n";
  for (int i = 0; i < 20; ++i) {
    double y = 170 + i * 2;
    if (y > 180) y -= 360;
    body += std::to_string(i * 0.01) + ",0,0,0,0,0," + std::to_string(y) + "\n";
  }
  auto s = emu::readTrajectoryCsv(nedSpec(writeCsv("w.csv", body)));
  EXPECT_NEAR(s.rpy[19][2], 208 * M_PI / 180, 1e-9);
}

TEST(Trajectory, BadInputNamesFileAndLine) {
  std::string rows = nedRows(20);
  auto replaceLine = [&](int line, const std::string& with) {  // 1-based line
    std::string out;
    std::size_t pos = 0;
    for (int l = 1; pos < rows.size(); ++l) {
      const auto e = rows.find('\n', pos);
      out += (l == line ? with : rows.substr(pos, e - pos)) + "\n";
      pos = e + 1;
    }
    return out;
  };
  const auto rep = writeCsv("rep.csv", replaceLine(6, "0.03,0,0,0,0,0,0"));
  EXPECT_NE(errorOf(nedSpec(rep)).find("rep.csv:6: time"), std::string::npos) << errorOf(nedSpec(rep));
  const auto back = writeCsv("back.csv", replaceLine(6, "0.01,0,0,0,0,0,0"));
  EXPECT_NE(errorOf(nedSpec(back)).find("back.csv:6: time goes backwards"), std::string::npos);
  const auto nan = writeCsv("nan.csv", replaceLine(7, "0.05,nan,0,0,0,0,0"));
  EXPECT_NE(errorOf(nedSpec(nan)).find("nan.csv:7:"), std::string::npos) << errorOf(nedSpec(nan));
  const auto gap = writeCsv("gap.csv", replaceLine(9, "5.0,0,0,0,0,0,0"));
  EXPECT_NE(errorOf(nedSpec(gap)).find("gap.csv:9: gap"), std::string::npos) << errorOf(nedSpec(gap));
  const auto shortRow = writeCsv("short.csv", replaceLine(4, "0.02,0,0"));
  EXPECT_NE(errorOf(nedSpec(shortRow)).find("short.csv:4:"), std::string::npos);
  auto noOrigin = nedSpec(writeCsv("ok.csv", rows));
  noOrigin.origin.reset();
  EXPECT_NE(errorOf(noOrigin).find("origin"), std::string::npos);
  auto badCol = nedSpec(writeCsv("ok2.csv", rows));
  badCol.col_yaw = "heading";
  EXPECT_NE(errorOf(badCol).find("'heading' not found"), std::string::npos);
  // positions beyond the ranges of limits.hpp (a latitude of 1e300 rad was smoothed and emulated)
  const auto far = writeCsv("far.csv", replaceLine(8, "0.06,3e7,0,0,0,0,0"));
  EXPECT_NE(errorOf(nedSpec(far)).find("far.csv:8: column 'n': 3e+07 is out of [-2e+07, 2e+07] m"), std::string::npos)
      << errorOf(nedSpec(far));
  const auto deep = writeCsv("deep.csv", replaceLine(8, "0.06,0,0,20000,0,0,0"));  // 20 km below the origin
  EXPECT_NE(errorOf(nedSpec(deep)).find("deep.csv:8: column 'd'"), std::string::npos) << errorOf(nedSpec(deep));
  emu::TrajectorySpec geo;
  std::string lat = "time_s,lat_rad,lon_rad,alt_m,roll_rad,pitch_rad,yaw_rad\n";
  for (int i = 0; i < 10; ++i) lat += std::to_string(i * 0.01) + (i == 2 ? ",1e300" : ",0.8") + ",0.1,500,0,0,0\n";
  geo.file = writeCsv("lat.csv", lat);
  EXPECT_EQ(errorOf(geo), geo.file + ":4: column 'lat_rad': 1e+300 (5.72958e+301 deg) is out of [-89.9, 89.9] deg");
  // a column twice in the header, or one column for two quantities: one of them was taken without a word
  std::string dup = "time_s,lat_rad,lon_rad,alt_m,roll_rad,pitch_rad,yaw_rad,lat_rad\n";
  for (int i = 0; i < 10; ++i) dup += std::to_string(i * 0.01) + ",0.8,0.1,500,0,0,0,0.2\n";
  geo.file = writeCsv("dup.csv", dup);
  EXPECT_EQ(errorOf(geo), geo.file + ":1: column 'lat_rad' appears more than once in the header");
  geo.file = writeCsv("ok3.csv", lat);
  geo.col_lon = "lat_rad";
  EXPECT_EQ(errorOf(geo), geo.file + ":1: column 'lat_rad' is named for two quantities (trajectory.columns: each needs its own)");
}

// The window's keys name the configuration that gave them (the CSV alone was
// named, with "only 1 samples in the selected window").
TEST(Trajectory, AnEmptyWindowNamesItsKey) {
  const auto csv = writeCsv("win.csv", nedRows(20));
  const auto dir = std::filesystem::path(csv).parent_path();
  auto load = [&](const std::string& keys) {
    const std::string cfg = (dir / "t.yaml").string();
    std::ofstream(cfg) << "trajectory: {file: win.csv, system: ned, origin: {lat_deg: 46, lon_deg: 6, height_m: 400},"
                          " attitude_unit: deg, columns: {time: t, north: n, east: e, down: d, roll: r, pitch: p, yaw: y}"
                       << keys << "}\n";
    emu::TrajectorySpec s;
    s.loadFrom(navimpact::ConfigNode::load(cfg).map("trajectory"));
    return s;
  };
  const std::string cfg = (dir / "t.yaml").string();
  // a window past the file's times (it was cut to the data without a word)
  EXPECT_EQ(errorOf(load(", end_s: 1000")), cfg + ": key 'trajectory.end_s': end_s 1000 s is after the trajectory's last time "
                                                  "(the file spans 0 to 0.19 s) of " + csv);
  EXPECT_EQ(errorOf(load(", start_s: -50, end_s: 0.1")), cfg + ": key 'trajectory.start_s': start_s -50 s is before the "
                                                               "trajectory's first time (the file spans 0 to 0.19 s) of " + csv);
  EXPECT_EQ(errorOf(load(", end_s: 0.02")),
            cfg + ": key 'trajectory.end_s': only 3 samples in the selected window (need >= 8) of " + csv + " (rows 20)");
  try {
    load(", start_s: 5, end_s: 5");
    ADD_FAILURE() << "end_s = start_s accepted";
  } catch (const navimpact::Error& e) {
    EXPECT_EQ(std::string(e.what()), cfg + ": key 'trajectory.end_s': must be after start_s (5 s), got 5");
  }
}

TEST(Trajectory, ReadsTheUavFlight) {
  emu::TrajectorySpec g;
  g.file = navimpact::test::dataPath("uav_flight_600s_ellipsoidal.csv.gz");  // committed (tests/data)
  auto a = emu::readTrajectoryCsv(g);
  EXPECT_EQ(a.t.size(), 60000u);
  EXPECT_NEAR(a.origin.lat, 0.81278354095, 1e-12);
  EXPECT_LT(a.p_L[0].norm(), 1e-6);
  emu::SmoothTrajectory ta(a, {});
  const auto s = ta.at(300.0);
  EXPECT_GT(s.v_N.head<2>().norm(), 1.0);
  EXPECT_LT(s.v_N.norm(), 60.0);
}

namespace {
// The synthetic figure-eight of the R package navigation: x_N = 50 sin(w t),
// x_E = 25 sin(2 w t), x_D = 0, w = 2 pi / 60, 100 Hz over 600 s (60,001
// rows), columns as in the distributed file; level, heading along the path.
void checkLemniscate(const std::string& file) {
  emu::TrajectorySpec n;
  n.file = file;
  n.system = "ned";
  n.origin = navimpact::earth::Geodetic{46.5 * M_PI / 180, 6.5 * M_PI / 180, 400};
  auto b = emu::readTrajectoryCsv(n);
  EXPECT_EQ(b.t.size(), 60001u);
  emu::SmoothTrajectory tb(b, {});
  // x_N = 50 sin(w t): the smooth velocity follows 50 w cos(w t) (spline gain ~1 at 1/60 Hz).
  const double w = 2 * M_PI / 60;
  const auto sb = tb.at(100.0);
  EXPECT_NEAR(sb.v_N[0], 50 * w * std::cos(w * 100.0), 1e-3);
  EXPECT_NEAR(sb.v_N[1], 25 * 2 * w * std::cos(2 * w * 100.0), 1e-3);
}
}  // namespace

TEST(Trajectory, LemniscateFromItsFormula) {
  const double w = 2 * M_PI / 60;
  std::ostringstream csv;
  csv.precision(17);
  csv << "time_s,x_N_m,x_E_m,x_D_m,roll_rad,pitch_rad,yaw_rad\n";
  double yaw_prev = 0;
  for (int k = 0; k <= 60000; ++k) {
    const double t = k / 100.0;
    double yaw = std::atan2(50 * w * std::cos(2 * w * t), 50 * w * std::cos(w * t));
    yaw += 2 * M_PI * std::round((yaw_prev - yaw) / (2 * M_PI));  // unwrapped, as in the file
    yaw_prev = yaw;
    csv << t << "," << 50 * std::sin(w * t) << "," << 25 * std::sin(2 * w * t) << ",0,0,0," << yaw << "\n";
  }
  checkLemniscate(writeCsv("lemniscate_600s_ned.csv", csv.str()));
}

// The same on the file as the R package distributes it (attitudes of its own
// generator), when the shared data folder is present.
TEST(Trajectory, ReadsTheDistributedLemniscateFile) {
  NAVIMPACT_REQUIRE_SHARED("data/trajectories/lemniscate_600s_ned.csv");
  checkLemniscate(navimpact::test::sharedPath("data/trajectories/lemniscate_600s_ned.csv"));
}
