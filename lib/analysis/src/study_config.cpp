// Study configuration (YAML) -> StudyConfig, with key-named errors.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/units.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;

StudyConfig::StudyConfig() {
  ekf.propagate_every = 10;
  initial_sigma << 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.2 * units::kDeg, 0.2 * units::kDeg, 1.0 * units::kDeg;
  outages.push_back({200.0, 260.0});
}

namespace {

struct Ctx {
  std::string file;
  fs::path dir;
};

void checkKeys(const YAML::Node& n, const Ctx& c, const std::string& where,
               const std::set<std::string>& allowed) {
  if (!n.IsMap()) throw keyError(c.file, where, "expected a mapping");
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw keyError(c.file, where.empty() ? k : where + "." + k, "unknown key (accepted: " + list + ")");
    }
  }
}

template <class T>
T get(const YAML::Node& n, const Ctx& c, const std::string& key) {
  try {
    return n.as<T>();
  } catch (const YAML::Exception&) {
    throw keyError(c.file, key, "wrong type or value '" + YAML::Dump(n) + "'");
  }
}

template <class T>
void opt(const YAML::Node& parent, const char* k, const Ctx& c, const std::string& where, T& out) {
  const YAML::Node n = parent[k];
  if (n) out = get<T>(n, c, where.empty() ? std::string(k) : where + "." + k);
}

double positive(double v, const Ctx& c, const std::string& key) {
  if (!(v > 0.0) || !std::isfinite(v)) throw keyError(c.file, key, "must be a finite number > 0");
  return v;
}

std::string resolvePath(const Ctx& c, const std::string& p) {
  if (p.empty()) return p;
  fs::path q(p);
  if (q.is_absolute()) return p;
  return (c.dir / q).lexically_normal().string();
}

/// FILE[:NAME] with FILE relative to the configuration folder.
std::string resolveModelSpec(const Ctx& c, const std::string& spec) {
  if (spec.empty()) return spec;
  const auto colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0) return resolvePath(c, spec);
  const std::string file = spec.substr(0, colon), name = spec.substr(colon + 1);
  if (name.find('/') != std::string::npos) return resolvePath(c, spec);
  return resolvePath(c, file) + ":" + name;
}

}  // namespace

StudyConfig loadStudyConfig(const std::string& path) { return loadStudyConfig(path, {}); }

