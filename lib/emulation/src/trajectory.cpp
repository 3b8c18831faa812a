#include "navimpact/emulation/trajectory.hpp"

#include <cmath>
#include <map>
#include <set>
#include <algorithm>

#include <Eigen/Geometry>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/gz_input.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/units.hpp"

namespace navimpact::emulation {

Eigen::Matrix3d eulerToC_NtoB(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll);
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  Eigen::Matrix3d C;  // Groves 2013 eq. 2.22
  C << cp * cy, cp * sy, -sp,
      -cr * sy + sr * sp * cy, cr * cy + sr * sp * sy, sr * cp,
      sr * sy + cr * sp * cy, -sr * cy + cr * sp * sy, cr * cp;
  return C;
}

namespace {

double angleFactor(const std::string& unit, const std::string& key, const std::string& file) {
  if (unit == "rad") return 1.0;
  if (unit == "deg") return units::kDeg;
  throw keyError(file, key, "unit '" + unit + "' is not 'rad' or 'deg'");
}

/// North and east of a local tangent-plane trajectory [m]: within half the
/// Earth's circumference (a tangent plane is meaningless long before).
constexpr limits::Range kNedHorizontalM{-2.0e7, 2.0e7, false, "m"};

}  // namespace

SampledTrajectory readTrajectoryCsv(const TrajectorySpec& spec) {
  InputScope scope(spec.file);
  const std::string& path = spec.file;
  // a key of the spec: named in its configuration when it has one, else with the CSV
  const std::string keyFile = spec.config_file.empty() ? path : spec.config_file;
  const std::string keyPrefix = spec.config_path.empty() ? "trajectory" : spec.config_path;
  const bool geo = spec.system == "geodetic";
  if (!geo && spec.system != "ned")
    throw keyError(keyFile, keyPrefix + ".system", "'" + spec.system + "' is not 'geodetic' or 'ned'");
  if (!geo && !spec.origin)
    throw keyError(keyFile, keyPrefix + ".origin",
                   "a local NED trajectory needs a geodetic origin (lat_deg, lon_deg, height_m)");
  const double kLL = geo ? angleFactor(spec.latlon_unit, keyPrefix + ".latlon_unit", keyFile) : 1.0;
  const double kAtt = angleFactor(spec.attitude_unit, keyPrefix + ".attitude_unit", keyFile);
  double kT = 1.0;
  if (spec.time_unit == "ms") kT = 1e-3;
  else if (spec.time_unit != "s")
    throw keyError(keyFile, keyPrefix + ".time_unit", "'" + spec.time_unit + "' is not 's' or 'ms'");
  if (!(spec.max_gap_s > 0.0)) throw keyError(keyFile, keyPrefix + ".max_gap_s", "must be > 0");

  LineReader reader(path);  // streamed, lines of at most 1 MiB
  std::string_view headerView;
  if (!reader.next(headerView) || trim(headerView).empty()) throw fileError(path, 1, "empty file, expected a header line");
  const std::string headerText(headerView);
  const std::string_view header(headerText);
  const auto names = splitView(header, ',');
  std::map<std::string, int> colIndex;
  std::set<std::string> twice;  // a name in the header more than once: which one is meant?
  for (std::size_t i = 0; i < names.size(); ++i)
    if (!colIndex.emplace(std::string(trim(names[i])), int(i)).second) twice.insert(std::string(trim(names[i])));
  const std::vector<std::string> want =
      geo ? std::vector<std::string>{spec.col_time, spec.col_lat, spec.col_lon, spec.col_height,
                                     spec.col_roll, spec.col_pitch, spec.col_yaw}
          : std::vector<std::string>{spec.col_time, spec.col_north, spec.col_east, spec.col_down,
                                     spec.col_roll, spec.col_pitch, spec.col_yaw};
  int idx[7];
  for (int k = 0; k < 7; ++k) {
    auto it = colIndex.find(want[k]);
    if (it == colIndex.end())
      throw fileError(path, 1, "column '" + want[k] + "' not found in the header (set it in trajectory.columns)");
    if (twice.count(want[k]))
      throw fileError(path, 1, "column '" + printable(want[k]) + "' appears more than once in the header");
    for (int j = 0; j < k; ++j)
      if (want[j] == want[k])
        throw fileError(path, 1, "column '" + printable(want[k]) + "' is named for two quantities (trajectory.columns: each needs its own)");
    idx[k] = it->second;
  }

  SampledTrajectory out;
  out.source = path;
  std::vector<std::array<double, 7>> rows;
  rows.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(reader.input().statedSize() / 60, 1u << 24)));
  std::vector<std::size_t> lines;
  std::string_view line;
  while (reader.next(line)) {
    if (trim(line).empty()) continue;
    const auto f = splitView(line, ',');
    if (f.size() != names.size())
      throw fileError(path, reader.lineNo(), "expected " + std::to_string(names.size()) + " fields, found " +
                                        std::to_string(f.size()));
    std::array<double, 7> r{};
    for (int k = 0; k < 7; ++k) {
      if (!parseDouble(trim(f[idx[k]]), r[k]))
        throw fileError(path, reader.lineNo(), "column '" + want[k] + "': '" + printable(f[idx[k]]) + "' is not a number");
      if (!std::isfinite(r[k]))
        throw fileError(path, reader.lineNo(), "column '" + want[k] + "': value is NaN or infinite");
    }
    r[0] *= kT;
    if (!rows.empty()) {
      const double dt = r[0] - rows.back()[0];
      if (dt == 0.0) throw fileError(path, reader.lineNo(), "time " + formatNumber(r[0], 12) + " s repeats the previous line");
      if (dt < 0.0) throw fileError(path, reader.lineNo(), "time goes backwards (" + formatNumber(rows.back()[0], 12) +
                                                      " s then " + formatNumber(r[0], 12) + " s)");
      if (dt > spec.max_gap_s)
        throw fileError(path, reader.lineNo(), "gap of " + formatNumber(dt) + " s before this line exceeds max_gap_s = " +
                                          formatNumber(spec.max_gap_s) + " s that the smoothing spline may bridge");
    }
    if (spec.start_s && r[0] < *spec.start_s) { rows.push_back(r); lines.push_back(0); continue; }
    rows.push_back(r);
    lines.push_back(reader.lineNo());
  }
  // window: inside the file's times (a window past them was cut to the data
  // without a word: end_s 1000 on a 260 s file emulated 260 s)
  if (!rows.empty()) {
    auto outside = [&](const char* key, double v, const std::string& why) {
      const std::string what = std::string(key) + " " + formatNumber(v, 10) + " s is " + why + " (the file spans " +
                               formatNumber(rows.front()[0], 10) + " to " + formatNumber(rows.back()[0], 10) + " s)";
      if (!spec.config_file.empty()) throw keyError(spec.config_file, keyPrefix + "." + key, what + " of " + printable(path, 120));
      throw fileError(path, 0, what);
    };
    if (spec.start_s && *spec.start_s < rows.front()[0] - 1e-9) outside("start_s", *spec.start_s, "before the trajectory's first time");
    if (spec.end_s && *spec.end_s > rows.back()[0] + 1e-9) outside("end_s", *spec.end_s, "after the trajectory's last time");
  }
  std::size_t first = 0, last = rows.size();
  while (first < rows.size() && spec.start_s && rows[first][0] < *spec.start_s) ++first;
  while (last > first && spec.end_s && rows[last - 1][0] > *spec.end_s) --last;
  if (last - first < 8) {
    const std::string what = "only " + std::to_string(last - first) + " samples in the selected window (need >= 8)";
    if ((spec.start_s || spec.end_s) && !spec.config_file.empty())  // the window's keys chose them
      throw keyError(spec.config_file, keyPrefix + (spec.end_s ? ".end_s" : ".start_s"),
                     what + " of " + printable(path, 120) + " (rows " + std::to_string(rows.size()) + ")");
    throw fileError(path, 0, what);
  }

  const auto& r0 = rows[first];
  if (geo) out.origin = spec.origin ? *spec.origin : earth::Geodetic{r0[1] * kLL, r0[2] * kLL, r0[3]};
  else out.origin = *spec.origin;
  out.t.reserve(last - first);
  out.p_L.reserve(last - first);
  out.rpy.reserve(last - first);
  Eigen::Vector3d prev = Eigen::Vector3d::Zero(), offset = Eigen::Vector3d::Zero();
  for (std::size_t i = first; i < last; ++i) {
    const auto& r = rows[i];
    out.t.push_back(r[0]);
    // positions within the ranges of limits.hpp (a latitude of 1e300 rad went
    // through the smoothing and emulated a run; the filter failed at t = 0)
    auto within = [&](int k, double v, const limits::Range& rg, double to_unit) {
      if (!(v * to_unit >= rg.lo && v * to_unit <= rg.hi))
        throw fileError(path, lines[i], "column '" + want[k] + "': " + formatNumber(r[k]) +
                                            (to_unit == 1.0 ? "" : " (" + formatNumber(v * to_unit) + " " + rg.unit + ")") +
                                            " is out of " + limits::describe(rg));
    };
    if (geo) {
      within(1, r[1] * kLL, limits::kLatitudeDeg, 180.0 / units::kPi);
      within(2, r[2] * kLL, limits::kLongitudeDeg, 180.0 / units::kPi);
      within(3, r[3], limits::kHeightM, 1.0);
      out.p_L.push_back(earth::geodeticToNed(out.origin, earth::Geodetic{r[1] * kLL, r[2] * kLL, r[3]}));
    } else {
      within(1, r[1], kNedHorizontalM, 1.0);
      within(2, r[2], kNedHorizontalM, 1.0);
      within(3, -r[3], limits::kHeightM, 1.0);
      out.p_L.emplace_back(r[1], r[2], r[3]);
    }
    Eigen::Vector3d a(r[4] * kAtt, r[5] * kAtt, r[6] * kAtt);
    if (std::abs(a[1]) > 85.0 * units::kDeg)
      throw fileError(path, lines[i], "|pitch| > 85 deg: Euler-angle smoothing is singular there");
    if (i > first)  // unwrap roll and yaw (pitch stays in [-pi/2, pi/2])
      for (int k : {0, 2}) {
        const double d = a[k] + offset[k] - prev[k];
        offset[k] -= 2.0 * units::kPi * std::round(d / (2.0 * units::kPi));
      }
    a += offset;
    prev = a;
    out.rpy.push_back(a);
  }
  return out;
}

