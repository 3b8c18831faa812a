// Sweep configuration: a study config plus a `sweep:` block with the axes.
#include <algorithm>
#include <cmath>
#include <set>

#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::analysis {

namespace {

constexpr limits::Range kOutageStartS{0.0, 1.0e6, false, "s"};
// the lower bounds of limits.hpp, narrower upper bounds for the axes of a map
constexpr limits::Range kSweepDurationS{limits::kDurationS.lo, 1.0e5, false, "s"};
constexpr limits::Range kSweepGnssRateHz{0.01, 100.0, false, "Hz"};
constexpr limits::Range kSweepPosSigmaM{limits::kPositionSigmaM.lo, 1000.0, false, "m"};
constexpr limits::Range kSweepVelSigmaMps{limits::kVelocitySigmaMps.lo, 100.0, false, "m/s"};
constexpr limits::Range kAlpha{0.0, 0.5, true, "(probability)"};

}  // namespace

SweepConfig loadSweepConfig(const std::string& path) {
  InputScope scope(path);
  SweepConfig cfg;
  cfg.config_file = path;
  cfg.config_text = ConfigNode::readText(path);
  const ConfigNode root = ConfigNode::parse(cfg.config_text, path);
  if (root.has("outages"))
    throw root.error("outages", "not used by a sweep: the outage comes from sweep.outage (start_s, durations_s)");
  const ConfigNode sw = root.map("sweep", "the axes: outage, gnss, baro, imu_rate_hz");
  cfg.study.config_file = path;
  cfg.study.config_text = cfg.config_text;
  cfg.study.loadFrom(root, {"sweep"});
  cfg.study.outages.clear();
  if (cfg.study.runs < 2)
    throw keyError(path, "monte_carlo.runs", "a sweep needs at least 2 runs per cell for its paired tests");

  sw.allowKeys({"outage", "gnss", "baro", "imu_rate_hz", "alpha", "bootstrap"});
  const ConfigNode o = sw.map("outage", "{start_s, durations_s}");
  o.allowKeys({"start_s", "durations_s"});
  cfg.outage_start_s = o.number("start_s", kOutageStartS, "s from the trajectory start");
  if (!o.has("durations_s")) throw o.error("durations_s", "missing (a list of 1 to 200 durations [s])");
  for (const ConfigNode& d : o.list("durations_s", 1, 200, "a list of 1 to 200 durations [s]")) {
    const double v = d.asNumber(kSweepDurationS);
    if (!cfg.durations_s.empty() && v <= cfg.durations_s.back()) throw d.error("durations must increase strictly");
    cfg.durations_s.push_back(v);
  }

  if (sw.has("gnss")) {
    std::set<std::string> names;
    for (const ConfigNode& g : sw.list("gnss", 1, 50, "a list of 1 to 50 GNSS qualities")) {
      g.allowKeys({"name", "rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps"});
      GnssQuality q;
      q.gnss = cfg.study.gnss;
      q.name = g.text("name");
      if (q.name.empty() || q.name.size() > 40 || !names.insert(q.name).second)
        throw g.error("name", "'" + printable(q.name, 60) + "' is empty, longer than 40 characters or repeated");
      g.read("rate_hz", q.gnss.rate_hz, kSweepGnssRateHz);
      g.read("sigma_pos_h_m", q.gnss.sigma_pos_h_m, kSweepPosSigmaM);
      g.read("sigma_pos_v_m", q.gnss.sigma_pos_v_m, kSweepPosSigmaM);
      g.read("sigma_vel_h_mps", q.gnss.sigma_vel_h_mps, kSweepVelSigmaMps);
      g.read("sigma_vel_v_mps", q.gnss.sigma_vel_v_mps, kSweepVelSigmaMps);
      cfg.gnss.push_back(q);
    }
  } else {
    cfg.gnss.push_back({"base", cfg.study.gnss});
  }

  if (sw.has("baro")) {
    for (const ConfigNode& b : sw.list("baro", 1, 2, "a list of on and/or off")) {
      const bool v = b.asBool();  // YAML: on/off, true/false
      for (bool x : cfg.baro)
        if (x == v) throw b.error("repeated");
      cfg.baro.push_back(v);
    }
  } else {
    cfg.baro.push_back(true);
  }

  if (sw.has("imu_rate_hz")) {
    for (const ConfigNode& r : sw.list("imu_rate_hz", 1, 20, "a list of 1 to 20 IMU rates [Hz]")) {
      const double v = r.asNumber(limits::kImuRateHz);
      for (double x : cfg.imu_rates_hz)
        if (x == v) throw r.error("repeated");
      if (v < std::max(cfg.study.record_rate_hz, cfg.study.outage_record_rate_hz))
        throw r.error("must not be below the study's record rates (record.rate_hz, record.outage_rate_hz: " +
                      formatNumber(std::max(cfg.study.record_rate_hz, cfg.study.outage_record_rate_hz)) + " Hz)");
      cfg.imu_rates_hz.push_back(v);
    }
  } else {
    cfg.imu_rates_hz.push_back(cfg.study.imu_rate_hz);
  }
  sw.read("alpha", cfg.alpha, kAlpha);
  sw.read("bootstrap", cfg.bootstrap, 0, 100000);
  // (B + 1) 0.025 >= 1 for a 95 % percentile interval (Davison & Hinkley 5.2.2): with 1 it was one value twice
  if (cfg.bootstrap > 0 && cfg.bootstrap < static_cast<std::size_t>(limits::kMinBootstrap))
    throw keyError(path, "sweep.bootstrap", "must be 0 or at least " + std::to_string(limits::kMinBootstrap) +
                                               " resamples (a 95 % percentile interval needs them), got " + std::to_string(cfg.bootstrap));
  if (!(cfg.study.margin >= 0.0 && cfg.study.margin <= 1.0))
    throw keyError(path, "report.margin", "must be in [0, 1] for a sweep (a relative margin)");
  return cfg;
}

}  // namespace navimpact::analysis