static StudyConfig loadStudyConfigImpl(const std::string& path, const std::vector<std::string>& extra_keys) {
  InputScope scope(path);
  StudyConfig cfg;
  cfg.config_file = path;
  cfg.config_text = readFileMaybeGz(path);
  Ctx c{path, fs::path(path).parent_path()};
  YAML::Node root;
  try {
    root = YAML::Load(cfg.config_text);
  } catch (const YAML::Exception& e) {
    throw fileError(path, e.mark.line + 1, std::string("YAML: ") + printable(e.msg, 120));
  }
  std::set<std::string> top{"trajectory", "smoothing", "imu",         "truth",  "candidates", "sets",  "gnss",
                            "baro",       "outages",   "monte_carlo", "filter", "record",     "report"};
  top.insert(extra_keys.begin(), extra_keys.end());
  checkKeys(root, c, "", top);

  // trajectory
  const YAML::Node tr = root["trajectory"];
  if (!tr) throw keyError(path, "trajectory", "missing (a trajectory CSV is required)");
  checkKeys(tr, c, "trajectory",
            {"file", "system", "columns", "latlon_unit", "attitude_unit", "time_unit", "origin", "max_gap_s",
             "start_s", "end_s"});
  auto& ts = cfg.trajectory;
  if (!tr["file"]) throw keyError(path, "trajectory.file", "missing");
  ts.file = resolvePath(c, get<std::string>(tr["file"], c, "trajectory.file"));
  opt(tr, "system", c, "trajectory", ts.system);
  opt(tr, "latlon_unit", c, "trajectory", ts.latlon_unit);
  opt(tr, "attitude_unit", c, "trajectory", ts.attitude_unit);
  opt(tr, "time_unit", c, "trajectory", ts.time_unit);
  opt(tr, "max_gap_s", c, "trajectory", ts.max_gap_s);
  if (tr["start_s"]) ts.start_s = get<double>(tr["start_s"], c, "trajectory.start_s");
  if (tr["end_s"]) ts.end_s = get<double>(tr["end_s"], c, "trajectory.end_s");
  if (const YAML::Node cols = tr["columns"]) {
    checkKeys(cols, c, "trajectory.columns",
              {"time", "lat", "lon", "height", "north", "east", "down", "roll", "pitch", "yaw"});
    const std::string w = "trajectory.columns";
    opt(cols, "time", c, w, ts.col_time);
    opt(cols, "lat", c, w, ts.col_lat);
    opt(cols, "lon", c, w, ts.col_lon);
    opt(cols, "height", c, w, ts.col_height);
    opt(cols, "north", c, w, ts.col_north);
    opt(cols, "east", c, w, ts.col_east);
    opt(cols, "down", c, w, ts.col_down);
    opt(cols, "roll", c, w, ts.col_roll);
    opt(cols, "pitch", c, w, ts.col_pitch);
    opt(cols, "yaw", c, w, ts.col_yaw);
  }
  if (const YAML::Node o = tr["origin"]) {
    checkKeys(o, c, "trajectory.origin", {"lat_deg", "lon_deg", "height_m"});
    earth::Geodetic g;
    double lat = 0, lon = 0, h = 0;
    opt(o, "lat_deg", c, "trajectory.origin", lat);
    opt(o, "lon_deg", c, "trajectory.origin", lon);
    opt(o, "height_m", c, "trajectory.origin", h);
    g.lat = lat * units::kDeg;
    g.lon = lon * units::kDeg;
    g.h = h;
    ts.origin = g;
  }
  if (const YAML::Node s = root["smoothing"]) {
    checkKeys(s, c, "smoothing", {"position_cutoff_hz", "attitude_cutoff_hz", "knot_step_s", "penalty_order"});
    opt(s, "position_cutoff_hz", c, "smoothing", cfg.smoothing.position_cutoff_hz);
    opt(s, "attitude_cutoff_hz", c, "smoothing", cfg.smoothing.attitude_cutoff_hz);
    opt(s, "knot_step_s", c, "smoothing", cfg.smoothing.knot_step_s);
    opt(s, "penalty_order", c, "smoothing", cfg.smoothing.penalty_order);
  }
  if (const YAML::Node s = root["imu"]) {
    checkKeys(s, c, "imu", {"rate_hz"});
    opt(s, "rate_hz", c, "imu", cfg.imu_rate_hz);
  }
  limits::check(path, "imu.rate_hz", cfg.imu_rate_hz, limits::kImuRateHz);

  // truth
  const YAML::Node tn = root["truth"];
  if (!tn) throw keyError(path, "truth", "missing (errors: model | static)");
  checkKeys(tn, c, "truth", {"errors", "model", "static"});
  opt(tn, "errors", c, "truth", cfg.truth.kind);
  if (cfg.truth.kind == "model") {
    if (!tn["model"]) throw keyError(path, "truth.model", "missing (FILE:NAME of the true error model)");
    cfg.truth.model = resolveModelSpec(c, get<std::string>(tn["model"], c, "truth.model"));
  } else if (cfg.truth.kind == "static") {
    const YAML::Node s = tn["static"];
    if (!s) throw keyError(path, "truth.static", "missing (file, gyro_unit, acc_unit, rate_hz)");
    checkKeys(s, c, "truth.static", {"file", "gyro_unit", "acc_unit", "rate_hz", "axes"});
    if (!s["file"]) throw keyError(path, "truth.static.file", "missing");
    cfg.truth.recording.file = resolvePath(c, get<std::string>(s["file"], c, "truth.static.file"));
    opt(s, "gyro_unit", c, "truth.static", cfg.truth.recording.csv.gyro_unit);
    opt(s, "acc_unit", c, "truth.static", cfg.truth.recording.csv.acc_unit);
    opt(s, "axes", c, "truth.static", cfg.truth.recording.csv.axes);
    if (s["rate_hz"])
      cfg.truth.recording.csv.rate_hz = positive(get<double>(s["rate_hz"], c, "truth.static.rate_hz"), c,
                                                 "truth.static.rate_hz");
  } else {
    throw keyError(path, "truth.errors", "'" + cfg.truth.kind + "': expected model or static");
  }

  // candidates
  const YAML::Node cands = root["candidates"];
  if (!cands || !cands.IsSequence() || cands.size() == 0)
    throw keyError(path, "candidates", "missing or empty (a list of {label, model | accelerometer/gyroscope})");
  std::set<std::string> labels;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const std::string w = "candidates[" + std::to_string(i) + "]";
    const YAML::Node n = cands[i];
    checkKeys(n, c, w, {"label", "model", "accelerometer", "gyroscope"});
    CandidateSpec cs;
    if (!n["label"]) throw keyError(path, w + ".label", "missing");
    cs.label = get<std::string>(n["label"], c, w + ".label");
    if (cs.label.empty() || !labels.insert(cs.label).second)
      throw keyError(path, w + ".label", "'" + cs.label + "' is empty or repeated");
    if (n["model"]) cs.model = resolveModelSpec(c, get<std::string>(n["model"], c, w + ".model"));
    if (n["accelerometer"])
      cs.accelerometer = resolveModelSpec(c, get<std::string>(n["accelerometer"], c, w + ".accelerometer"));
    if (n["gyroscope"]) cs.gyroscope = resolveModelSpec(c, get<std::string>(n["gyroscope"], c, w + ".gyroscope"));
    if (!cs.model.empty() && (!cs.accelerometer.empty() || !cs.gyroscope.empty()))
      throw keyError(path, w, "give either model or accelerometer/gyroscope, not both");
    if (cs.model.empty() && cs.accelerometer.empty() && cs.gyroscope.empty())
      throw keyError(path, w, "needs model or accelerometer and/or gyroscope");
    cfg.candidates.push_back(cs);
  }

  // sets
  if (const YAML::Node sets = root["sets"]) {
    if (!sets.IsSequence()) throw keyError(path, "sets", "expected a list");
    for (std::size_t i = 0; i < sets.size(); ++i) {
      const std::string w = "sets[" + std::to_string(i) + "]";
      const YAML::Node n = sets[i];
      checkKeys(n, c, w, {"name", "title", "models", "reference", "white_noise"});
      ModelSetSpec s;
      if (!n["name"]) throw keyError(path, w + ".name", "missing");
      s.name = get<std::string>(n["name"], c, w + ".name");
      for (char ch : s.name)
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-'))
          throw keyError(path, w + ".name", "'" + s.name + "': use letters, digits, _ and - only");
      for (const auto& other : cfg.sets)
        if (other.name == s.name)
          throw keyError(path, w + ".name", "'" + s.name + "' is used by an earlier set (names must be unique)");
      s.title = s.name;
      opt(n, "title", c, w, s.title);
      if (!n["models"]) throw keyError(path, w + ".models", "missing");
      s.models = get<std::vector<std::string>>(n["models"], c, w + ".models");
      if (s.models.empty()) throw keyError(path, w + ".models", "empty");
      for (const auto& l : s.models)
        if (!labels.count(l)) throw keyError(path, w + ".models", "unknown candidate label '" + l + "'");
      opt(n, "reference", c, w, s.reference);
      opt(n, "white_noise", c, w, s.white_noise);
      if (s.reference.empty()) s.reference = s.models.back();
      if (s.white_noise.empty()) s.white_noise = s.models.front();
      for (const auto* l : {&s.reference, &s.white_noise})
        if (std::find(s.models.begin(), s.models.end(), *l) == s.models.end())
          throw keyError(path, w, "reference/white_noise '" + *l + "' is not among the set's models");
      cfg.sets.push_back(s);
    }
  }
  if (cfg.sets.empty()) {
    ModelSetSpec s;
    s.name = "all";
    s.title = "all candidates";
    for (const auto& cs : cfg.candidates) s.models.push_back(cs.label);
    s.reference = s.models.back();
    s.white_noise = s.models.front();
    cfg.sets.push_back(s);
  }

  if (const YAML::Node g = root["gnss"]) {
    checkKeys(g, c, "gnss",
              {"rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps", "lever_arm_B_m"});
    opt(g, "rate_hz", c, "gnss", cfg.gnss.rate_hz);
    opt(g, "sigma_pos_h_m", c, "gnss", cfg.gnss.sigma_pos_h_m);
    opt(g, "sigma_pos_v_m", c, "gnss", cfg.gnss.sigma_pos_v_m);
    opt(g, "sigma_vel_h_mps", c, "gnss", cfg.gnss.sigma_vel_h_mps);
    opt(g, "sigma_vel_v_mps", c, "gnss", cfg.gnss.sigma_vel_v_mps);
    if (g["lever_arm_B_m"]) {
      const auto v = get<std::vector<double>>(g["lever_arm_B_m"], c, "gnss.lever_arm_B_m");
      if (v.size() != 3) throw keyError(path, "gnss.lever_arm_B_m", "expected 3 numbers [m]");
      for (int k = 0; k < 3; ++k)
        limits::check(path, "gnss.lever_arm_B_m[" + std::to_string(k) + "]", v[k], limits::kLeverArmM);
      cfg.gnss.lever_arm_B = Eigen::Vector3d(v[0], v[1], v[2]);
    }
  }
  limits::check(path, "gnss.rate_hz", cfg.gnss.rate_hz, limits::kAidingRateHz);
  limits::check(path, "gnss.sigma_pos_h_m", cfg.gnss.sigma_pos_h_m, limits::kPositionSigmaM);
  limits::check(path, "gnss.sigma_pos_v_m", cfg.gnss.sigma_pos_v_m, limits::kPositionSigmaM);
  limits::check(path, "gnss.sigma_vel_h_mps", cfg.gnss.sigma_vel_h_mps, limits::kVelocitySigmaMps);
  limits::check(path, "gnss.sigma_vel_v_mps", cfg.gnss.sigma_vel_v_mps, limits::kVelocitySigmaMps);
  if (const YAML::Node b = root["baro"]) {
    checkKeys(b, c, "baro", {"rate_hz", "sigma_m", "during_outages"});
    opt(b, "rate_hz", c, "baro", cfg.baro.rate_hz);
    opt(b, "sigma_m", c, "baro", cfg.baro.sigma_m);
    opt(b, "during_outages", c, "baro", cfg.baro_in_outage);
  }
  limits::check(path, "baro.rate_hz", cfg.baro.rate_hz, limits::kAidingRateHz);
  limits::check(path, "baro.sigma_m", cfg.baro.sigma_m, limits::kPositionSigmaM);

  if (const YAML::Node o = root["outages"]) {
    if (!o.IsSequence() || o.size() == 0) throw keyError(path, "outages", "expected a non-empty list");
    cfg.outages.clear();
    for (std::size_t i = 0; i < o.size(); ++i) {
      const std::string w = "outages[" + std::to_string(i) + "]";
      checkKeys(o[i], c, w, {"start_s", "duration_s"});
      if (!o[i]["start_s"] || !o[i]["duration_s"]) throw keyError(path, w, "needs start_s and duration_s");
      const double s = get<double>(o[i]["start_s"], c, w + ".start_s");
      const double d = limits::check(path, w + ".duration_s", get<double>(o[i]["duration_s"], c, w + ".duration_s"),
                                     limits::kDurationS);
      if (!(s >= 0.0)) throw keyError(path, w + ".start_s", "must be >= 0 (seconds from the trajectory start)");
      if (!cfg.outages.empty() && s < cfg.outages.back().end_s)
        throw keyError(path, w + ".start_s", "outages must be in time order and not overlap");
      cfg.outages.push_back(Outage::fromStartDuration(s, d));
    }
  }
  if (const YAML::Node m = root["monte_carlo"]) {
    checkKeys(m, c, "monte_carlo", {"runs", "seed", "threads"});
    if (m["runs"]) {
      const long long r = get<long long>(m["runs"], c, "monte_carlo.runs");
      if (r < 1 || r > limits::kMaxMonteCarloRuns)
        throw keyError(path, "monte_carlo.runs",
                       "must be in [1, " + std::to_string(limits::kMaxMonteCarloRuns) + "], got " + std::to_string(r));
      cfg.runs = static_cast<std::size_t>(r);
    }
    opt(m, "seed", c, "monte_carlo", cfg.seed);
    opt(m, "threads", c, "monte_carlo", cfg.threads);
  }
  if (const YAML::Node f = root["filter"]) {
    checkKeys(f, c, "filter", {"propagate_every", "discretization", "coning_sculling", "initial_sigma"});
    opt(f, "propagate_every", c, "filter", cfg.ekf.propagate_every);
    if (cfg.ekf.propagate_every < 1) throw keyError(path, "filter.propagate_every", "must be >= 1");
    if (f["discretization"]) {
      try {
        cfg.ekf.discretization =
            filter::parseDiscretization(get<std::string>(f["discretization"], c, "filter.discretization"));
      } catch (const Error& e) {
        throw keyError(path, "filter.discretization", e.what());
      }
    }
    opt(f, "coning_sculling", c, "filter", cfg.ekf.mechanization.coning_sculling);
    if (const YAML::Node s = f["initial_sigma"]) {
      checkKeys(s, c, "filter.initial_sigma", {"pos_h_m", "pos_v_m", "vel_mps", "roll_pitch_deg", "yaw_deg"});
      double ph = cfg.initial_sigma(0), pv = cfg.initial_sigma(2), v = cfg.initial_sigma(3),
             rp = cfg.initial_sigma(6) / units::kDeg, y = cfg.initial_sigma(8) / units::kDeg;
      const std::string w = "filter.initial_sigma";
      opt(s, "pos_h_m", c, w, ph);
      opt(s, "pos_v_m", c, w, pv);
      opt(s, "vel_mps", c, w, v);
      opt(s, "roll_pitch_deg", c, w, rp);
      opt(s, "yaw_deg", c, w, y);
      for (double x : {ph, pv, v, rp, y}) positive(x, c, w);
      cfg.initial_sigma << ph, ph, pv, v, v, v, rp * units::kDeg, rp * units::kDeg, y * units::kDeg;
    }
  }
  if (const YAML::Node r = root["record"]) {
    checkKeys(r, c, "record", {"rate_hz", "outage_rate_hz"});
    opt(r, "rate_hz", c, "record", cfg.record_rate_hz);
    opt(r, "outage_rate_hz", c, "record", cfg.outage_record_rate_hz);
  }
  limits::check(path, "record.rate_hz", cfg.record_rate_hz, limits::kAidingRateHz);
  limits::check(path, "record.outage_rate_hz", cfg.outage_record_rate_hz, limits::kAidingRateHz);
  if (const YAML::Node r = root["report"]) {
    checkKeys(r, c, "report", {"margin", "plot_before_s", "plot_after_s"});
    opt(r, "margin", c, "report", cfg.margin);
    opt(r, "plot_before_s", c, "report", cfg.plot_before_s);
    opt(r, "plot_after_s", c, "report", cfg.plot_after_s);
  }
  positive(cfg.margin, c, "report.margin");
  return cfg;
}

// A value of the wrong type (yaml-cpp's conversion errors, a list or map used
// as a key) is an error naming the file and line, never an internal error.
StudyConfig loadStudyConfig(const std::string& path, const std::vector<std::string>& extra_keys) {
  try {
    return loadStudyConfigImpl(path, extra_keys);
  } catch (const YAML::Exception& e) {
    throw Error(path + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) : "") +
                ": " + printable(e.msg, 120) + " (a value or key of the wrong type)");
  }
}

Shard parseShard(const std::string& text) {
  const auto slash = text.find('/');
  double k = 0, n = 0;
  if (slash == std::string::npos || !parseDouble(text.substr(0, slash), k) ||
      !parseDouble(text.substr(slash + 1), n) || k != std::floor(k) || n != std::floor(n) || k < 1 || n < 1 ||
      k > n || n > 1e6)
    throw Error("--shard '" + text + "': expected K/N with integers 1 <= K <= N (e.g. 2/4)");
  return Shard{static_cast<unsigned>(k), static_cast<unsigned>(n)};
}

}  // namespace navimpact::analysis