SmoothTrajectory::SmoothTrajectory(const SampledTrajectory& s, const SmoothingOptions& opt)
    : origin_(s.origin), opt_(opt) {
  const std::size_t n = s.t.size();
  std::vector<std::vector<double>> p(3, std::vector<double>(n)), a(3, std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      p[k][i] = s.p_L[i][k];
      a[k][i] = s.rpy[i][k];
    }
  try {
    pos_ = PSpline(s.t, p, {opt.position_cutoff_hz, opt.knot_step_s, opt.penalty_order});
    att_ = PSpline(s.t, a, {opt.attitude_cutoff_hz, opt.knot_step_s, opt.penalty_order});
  } catch (const Error& e) {  // name the data the smoothing failed on (its keys: `smoothing:`)
    throw Error((s.source.empty() ? std::string("trajectory") : s.source) + ": " + e.what() + " (keys smoothing.*)");
  }
  t0_ = s.t.front();
  t1_ = s.t.back();
  r0_E_ = earth::geodeticToEcef(origin_);
  C_LtoE_ = earth::C_EtoN(origin_.lat, origin_.lon).transpose();
}

void SmoothTrajectory::kinematics(double t, bool full, TruthState& s) const {
  s.t = t;
  Eigen::Vector3d v_L, a_L;
  for (int k = 0; k < 3; ++k) pos_.eval(k, t, &s.p_L[k], &v_L[k], &a_L[k]);
  s.pos = earth::ecefToGeodetic(r0_E_ + C_LtoE_ * s.p_L);
  const Eigen::Matrix3d C_LtoN = earth::C_EtoN(s.pos.lat, s.pos.lon) * C_LtoE_;
  s.v_N = C_LtoN * v_L;
  s.w_IE_N = earth::w_IE_N(s.pos.lat);
  s.w_EN_N = earth::w_EN_N(s.pos.lat, s.pos.h, s.v_N);
  s.a_N = C_LtoN * a_L - s.w_EN_N.cross(s.v_N);
  Eigen::Vector3d rate;
  for (int k = 0; k < 3; ++k) att_.eval(k, t, &s.rpy[k], &rate[k], nullptr);
  const double r = s.rpy[0], p = s.rpy[1];
  const Eigen::Matrix3d C_NtoB = eulerToC_NtoB(r, p, s.rpy[2]);
  s.C_BtoN = C_NtoB.transpose();
  // Body rate from Euler rates (Groves 2013 eq. 2.58 inverted / Titterton & Weston 3.60).
  const double cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p);
  s.w_NB_B = Eigen::Vector3d(rate[0] - rate[2] * sp, rate[1] * cr + rate[2] * sr * cp,
                             -rate[1] * sr + rate[2] * cr * cp);
  if (!full) return;
  s.g_N = earth::gravity_N(s.pos.lat, s.pos.h);
  // Groves 2013 eq. 5.54: dv_N/dt = C_BtoN f_B + g_N - (w_EN_N + 2 w_IE_N) x v_N
  s.f_B = C_NtoB * (s.a_N - s.g_N + (2.0 * s.w_IE_N + s.w_EN_N).cross(s.v_N));
  // Groves 2013 eq. 5.45: w_NB_B = w_IB_B - C_NtoB (w_IE_N + w_EN_N)
  s.w_IB_B = s.w_NB_B + C_NtoB * (s.w_IE_N + s.w_EN_N);
}

