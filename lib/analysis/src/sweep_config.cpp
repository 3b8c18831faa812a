// Sweep configuration: a study config plus a `sweep:` block with the axes.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact::analysis {

namespace {

struct Reader {
  std::string file;

  void keys(const YAML::Node& n, const std::string& where, const std::set<std::string>& allowed) const {
    if (!n.IsMap()) throw keyError(file, where, "expected a mapping");
    for (const auto& kv : n) {
      const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        throw keyError(file, where + "." + k, "unknown key (accepted: " + list + ")");
      }
    }
  }
  template <class T>
  T get(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      std::string text = n.IsScalar() ? n.Scalar() : std::string("a ") + (n.IsSequence() ? "list" : "mapping");
      if (text.size() > 60) text = text.substr(0, 60) + "...";
      throw keyError(file, key, "wrong type or value '" + text + "'");
    }
  }
  /// A finite number in [lo, hi] (open at lo when @p open_lo).
  double number(const YAML::Node& n, const std::string& key, double lo, double hi, bool open_lo,
                const std::string& unit) const {
    const double v = get<double>(n, key);
    if (!std::isfinite(v) || v < lo || (open_lo && v == lo) || v > hi)
      throw keyError(file, key,
                     "must be a number in " + std::string(open_lo ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) + "] " +
                         unit + ", got " + formatNumber(v));
    return v;
  }
};

}  // namespace

