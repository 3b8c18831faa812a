// Study configuration (YAML) -> StudyConfig, with key-named errors.
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
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

/// Threads of one process.
constexpr long long kMaxThreads = 1024;
/// Start of an outage, seconds from the trajectory start.
constexpr limits::Range kOutageStartS{0.0, limits::kDurationS.hi, false, "s"};
/// Relative margin of the recommendation (0.25 = 25 %).
constexpr limits::Range kMarginRange{0.0, 1.0e3, true, ""};
/// Figure windows around an outage [s].
constexpr limits::Range kPlotWindowS{0.0, limits::kDurationS.hi, false, "s"};

}  // namespace

StudyConfig loadStudyConfig(const std::string& path) { return loadStudyConfig(path, {}); }

StudyConfig loadStudyConfig(const std::string& path, const std::vector<std::string>& extra_keys) {
  InputScope scope(path);
  StudyConfig cfg;
  cfg.config_file = path;
  cfg.config_text = ConfigNode::readText(path);
  cfg.loadFrom(ConfigNode::parse(cfg.config_text, path), extra_keys);
  return cfg;
}

void StudyConfig::loadFrom(const ConfigNode& root, const std::vector<std::string>& extra_keys) {
  std::vector<std::string> top{"trajectory", "smoothing", "imu",         "truth",  "candidates", "sets",  "gnss",
                               "baro",       "outages",   "monte_carlo", "filter", "record",     "report"};
  top.insert(top.end(), extra_keys.begin(), extra_keys.end());
  root.allowKeys(top);

  trajectory.loadFrom(root.map("trajectory", "a trajectory CSV is required"));
  if (const auto s = root.optMap("smoothing")) smoothing.loadFrom(*s);
  if (const auto s = root.optMap("imu")) {
    s->allowKeys({"rate_hz"});
    s->read("rate_hz", imu_rate_hz, limits::kImuRateHz);
  }

  // truth
  const ConfigNode tn = root.map("truth", "errors: model | static");
  tn.allowKeys({"errors", "model", "static"});
  tn.readChoice("errors", truth.kind, {"model", "static"});
  if (truth.kind == "model") {
    if (!tn.has("model")) throw tn.error("model", "missing (FILE:NAME of the true error model)");
    truth.model = tn.modelRef("model");
  } else {
    truth.recording.loadFrom(tn.map("static", "file, gyro_unit, acc_unit, rate_hz"), false);
  }

  // candidates
  std::set<std::string> labels;
  for (const ConfigNode& n :
       root.list("candidates", 1, SIZE_MAX, "a non-empty list of {label, model | accelerometer/gyroscope}")) {
    n.allowKeys({"label", "model", "accelerometer", "gyroscope"});
    CandidateSpec cs;
    cs.label = n.text("label");
    if (cs.label.empty() || !labels.insert(cs.label).second)
      throw n.error("label", "'" + printable(cs.label, 40) + "' is empty or repeated");
    cs.model = n.modelRef("model");
    cs.accelerometer = n.modelRef("accelerometer");
    cs.gyroscope = n.modelRef("gyroscope");
    if (!cs.model.empty() && (!cs.accelerometer.empty() || !cs.gyroscope.empty()))
      throw n.error("give either model or accelerometer/gyroscope, not both");
    if (cs.model.empty() && cs.accelerometer.empty() && cs.gyroscope.empty())
      throw n.error("needs model or accelerometer and/or gyroscope");
    candidates.push_back(cs);
  }

  // sets
  for (const ConfigNode& n : root.list("sets")) {
    n.allowKeys({"name", "title", "models", "reference", "white_noise"});
    ModelSetSpec s;
    s.name = n.text("name");
    for (char ch : s.name)
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-'))
        throw n.error("name", "'" + printable(s.name, 40) + "': use letters, digits, _ and - only");
    for (const auto& other : sets)
      if (other.name == s.name)
        throw n.error("name", "'" + s.name + "' is used by an earlier set (names must be unique)");
    s.title = s.name;
    n.read("title", s.title);
    if (!n.has("models")) throw n.error("models", "missing");
    n.read("models", s.models, 1);
    for (const auto& l : s.models)
      if (!labels.count(l)) throw n.error("models", "unknown candidate label '" + printable(l, 40) + "'");
    n.read("reference", s.reference);
    n.read("white_noise", s.white_noise);
    if (s.reference.empty()) s.reference = s.models.back();
    if (s.white_noise.empty()) s.white_noise = s.models.front();
    for (const auto* l : {&s.reference, &s.white_noise})
      if (std::find(s.models.begin(), s.models.end(), *l) == s.models.end())
        throw n.error("reference/white_noise '" + printable(*l, 40) + "' is not among the set's models");
    sets.push_back(s);
  }
  if (sets.empty()) {
    ModelSetSpec s;
    s.name = "all";
    s.title = "all candidates";
    for (const auto& cs : candidates) s.models.push_back(cs.label);
    s.reference = s.models.back();
    s.white_noise = s.models.front();
    sets.push_back(s);
  }

  if (const auto g = root.optMap("gnss")) gnss.loadFrom(*g, false);
  if (const auto b = root.optMap("baro")) {
    baro.loadFrom(*b, false, {"during_outages"});
    b->read("during_outages", baro_in_outage);
  }

  if (root.has("outages")) {
    outages.clear();
    for (const ConfigNode& o : root.list("outages", 1, SIZE_MAX, "a non-empty list of {start_s, duration_s}")) {
      o.allowKeys({"start_s", "duration_s"});
      const double st = o.number("start_s", kOutageStartS, "seconds from the trajectory start");
      const double d = o.number("duration_s", limits::kDurationS);
      if (!outages.empty() && st < outages.back().end_s)
        throw o.error("start_s", "outages must be in time order and not overlap");
      outages.push_back(Outage::fromStartDuration(st, d));
    }
  }
  if (const auto m = root.optMap("monte_carlo")) {
    m->allowKeys({"runs", "seed", "threads"});
    m->read("runs", runs, 1, limits::kMaxMonteCarloRuns);
    m->readSeed("seed", seed);
    long long t = threads;
    if (m->read("threads", t, 0, kMaxThreads)) threads = static_cast<unsigned>(t);
  }
  if (const auto f = root.optMap("filter")) {
    f->allowKeys({"propagate_every", "discretization", "coning_sculling", "initial_sigma", "extra_states"});
    if (const auto x = f->optMap("extra_states")) ekf.imu.extra.loadFrom(*x);
    f->read("propagate_every", ekf.propagate_every, 1, limits::kMaxPropagateEvery);
    std::string disc;
    if (f->readChoice("discretization", disc, {"series", "vanloan"}) >= 0)
      ekf.discretization = filter::parseDiscretization(disc);
    f->read("coning_sculling", ekf.mechanization.coning_sculling);
    if (const auto s = f->optMap("initial_sigma")) {
      s->allowKeys({"pos_h_m", "pos_v_m", "vel_mps", "roll_pitch_deg", "yaw_deg"});
      double ph = initial_sigma(0), pv = initial_sigma(2), v = initial_sigma(3),
             rp = initial_sigma(6) / units::kDeg, y = initial_sigma(8) / units::kDeg;
      s->read("pos_h_m", ph, limits::kPositionSigmaM);
      s->read("pos_v_m", pv, limits::kPositionSigmaM);
      s->read("vel_mps", v, limits::kVelocitySigmaMps);
      s->read("roll_pitch_deg", rp, limits::kAttitudeSigmaDeg);
      s->read("yaw_deg", y, limits::kAttitudeSigmaDeg);
      initial_sigma << ph, ph, pv, v, v, v, rp * units::kDeg, rp * units::kDeg, y * units::kDeg;
    }
  }
  if (const auto r = root.optMap("record")) {
    r->allowKeys({"rate_hz", "outage_rate_hz"});
    r->read("rate_hz", record_rate_hz, limits::kAidingRateHz);
    r->read("outage_rate_hz", outage_record_rate_hz, limits::kAidingRateHz);
    // epochs fall on IMU samples: a faster record was recorded at the IMU rate without a word
    if (record_rate_hz > imu_rate_hz) throw r->error("rate_hz", "must not exceed imu.rate_hz (" + formatNumber(imu_rate_hz) + " Hz)");
    if (outage_record_rate_hz > imu_rate_hz)
      throw r->error("outage_rate_hz", "must not exceed imu.rate_hz (" + formatNumber(imu_rate_hz) + " Hz)");
  }
  if (const auto r = root.optMap("report")) {
    r->allowKeys({"margin", "plot_before_s", "plot_after_s"});
    r->read("margin", margin, kMarginRange);
    r->read("plot_before_s", plot_before_s, kPlotWindowS);
    r->read("plot_after_s", plot_after_s, kPlotWindowS);
  }
}

Shard parseShard(const std::string& text) {
  const auto slash = text.find('/');
  double k = 0, n = 0;
  if (slash == std::string::npos || !parseDouble(text.substr(0, slash), k) ||
      !parseDouble(text.substr(slash + 1), n) || k != std::floor(k) || n != std::floor(n) || k < 1 || n < 1 ||
      k > n || n > 1e6)
    throw Error("--shard '" + printable(text, 60) + "': expected K/N with integers 1 <= K <= N (e.g. 2/4)");
  return Shard{static_cast<unsigned>(k), static_cast<unsigned>(n)};
}

}  // namespace navimpact::analysis