TruthState SmoothTrajectory::at(double t) const {
  TruthState s;
  kinematics(t, true, s);
  return s;
}

void SmoothTrajectory::increments(double ta, double tb, Eigen::Vector3d& dv_B,
                                  Eigen::Vector3d& dth_B) const {
  static const double x3 = std::sqrt(0.6);
  static const double nodes[3] = {-x3, 0.0, x3};
  static const double weights[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  thread_local std::vector<double> knots;
  pos_.knotsInside(ta, tb, knots);
  dv_B.setZero();
  dth_B.setZero();
  TruthState s;
  double lo = ta;
  for (std::size_t k = 0; k <= knots.size(); ++k) {
    const double hi = k < knots.size() ? knots[k] : tb;
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (int q = 0; q < 3; ++q) {
      kinematics(mid + half * nodes[q], true, s);
      dv_B += (weights[q] * half) * s.f_B;
      dth_B += (weights[q] * half) * s.w_IB_B;
    }
    lo = hi;
  }
}

}  // namespace navimpact::emulation

namespace navimpact::emulation {

void TrajectorySpec::loadFrom(const ConfigNode& n) {
  n.allowKeys({"file", "system", "columns", "latlon_unit", "attitude_unit", "time_unit", "origin", "max_gap_s",
               "start_s", "end_s"});
  file = n.inputFile("file", "the trajectory CSV");
  n.readChoice("system", system, {"geodetic", "ned"});
  if (const auto cols = n.optMap("columns")) {
    cols->allowKeys({"time", "lat", "lon", "height", "north", "east", "down", "roll", "pitch", "yaw"});
    cols->read("time", col_time);
    cols->read("lat", col_lat);
    cols->read("lon", col_lon);
    cols->read("height", col_height);
    cols->read("north", col_north);
    cols->read("east", col_east);
    cols->read("down", col_down);
    cols->read("roll", col_roll);
    cols->read("pitch", col_pitch);
    cols->read("yaw", col_yaw);
  }
  n.readChoice("latlon_unit", latlon_unit, {"rad", "deg"});
  n.readChoice("attitude_unit", attitude_unit, {"rad", "deg"});
  n.readChoice("time_unit", time_unit, {"s", "ms"});
  if (const auto o = n.optMap("origin")) {
    o->allowKeys({"lat_deg", "lon_deg", "height_m"});
    origin = earth::Geodetic{o->number("lat_deg", limits::kLatitudeDeg) * M_PI / 180,
                             o->number("lon_deg", limits::kLongitudeDeg) * M_PI / 180,
                             o->number("height_m", limits::kHeightM)};
  }
  n.read("max_gap_s", max_gap_s, limits::kDurationS);
  n.read("start_s", start_s, limits::kFileTimeS);
  n.read("end_s", end_s, limits::kFileTimeS);
  if (start_s && end_s && !(*end_s > *start_s))
    throw n.error("end_s", "must be after start_s (" + formatNumber(*start_s, 10) + " s), got " + formatNumber(*end_s, 10));
  config_file = n.file();
  config_path = n.path();
}

void SmoothingOptions::loadFrom(const ConfigNode& n) {
  n.allowKeys({"position_cutoff_hz", "attitude_cutoff_hz", "knot_step_s", "penalty_order"});
  n.read("position_cutoff_hz", position_cutoff_hz, limits::kCutoffHz);
  n.read("attitude_cutoff_hz", attitude_cutoff_hz, limits::kCutoffHz);
  n.read("knot_step_s", knot_step_s, limits::kDurationS);
  n.read("penalty_order", penalty_order, 1, 4);
  for (const auto& [key, f] : {std::pair<const char*, double>{"position_cutoff_hz", position_cutoff_hz},
                               std::pair<const char*, double>{"attitude_cutoff_hz", attitude_cutoff_hz}}) {
    const std::string why = checkSmoothing(f, knot_step_s);
    if (!why.empty()) throw n.error(n.has("knot_step_s") && !n.has(key) ? "knot_step_s" : key, why);
  }
}

}  // namespace navimpact::emulation