SweepConfig loadSweepConfig(const std::string& path) {
  SweepConfig cfg;
  cfg.config_file = path;
  cfg.config_text = readFileMaybeGz(path);
  YAML::Node root;
  try {
    root = YAML::Load(cfg.config_text);
  } catch (const YAML::Exception& e) {
    throw fileError(path, e.mark.line + 1, std::string("YAML: ") + e.msg);
  }
  if (!root.IsMap()) throw keyError(path, "", "expected a mapping (a study config plus a sweep block)");
  if (root["outages"])
    throw keyError(path, "outages", "not used by a sweep: the outage comes from sweep.outage (start_s, durations_s)");
  const YAML::Node sw = root["sweep"];
  if (!sw) throw keyError(path, "sweep", "missing (the axes: outage, gnss, baro, imu_rate_hz)");
  cfg.study = loadStudyConfig(path, {"sweep"});
  cfg.study.outages.clear();
  if (cfg.study.runs < 2)
    throw keyError(path, "monte_carlo.runs", "a sweep needs at least 2 runs per cell for its paired tests");

  const Reader r{path};
  r.keys(sw, "sweep", {"outage", "gnss", "baro", "imu_rate_hz", "alpha", "bootstrap"});

  const YAML::Node o = sw["outage"];
  if (!o) throw keyError(path, "sweep.outage", "missing ({start_s, durations_s})");
  r.keys(o, "sweep.outage", {"start_s", "durations_s"});
  if (!o["start_s"]) throw keyError(path, "sweep.outage.start_s", "missing (s from the trajectory start)");
  cfg.outage_start_s = r.number(o["start_s"], "sweep.outage.start_s", 0.0, 1e6, false, "s");
  const YAML::Node d = o["durations_s"];
  if (!d || !d.IsSequence() || d.size() == 0 || d.size() > 200)
    throw keyError(path, "sweep.outage.durations_s", "expected a list of 1 to 200 durations [s]");
  for (std::size_t i = 0; i < d.size(); ++i) {
    const std::string k = "sweep.outage.durations_s[" + std::to_string(i) + "]";
    const double v = r.number(d[i], k, 0.0, 1e5, true, "s");
    if (!cfg.durations_s.empty() && v <= cfg.durations_s.back())
      throw keyError(path, k, "durations must increase strictly");
    cfg.durations_s.push_back(v);
  }

  if (const YAML::Node g = sw["gnss"]) {
    if (!g.IsSequence() || g.size() == 0 || g.size() > 50)
      throw keyError(path, "sweep.gnss", "expected a list of 1 to 50 GNSS qualities");
    std::set<std::string> names;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const std::string w = "sweep.gnss[" + std::to_string(i) + "]";
      r.keys(g[i], w,
             {"name", "rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps"});
      GnssQuality q;
      q.gnss = cfg.study.gnss;
      if (!g[i]["name"]) throw keyError(path, w + ".name", "missing");
      q.name = r.get<std::string>(g[i]["name"], w + ".name");
      if (q.name.empty() || q.name.size() > 40 || !names.insert(q.name).second)
        throw keyError(path, w + ".name", "'" + q.name + "' is empty, longer than 40 characters or repeated");
      if (g[i]["rate_hz"]) q.gnss.rate_hz = r.number(g[i]["rate_hz"], w + ".rate_hz", 0.01, 100.0, false, "Hz");
      if (g[i]["sigma_pos_h_m"])
        q.gnss.sigma_pos_h_m = r.number(g[i]["sigma_pos_h_m"], w + ".sigma_pos_h_m", 0.0, 1000.0, true, "m");
      if (g[i]["sigma_pos_v_m"])
        q.gnss.sigma_pos_v_m = r.number(g[i]["sigma_pos_v_m"], w + ".sigma_pos_v_m", 0.0, 1000.0, true, "m");
      if (g[i]["sigma_vel_h_mps"])
        q.gnss.sigma_vel_h_mps = r.number(g[i]["sigma_vel_h_mps"], w + ".sigma_vel_h_mps", 0.0, 100.0, true, "m/s");
      if (g[i]["sigma_vel_v_mps"])
        q.gnss.sigma_vel_v_mps = r.number(g[i]["sigma_vel_v_mps"], w + ".sigma_vel_v_mps", 0.0, 100.0, true, "m/s");
      cfg.gnss.push_back(q);
    }
  } else {
    cfg.gnss.push_back({"base", cfg.study.gnss});
  }

  if (const YAML::Node b = sw["baro"]) {
    if (!b.IsSequence() || b.size() == 0 || b.size() > 2)
      throw keyError(path, "sweep.baro", "expected a list of on and/or off");
    for (std::size_t i = 0; i < b.size(); ++i) {
      const std::string k = "sweep.baro[" + std::to_string(i) + "]";
      const bool v = r.get<bool>(b[i], k);  // YAML: on/off, true/false
      for (bool x : cfg.baro)
        if (x == v) throw keyError(path, k, "repeated");
      cfg.baro.push_back(v);
    }
  } else {
    cfg.baro.push_back(true);
  }

  if (const YAML::Node ir = sw["imu_rate_hz"]) {
    if (!ir.IsSequence() || ir.size() == 0 || ir.size() > 20)
      throw keyError(path, "sweep.imu_rate_hz", "expected a list of 1 to 20 IMU rates [Hz]");
    for (std::size_t i = 0; i < ir.size(); ++i) {
      const std::string k = "sweep.imu_rate_hz[" + std::to_string(i) + "]";
      const double v = r.number(ir[i], k, 1.0, 10000.0, false, "Hz");
      for (double x : cfg.imu_rates_hz)
        if (x == v) throw keyError(path, k, "repeated");
      cfg.imu_rates_hz.push_back(v);
    }
  } else {
    cfg.imu_rates_hz.push_back(cfg.study.imu_rate_hz);
  }
  if (sw["alpha"]) cfg.alpha = r.number(sw["alpha"], "sweep.alpha", 0.0, 0.5, true, "(probability)");
  if (sw["bootstrap"]) {
    const double v = r.number(sw["bootstrap"], "sweep.bootstrap", 0.0, 100000.0, false, "resamples");
    if (v != std::floor(v)) throw keyError(path, "sweep.bootstrap", "must be a whole number of resamples");
    cfg.bootstrap = static_cast<std::size_t>(v);
  }
  if (!(cfg.study.margin >= 0.0 && cfg.study.margin <= 1.0))
    throw keyError(path, "report.margin", "must be in [0, 1] for a sweep (a relative margin)");
  return cfg;
}

}  // namespace navimpact::analysis
