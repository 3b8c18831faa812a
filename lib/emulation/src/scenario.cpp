#include "navimpact/emulation/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::emulation {

namespace fs = std::filesystem;

namespace {

struct Ctx {
  std::string file;
  fs::path dir;
  std::string resolve(const std::string& p) const {
    if (p.empty() || fs::path(p).is_absolute() || dir.empty()) return p;
    return (dir / p).lexically_normal().string();
  }
};

void checkKeys(const YAML::Node& n, const Ctx& c, const std::string& prefix, const std::set<std::string>& allowed) {
  if (!n.IsMap()) throw keyError(c.file, prefix.empty() ? "(root)" : prefix, "expected a map");
  for (const auto& kv : n) {
    const auto k = kv.first.as<std::string>();
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw keyError(c.file, prefix.empty() ? k : prefix + "." + k, "unknown key (expected one of: " + list + ")");
    }
  }
}

template <class T>
T get(const YAML::Node& n, const char* key, const Ctx& c, const std::string& prefix, T def) {
  if (!n || !n[key]) return def;
  try {
    return n[key].as<T>();
  } catch (const YAML::Exception&) {
    throw keyError(c.file, prefix + "." + key, "wrong type or value");
  }
}

double positive(double v, const Ctx& c, const std::string& key) {
  if (!(v > 0.0) || !std::isfinite(v)) throw keyError(c.file, key, "must be a finite number > 0");
  return v;
}

std::string modelPath(const std::string& spec, const Ctx& c) {
  // FILE or FILE:NAME; resolve FILE only.
  const auto colon = spec.rfind(':');
  if (colon != std::string::npos && colon > 1) return c.resolve(spec.substr(0, colon)) + spec.substr(colon);
  return c.resolve(spec);
}

long long parseUtc(const std::string& s, const Ctx& c) {
  std::tm tm{};
  std::istringstream in(s);
  in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%S");
  if (in.fail()) throw keyError(c.file, "output.start_utc", "'" + s + "' is not YYYY-MM-DDTHH:MM:SSZ");
  return static_cast<long long>(timegm(&tm));
}

std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') o += '\\';
    o += ch;
  }
  return o + "\"";
}

}  // namespace

