// Monte Carlo emulation study: preparation, parallel runs, exact accumulation,
// shards and their merge.
#include "navimpact/analysis/study.hpp"

#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "navimpact/core/build_info.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/analysis/run_plan.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/filter/state_layout.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "study_internal.hpp"

namespace navimpact::analysis {

using nlohmann::json;

namespace {

/// Text of the six axis models, compact when the axes of a sensor agree.
std::string describeModel(const stochastic::ImuModel& m) {
  auto sensor = [&](int a0, const char* name) {
    const auto& x = m.axis[a0];
    const bool same = x.terms == m.axis[a0 + 1].terms && x.terms == m.axis[a0 + 2].terms;
    std::string s = std::string(name) + ": ";
    if (same) return s + stochastic::formatTerms(x.terms);
    for (int i = a0; i < a0 + 3; ++i)
      s += std::string(i > a0 ? "; " : "") + kChannelNames[i] + " " + stochastic::formatTerms(m.axis[i].terms);
    return s;
  };
  return sensor(3, "acc") + " | " + sensor(0, "gyro");
}

}  // namespace

namespace detail {

double chi2Quantile(double p, double dof) {
  boost::math::chi_squared d(dof);
  return boost::math::quantile(d, p);
}

void headerToJson(const StudyHeader& h, json& j) {
  j["version"] = h.version;
  j["versions"] = h.versions;
  j["config_file"] = h.config_file;
  j["config_text"] = h.config_text;
  j["seed"] = h.seed;
  j["runs_total"] = h.runs_total;
  j["labels"] = h.labels;
  json sets = json::array();
  for (const auto& s : h.sets)
    sets.push_back({{"name", s.name}, {"title", s.title}, {"models", s.models}, {"reference", s.reference},
                    {"white_noise", s.white_noise}});
  j["sets"] = sets;
  j["margin"] = h.margin;
}

namespace {
bool finite(double v) { return std::isfinite(v); }
}  // namespace

void checkHeader(const StudyHeader& h, const std::string& where) {
  const auto bad = [&](const std::string& what) { throw Error(where + ": " + what + " (not as navimpact writes it)"); };
  if (h.runs_total < 1 || h.runs_total > std::size_t(limits::kMaxMonteCarloRuns))
    bad("runs_total " + std::to_string(h.runs_total) + " is outside [1, " + std::to_string(limits::kMaxMonteCarloRuns) + "]");
  if (h.labels.empty()) bad("no candidate labels");
  for (std::size_t i = 0; i < h.labels.size(); ++i)
    for (std::size_t k = 0; k < i; ++k)
      if (h.labels[i] == h.labels[k]) bad("candidate label '" + printable(h.labels[i]) + "' appears twice");
  const auto known = [&](const std::string& l) { return std::find(h.labels.begin(), h.labels.end(), l) != h.labels.end(); };
  for (const auto& set : h.sets) {
    if (set.models.empty()) bad("set '" + printable(set.name) + "' has no models");
    for (const auto& m : set.models)
      if (!known(m)) bad("set '" + printable(set.name) + "' names the unknown candidate '" + printable(m) + "'");
    if (!known(set.reference)) bad("set '" + printable(set.name) + "' has the unknown reference '" + printable(set.reference) + "'");
    if (!set.white_noise.empty() && !known(set.white_noise))
      bad("set '" + printable(set.name) + "' has the unknown white-noise model '" + printable(set.white_noise) + "'");
  }
  if (!(h.margin >= 0.0 && h.margin <= 10.0)) bad("margin " + formatNumber(h.margin) + " is outside [0, 10]");
}

void headerFromJson(const json& j, StudyHeader& h) {
  h.version = j.at("version");
  h.versions = j.at("versions").get<std::vector<std::pair<std::string, std::string>>>();
  h.config_file = j.at("config_file");
  h.config_text = j.at("config_text");
  h.seed = j.at("seed");
  h.runs_total = j.at("runs_total");
  h.labels = j.at("labels").get<std::vector<std::string>>();
  for (const auto& s : j.at("sets"))
    h.sets.push_back({s.at("name"), s.at("title"), s.at("models").get<std::vector<std::string>>(),
                      s.at("reference"), s.at("white_noise")});
  h.margin = j.at("margin");
}

json metaToJson(const StudyMeta& m) {
  json j;
  headerToJson(m, j);
  j["t0"] = m.t0;
  j["duration_s"] = m.duration_s;
  j["imu_rate_hz"] = m.imu_rate_hz;
  j["trajectory"] = m.trajectory;
  j["truth_description"] = m.truth_description;
  j["notices"] = m.notices;
  j["sources"] = m.sources;
  j["states"] = m.states;
  json o = json::array();
  for (const auto& w : m.outages) o.push_back({w.start_s, w.end_s});
  j["outages"] = o;
  j["epochs"] = m.epochs;
  j["plot_before_s"] = m.plot_before_s;
  j["plot_after_s"] = m.plot_after_s;
  j["settings"] = m.settings;
  return j;
}

StudyMeta metaFromJson(const json& j, const std::string& where) {
  try {
    StudyMeta m;
    headerFromJson(j, m);
    m.t0 = j.at("t0");
    m.duration_s = j.at("duration_s");
    m.imu_rate_hz = j.at("imu_rate_hz");
    m.trajectory = j.at("trajectory");
    m.truth_description = j.at("truth_description");
    m.notices = j.at("notices").get<std::vector<std::string>>();
    m.sources = j.at("sources").get<std::vector<std::string>>();
    m.states = j.at("states").get<std::vector<int>>();
    for (const auto& o : j.at("outages")) m.outages.push_back({o.at(0), o.at(1)});
    m.epochs = j.at("epochs").get<std::vector<double>>();
    m.plot_before_s = j.at("plot_before_s");
    m.plot_after_s = j.at("plot_after_s");
    m.settings = j.at("settings");
    checkHeader(m, where);
    const auto bad = [&](const std::string& what) { throw Error(where + ": " + what + " (not as navimpact writes it)"); };
    if (m.states.size() != m.labels.size() || m.sources.size() != m.labels.size())
      bad("states and sources do not match the " + std::to_string(m.labels.size()) + " candidates");
    if (!(m.imu_rate_hz >= limits::kImuRateHz.lo && m.imu_rate_hz <= limits::kImuRateHz.hi))
      bad("imu_rate_hz " + formatNumber(m.imu_rate_hz) + " is outside " + limits::describe(limits::kImuRateHz));
    if (!finite(m.t0) || !(m.duration_s > 0.0 && m.duration_s <= limits::kDurationS.hi))
      bad("t0 or duration_s is not a run's");
    for (std::size_t k = 0; k < m.epochs.size(); ++k)
      if (!finite(m.epochs[k]) || (k > 0 && !(m.epochs[k] > m.epochs[k - 1]))) bad("epochs are not finite and increasing");
    for (const auto& o : m.outages)
      if (!finite(o.start_s) || !finite(o.end_s) || !(o.end_s > o.start_s)) bad("an outage is not finite with start < end");
    if (!(m.plot_before_s >= 0.0 && m.plot_before_s <= limits::kDurationS.hi) ||
        !(m.plot_after_s >= 0.0 && m.plot_after_s <= limits::kDurationS.hi))
      bad("plot_before_s or plot_after_s is outside [0, 604800] s");
    return m;
  } catch (const json::exception& e) {
    throw Error(where + ": not a navimpact study shard (" + printable(e.what(), 120) + ")");
  }
}

}  // namespace detail

std::pair<double, double> aneesBand(std::size_t runs, int dof, double confidence) {
  const double a = 0.5 * (1.0 - confidence), R = static_cast<double>(runs);
  return {detail::chi2Quantile(a, R * dof) / R, detail::chi2Quantile(1.0 - a, R * dof) / R};
}

// ---------------------------------------------------------------------------
// Plan

class StudyPlan {
 public:
  StudyConfig cfg;
  StudyMeta meta;
  RunPlan run;
  stochastic::ImuModel truth_model;
  std::optional<ImuSeries> recording;
  std::size_t rec_block = 1;  // recording samples per IMU sample
  std::vector<stochastic::ImuModel> filter_models;
};

const StudyMeta& studyMeta(const StudyPlan& plan) { return plan.meta; }

namespace {

stochastic::ImuModel atRate(const stochastic::ImuModel& m, double rate, std::vector<std::string>& notices) {
  return stochastic::atRate(m, rate, &notices);
}

stochastic::ImuModel buildCandidate(const CandidateSpec& c, double rate, std::vector<std::string>& notices) {
  if (!c.model.empty()) {
    stochastic::ImuModel m = atRate(stochastic::loadImuModel(c.model), rate, notices);
    m.name = c.label;
    return m;
  }
  stochastic::ImuModel m;
  m.rate_hz = rate;
  m.name = c.label;
  m.source = "acc " + (c.accelerometer.empty() ? std::string("none") : c.accelerometer) + ", gyro " +
             (c.gyroscope.empty() ? std::string("none") : c.gyroscope);
  for (auto& a : m.axis) a.rate_hz = rate;
  if (!c.accelerometer.empty()) {
    const auto a = atRate(stochastic::loadImuModel(c.accelerometer), rate, notices);
    for (int i = 3; i < 6; ++i) m.axis[i] = a.axis[i];
  }
  if (!c.gyroscope.empty()) {
    const auto g = atRate(stochastic::loadImuModel(c.gyroscope), rate, notices);
    for (int i = 0; i < 3; ++i) m.axis[i] = g.axis[i];
  }
  return m;
}

}  // namespace

std::shared_ptr<const StudyPlan> prepareStudy(const StudyConfig& cfg, const std::string& version) {
  if (cfg.runs < 1) throw Error("study: the number of runs must be >= 1");
  if (cfg.candidates.empty()) throw Error("study: no candidate models");
  auto plan = std::make_shared<StudyPlan>();
  plan->cfg = cfg;
  StudyMeta& meta = plan->meta;
  const double rate = cfg.imu_rate_hz;

  // Models first (cheap, most likely to be mistyped).
  for (const auto& c : cfg.candidates) {
    try {
      plan->filter_models.push_back(buildCandidate(c, rate, meta.notices));
      const filter::ModelEntry entry = filter::layoutFor(plan->filter_models.back(), cfg.ekf, rate);
      meta.states.push_back(entry.layout.size());
      for (const auto& n : entry.notes) meta.notices.push_back("candidate '" + c.label + "': " + n);
    } catch (const Error& e) {
      throw Error("candidate '" + c.label + "': " + e.what());
    }
    meta.labels.push_back(c.label);
    meta.sources.push_back(describeModel(plan->filter_models.back()));
  }

  // The runs: trajectory, outages, perfect IMU, record epochs and their truth, filter options.
  RunPlanOptions ro;
  ro.trajectory = cfg.trajectory;
  ro.smoothing = cfg.smoothing;
  ro.imu_rate_hz = rate;
  ro.outages = cfg.outages;
  if (!cfg.config_file.empty() && !cfg.outages_key.empty())
    ro.outage_name = keyError(cfg.config_file, cfg.outages_key, "outage").what();
  ro.outage_names = cfg.outage_names;
  ro.record_rate_hz = cfg.record_rate_hz;
  ro.outage_record_rate_hz = cfg.outage_record_rate_hz;
  ro.gnss = cfg.gnss;
  ro.baro = cfg.baro;
  ro.use_baro = cfg.use_baro;
  ro.baro_in_outage = cfg.baro_in_outage;
  ro.ekf = cfg.ekf;
  ro.initial_sigma = cfg.initial_sigma;
  plan->run = planRuns(ro);
  const RunPlan& run = plan->run;
  const std::size_t n = run.samples();
  const double duration = run.duration_s();
  meta.t0 = run.t0;
  meta.duration_s = duration;
  meta.imu_rate_hz = rate;
  meta.trajectory = cfg.trajectory.file + " (" + formatNumber(duration) + " s used)";
  meta.outages = run.nav.outages;
  meta.epochs = run.truth.t;

  // True errors.
  if (cfg.truth.kind == "model") {
    plan->truth_model = atRate(stochastic::loadImuModel(cfg.truth.model), rate, meta.notices);
    meta.truth_description = "simulated from model " + cfg.truth.model + " (" + describeModel(plan->truth_model) +
                             ")";
  } else {
    plan->recording = readImuCsv(cfg.truth.recording.file, cfg.truth.recording.csv);
    const ImuSeries& rec = *plan->recording;
    const double ratio = rec.rate_hz / rate, m_real = std::round(ratio);
    if (m_real < 1.0 || std::abs(ratio - m_real) > 1e-6 * ratio)
      throw Error(cfg.truth.recording.file + ": static recording is at " + formatNumber(rec.rate_hz) + " Hz, emulation at " +
                  formatNumber(rate) + " Hz (set imu.rate_hz to the recording's rate or an integer divisor of it)");
    plan->rec_block = static_cast<std::size_t>(m_real);
    if (n * plan->rec_block > rec.size())
      throw Error(cfg.truth.recording.file + ": static recording too short: " + formatNumber(rec.size() / rec.rate_hz) +
                  " s available, " + formatNumber(duration) + " s needed");
    meta.truth_description = "measured static recording " + cfg.truth.recording.file + " (" +
                             formatNumber(rec.size() / rec.rate_hz) + " s at " + formatNumber(rec.rate_hz) +
                             " Hz): each run takes a " + formatNumber(duration) +
                             " s window chosen by its seed, mean removed per axis" +
                             (plan->rec_block > 1 ? ", block means of " + std::to_string(plan->rec_block) : "");
  }

  meta.version = version;
  meta.versions = buildVersions();
  meta.config_file = cfg.config_file;
  meta.config_text = cfg.config_text;
  meta.seed = cfg.seed;
  meta.runs_total = cfg.runs;
  meta.sets = cfg.sets;
  meta.margin = cfg.margin;
  meta.plot_before_s = cfg.plot_before_s;
  meta.plot_after_s = cfg.plot_after_s;
  std::ostringstream st;
  st << "IMU " << formatNumber(rate) << " Hz; GNSS " << formatNumber(cfg.gnss.rate_hz) << " Hz, position sigma "
     << formatNumber(cfg.gnss.sigma_pos_h_m) << " m horizontal / " << formatNumber(cfg.gnss.sigma_pos_v_m)
     << " m vertical, velocity sigma " << formatNumber(cfg.gnss.sigma_vel_h_mps) << " / " << formatNumber(cfg.gnss.sigma_vel_v_mps)
     << " m/s\n"
     << (cfg.use_baro ? "barometer " + formatNumber(cfg.baro.rate_hz) + " Hz, sigma " + formatNumber(cfg.baro.sigma_m) + " m, " +
                            (cfg.baro_in_outage ? "kept during GNSS outages" : "off during GNSS outages")
                      : std::string("no barometer"))
     << "\n"
     << "EKF: covariance propagated every " << cfg.ekf.propagate_every << " IMU samples ("
     << (cfg.ekf.discretization == filter::Discretization::Series ? "series" : "Van Loan")
     << " discretisation); initial error sigmas " << formatNumber(cfg.initial_sigma(0)) << " m, "
     << formatNumber(cfg.initial_sigma(3)) << " m/s, roll/pitch " << formatNumber(cfg.initial_sigma(6) / units::kDeg)
     << " deg, yaw " << formatNumber(cfg.initial_sigma(8) / units::kDeg) << " deg (drawn per run, same for all models)";
  meta.settings = st.str();
  return plan;
}

StudyWork studyWork(const StudyPlan& p, const Shard& shard, unsigned threads) {
  StudyWork w;
  for (std::size_t i = 0; i < p.cfg.runs; ++i) w.runs += shard.contains(i) ? 1.0 : 0.0;
  w.samples = double(p.run.samples());
  w.filters = double(p.filter_models.size());
  w.workers = double(workerThreads(threads, static_cast<std::size_t>(w.runs)));
  w.steps = w.runs * w.samples * (1.0 + w.filters);
  w.bytes = (w.workers * 120.0 + 100.0) * w.samples;
  return w;
}

unsigned studyThreads(const StudyPlan& p, const Shard& shard, unsigned requested) {
  if (requested > 0) return requested;
  const StudyWork w = studyWork(p, shard, 0);
  return limits::budgetWorkers(w.workers, w.samples, 100.0, 120.0);
}

void checkStudyBudget(const std::string& command, const StudyWork& w, bool allow_large) {
  const std::string place = command + ": " + formatNumber(w.runs) + " runs";
  limits::checkBudget(
      {{place, "the runs", w.steps, limits::kDefaultFilterStepBudget, "IMU steps",
        formatNumber(w.samples, 3) + " samples x " + formatNumber(1.0 + w.filters) + " (emulation and filters) per run" +
            (w.columns > 1 ? " x " + formatNumber(w.columns) + " columns" : ""),
        "lower --runs (monte_carlo.runs) or run shards (--shard K/N)"},
       {place, "the workers", w.bytes / 1e6, limits::kDefaultMemoryBudgetBytes / 1e6, "MB",
        formatNumber(w.workers) + " workers x " + formatNumber(w.samples, 3) + " samples",
        "lower --threads or imu.rate_hz"}},
      allow_large);
}

// ---------------------------------------------------------------------------
// One run: the shared realisation, then every candidate model.

namespace {

RunRecord doRun(const StudyPlan& p, std::uint64_t index) {
  const StudyConfig& cfg = p.cfg;
  RunRecord rec;
  rec.index = index;
  rec.seed = stochastic::deriveSeed(cfg.seed, index);
  const std::size_t n = p.run.samples();

  // IMU errors, shared by every candidate model.
  std::array<std::vector<double>, 6> err;
  if (p.recording) {
    // A window of the recording loaded once in prepareStudy (start from the
    // run's seed), block means to the IMU rate, window mean removed per axis.
    emulation::StaticRecordingSpec spec = cfg.truth.recording;
    spec.offset_s.reset();
    spec.seed = stochastic::deriveSeed(rec.seed, 4);
    err = emulation::staticImuErrors(*p.recording, spec, cfg.imu_rate_hz, n).axis;
  } else {
    err = emulation::modelImuErrors(p.truth_model, cfg.imu_rate_hz, n, stochastic::deriveSeed(rec.seed, 0)).axis;
  }
  const EmulatedRun run = p.run.emulate(err, rec.seed);
  const NavRunInput in = p.run.input(run);

  const std::size_t E = p.run.truth.t.size(), O = p.run.nav.outages.size();
  for (const auto& model : p.filter_models) {
    const NavRunResult r = runNav(in, model, p.run.nav);
    if (r.epochs.size() != E)
      throw Error("study: run " + std::to_string(index) + " recorded " + std::to_string(r.epochs.size()) +
                  " epochs, expected " + std::to_string(E));
    RunRecord::Model m;
    m.epochs.resize(E * detail::kEpochValues);
    for (std::size_t k = 0; k < E; ++k) {
      double* d = &m.epochs[k * detail::kEpochValues];
      for (int j = 0; j < 9; ++j) {
        d[j] = r.epochs[k].err(j);
        d[9 + j] = r.epochs[k].sigma(j);
      }
      for (int j = 0; j < 4; ++j) d[18 + j] = r.epochs[k].nees[j];
    }
    for (std::size_t o = 0; o < O; ++o) {
      m.drift.push_back(r.outages[o].max_drift_h);
      m.drift.push_back(r.outages[o].max_drift_3d);
    }
    m.wall_s = r.wall_s;
    m.steps = r.steps;
    rec.models.push_back(std::move(m));
  }
  if (const std::string why = detail::implausible(rec); !why.empty())
    throw Error("study: run " + std::to_string(index) + " (seed " + std::to_string(rec.seed) + "): " + why);
  return rec;
}

}  // namespace

void StudyAccumulator::add(const RunRecord& r, std::size_t E, std::size_t O) {
  static const double q68[2] = {detail::chi2Quantile(0.6826894921370859, 3),
                                detail::chi2Quantile(0.6826894921370859, 9)};
  static const double q95[2] = {detail::chi2Quantile(0.95, 3), detail::chi2Quantile(0.95, 9)};
  if (models.empty()) {
    models.resize(r.models.size());
    for (auto& m : models) {
      m.e.assign(9 * E, 0.0);
      m.e2.assign(9 * E, 0.0);
      m.s2.assign(9 * E, 0.0);
      m.nees.assign(4 * E, 0.0);
      m.n_valid.assign(4 * E, 0.0);
      m.in68.assign(4 * E, 0.0);
      m.in95.assign(4 * E, 0.0);
      m.drift_h.assign(O, 0.0);
      m.drift_h2.assign(O, 0.0);
      m.drift_3d.assign(O, 0.0);
    }
  }
  if (r.models.size() != models.size()) throw Error("study: run record with a different number of models");
  for (std::size_t mi = 0; mi < models.size(); ++mi) {
    Model& a = models[mi];
    const RunRecord::Model& x = r.models[mi];
    if (x.epochs.size() != E * detail::kEpochValues || x.drift.size() != 2 * O)
      throw Error("study: run record " + std::to_string(r.index) + " has the wrong size");
    for (std::size_t k = 0; k < E; ++k) {
      const double* d = &x.epochs[k * detail::kEpochValues];
      for (int j = 0; j < 9; ++j) {
        a.e[9 * k + j] += d[j];
        a.e2[9 * k + j] += d[j] * d[j];
        a.s2[9 * k + j] += d[9 + j] * d[9 + j];
      }
      for (int b = 0; b < 4; ++b) {
        const double v = d[18 + b];
        if (!std::isfinite(v)) continue;
        const int q = b == 3 ? 1 : 0;
        a.nees[4 * k + b] += v;
        a.n_valid[4 * k + b] += 1.0;
        a.in68[4 * k + b] += v <= q68[q] ? 1.0 : 0.0;
        a.in95[4 * k + b] += v <= q95[q] ? 1.0 : 0.0;
      }
    }
    for (std::size_t o = 0; o < O; ++o) {
      a.drift_h[o] += x.drift[2 * o];
      a.drift_h2[o] += x.drift[2 * o] * x.drift[2 * o];
      a.drift_3d[o] += x.drift[2 * o + 1];
    }
    a.wall_s += x.wall_s;
    a.steps += double(x.steps);
  }
  ++runs;
}

StudyResults runStudy(const std::shared_ptr<const StudyPlan>& plan, const Shard& shard, unsigned threads,
                      const ProgressFn& progress) {
  return runStudy(plan, shard, threads, progress, RunSink{});
}

StudyResults runStudy(const std::shared_ptr<const StudyPlan>& plan, const Shard& shard, unsigned threads,
                      const ProgressFn& progress, const RunSink& sink) {
  if (!plan) throw Error("study: no plan");
  const StudyPlan& p = *plan;
  StudyResults res;
  res.meta = p.meta;
  res.shard = shard;
  for (std::size_t i = 0; i < p.cfg.runs; ++i)
    if (shard.contains(i)) res.run_indices.push_back(i);
  const std::size_t N = res.run_indices.size();
  if (N == 0) throw Error("study: shard " + std::to_string(shard.k) + "/" + std::to_string(shard.n) +
                          " holds no run (only " + std::to_string(p.cfg.runs) + " runs)");
  const std::size_t E = p.run.truth.t.size(), O = p.run.nav.outages.size();
  std::mutex mu;
  std::map<std::size_t, RunRecord> pending;  // finished out of order, by position
  std::size_t merged = 0;
  parallelFor(N, threads, [&](std::size_t pos) {
    RunRecord rec = doRun(p, res.run_indices[pos]);
    std::lock_guard<std::mutex> lock(mu);
    pending.emplace(pos, std::move(rec));
    // Add in run-index order: the sums do not depend on scheduling.
    for (auto it = pending.find(merged); it != pending.end(); it = pending.find(merged)) {
      res.acc.add(it->second, E, O);
      if (sink) sink(it->second);
      else if (!shard.whole()) res.records.push_back(std::move(it->second));
      pending.erase(it);
      ++merged;
      if (progress) progress(merged, N);
    }
  });
  return res;
}

// ---------------------------------------------------------------------------
// Shards

namespace detail {

void putU64(std::ostream& o, std::uint64_t v) { o.write(reinterpret_cast<const char*>(&v), 8); }
void putD(std::ostream& o, const double* v, std::size_t n) {
  o.write(reinterpret_cast<const char*>(v), static_cast<std::streamsize>(8 * n));
}
std::uint64_t getU64(std::istream& i, const std::string& file) {
  std::uint64_t v = 0;
  if (!i.read(reinterpret_cast<char*>(&v), 8)) throw Error(file + ": truncated");
  return v;
}
void getD(std::istream& i, double* v, std::size_t n, const std::string& file) {
  if (!i.read(reinterpret_cast<char*>(v), static_cast<std::streamsize>(8 * n))) throw Error(file + ": truncated");
}

std::string implausible(const RunRecord& rec) {
  const auto size = [](double v) { return std::isfinite(v) && std::abs(v) <= kMaxRunValue; };
  for (std::size_t mi = 0; mi < rec.models.size(); ++mi) {
    const RunRecord::Model& m = rec.models[mi];
    const std::string model = "model " + std::to_string(mi + 1);
    if (!(size(m.wall_s) && m.wall_s >= 0.0)) return model + ": its time is not finite and >= 0";
    for (std::size_t k = 0; k < m.epochs.size(); ++k) {
      const std::size_t j = k % kEpochValues, epoch = k / kEpochValues;
      const double v = m.epochs[k];
      if (j < 9 && !size(v)) return model + ": an error of epoch " + std::to_string(epoch) + " is not finite";
      if (j >= 9 && j < 18 && !(size(v) && v >= 0.0))
        return model + ": a sigma of epoch " + std::to_string(epoch) + " is not finite and >= 0";
      if (j >= 18 && !std::isnan(v) && !(size(v) && v >= 0.0))  // a NEES may be missing (NaN)
        return model + ": a NEES of epoch " + std::to_string(epoch) + " is neither missing nor finite and >= 0";
    }
    for (std::size_t o = 0; o < m.drift.size(); ++o)
      if (!(size(m.drift[o]) && m.drift[o] >= 0.0))
        return model + ": the drift of outage " + std::to_string(o / 2) + " is not finite and >= 0";
  }
  return {};
}

json readShardJson(const std::string& dir, const std::string& file, const std::string& marker,
                   const std::string& writer) {
  const std::string path = dir + "/" + file;
  std::ifstream f(path);
  if (!f) throw Error(path + ": cannot open (is " + dir + " a folder written by navimpact " + writer + "?)");
  noteInput(path);  // the merged output must not replace a shard (output.hpp)
  json j;
  try {
    f >> j;
  } catch (const json::exception& e) {
    throw Error(path + ": not valid JSON (" + printable(e.what(), 120) + ")");
  }
  if (!j.is_object() || !j.contains(marker))
    throw Error(path + ": not a navimpact " + writer.substr(0, writer.find(' ')) + " shard");
  return j;
}

}  // namespace detail

namespace {
constexpr char kMagic[8] = {'N', 'I', 'S', 'T', 'U', 'D', 'Y', '1'};
using detail::getD;
using detail::getU64;
using detail::putD;
using detail::putU64;
}  // namespace

void writeShard(const StudyResults& r, const std::string& build_id, OutputSet& out) {
  json j;
  j["navimpact_study_shard"] = 1;
  j["build_id"] = build_id;
  j["meta"] = detail::metaToJson(r.meta);
  j["shard"] = {{"k", r.shard.k}, {"n", r.shard.n}};
  j["run_indices"] = r.run_indices;
  j["byte_order"] = "native little-endian IEEE-754 doubles";
  out.writeText("shard.json", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  const std::size_t E = r.meta.epochs.size(), O = r.meta.outages.size();
  std::ofstream f(out.stage("runs.bin"), std::ios::binary);
  f.write(kMagic, 8);
  putU64(f, r.records.size());
  putU64(f, r.meta.labels.size());
  putU64(f, E);
  putU64(f, O);
  for (const RunRecord& rec : r.records) {
    putU64(f, rec.index);
    putU64(f, rec.seed);
    for (const auto& m : rec.models) {
      putD(f, &m.wall_s, 1);
      putU64(f, m.steps);
      putD(f, m.epochs.data(), m.epochs.size());
      putD(f, m.drift.data(), m.drift.size());
    }
  }
  if (!f) throw Error(out.dir().string() + "/runs.bin: write failed");
}

StudyResults mergeShards(const std::vector<std::string>& dirs, const std::string& build_id) {
  if (dirs.empty()) throw Error("study-merge: no shard folders given");
  struct In {
    std::string dir;
    std::unique_ptr<std::ifstream> f;
    std::vector<std::uint64_t> idx;
    std::size_t pos = 0;
  };
  std::vector<In> ins;
  StudyResults res;
  json first_meta;
  for (const auto& d : dirs) {
    const std::string sj = d + "/shard.json";
    const json j = detail::readShardJson(d, "shard.json", "navimpact_study_shard", "study --shard");
    In in;
    in.dir = d;
    try {
      const std::string b = j.at("build_id");
      if (b != build_id)
        throw Error(sj + ": shard written by another build of navimpact (" + b + "; this one is " + build_id +
                    "): rerun it with this build");
      const json& meta = j.at("meta");
      if (ins.empty()) {
        first_meta = meta;
        res.meta = detail::metaFromJson(meta, sj);
      } else {
        (void)detail::metaFromJson(meta, sj);  // the same checks for every shard
        for (const char* k : {"config_text", "seed", "runs_total", "labels", "sets", "states", "epochs", "outages",
                              "version", "versions", "imu_rate_hz", "margin"})
          if (meta.at(k) != first_meta.at(k))
            throw Error(sj + ": shard of a different study (" + std::string(k) + " differs from " + dirs[0] + ")");
      }
      in.idx = j.at("run_indices").get<std::vector<std::uint64_t>>();
    } catch (const json::exception& e) {
      throw Error(sj + ": not a navimpact study shard (" + printable(e.what(), 120) + ")");
    }
    const std::string bin = d + "/runs.bin";
    in.f = std::make_unique<std::ifstream>(bin, std::ios::binary);
    if (!*in.f) throw Error(bin + ": cannot open");
    char magic[8];
    if (!in.f->read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) throw Error(bin + ": not a study run file");
    const auto nr = getU64(*in.f, bin), nm = getU64(*in.f, bin), E = getU64(*in.f, bin), O = getU64(*in.f, bin);
    if (nr != in.idx.size() || nm != res.meta.labels.size() || E != res.meta.epochs.size() ||
        O != res.meta.outages.size())
      throw Error(bin + ": header does not match shard.json");
    ins.push_back(std::move(in));
  }
  // Every run exactly once.
  const std::size_t R = res.meta.runs_total;
  std::vector<int> owner(R, -1);
  for (std::size_t s = 0; s < ins.size(); ++s)
    for (auto i : ins[s].idx) {
      if (i >= R) throw Error(ins[s].dir + ": run index " + std::to_string(i) + " out of range");
      if (owner[i] >= 0)
        throw Error("run " + std::to_string(i) + " is in both " + ins[owner[i]].dir + " and " + ins[s].dir);
      owner[i] = static_cast<int>(s);
    }
  for (std::size_t i = 0; i < R; ++i)
    if (owner[i] < 0) throw Error("study-merge: run " + std::to_string(i) + " of " + std::to_string(R) +
                                  " is in no shard (give every shard folder)");
  const std::size_t E = res.meta.epochs.size(), O = res.meta.outages.size(), M = res.meta.labels.size();
  for (std::size_t i = 0; i < R; ++i) {
    In& in = ins[owner[i]];
    const std::string bin = in.dir + "/runs.bin";
    RunRecord rec;
    rec.index = getU64(*in.f, bin);
    rec.seed = getU64(*in.f, bin);
    if (rec.index != i) throw Error(bin + ": runs not in index order (found " + std::to_string(rec.index) + ")");
    if (rec.seed != stochastic::deriveSeed(res.meta.seed, rec.index))
      throw Error(bin + ": run " + std::to_string(i) + " has a seed that is not the study's (seed " +
                  std::to_string(res.meta.seed) + ")");
    rec.models.resize(M);
    for (auto& m : rec.models) {
      getD(*in.f, &m.wall_s, 1, bin);
      m.steps = getU64(*in.f, bin);
      m.epochs.resize(E * detail::kEpochValues);
      m.drift.resize(2 * O);
      getD(*in.f, m.epochs.data(), m.epochs.size(), bin);
      getD(*in.f, m.drift.data(), m.drift.size(), bin);
    }
    if (const std::string why = detail::implausible(rec); !why.empty())
      throw Error(bin + ": run " + std::to_string(i) + ": " + why + " (not as navimpact writes it)");
    res.acc.add(rec, E, O);
    res.run_indices.push_back(i);
  }
  for (const In& in : ins)
    if (in.f->peek() != std::char_traits<char>::eof())
      throw Error(in.dir + "/runs.bin: bytes after its last run (not as navimpact writes it)");
  res.shard = Shard{1, 1};
  return res;
}

}  // namespace navimpact::analysis
