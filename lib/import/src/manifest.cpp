// Import of a measured run from a YAML manifest (see manifest.hpp and README, "Import").
#include "navimpact/import/manifest.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <set>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/recording.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/import/csv_columns.hpp"

namespace navimpact::import {

namespace {

namespace fs = std::filesystem;
using units::kDeg;

// ---------------------------------------------------------------------------
// Manifest keys: the one place that reads YAML nodes (types, units, ranges,
// unknown and duplicate keys), every error naming the manifest and the key.
// ---------------------------------------------------------------------------

struct Keys {
  std::string file;

  Error err(const std::string& key, const std::string& what) const { return keyError(file, key, what); }

  /// @p n must be a map whose keys are in @p allowed, with every key of @p required
  /// (duplicate keys are refused when the manifest is parsed).
  void map(const ConfigNode& n, const std::string& /*path: n.path()*/, std::initializer_list<const char*> allowed,
           std::initializer_list<const char*> required = {}) const {
    n.allowKeys(allowed);
    n.requireKeys(required);
  }
  double number(const ConfigNode& n, const std::string& /*key*/, double lo, double hi, const char* unit) const {
    return n.asNumber(limits::Range{lo, hi, false, unit});
  }
  /// A positive value: from the lower bound of @p r (limits.hpp: no real sensor has less) to @p hi.
  double positive(const ConfigNode& n, const limits::Range& r, double hi) const {
    return n.asNumber(limits::Range{r.lo, hi, false, r.unit});
  }
  std::string text(const ConfigNode& n, const std::string& /*key*/) const {
    const std::string s = n.asText();
    if (s.empty()) throw n.error("must be a non-empty text");
    return s;
  }
  std::vector<std::string> texts(const ConfigNode& n, const std::string& key, std::size_t lo, std::size_t hi) const {
    if (!n.isList() || n.items().size() < lo || n.items().size() > hi)
      throw err(key, lo == hi ? "must be a list of " + std::to_string(lo) + " names"
                              : "must be a list of " + std::to_string(lo) + " to " + std::to_string(hi) + " names");
    std::vector<std::string> out;
    for (const ConfigNode& item : n.items()) out.push_back(text(item, item.path()));
    return out;
  }
  /// A unit from a list; returns its index.
  std::size_t oneOf(const ConfigNode& n, const std::string& key, const std::vector<std::string>& names) const {
    const std::string s = n.scalar();
    for (std::size_t i = 0; i < names.size(); ++i)
      if (n.isScalar() && s == names[i]) return i;
    std::string list;  // punctuation quoted: "',', ';', tab", not ",, ;, tab"
    for (const auto& a : names) {
      const bool word = std::any_of(a.begin(), a.end(), [](char c) { return std::isalpha(static_cast<unsigned char>(c)); });
      list += (list.empty() ? "" : ", ") + (word ? a : "'" + a + "'");
    }
    const std::string got = n.isScalar() ? "'" + printable(s) + "'" : n.isNull() ? std::string("nothing") : std::string("a list or a map");
    throw err(key, "must be one of " + list + ", got " + got);
  }
};

// ---------------------------------------------------------------------------
// Streams
// ---------------------------------------------------------------------------

/// The shortest median step of a GNSS stream [s]: receivers give at most 100 Hz.
constexpr double kMinGnssStepS = (1.0 / limits::kGnssRateHz.hi) * (1.0 - 1e-9);

/// A stream's file, delimiter, time and gap rule.
struct StreamSpec {
  std::string name;   // imu, gnss, baro, reference
  std::string file;
  char delimiter = ',';
  bool time_column = false;
  std::string column;
  double time_factor = 1.0;  // column unit -> s
  std::string time_unit;     // the manifest's name of it
  double rate_hz = 0.0;
  double start_s = 0.0;
  double offset_s = 0.0;
  double max_gap_s = 0.0;    // 0: no limit
};

StreamSpec streamSpec(const Keys& k, const ConfigNode& n, const std::string& name) {
  StreamSpec s;
  s.name = name;
  s.file = n.inputFile("file", "the " + name + " CSV");
  if (const ConfigNode d = n["delimiter"]) {
    // a tab also as YAML writes it: "\t" (a tab) or '\t' (backslash, t)
    const bool tab = d.isScalar() && (d.scalar() == "\t" || d.scalar() == "\\t");
    const std::size_t i = tab ? 2 : k.oneOf(d, name + ".delimiter", {",", ";", "tab"});
    s.delimiter = i == 0 ? ',' : i == 1 ? ';' : '\t';
  }
  const std::string tk = name + ".time";
  const ConfigNode t = n["time"];
  if (t && t.isMap() && t["rate_hz"]) {
    if (name != "imu") throw k.err(tk + ".rate_hz", "only the IMU stream may be given by a rate (others need a time column)");
    k.map(t, tk, {"rate_hz", "start_s"}, {"rate_hz"});
    s.rate_hz = t["rate_hz"].asNumber(limits::kImuRateHz);
    if (t["start_s"]) s.start_s = t["start_s"].asNumber(limits::kFileTimeS);
  } else {
    k.map(t, tk, {"column", "unit"}, {"column", "unit"});
    s.time_column = true;
    s.column = k.text(t["column"], tk + ".column");
    const auto names = units::acceptedTimeUnits();
    s.time_unit = names[k.oneOf(t["unit"], tk + ".unit", names)];
    s.time_factor = units::secondsPer(s.time_unit);
  }
  if (n["max_gap_s"]) s.max_gap_s = n["max_gap_s"].asNumber(limits::kDurationS);
  return s;
}

/// The unit the header of @p file writes for request @p i of @p tab (e.g.
/// "gyro_x[deg/s]") must be the one the manifest's @p key tells, @p told:
/// compared by their factors (@p factorOf, which throws for a unit it does not
/// know). A header in deg/s under a manifest in rad/s was read 57x too large.
void headerUnitAgrees(const std::string& file, const ColumnTable& tab, std::size_t i, const std::string& column,
                      const std::string& key, const std::string& told,
                      const std::function<double(const std::string&)>& factorOf) {
  const std::string& hu = tab.header_unit.at(i);
  if (hu.empty()) return;
  bool same = false;
  try {
    same = factorOf(hu) == factorOf(told);
  } catch (const Error&) {
  }
  if (!same)
    throw fileError(file, tab.header_line, "column '" + printable(column) + "' is in " + printable(hu, 40) +
                                               " by its header, but " + key + " says " + told +
                                               ": correct the header or the manifest");
}

/// Times of a stream (file time * unit + offset), checked increasing and within the gap rule.
std::vector<double> streamTimes(const StreamSpec& s, const ColumnTable& tab, std::size_t timeCol) {
  const std::size_t n = tab.rows();
  std::vector<double> t(n);
  if (s.time_column) {
    headerUnitAgrees(s.file, tab, timeCol, s.column, s.name + ".time.unit", s.time_unit,
                     [](const std::string& u) { return units::secondsPer(u); });
    const auto& c = tab.columns[timeCol];
    for (std::size_t i = 0; i < n; ++i) t[i] = c[i] * s.time_factor + s.offset_s;
    // on the recording's axis (with time_offset_s) within the documented range of times
    for (std::size_t i = 0; i < n; ++i)
      if (!(std::abs(t[i]) <= limits::kFileTimeS.hi))
        throw fileError(s.file, tab.line[i], "time " + formatNumber(t[i]) + " s (key " + s.name +
                                                 ".time, with time_offset_s) is outside " + limits::describe(limits::kFileTimeS));
    const std::string key = s.name + ".time.column";
    for (std::size_t i = 1; i < n; ++i) {
      const double dt = t[i] - t[i - 1];
      if (dt <= 0.0)
        throw fileError(s.file, tab.line[i], "column '" + printable(s.column) + "' (key " + key + "): time " +
                                                 (dt == 0.0 ? "repeats" : "goes backwards") + " (" +
                                                 formatNumber(c[i]) + " after " + formatNumber(c[i - 1]) +
                                                 " on line " + std::to_string(tab.line[i - 1]) + ")");
      if (s.max_gap_s > 0.0 && dt > s.max_gap_s)
        throw fileError(s.file, tab.line[i], "column '" + printable(s.column) + "' (key " + key + "): gap of " +
                                                 formatNumber(dt) + " s after line " +
                                                 std::to_string(tab.line[i - 1]) + " exceeds " + s.name +
                                                 ".max_gap_s = " + formatNumber(s.max_gap_s) + " s");
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) t[i] = s.start_s + static_cast<double>(i) / s.rate_hz + s.offset_s;
    if (n > 0 && !(std::abs(t[0]) <= limits::kFileTimeS.hi && std::abs(t[n - 1]) <= limits::kFileTimeS.hi))
      throw fileError(s.file, 0, "times " + formatNumber(t[0]) + " .. " + formatNumber(t[n - 1]) + " s (key " + s.name +
                                     ".time, with time_offset_s) are outside " + limits::describe(limits::kFileTimeS));
  }
  return t;
}

/// Column indices of a request list being built.
struct Requests {
  std::vector<ColumnRequest> req;
  std::size_t add(const std::string& name, const std::string& key, bool allowEmpty = false) {
    req.push_back({name, key, allowEmpty});
    return req.size() - 1;
  }
};

std::size_t addTime(Requests& r, const StreamSpec& s) {
  return s.time_column ? r.add(s.column, s.name + ".time.column") : std::size_t(-1);
}

/// Axes: body FRD axis i = sign_i * file axis src_i (a proper signed permutation), or a rotation matrix.
Eigen::Matrix3d axesMatrix(const Keys& k, const ConfigNode& n, const std::string& key) {
  const char* accepted = " (expected the body forward, right, down axes written in the file's axes as a proper signed "
                         "permutation such as [-y, x, z], or a 3x3 rotation matrix [[..], [..], [..]] from file to body axes)";
  if (!n.isList() || n.items().size() != 3) throw k.err(key, std::string("expected a list of three axes") + accepted);
  const std::vector<ConfigNode> rows = n.items();
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  if (rows[0].isList()) {
    for (int i = 0; i < 3; ++i) {
      if (!rows[i].isList() || rows[i].items().size() != 3)
        throw k.err(key, std::string("a rotation matrix needs 3 rows of 3 numbers") + accepted);
      const std::vector<ConfigNode> row = rows[i].items();
      for (int j = 0; j < 3; ++j) C(i, j) = row[j].asNumber(limits::Range{-2.0, 2.0, false, ""});
    }
    if ((C * C.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || C.determinant() < 0.0)
      throw k.err(key, "is not a rotation matrix (orthonormal to 1e-6 with determinant +1)");
    return C;
  }
  bool used[3] = {false, false, false};
  for (int i = 0; i < 3; ++i) {
    const std::string s = rows[i].isScalar() ? rows[i].scalar() : std::string("(not an axis)");
    std::string_view p = trim(s);
    double sign = 1.0;
    if (!p.empty() && (p.front() == '-' || p.front() == '+')) {
      sign = p.front() == '-' ? -1.0 : 1.0;
      p.remove_prefix(1);
    }
    if (p.size() != 1 || p[0] < 'x' || p[0] > 'z')
      throw k.err(key + "[" + std::to_string(i) + "]", "'" + printable(s) + "' is not an axis" + accepted);
    const int a = p[0] - 'x';
    if (used[a]) throw k.err(key, "axis '" + std::string(p) + "' is used twice" + accepted);
    used[a] = true;
    C(i, a) = sign;
  }
  if (C.determinant() < 0.0)
    throw k.err(key, "is a mirror (determinant -1): the body axes would be left-handed" + std::string(accepted));
  return C;
}

/// height_datum: "ellipsoid" or {geoid_undulation_m: N}; returns N [m] (added to the heights).
double heightDatum(const Keys& k, const ConfigNode& n, const std::string& key) {
  if (n.isScalar()) {
    k.oneOf(n, key, {"ellipsoid"});
    return 0.0;
  }
  k.map(n, key, {"geoid_undulation_m"}, {"geoid_undulation_m"});
  return k.number(n["geoid_undulation_m"], key + ".geoid_undulation_m", -120.0, 120.0, "m");
}

/// position: {lat, lon, height, angle_unit}
struct PositionSpec {
  std::size_t lat, lon, h;
  double angle = kDeg;
};

PositionSpec positionSpec(const Keys& k, const ConfigNode& n, const std::string& key, Requests& r) {
  k.map(n, key, {"lat", "lon", "height", "angle_unit", "height_unit"}, {"lat", "lon", "height", "angle_unit"});
  PositionSpec p;
  p.lat = r.add(k.text(n["lat"], key + ".lat"), key + ".lat");
  p.lon = r.add(k.text(n["lon"], key + ".lon"), key + ".lon");
  p.h = r.add(k.text(n["height"], key + ".height"), key + ".height");
  p.angle = k.oneOf(n["angle_unit"], key + ".angle_unit", {"deg", "rad"}) == 0 ? kDeg : 1.0;
  if (n["height_unit"]) k.oneOf(n["height_unit"], key + ".height_unit", {"m"});
  return p;
}

earth::Geodetic positionAt(const StreamSpec& s, const ColumnTable& tab, const PositionSpec& p, double undulation,
                           const std::string& key, std::size_t i) {
  const double lat = tab.columns[p.lat][i] * p.angle, lon = tab.columns[p.lon][i] * p.angle;
  const double h = tab.columns[p.h][i] + undulation;
  if (std::abs(lat) > 90.0 * kDeg)
    throw fileError(s.file, tab.line[i], "column key " + key + ".lat: latitude " + formatNumber(tab.columns[p.lat][i]) +
                                             " is outside [-90, 90] deg (is angle_unit right?)");
  if (lon < -180.0 * kDeg || lon > 360.0 * kDeg)
    throw fileError(s.file, tab.line[i], "column key " + key + ".lon: longitude " + formatNumber(tab.columns[p.lon][i]) +
                                             " is outside [-180, 360] deg (is angle_unit right?)");
  if (!(h >= kMinHeightM && h <= kMaxHeightM))
    throw fileError(s.file, tab.line[i], "column key " + key + ".height: height " + formatNumber(h) +
                                             " m is outside [-12000, 1e6] m");
  return {lat, lon > 180.0 * kDeg ? lon - 360.0 * kDeg : lon, h};
}

/// sigma: {horizontal_m, vertical_m} constant, or {columns: [n, e, vertical] | [horizontal, vertical], unit: m}.
struct SigmaSpec {
  bool present = false;
  bool per_row = false;
  double h = 0.0, v = 0.0;
  std::vector<std::size_t> cols;
};

SigmaSpec sigmaSpec(const Keys& k, const ConfigNode& n, const std::string& key, Requests& r, const char* unitName,
                    const char* hKey, const char* vKey) {
  SigmaSpec s;
  if (!n) return s;
  s.present = true;
  if (n.isMap() && n["columns"]) {
    k.map(n, key, {"columns", "unit"}, {"columns", "unit"});
    k.oneOf(n["unit"], key + ".unit", {unitName});
    const auto names = k.texts(n["columns"], key + ".columns", 2, 3);
    for (std::size_t i = 0; i < names.size(); ++i) s.cols.push_back(r.add(names[i], key + ".columns[" + std::to_string(i) + "]"));
    s.per_row = true;
    return s;
  }
  k.map(n, key, {hKey, vKey, "columns"}, {hKey, vKey});
  const limits::Range& range = std::string(unitName) == "m" ? limits::kPositionSigmaM : limits::kVelocitySigmaMps;
  s.h = k.positive(n[hKey], range, 1e6);
  s.v = k.positive(n[vKey], range, 1e6);
  return s;
}

/// Per-axis (N, E, D) sigma of row i.
Eigen::Vector3d sigmaAt(const StreamSpec& st, const ColumnTable& tab, const SigmaSpec& s, const std::string& key, std::size_t i) {
  if (!s.per_row) return {s.h, s.h, s.v};
  Eigen::Vector3d out;
  for (std::size_t c = 0; c < s.cols.size(); ++c) {
    const double v = tab.columns[s.cols[c]][i];
    if (!(v > 0.0))
      throw fileError(st.file, tab.line[i], "column key " + key + ".columns[" + std::to_string(c) + "]: sigma " +
                                                formatNumber(v) + " must be > 0");
  }
  if (s.cols.size() == 3) return {tab.columns[s.cols[0]][i], tab.columns[s.cols[1]][i], tab.columns[s.cols[2]][i]};
  return {tab.columns[s.cols[0]][i], tab.columns[s.cols[0]][i], tab.columns[s.cols[1]][i]};
}

/// velocity: {columns: [3], frame: NED|ENU, unit: m/s|km/h, sigma: ...}
struct VelocitySpec {
  bool present = false;
  std::size_t c[3];
  bool enu = false;
  double factor = 1.0;
  SigmaSpec sigma;
};

VelocitySpec velocitySpec(const Keys& k, const ConfigNode& n, const std::string& key, Requests& r) {
  VelocitySpec v;
  if (!n) return v;
  v.present = true;
  k.map(n, key, {"columns", "frame", "unit", "sigma"}, {"columns", "frame", "unit"});
  const auto names = k.texts(n["columns"], key + ".columns", 3, 3);
  for (int i = 0; i < 3; ++i) v.c[i] = r.add(names[i], key + ".columns[" + std::to_string(i) + "]", true);
  v.enu = k.oneOf(n["frame"], key + ".frame", {"NED", "ENU"}) == 1;
  v.factor = k.oneOf(n["unit"], key + ".unit", {"m/s", "km/h"}) == 0 ? 1.0 : 1.0 / 3.6;
  v.sigma = sigmaSpec(k, n["sigma"], key + ".sigma", r, "m/s", "horizontal_m_s", "vertical_m_s");
  return v;
}

/// Velocity of row i in NED [m/s]; absent when all three fields are empty.
std::optional<Eigen::Vector3d> velocityAt(const StreamSpec& s, const ColumnTable& tab, const VelocitySpec& v,
                                          const std::string& key, std::size_t i) {
  if (!v.present) return std::nullopt;
  const double a = tab.columns[v.c[0]][i], b = tab.columns[v.c[1]][i], c = tab.columns[v.c[2]][i];
  const int empty = std::isnan(a) + std::isnan(b) + std::isnan(c);
  if (empty == 3) return std::nullopt;
  if (empty != 0)
    throw fileError(s.file, tab.line[i], "key " + key + ".columns: some velocity fields are empty (give all three or none)");
  if (v.enu) return Eigen::Vector3d(b * v.factor, a * v.factor, -c * v.factor);
  return Eigen::Vector3d(a * v.factor, b * v.factor, c * v.factor);
}

/// The velocity sigma of row i per axis N, E, D [m/s]: sigma columns are given
/// in the velocity's own frame, so an ENU velocity's [se, sn, su] swap to N, E, D.
Eigen::Vector3d velocitySigmaAt(const StreamSpec& s, const ColumnTable& tab, const VelocitySpec& v,
                                const std::string& key, std::size_t i) {
  Eigen::Vector3d sig = sigmaAt(s, tab, v.sigma, key, i);
  if (v.enu && v.sigma.cols.size() == 3) std::swap(sig[0], sig[1]);
  return sig;
}

/// C_BtoN from ZYX roll, pitch, yaw (yaw clockwise from true north; README conventions).
Eigen::Quaterniond quatRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .normalized();
}

}  // namespace

Recording importManifest(const std::string& manifestPath, ImportReport* report) {
  InputScope scope(manifestPath);
  // plain or gzip like every configuration, at most 1 MiB (a manifest is a page)
  const std::string manifestText = ConfigNode::readText(manifestPath, std::size_t(1) << 20);
  const ConfigNode root = ConfigNode::parse(manifestText, manifestPath);
  const Keys k{manifestPath};
  k.map(root, "", {"imu", "gnss", "baro", "reference", "time_offset_s", "time_zero_unix_s", "origin"}, {"imu"});

  double offset[4] = {0, 0, 0, 0};  // imu, gnss, baro, reference
  if (root["time_offset_s"]) {
    const ConfigNode o = root["time_offset_s"];
    k.map(o, "time_offset_s", {"imu", "gnss", "baro", "reference"});
    const char* names[] = {"imu", "gnss", "baro", "reference"};
    for (int i = 0; i < 4; ++i)
      if (o[names[i]]) {
        if (!root[names[i]])  // an offset for a stream the run lacks was ignored without a word
          throw k.err(std::string("time_offset_s.") + names[i], std::string("the manifest has no ") + names[i] + " stream");
        offset[i] = k.number(o[names[i]], std::string("time_offset_s.") + names[i], -1e6, 1e6, "s");
      }
  }
  const bool timeBaseKnown = static_cast<bool>(root["time_zero_unix_s"]);
  // its whole seconds and their fraction, exactly as written ("1448546404.917"):
  // a double near 1.4e9 s holds 0.917 only to 2.4e-7 s, a tick of the rawlog's
  // 100 ns clock lost (found by a probe)
  long long zeroWhole = 0;
  double zeroFraction = 0.0;
  if (timeBaseKnown) {
    const double zeroUnix = k.number(root["time_zero_unix_s"], "time_zero_unix_s", 0.0, 1e10, "s");
    const std::string text = root["time_zero_unix_s"].asText();
    const auto dot = text.find('.');
    if (text.find_first_not_of("0123456789.") == std::string::npos && dot != std::string::npos && dot > 0 &&
        text.find('.', dot + 1) == std::string::npos) {
      zeroWhole = std::stoll(text.substr(0, dot));
      zeroFraction = dot + 1 < text.size() ? std::stod("0." + text.substr(dot + 1)) : 0.0;
    } else {
      zeroWhole = static_cast<long long>(std::floor(zeroUnix));
      zeroFraction = zeroUnix - static_cast<double>(zeroWhole);
    }
  }

  Recording d;
  d.source = manifestPath;
  std::optional<earth::Geodetic> origin;
  if (const ConfigNode o = root["origin"]) {
    k.map(o, "origin", {"lat_deg", "lon_deg", "height_m"}, {"lat_deg", "lon_deg", "height_m"});
    origin = earth::Geodetic{k.number(o["lat_deg"], "origin.lat_deg", -90.0, 90.0, "deg") * kDeg,
                             k.number(o["lon_deg"], "origin.lon_deg", -180.0, 360.0, "deg") * kDeg,
                             k.number(o["height_m"], "origin.height_m", kMinHeightM, kMaxHeightM, "m")};
  }
  ImportReport rep;

  // --- IMU ------------------------------------------------------------------
  {
    const ConfigNode n = root["imu"];
    k.map(n, "imu", {"file", "delimiter", "time", "gyro", "acc", "axes", "max_gap_s"}, {"file", "time", "gyro", "acc", "axes"});
    StreamSpec s = streamSpec(k, n, "imu");
    s.offset_s = offset[0];
    Requests r;
    const std::size_t tc = addTime(r, s);
    std::size_t sc[2][3];
    double factor[2];
    bool increments[2];
    std::string told[2];                                       // the manifest's unit or increments
    std::function<double(const std::string&)> unitFactor[2];  // a unit of its kind -> SI
    const char* sensor[2] = {"gyro", "acc"};
    for (int q = 0; q < 2; ++q) {
      const std::string key = std::string("imu.") + sensor[q];
      const ConfigNode g = n[sensor[q]];
      k.map(g, key, {"columns", "unit", "increments"}, {"columns"});
      const auto names = k.texts(g["columns"], key + ".columns", 3, 3);
      for (int i = 0; i < 3; ++i) sc[q][i] = r.add(names[i], key + ".columns[" + std::to_string(i) + "]");
      if (!!g["unit"] == !!g["increments"])
        throw k.err(key, q == 0 ? "give exactly one of unit (rad/s, deg/s, deg/h, mrad/s) or increments (rad, deg, mrad)"
                                : "give exactly one of unit (m/s2, g, mg, ug) or increments (m/s)");
      increments[q] = !!g["increments"];
      if (!increments[q]) {
        const auto quantity = q == 0 ? units::Quantity::AngularRate : units::Quantity::SpecificForce;
        const std::string u = k.text(g["unit"], key + ".unit");
        told[q] = u;
        unitFactor[q] = [quantity](const std::string& x) { return units::toSiFactor(quantity, x); };
        try {
          factor[q] = units::toSiFactor(quantity, u);
        } catch (const Error& e) {
          throw k.err(key + ".unit", e.what());
        }
      } else if (q == 0) {
        static const std::vector<std::pair<std::string, double>> kAngleIncrements = {{"rad", 1.0}, {"deg", kDeg}, {"mrad", 1e-3}};
        std::vector<std::string> names;
        for (const auto& [name, f] : kAngleIncrements) names.push_back(name);
        const auto& chosen = kAngleIncrements[k.oneOf(g["increments"], key + ".increments", names)];
        factor[q] = chosen.second;
        told[q] = chosen.first;
        unitFactor[q] = [](const std::string& x) {
          for (const auto& [name, f] : kAngleIncrements)
            if (x == name) return f;
          throw Error("not an angle increment");
        };
      } else {
        factor[q] = 1.0;
        k.oneOf(g["increments"], key + ".increments", {"m/s"});
        told[q] = "m/s";
        unitFactor[q] = [](const std::string& x) {
          if (x == "m/s") return 1.0;
          throw Error("not a velocity increment");
        };
      }
    }
    const Eigen::Matrix3d C_FtoB = axesMatrix(k, n["axes"], "imu.axes");
    const ColumnTable tab = readColumns(s.file, r.req, s.delimiter);
    for (int a = 0; a < 6; ++a)  // six channels from six columns (a column named twice made a copied axis)
      for (int b = 0; b < a; ++b)
        if (tab.column[sc[a / 3][a % 3]] == tab.column[sc[b / 3][b % 3]])
          throw fileError(s.file, tab.header_line, "keys " + r.req[sc[b / 3][b % 3]].key + " and " + r.req[sc[a / 3][a % 3]].key +
                                                       " name the same column '" + printable(r.req[sc[a / 3][a % 3]].name) +
                                                       "' (each axis needs its own column)");
    for (int q = 0; q < 2; ++q)
      for (int i = 0; i < 3; ++i)
        headerUnitAgrees(s.file, tab, sc[q][i], r.req[sc[q][i]].name,
                         std::string("imu.") + sensor[q] + (increments[q] ? ".increments" : ".unit"), told[q], unitFactor[q]);
    if (tab.rows() < 2) throw fileError(s.file, tab.line[0], "the IMU stream needs at least 2 samples");
    // the nominal step: the rate, or nominalStep() of the time steps (the default gap limit is 1.5 of it)
    std::vector<double> t;
    if (s.time_column) {
      std::vector<double> raw(tab.rows());
      for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = tab.columns[tc][i] * s.time_factor;
      std::vector<double> steps(raw.size() - 1);
      for (std::size_t i = 1; i < raw.size(); ++i) steps[i - 1] = raw[i] - raw[i - 1];
      const double nominal = nominalStep(steps);
      if (!(nominal > 0.0))
        throw fileError(s.file, tab.line[0], "column '" + printable(s.column) + "' (key imu.time.column): the median time step is not > 0");
      if (s.max_gap_s == 0.0) s.max_gap_s = 1.5 * nominal;
      d.imu_rate_hz = 1.0 / nominal;
    } else {
      d.imu_rate_hz = s.rate_hz;
    }
    // the documented IMU rates (a time unit 1000x off gave a "200000 Hz" run that replay could not plot)
    if (!(d.imu_rate_hz >= limits::kImuRateHz.lo && d.imu_rate_hz <= limits::kImuRateHz.hi))
      throw fileError(s.file, tab.line[0], "the time column '" + printable(s.column) + "' gives a rate of " +
                                               formatNumber(d.imu_rate_hz) + " Hz, outside " + limits::describe(limits::kImuRateHz) +
                                               " (is imu.time.unit right?)");
    t = streamTimes(s, tab, tc);
    const double dtNominal = 1.0 / d.imu_rate_hz;
    d.imu.resize(tab.rows());
    double maxGap = 0.0;
    for (std::size_t i = 0; i < tab.rows(); ++i) {
      const double dt = i == 0 ? dtNominal : t[i] - t[i - 1];
      if (i > 0) maxGap = std::max(maxGap, dt);
      Eigen::Vector3d v[2];
      for (int q = 0; q < 2; ++q) {
        const Eigen::Vector3d file(tab.columns[sc[q][0]][i], tab.columns[sc[q][1]][i], tab.columns[sc[q][2]][i]);
        v[q] = C_FtoB * file * (increments[q] ? factor[q] / dt : factor[q]);
      }
      d.imu[i] = {t[i], v[0], v[1]};
      if (const std::string p = recordProblem(d.imu[i]); !p.empty())
        throw fileError(s.file, tab.line[i], "keys imu.gyro, imu.acc: " + p + " (are the units right?)");
    }
    rep.imu_file = s.file;
    rep.imu_rate_hz = d.imu_rate_hz;
    rep.imu_max_gap_s = maxGap;
  }

  // --- GNSS -----------------------------------------------------------------
  std::optional<double> gnssUndulation;
  if (const ConfigNode n = root["gnss"]) {
    k.map(n, "gnss", {"file", "delimiter", "time", "position", "height_datum", "velocity", "sigma", "lever_arm_m", "max_gap_s"},
          {"file", "time", "position", "height_datum"});
    StreamSpec s = streamSpec(k, n, "gnss");
    s.offset_s = offset[1];
    Requests r;
    const std::size_t tc = addTime(r, s);
    const PositionSpec ps = positionSpec(k, n["position"], "gnss.position", r);
    gnssUndulation = heightDatum(k, n["height_datum"], "gnss.height_datum");
    const VelocitySpec vs = velocitySpec(k, n["velocity"], "gnss.velocity", r);
    const SigmaSpec ss = sigmaSpec(k, n["sigma"], "gnss.sigma", r, "m", "horizontal_m", "vertical_m");
    if (n["lever_arm_m"]) {
      Eigen::Vector3d la;
      n.read("lever_arm_m", la, limits::kLeverArmM);  // [forward, right, down], body FRD, IMU to antenna
      d.lever_arm_B = la;
    }
    const ColumnTable tab = readColumns(s.file, r.req, s.delimiter);
    const std::vector<double> t = streamTimes(s, tab, tc);
    // receivers give at most 100 fixes a second: a median step below 10 ms is
    // a time unit gone wrong (seconds read as ms put 20 s of fixes into 20 ms)
    if (t.size() >= 2) {
      std::vector<double> steps(t.size() - 1);
      for (std::size_t i = 1; i < t.size(); ++i) steps[i - 1] = t[i] - t[i - 1];
      if (const double step = nominalStep(steps); step < kMinGnssStepS)
        throw fileError(s.file, tab.line[0], "the GNSS fixes come every " + formatNumber(step) + " s (median), faster than " +
                                                 "the 100 Hz of any receiver (is gnss.time.unit right?)");
    }
    d.gnss.resize(tab.rows());
    for (std::size_t i = 0; i < tab.rows(); ++i) {
      GnssFix& f = d.gnss[i];
      f.t = t[i];
      f.pos = positionAt(s, tab, ps, *gnssUndulation, "gnss.position", i);
      f.v_N = velocityAt(s, tab, vs, "gnss.velocity", i);
      if (ss.present) f.cov_pos_N = sigmaAt(s, tab, ss, "gnss.sigma", i).cwiseAbs2().asDiagonal();
      if (f.v_N && vs.sigma.present) f.cov_vel_N = velocitySigmaAt(s, tab, vs, "gnss.velocity.sigma", i).cwiseAbs2().asDiagonal();
      if (const std::string p = recordProblem(f); !p.empty()) throw fileError(s.file, tab.line[i], "key gnss: " + p);
    }
    rep.gnss_file = s.file;
  }

  // --- barometer ------------------------------------------------------------
  if (const ConfigNode n = root["baro"]) {
    k.map(n, "baro", {"file", "delimiter", "time", "height", "height_datum", "sigma_m", "max_gap_s"}, {"file", "time", "height"});
    StreamSpec s = streamSpec(k, n, "baro");
    s.offset_s = offset[2];
    Requests r;
    const std::size_t tc = addTime(r, s);
    k.map(n["height"], "baro.height", {"column", "unit"}, {"column"});
    if (n["height"]["unit"]) k.oneOf(n["height"]["unit"], "baro.height.unit", {"m"});
    const std::size_t hc = r.add(k.text(n["height"]["column"], "baro.height.column"), "baro.height.column");
    double und;
    if (n["height_datum"]) und = heightDatum(k, n["height_datum"], "baro.height_datum");
    else if (gnssUndulation) und = *gnssUndulation;
    else throw k.err("baro.height_datum", "missing (required without a gnss stream, whose datum it otherwise takes)");
    std::optional<double> sigma;
    if (n["sigma_m"]) sigma = n["sigma_m"].asNumber(limits::kPositionSigmaM);
    const ColumnTable tab = readColumns(s.file, r.req, s.delimiter);
    const std::vector<double> t = streamTimes(s, tab, tc);
    d.baro.resize(tab.rows());
    for (std::size_t i = 0; i < tab.rows(); ++i) {
      d.baro[i] = {t[i], tab.columns[hc][i] + und, sigma};
      if (const std::string p = recordProblem(d.baro[i]); !p.empty()) throw fileError(s.file, tab.line[i], "key baro: " + p);
    }
    rep.baro_file = s.file;
  }

  // --- reference ------------------------------------------------------------
  if (const ConfigNode n = root["reference"]) {
    k.map(n, "reference", {"file", "delimiter", "time", "position", "height_datum", "attitude", "velocity", "sigma", "max_gap_s"},
          {"file", "time", "position"});
    StreamSpec s = streamSpec(k, n, "reference");
    s.offset_s = offset[3];
    Requests r;
    const std::size_t tc = addTime(r, s);
    const PositionSpec ps = positionSpec(k, n["position"], "reference.position", r);
    double und;
    if (n["height_datum"]) und = heightDatum(k, n["height_datum"], "reference.height_datum");
    else if (gnssUndulation) und = *gnssUndulation;
    else throw k.err("reference.height_datum", "missing (required without a gnss stream, whose datum it otherwise takes)");
    bool att = false;
    std::size_t ac[3] = {0, 0, 0};
    double aunit = kDeg;
    if (const ConfigNode a = n["attitude"]) {
      k.map(a, "reference.attitude", {"roll", "pitch", "yaw", "unit"}, {"roll", "pitch", "yaw", "unit"});
      const char* names[] = {"roll", "pitch", "yaw"};
      for (int i = 0; i < 3; ++i)
        ac[i] = r.add(k.text(a[names[i]], std::string("reference.attitude.") + names[i]), std::string("reference.attitude.") + names[i]);
      aunit = k.oneOf(a["unit"], "reference.attitude.unit", {"deg", "rad"}) == 0 ? kDeg : 1.0;
      att = true;
    }
    const VelocitySpec vs = velocitySpec(k, n["velocity"], "reference.velocity", r);
    const SigmaSpec ss = sigmaSpec(k, n["sigma"], "reference.sigma", r, "m", "horizontal_m", "vertical_m");
    const ColumnTable tab = readColumns(s.file, r.req, s.delimiter);
    const std::vector<double> t = streamTimes(s, tab, tc);
    std::vector<earth::Geodetic> pos(tab.rows());
    for (std::size_t i = 0; i < tab.rows(); ++i) pos[i] = positionAt(s, tab, ps, und, "reference.position", i);
    d.origin = origin ? *origin : pos.front();
    d.reference.resize(tab.rows());
    for (std::size_t i = 0; i < tab.rows(); ++i) {
      ReferenceRecord& e = d.reference[i];
      e.t = t[i];
      e.p_L = earth::geodeticToNed(d.origin, pos[i]);
      e.v_N = velocityAt(s, tab, vs, "reference.velocity", i);
      if (att) {
        // roll and yaw in [-360, 360] deg (either convention of the wrap), pitch in [-90, 90] deg
        const char* names[] = {"roll", "pitch", "yaw"};
        for (int a = 0; a < 3; ++a) {
          const double v = tab.columns[ac[a]][i] * aunit, lim = (a == 1 ? 90.0 : 360.0) * kDeg;
          if (!(std::abs(v) <= lim * (1.0 + 1e-12)))
            throw fileError(s.file, tab.line[i], std::string("column key reference.attitude.") + names[a] + ": " +
                                                     formatNumber(tab.columns[ac[a]][i]) + " is outside [-" +
                                                     formatNumber(lim / aunit) + ", " + formatNumber(lim / aunit) +
                                                     "] " + (aunit == 1.0 ? "rad" : "deg") + " (is the unit right?)");
        }
        e.q_BtoN = quatRpy(tab.columns[ac[0]][i] * aunit, tab.columns[ac[1]][i] * aunit, tab.columns[ac[2]][i] * aunit);
      }
      if (ss.present) e.sigma_p_L = sigmaAt(s, tab, ss, "reference.sigma", i);
      if (e.v_N && vs.sigma.present) e.sigma_v_N = velocitySigmaAt(s, tab, vs, "reference.velocity.sigma", i);
      if (const std::string p = recordProblem(e); !p.empty()) throw fileError(s.file, tab.line[i], "key reference: " + p);
    }
    rep.reference_file = s.file;
  } else if (origin) {
    d.origin = *origin;
  } else if (!d.gnss.empty()) {
    d.origin = d.gnss.front().pos;
  }

  // --- every aiding stream overlaps the IMU's time span --------------------------
  {
    const double a = d.imu.front().t, b = d.imu.back().t;
    // a record inside the span, not spans that overlap (two fixes at -5 s and 30 s around a 20 s IMU passed)
    auto overlaps = [&](const std::string& file, const char* key, const auto& recs) {
      if (recs.empty() || std::any_of(recs.begin(), recs.end(), [&](const auto& x) { return x.t >= a && x.t <= b; })) return;
      throw fileError(file, 0, std::string("no record of stream ") + key + " lies within the IMU's time span [" +
                                   formatNumber(a, 10) + ", " + formatNumber(b, 10) + "] s (it spans [" +
                                   formatNumber(recs.front().t, 10) + ", " + formatNumber(recs.back().t, 10) +
                                   "] s: are the time units and time_offset_s right?)");
    };
    overlaps(rep.gnss_file, "gnss", d.gnss);
    overlaps(rep.baro_file, "baro", d.baro);
    overlaps(rep.reference_file, "reference", d.reference);
  }

  // --- time base --------------------------------------------------------------
  rep.time_base_known = timeBaseKnown;
  if (timeBaseKnown) {
    double earliest = d.imu.front().t;
    if (!d.gnss.empty()) earliest = std::min(earliest, d.gnss.front().t);
    if (!d.baro.empty()) earliest = std::min(earliest, d.baro.front().t);
    if (!d.reference.empty()) earliest = std::min(earliest, d.reference.front().t);
    d.start_unix_s = zeroWhole + static_cast<long long>(std::floor(zeroFraction + earliest));
    const double shift = static_cast<double>(zeroWhole - d.start_unix_s) + zeroFraction;  // small: exact enough
    for (auto& x : d.imu) x.t += shift;
    for (auto& x : d.gnss) x.t += shift;
    for (auto& x : d.baro) x.t += shift;
    for (auto& x : d.reference) x.t += shift;
  }
  d.t_start_s = 0.0;

  // --- metadata -------------------------------------------------------------
  {
    YAML::Emitter y;
    y << YAML::BeginMap << YAML::Key << "navimpact_scenario" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "source" << YAML::Value << "import";
    y << YAML::Key << "frames" << YAML::Value
      << "body FRD, navigation NED, reference position tangent-plane NED at origin, attitude C_BtoN";
    y << YAML::Key << "origin" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "lat_deg" << YAML::Value
      << formatExact(d.origin.lat / kDeg) << YAML::Key << "lon_deg" << YAML::Value << formatExact(d.origin.lon / kDeg) << YAML::Key
      << "height_m" << YAML::Value << formatExact(d.origin.h) << YAML::EndMap;
    y << YAML::Key << "time" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "start_unix_s" << YAML::Value
      << d.start_unix_s << YAML::Key << "time_base_known" << YAML::Value << timeBaseKnown << YAML::EndMap;
    y << YAML::Key << "imu" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "rate_hz" << YAML::Value
      << formatExact(d.imu_rate_hz) << YAML::EndMap;
    if (d.lever_arm_B) {
      y << YAML::Key << "gnss" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "lever_arm_B_m" << YAML::Value
        << YAML::Flow << YAML::BeginSeq << formatExact((*d.lever_arm_B)[0]) << formatExact((*d.lever_arm_B)[1])
        << formatExact((*d.lever_arm_B)[2]) << YAML::EndSeq << YAML::EndMap;
    }
    if (!d.baro.empty() && d.baro.front().sigma_m) {  // rawlogs keep the barometer's sigma here
      y << YAML::Key << "baro" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "sigma_m" << YAML::Value
        << formatExact(*d.baro.front().sigma_m) << YAML::EndMap;
    }
    y << YAML::EndMap;
    y << YAML::Key << "navimpact_import" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "manifest_file" << YAML::Value << manifestPath;
    y << YAML::Key << "manifest" << YAML::Value << YAML::Literal << manifestText;
    y << YAML::EndMap << YAML::EndMap;
    d.metadata = y.c_str();
  }
  if (report) *report = rep;
  return d;
}

}  // namespace navimpact::import