static EmulationConfig loadEmulationConfigImpl(const std::string& path) {
  InputScope scope(path);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error(path + ": cannot open the emulation configuration");
  } catch (const YAML::Exception& e) {
    throw fileError(path, e.mark.line + 1, std::string("YAML syntax: ") + printable(e.msg, 120));
  }
  Ctx c{path, fs::path(path).parent_path()};
  EmulationConfig cfg;
  cfg.config_file = path;
  checkKeys(root, c, "", {"trajectory", "smoothing", "imu", "gnss", "baro", "ground_truth", "output"});

  const YAML::Node t = root["trajectory"];
  if (!t) throw keyError(path, "trajectory", "missing (file, system, columns, ...)");
  checkKeys(t, c, "trajectory", {"file", "system", "columns", "latlon_unit", "attitude_unit", "time_unit",
                                 "origin", "max_gap_s", "start_s", "end_s"});
  auto& ts = cfg.trajectory;
  if (!t["file"]) throw keyError(path, "trajectory.file", "missing");
  ts.file = c.resolve(get<std::string>(t, "file", c, "trajectory", ""));
  ts.system = get<std::string>(t, "system", c, "trajectory", ts.system);
  if (const auto cols = t["columns"]) {
    checkKeys(cols, c, "trajectory.columns",
              {"time", "lat", "lon", "height", "north", "east", "down", "roll", "pitch", "yaw"});
    const std::string p = "trajectory.columns";
    ts.col_time = get<std::string>(cols, "time", c, p, ts.col_time);
    ts.col_lat = get<std::string>(cols, "lat", c, p, ts.col_lat);
    ts.col_lon = get<std::string>(cols, "lon", c, p, ts.col_lon);
    ts.col_height = get<std::string>(cols, "height", c, p, ts.col_height);
    ts.col_north = get<std::string>(cols, "north", c, p, ts.col_north);
    ts.col_east = get<std::string>(cols, "east", c, p, ts.col_east);
    ts.col_down = get<std::string>(cols, "down", c, p, ts.col_down);
    ts.col_roll = get<std::string>(cols, "roll", c, p, ts.col_roll);
    ts.col_pitch = get<std::string>(cols, "pitch", c, p, ts.col_pitch);
    ts.col_yaw = get<std::string>(cols, "yaw", c, p, ts.col_yaw);
  }
  ts.latlon_unit = get<std::string>(t, "latlon_unit", c, "trajectory", ts.latlon_unit);
  ts.attitude_unit = get<std::string>(t, "attitude_unit", c, "trajectory", ts.attitude_unit);
  ts.time_unit = get<std::string>(t, "time_unit", c, "trajectory", ts.time_unit);
  if (const auto o = t["origin"]) {
    checkKeys(o, c, "trajectory.origin", {"lat_deg", "lon_deg", "height_m"});
    for (const char* k : {"lat_deg", "lon_deg", "height_m"})
      if (!o[k]) throw keyError(path, std::string("trajectory.origin.") + k, "missing");
    ts.origin = earth::Geodetic{get<double>(o, "lat_deg", c, "trajectory.origin", 0) * M_PI / 180,
                                get<double>(o, "lon_deg", c, "trajectory.origin", 0) * M_PI / 180,
                                get<double>(o, "height_m", c, "trajectory.origin", 0)};
    if (std::abs(ts.origin->lat) > M_PI / 2) throw keyError(path, "trajectory.origin.lat_deg", "must be in [-90, 90]");
  }
  ts.max_gap_s = positive(get<double>(t, "max_gap_s", c, "trajectory", ts.max_gap_s), c, "trajectory.max_gap_s");
  if (t["start_s"]) ts.start_s = get<double>(t, "start_s", c, "trajectory", 0.0);
  if (t["end_s"]) ts.end_s = get<double>(t, "end_s", c, "trajectory", 0.0);

  if (const auto s = root["smoothing"]) {
    checkKeys(s, c, "smoothing", {"position_cutoff_hz", "attitude_cutoff_hz", "knot_step_s", "penalty_order"});
    auto& so = cfg.smoothing;
    so.position_cutoff_hz = positive(get<double>(s, "position_cutoff_hz", c, "smoothing", so.position_cutoff_hz), c,
                                     "smoothing.position_cutoff_hz");
    so.attitude_cutoff_hz = positive(get<double>(s, "attitude_cutoff_hz", c, "smoothing", so.attitude_cutoff_hz), c,
                                     "smoothing.attitude_cutoff_hz");
    so.knot_step_s = positive(get<double>(s, "knot_step_s", c, "smoothing", so.knot_step_s), c, "smoothing.knot_step_s");
    so.penalty_order = get<int>(s, "penalty_order", c, "smoothing", so.penalty_order);
  }

  if (const auto i = root["imu"]) {
    checkKeys(i, c, "imu", {"rate_hz", "errors", "model", "seed", "static"});
    cfg.imu_rate_hz = limits::check(c.file, "imu.rate_hz", get<double>(i, "rate_hz", c, "imu", cfg.imu_rate_hz), limits::kImuRateHz);
    cfg.imu_errors = get<std::string>(i, "errors", c, "imu", cfg.imu_errors);
    if (cfg.imu_errors != "model" && cfg.imu_errors != "static" && cfg.imu_errors != "none")
      throw keyError(path, "imu.errors", "'" + cfg.imu_errors + "' is not model, static or none");
    if (i["model"]) cfg.model_spec = modelPath(get<std::string>(i, "model", c, "imu", ""), c);
    cfg.imu_seed = get<std::uint64_t>(i, "seed", c, "imu", cfg.imu_seed);
    if (const auto st = i["static"]) {
      checkKeys(st, c, "imu.static", {"file", "gyro_unit", "acc_unit", "rate_hz", "axes", "offset_s", "seed"});
      auto& sr = cfg.static_rec;
      sr.file = c.resolve(get<std::string>(st, "file", c, "imu.static", ""));
      sr.csv.gyro_unit = get<std::string>(st, "gyro_unit", c, "imu.static", "");
      sr.csv.acc_unit = get<std::string>(st, "acc_unit", c, "imu.static", "");
      if (st["rate_hz"]) sr.csv.rate_hz = positive(get<double>(st, "rate_hz", c, "imu.static", 0), c, "imu.static.rate_hz");
      sr.csv.axes = get<std::string>(st, "axes", c, "imu.static", "");
      if (st["offset_s"]) sr.offset_s = get<double>(st, "offset_s", c, "imu.static", 0);
      sr.seed = get<std::uint64_t>(st, "seed", c, "imu.static", 0);
    }
  }
  if (cfg.imu_errors == "model" && cfg.model_spec.empty())
    throw keyError(path, "imu.model", "missing (FILE[:NAME] of the IMU error model) for imu.errors: model");
  if (cfg.imu_errors == "static" && cfg.static_rec.file.empty())
    throw keyError(path, "imu.static.file", "missing for imu.errors: static");

  if (const auto g = root["gnss"]) {
    checkKeys(g, c, "gnss", {"rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps",
                             "lever_arm_B_m", "seed"});
    auto& o = cfg.gnss;
    o.rate_hz = limits::check(c.file, "gnss.rate_hz", get<double>(g, "rate_hz", c, "gnss", o.rate_hz), limits::kAidingRateHz);
    o.sigma_pos_h_m = limits::check(c.file, "gnss.sigma_pos_h_m", get<double>(g, "sigma_pos_h_m", c, "gnss", o.sigma_pos_h_m), limits::kPositionSigmaM);
    o.sigma_pos_v_m = limits::check(c.file, "gnss.sigma_pos_v_m", get<double>(g, "sigma_pos_v_m", c, "gnss", o.sigma_pos_v_m), limits::kPositionSigmaM);
    o.sigma_vel_h_mps = limits::check(c.file, "gnss.sigma_vel_h_mps", get<double>(g, "sigma_vel_h_mps", c, "gnss", o.sigma_vel_h_mps), limits::kVelocitySigmaMps);
    o.sigma_vel_v_mps = limits::check(c.file, "gnss.sigma_vel_v_mps", get<double>(g, "sigma_vel_v_mps", c, "gnss", o.sigma_vel_v_mps), limits::kVelocitySigmaMps);
    if (g["lever_arm_B_m"]) {
      const auto l = get<std::vector<double>>(g, "lever_arm_B_m", c, "gnss", {});
      if (l.size() != 3) throw keyError(path, "gnss.lever_arm_B_m", "expected [x, y, z] in metres (body FRD)");
      for (int k = 0; k < 3; ++k)
        limits::check(c.file, "gnss.lever_arm_B_m[" + std::to_string(k) + "]", l[k], limits::kLeverArmM);
      o.lever_arm_B = Eigen::Vector3d(l[0], l[1], l[2]);
    }
    o.seed = get<std::uint64_t>(g, "seed", c, "gnss", o.seed);
  }
  if (const auto b = root["baro"]) {
    checkKeys(b, c, "baro", {"rate_hz", "sigma_m", "seed"});
    cfg.baro.rate_hz = limits::check(c.file, "baro.rate_hz", get<double>(b, "rate_hz", c, "baro", cfg.baro.rate_hz), limits::kAidingRateHz);
    cfg.baro.sigma_m = limits::check(c.file, "baro.sigma_m", get<double>(b, "sigma_m", c, "baro", cfg.baro.sigma_m), limits::kPositionSigmaM);
    cfg.baro.seed = get<std::uint64_t>(b, "seed", c, "baro", cfg.baro.seed);
  }
  if (const auto gt = root["ground_truth"]) {
    checkKeys(gt, c, "ground_truth", {"rate_hz"});
    cfg.truth_rate_hz = limits::check(c.file, "ground_truth.rate_hz",
                                      get<double>(gt, "rate_hz", c, "ground_truth", cfg.truth_rate_hz),
                                      limits::kAidingRateHz);
  }
  if (const auto o = root["output"]) {
    checkKeys(o, c, "output", {"start_utc"});
    cfg.start_utc = get<std::string>(o, "start_utc", c, "output", cfg.start_utc);
  }
  parseUtc(cfg.start_utc, c);
  return cfg;
}

// A value of the wrong type (yaml-cpp's conversion errors, a list or map used
// as a key) is an error naming the file and line, never an internal error.
EmulationConfig loadEmulationConfig(const std::string& path) {
  try {
    return loadEmulationConfigImpl(path);
  } catch (const YAML::Exception& e) {
    throw Error(path + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) : "") +
                ": " + printable(e.msg, 120) + " (a value or key of the wrong type)");
  }
}

Recording runEmulation(const EmulationConfig& cfg, const std::string& version) {
  Ctx c{cfg.config_file, {}};
  const long long startUnix = parseUtc(cfg.start_utc, c);
  Recording d;
  d.source = cfg.config_file.empty() ? "emulation" : cfg.config_file;
  const SmoothTrajectory tr(readTrajectoryCsv(cfg.trajectory), cfg.smoothing);
  d.origin = tr.origin();
  d.imu_rate_hz = cfg.imu_rate_hz;
  d.start_unix_s = startUnix;
  d.t_start_s = tr.tBegin();
  const auto perfect = perfectImu(tr, cfg.imu_rate_hz);
  const std::size_t n = perfect.size();

  ImuErrors err;
  stochastic::ImuModel model;
  if (cfg.imu_errors == "model") {
    model = stochastic::loadImuModel(cfg.model_spec);
    err = modelImuErrors(model, cfg.imu_rate_hz, n, cfg.imu_seed);
  } else if (cfg.imu_errors == "static") {
    err = staticImuErrors(cfg.static_rec, cfg.imu_rate_hz, n);
  } else {
    for (auto& a : err.axis) a.assign(n, 0.0);
    err.description = "none (perfect IMU)";
  }
  d.notices = err.notices;
  d.imu.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto& s = perfect[k];
    ImuRecord& r = d.imu[k];
    r.t = s.t;
    r.w_IB_B = s.dtheta_B / s.dt + Eigen::Vector3d(err.axis[0][k], err.axis[1][k], err.axis[2][k]);
    r.f_B = s.dv_B / s.dt + Eigen::Vector3d(err.axis[3][k], err.axis[4][k], err.axis[5][k]);
  }
  const double t0 = tr.tBegin(), t1 = perfect.back().t;
  d.gnss = simulateGnss(tr, cfg.gnss, t0, t1);
  d.baro = simulateBaro(tr, cfg.baro, t0, t1);
  const auto nt = static_cast<std::size_t>(std::floor((t1 - t0) * cfg.truth_rate_hz + 1e-9)) + 1;
  d.reference.resize(nt);
  for (std::size_t k = 0; k < nt; ++k) {
    const double t = t0 + double(k) / cfg.truth_rate_hz;
    const TruthState s = tr.at(t);
    d.reference[k] = {t, s.p_L, s.v_N, Eigen::Quaterniond(s.C_BtoN).normalized(), {}, {}, {}};
  }

  // Scenario text (YAML), stored as the rawlog's first entry.
  std::ostringstream y;
  const auto& g = cfg.gnss;
  y << "navimpact_scenario:\n"
    << "  navimpact_version: " << quote(version) << "\n"
    << "  frames: {body: FRD, navigation: NED, ground_truth_position: tangent-plane NED at origin,"
       " attitude: C_BtoN quaternion (Hamilton, active)}\n"
    << "  units: {IMU: \"IMU_WX..IMU_WZ rad/s, IMU_X_ACC..IMU_Z_ACC m/s^2, means over the interval ending at the timestamp\","
       " BARO: \"IMU_ALTITUDE m above the WGS84 ellipsoid\","
       " GNSS: \"GGA lat/lon deg, altitude_meters ellipsoidal, geoidal_distance 0; TOPCON_PZS ECEF m, m/s, covariances m^2, m^2/s^2\","
       " GT: \"IMU_X..IMU_Z m (tangent NED at origin), IMU_X_VEL..IMU_Z_VEL m/s (local NED), IMU_ORI_QUAT_X..W of C_BtoN\"}\n"
    << "  origin: {lat_deg: " << formatNumber(d.origin.lat * 180 / M_PI, 17) << ", lon_deg: " << formatNumber(d.origin.lon * 180 / M_PI, 17)
    << ", height_m: " << formatNumber(d.origin.h, 17) << "}\n"
    << "  time: {start_utc: " << quote(cfg.start_utc) << ", start_unix_s: " << startUnix
    << ", trajectory_time_at_start_s: " << formatNumber(t0, 17) << ", duration_s: " << formatNumber(t1 - t0, 17) << "}\n"
    << "  trajectory: {file: " << quote(cfg.trajectory.file) << ", system: " << cfg.trajectory.system
    << ", position_cutoff_hz: " << formatNumber(cfg.smoothing.position_cutoff_hz, 17)
    << ", attitude_cutoff_hz: " << formatNumber(cfg.smoothing.attitude_cutoff_hz, 17)
    << ", knot_step_s: " << formatNumber(cfg.smoothing.knot_step_s, 17) << ", penalty_order: " << cfg.smoothing.penalty_order << "}\n"
    << "  imu: {rate_hz: " << formatNumber(cfg.imu_rate_hz, 17) << ", errors: " << cfg.imu_errors
    << ", model: " << quote(cfg.model_spec) << ", seed: " << cfg.imu_seed
    << ", description: " << quote(err.description) << "}\n"
    << "  gnss: {rate_hz: " << formatNumber(g.rate_hz, 17) << ", sigma_pos_h_m: " << formatNumber(g.sigma_pos_h_m, 17)
    << ", sigma_pos_v_m: " << formatNumber(g.sigma_pos_v_m, 17) << ", sigma_vel_h_mps: " << formatNumber(g.sigma_vel_h_mps, 17)
    << ", sigma_vel_v_mps: " << formatNumber(g.sigma_vel_v_mps, 17) << ", lever_arm_B_m: [" << formatNumber(g.lever_arm_B[0], 17) << ", "
    << formatNumber(g.lever_arm_B[1], 17) << ", " << formatNumber(g.lever_arm_B[2], 17) << "], seed: " << g.seed << "}\n"
    << "  baro: {rate_hz: " << formatNumber(cfg.baro.rate_hz, 17) << ", sigma_m: " << formatNumber(cfg.baro.sigma_m, 17)
    << ", seed: " << cfg.baro.seed << "}\n"
    << "  ground_truth: {rate_hz: " << formatNumber(cfg.truth_rate_hz, 17) << "}\n"
    << "  notices:\n";
  for (const auto& nline : d.notices) y << "    - " << quote(nline) << "\n";
  if (d.notices.empty()) y << "    []\n";
  if (cfg.imu_errors == "model") {
    std::string mt = stochastic::toYaml(model, "IMU error model " + model.source);
    y << "  imu_model_yaml: |\n";
    std::istringstream in(mt);
    std::string line;
    while (std::getline(in, line)) y << "    " << line << "\n";
  }
  d.metadata = y.str();
  d.lever_arm_B = g.lever_arm_B;
  return d;
}

}  // namespace navimpact::emulation
