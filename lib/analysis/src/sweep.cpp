// Model-sufficiency sweep: one paired study per (GNSS quality, barometer, IMU
// rate) column, per-run values inside the outage, shards and their exact
// merge, paired tests and the white-noise threshold with its bootstrap interval.
#include "navimpact/analysis/sweep.hpp"

#include <boost/math/distributions/students_t.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "navimpact/core/build_info.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "study_internal.hpp"

namespace navimpact::analysis {

using nlohmann::json;

namespace {

// FNV-1a 64: a fingerprint of the inputs, to refuse shards of other inputs.
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 1099511628211ull;
    }
  }
  void addText(const std::string& s) {
    const std::uint64_t n = s.size();
    add(&n, 8);
    add(s.data(), s.size());
  }
  std::string hex() const {
    char b[17];
    std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h));
    return b;
  }
};

void addFile(Fnv& f, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open");
  f.addText(path);
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    f.add(buf.data(), static_cast<std::size_t>(in.gcount()));
  }
}

/// FILE of a FILE[:NAME] model reference.
std::string modelFile(const std::string& spec) {
  const auto colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0 || spec.find('/', colon) != std::string::npos) return spec;
  return spec.substr(0, colon);
}

std::string inputsHash(const SweepConfig& cfg) {
  Fnv f;
  f.addText(cfg.config_text);
  addFile(f, cfg.study.trajectory.file);
  std::vector<std::string> files;
  if (cfg.study.truth.kind == "model") files.push_back(modelFile(cfg.study.truth.model));
  else files.push_back(cfg.study.truth.recording.file);
  for (const auto& c : cfg.study.candidates)
    for (const auto* m : {&c.model, &c.accelerometer, &c.gyroscope})
      if (!m->empty()) files.push_back(modelFile(*m));
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  for (const auto& p : files) addFile(f, p);
  return f.hex();
}

std::string columnName(const SweepConfig& cfg, const SweepColumn& c) {
  return "GNSS " + cfg.gnss[c.gnss].name + ", " + (cfg.baro[c.baro] ? "baro on" : "baro off") + ", IMU " +
         formatNumber(cfg.imu_rates_hz[c.rate]) + " Hz";
}

}  // namespace

// ---------------------------------------------------------------------------
// Plan

class SweepPlan {
 public:
  SweepMeta meta;
  std::vector<std::shared_ptr<const StudyPlan>> studies;  ///< per column
  std::vector<std::vector<std::size_t>> epoch_index;      ///< per column: study epoch of each outage epoch
  std::size_t runs = 0;
};

const SweepMeta& sweepMeta(const SweepPlan& plan) { return plan.meta; }

std::shared_ptr<const SweepPlan> prepareSweep(const SweepConfig& cfg, const std::string& version) {
  if (cfg.durations_s.empty() || cfg.gnss.empty() || cfg.baro.empty() || cfg.imu_rates_hz.empty())
    throw Error(cfg.config_file + ": a sweep needs at least one value on every axis");
  if (cfg.study.runs < 2) throw Error(cfg.config_file + ": a sweep needs at least 2 runs");
  auto plan = std::make_shared<SweepPlan>();
  SweepMeta& m = plan->meta;
  m.version = version;
  m.versions = buildVersions();
  m.config_file = cfg.config_file;
  m.config_text = cfg.config_text;
  m.inputs_hash = inputsHash(cfg);
  m.seed = cfg.study.seed;
  m.runs_total = cfg.study.runs;
  m.outage_start_s = cfg.outage_start_s;
  m.durations_s = cfg.durations_s;
  m.gnss = cfg.gnss;
  m.baro = cfg.baro;
  m.imu_rates_hz = cfg.imu_rates_hz;
  m.alpha = cfg.alpha;
  m.margin = cfg.study.margin;
  m.bootstrap = cfg.bootstrap;
  m.sets = cfg.study.sets;
  for (const auto& c : cfg.study.candidates) m.labels.push_back(c.label);
  plan->runs = cfg.study.runs;

  for (std::size_t g = 0; g < cfg.gnss.size(); ++g)
    for (std::size_t b = 0; b < cfg.baro.size(); ++b)
      for (std::size_t r = 0; r < cfg.imu_rates_hz.size(); ++r) {
        SweepMeta::Column col;
        col.axes = {g, b, r};
        col.name = columnName(cfg, col.axes);
        StudyConfig sc = cfg.study;
        sc.imu_rate_hz = cfg.imu_rates_hz[r];
        const Eigen::Vector3d lever = sc.gnss.lever_arm_B;
        sc.gnss = cfg.gnss[g].gnss;
        sc.gnss.lever_arm_B = lever;
        sc.use_baro = cfg.baro[b];
        // Contiguous windows ending at every duration: GNSS stays off from
        // start to start + the longest duration, and each end is an epoch.
        // Each window is named in messages by the duration the user wrote.
        sc.outages.clear();
        sc.outages_key.clear();
        sc.outage_names.clear();
        double prev = 0.0;
        for (std::size_t k = 0; k < cfg.durations_s.size(); ++k) {
          const double d = cfg.durations_s[k];
          sc.outages.push_back({cfg.outage_start_s + prev, cfg.outage_start_s + d});
          sc.outage_names.push_back("key 'sweep.outage.durations_s[" + std::to_string(k) + "]': the outage of " +
                                    formatNumber(d) + " s from " + formatNumber(cfg.outage_start_s) + " s");
          prev = d;
        }
        std::shared_ptr<const StudyPlan> sp;
        try {
          sp = prepareStudy(sc, version);
        } catch (const Error& e) {
          throw Error(cfg.config_file + ": " + col.name + ": " + e.what());
        }
        const StudyMeta& sm = studyMeta(*sp);
        col.settings = sm.settings;
        col.notices = sm.notices;
        col.states = sm.states;
        const double start = sm.outages.front().start_s, half = 0.5 / sc.imu_rate_hz;
        std::vector<std::size_t> idx;
        for (std::size_t k = 0; k < sm.epochs.size(); ++k)
          if (sm.epochs[k] > start + half && sm.epochs[k] <= sm.outages.back().end_s + half) {
            idx.push_back(k);
            col.tau_s.push_back(sm.epochs[k] - start);
          }
        for (const auto& o : sm.outages) {
          std::size_t found = idx.size();
          for (std::size_t j = 0; j < idx.size(); ++j)
            if (std::abs(sm.epochs[idx[j]] - o.end_s) <= half) found = j;
          if (found == idx.size())
            throw Error("sweep: no record epoch at the end of the " + formatNumber(o.end_s - start) + " s outage in " + col.name);
          col.duration_epoch.push_back(found);
        }
        plan->studies.push_back(sp);
        plan->epoch_index.push_back(std::move(idx));
        m.columns.push_back(std::move(col));
      }
  return plan;
}

// ---------------------------------------------------------------------------
// Runs

StudyWork sweepWork(const SweepPlan& p, const Shard& shard, unsigned threads) {
  StudyWork w;
  w.columns = double(p.studies.size());
  for (const auto& sp : p.studies) {
    const StudyWork c = studyWork(*sp, shard, threads);
    w.runs = c.runs;
    w.workers = c.workers;
    w.filters = c.filters;
    w.steps += c.steps;
    if (c.bytes >= w.bytes) {
      w.bytes = c.bytes;
      w.samples = c.samples;
    }
  }
  return w;
}

unsigned sweepThreads(const SweepPlan& p, const Shard& shard, unsigned requested) {
  unsigned t = 0;
  for (const auto& sp : p.studies) {
    const unsigned c = studyThreads(*sp, shard, requested);
    t = t == 0 ? c : std::min(t, c);
  }
  return std::max(t, 1u);
}

SweepRuns runSweep(const std::shared_ptr<const SweepPlan>& plan, const Shard& shard, unsigned threads,
                   const SweepProgressFn& progress) {
  if (!plan) throw Error("sweep: no plan");
  const SweepPlan& p = *plan;
  SweepRuns out;
  out.meta = p.meta;
  out.shard = shard;
  for (std::size_t i = 0; i < p.runs; ++i)
    if (shard.contains(i)) out.run_indices.push_back(i);
  if (out.run_indices.empty())
    throw Error("sweep: shard " + std::to_string(shard.k) + "/" + std::to_string(shard.n) + " holds no run (only " +
                std::to_string(p.runs) + " runs)");
  const std::size_t C = p.studies.size(), M = p.meta.labels.size(), per = out.run_indices.size();
  const std::size_t total = C * per;
  out.values.resize(C);
  for (std::size_t c = 0; c < C; ++c) {
    const auto& idx = p.epoch_index[c];
    const std::size_t T = idx.size();
    std::vector<double>& v = out.values[c];
    v.reserve(per * M * T * 2);
    auto sink = [&](const RunRecord& rec) {
      if (rec.models.size() != M) throw Error("sweep: run record with a different number of models");
      for (const auto& mr : rec.models) {
        for (std::size_t k = 0; k < T; ++k) {
          const double* d = &mr.epochs[idx[k] * detail::kEpochValues];
          v.push_back(std::hypot(d[0], d[1]));
          v.push_back(d[18]);
        }
        out.filter_steps += double(mr.steps);
        out.filter_wall_s += mr.wall_s;
      }
    };
    const std::size_t base = c * per;
    runStudy(p.studies[c], shard, threads,
             [&](std::size_t done, std::size_t) {
               if (progress) progress(base + done, total);
             },
             sink);
    if (v.size() != per * M * T * 2) throw Error("sweep: column " + p.meta.columns[c].name + " is incomplete");
  }
  return out;
}

// ---------------------------------------------------------------------------
// Shards

namespace {

constexpr char kMagic[8] = {'N', 'I', 'S', 'W', 'E', 'E', 'P', '1'};

json gnssToJson(const GnssQuality& q) {
  return {{"name", q.name},
          {"rate_hz", q.gnss.rate_hz},
          {"sigma_pos_h_m", q.gnss.sigma_pos_h_m},
          {"sigma_pos_v_m", q.gnss.sigma_pos_v_m},
          {"sigma_vel_h_mps", q.gnss.sigma_vel_h_mps},
          {"sigma_vel_v_mps", q.gnss.sigma_vel_v_mps}};
}

json metaToJson(const SweepMeta& m) {
  json j;
  detail::headerToJson(m, j);
  j["inputs_hash"] = m.inputs_hash;
  j["outage_start_s"] = m.outage_start_s;
  j["durations_s"] = m.durations_s;
  json g = json::array();
  for (const auto& q : m.gnss) g.push_back(gnssToJson(q));
  j["gnss"] = g;
  j["baro"] = m.baro;
  j["imu_rates_hz"] = m.imu_rates_hz;
  j["alpha"] = m.alpha;
  j["bootstrap"] = m.bootstrap;
  json cols = json::array();
  for (const auto& c : m.columns)
    cols.push_back({{"axes", {c.axes.gnss, c.axes.baro, c.axes.rate}},
                    {"name", c.name},
                    {"settings", c.settings},
                    {"notices", c.notices},
                    {"states", c.states},
                    {"tau_s", c.tau_s},
                    {"duration_epoch", c.duration_epoch}});
  j["columns"] = cols;
  return j;
}

SweepMeta metaFromJson(const json& j, const std::string& where) {
  try {
    SweepMeta m;
    detail::headerFromJson(j, m);
    m.inputs_hash = j.at("inputs_hash");
    m.outage_start_s = j.at("outage_start_s");
    m.durations_s = j.at("durations_s").get<std::vector<double>>();
    for (const auto& q : j.at("gnss")) {
      GnssQuality g;
      g.name = q.at("name");
      g.gnss.rate_hz = q.at("rate_hz");
      g.gnss.sigma_pos_h_m = q.at("sigma_pos_h_m");
      g.gnss.sigma_pos_v_m = q.at("sigma_pos_v_m");
      g.gnss.sigma_vel_h_mps = q.at("sigma_vel_h_mps");
      g.gnss.sigma_vel_v_mps = q.at("sigma_vel_v_mps");
      m.gnss.push_back(g);
    }
    m.baro = j.at("baro").get<std::vector<bool>>();
    m.imu_rates_hz = j.at("imu_rates_hz").get<std::vector<double>>();
    m.alpha = j.at("alpha");
    m.bootstrap = j.at("bootstrap");
    for (const auto& c : j.at("columns")) {
      SweepMeta::Column col;
      col.axes = {c.at("axes").at(0), c.at("axes").at(1), c.at("axes").at(2)};
      col.name = c.at("name");
      col.settings = c.at("settings");
      col.notices = c.at("notices").get<std::vector<std::string>>();
      col.states = c.at("states").get<std::vector<int>>();
      col.tau_s = c.at("tau_s").get<std::vector<double>>();
      col.duration_epoch = c.at("duration_epoch").get<std::vector<std::size_t>>();
      m.columns.push_back(std::move(col));
    }
    detail::checkHeader(m, where);
    const auto bad = [&](const std::string& what) { throw Error(where + ": " + what + " (not as navimpact writes it)"); };
    if (m.durations_s.empty()) bad("no outage durations");
    for (double d : m.durations_s)
      if (!(d >= limits::kDurationS.lo && d <= limits::kDurationS.hi)) bad("an outage duration is outside [0.0001, 604800] s");
    if (!(m.alpha > 0.0 && m.alpha < 0.5)) bad("alpha " + formatNumber(m.alpha) + " is outside (0, 0.5)");
    if (m.bootstrap > 100000) bad("bootstrap " + std::to_string(m.bootstrap) + " is outside [0, 100000]");
    if (m.gnss.empty() || m.baro.empty() || m.imu_rates_hz.empty()) bad("an axis of the sweep is empty");
    if (m.columns.empty()) bad("no columns");
    for (const auto& c : m.columns) {
      if (c.axes.gnss >= m.gnss.size() || c.axes.baro >= m.baro.size() || c.axes.rate >= m.imu_rates_hz.size())
        bad("column '" + printable(c.name) + "' names an axis value the sweep does not have");
      if (c.states.size() != m.labels.size()) bad("column '" + printable(c.name) + "' has states of another candidate list");
      for (std::size_t k = 0; k < c.tau_s.size(); ++k)
        if (!std::isfinite(c.tau_s[k]) || (k > 0 && !(c.tau_s[k] > c.tau_s[k - 1])))
          bad("column '" + printable(c.name) + "': tau_s is not finite and increasing");
      if (c.duration_epoch.size() != m.durations_s.size()) bad("column '" + printable(c.name) + "' has another duration count");
      for (std::size_t e : c.duration_epoch)
        if (e >= c.tau_s.size()) bad("column '" + printable(c.name) + "': a duration's epoch is beyond its tau_s");
    }
    return m;
  } catch (const json::exception& e) {
    throw Error(where + ": not a navimpact sweep shard (" + printable(e.what(), 120) + ")");
  }
}

using detail::getU64;
using detail::putU64;

std::string rangesText(const std::vector<std::size_t>& v) {
  std::string s;
  std::size_t shown = 0;
  for (std::size_t i = 0; i < v.size() && shown < 8; ++shown) {
    std::size_t j = i;
    while (j + 1 < v.size() && v[j + 1] == v[j] + 1) ++j;
    s += (s.empty() ? "" : ", ") + std::to_string(v[i]) + (j > i ? "-" + std::to_string(v[j]) : "");
    i = j + 1;
  }
  return s + (shown == 8 ? ", ..." : "");
}

}  // namespace

void writeSweepShard(const SweepRuns& r, const std::string& build_id, OutputSet& out) {
  json j;
  j["navimpact_sweep_shard"] = 1;
  j["build_id"] = build_id;
  j["meta"] = metaToJson(r.meta);
  j["shard"] = {{"k", r.shard.k}, {"n", r.shard.n}};
  j["run_indices"] = r.run_indices;
  j["byte_order"] = "native little-endian IEEE-754 doubles";
  out.writeText("sweep_shard.json", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  const std::string bin = (out.dir() / "sweep_runs.bin").string();
  std::ofstream f(out.stage("sweep_runs.bin"), std::ios::binary);
  f.write(kMagic, 8);
  putU64(f, r.run_indices.size());
  putU64(f, r.values.size());
  for (const auto& v : r.values) {
    putU64(f, v.size());
    f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(8 * v.size()));
  }
  if (!f) throw Error(bin + ": write failed");
}

SweepRuns mergeSweepShards(const std::vector<std::string>& dirs, const std::string& build_id) {
  if (dirs.empty()) throw Error("sweep-merge: no shard folders given");
  struct In {
    std::string dir;
    Shard shard;
    std::vector<std::uint64_t> idx;
    std::vector<std::vector<double>> values;
  };
  std::vector<In> ins;
  SweepRuns res;
  json first;
  {
    // Folders without a shard (a task that failed or never ran): name them all.
    std::vector<std::string> absent;
    for (const auto& d : dirs)
      if (!std::ifstream(d + "/sweep_shard.json")) absent.push_back(d);
    if (!absent.empty()) {
      std::string list;
      for (std::size_t i = 0; i < absent.size() && i < 10; ++i) list += (i ? ", " : "") + absent[i];
      if (absent.size() > 10) list += ", ...";
      throw Error("sweep-merge: " + std::to_string(absent.size()) + " of " + std::to_string(dirs.size()) +
                  " folders hold no shard (no sweep_shard.json: the task failed or has not run): " + list);
    }
  }
  for (const auto& d : dirs) {
    const std::string sj = d + "/sweep_shard.json";
    const json j = detail::readShardJson(d, "sweep_shard.json", "navimpact_sweep_shard", "sweep --shard");
    In in;
    in.dir = d;
    try {
      const std::string b = j.at("build_id");
      if (b != build_id)
        throw Error(sj + ": shard written by another build of navimpact (" + b + "; this one is " + build_id +
                    "): rerun it with this build");
      in.shard = Shard{j.at("shard").at("k").get<unsigned>(), j.at("shard").at("n").get<unsigned>()};
      if (!(in.shard.n >= 1 && in.shard.k >= 1 && in.shard.k <= in.shard.n))
        throw Error(sj + ": shard " + std::to_string(in.shard.k) + "/" + std::to_string(in.shard.n) +
                    " is not K/N with 1 <= K <= N (not as navimpact writes it)");
      in.idx = j.at("run_indices").get<std::vector<std::uint64_t>>();
      (void)j.at("meta");
    } catch (const json::exception& e) {
      throw Error(sj + ": not a navimpact sweep shard (" + printable(e.what(), 120) + ")");
    }
    const json& meta = j.at("meta");
    if (ins.empty()) {
      first = meta;
      res.meta = metaFromJson(meta, sj);
    } else {
      (void)metaFromJson(meta, sj);  // the same checks for every shard
      for (const char* k : {"config_text", "inputs_hash", "seed", "runs_total", "version", "versions", "columns"})
        if (!meta.contains(k) || meta.at(k) != first.at(k)) {
          const std::string what = std::string(k) == "config_text" || std::string(k) == "inputs_hash"
                                       ? "another config or other input files"
                                   : std::string(k) == "seed" ? "another seed"
                                   : std::string(k) == "runs_total" ? "another run count"
                                   : std::string(k) == "columns" ? "another set of columns"
                                                                 : "another build";
          throw Error(sj + ": shard of " + what + " (" + k + " differs from " + dirs[0] + ")");
        }
    }
    const std::string bin = d + "/sweep_runs.bin";
    std::ifstream f(bin, std::ios::binary);
    if (!f) throw Error(bin + ": cannot open");
    char magic[8];
    if (!f.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) throw Error(bin + ": not a sweep run file");
    const auto nr = getU64(f, bin), nc = getU64(f, bin);
    const std::size_t M = res.meta.labels.size();
    if (nr != in.idx.size() || nc != res.meta.columns.size()) throw Error(bin + ": header does not match sweep_shard.json");
    for (std::size_t c = 0; c < nc; ++c) {
      const auto n = getU64(f, bin);
      if (n != nr * M * res.meta.columns[c].tau_s.size() * 2) throw Error(bin + ": column " + std::to_string(c + 1) +
                                                                          " has the wrong size");
      std::vector<double> v(n);
      if (!f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(8 * n)))
        throw Error(bin + ": truncated");
      // a horizontal error finite and >= 0, a NEES missing (NaN) or finite and >= 0,
      // both at most detail::kMaxRunValue
      const std::size_t perRun = M * res.meta.columns[c].tau_s.size() * 2;
      for (std::size_t q = 0; q < n; ++q) {
        const bool nees = q % 2 == 1;
        const bool ok = (nees && std::isnan(v[q])) || (std::isfinite(v[q]) && v[q] >= 0.0 && v[q] <= detail::kMaxRunValue);
        if (!ok)
          throw Error(bin + ": column " + std::to_string(c + 1) + ", run " + std::to_string(in.idx[q / perRun]) + ": " +
                      (nees ? "a position NEES neither missing nor finite and >= 0"
                            : "a horizontal error not finite and >= 0") +
                      " (not as navimpact writes it)");
      }
      in.values.push_back(std::move(v));
    }
    if (f.peek() != std::char_traits<char>::eof()) throw Error(bin + ": bytes after its last column (not as navimpact writes it)");
    ins.push_back(std::move(in));
  }
  // Every run exactly once; otherwise say which shards (or runs) are missing.
  const std::size_t R = res.meta.runs_total;
  std::vector<int> owner(R, -1);
  std::vector<std::size_t> pos(R, 0);
  for (std::size_t s = 0; s < ins.size(); ++s)
    for (std::size_t q = 0; q < ins[s].idx.size(); ++q) {
      const auto i = ins[s].idx[q];
      if (i >= R) throw Error(ins[s].dir + ": run index " + std::to_string(i) + " out of range");
      if (owner[i] >= 0)
        throw Error("sweep-merge: run " + std::to_string(i) + " is in both " + ins[owner[i]].dir + " and " +
                    ins[s].dir + " (give each shard once)");
      owner[i] = static_cast<int>(s);
      pos[i] = q;
    }
  std::vector<std::size_t> missing;
  for (std::size_t i = 0; i < R; ++i)
    if (owner[i] < 0) missing.push_back(i);
  if (!missing.empty()) {
    const unsigned n = ins.front().shard.n;
    bool same_n = true;
    std::vector<bool> have(n + 1, false);
    for (const auto& in : ins) {
      same_n = same_n && in.shard.n == n;
      if (in.shard.n == n) have[in.shard.k] = true;
    }
    std::string which;
    if (same_n) {
      std::vector<std::size_t> ks;
      for (unsigned k = 1; k <= n; ++k)
        if (!have[k]) ks.push_back(k);
      for (std::size_t q = 0; q < ks.size() && q < 20; ++q)
        which += (which.empty() ? "" : ", ") + std::to_string(ks[q]) + "/" + std::to_string(n);
      if (ks.size() > 20) which += ", ...";
      throw Error("sweep-merge: " + std::to_string(ks.size()) + " of " + std::to_string(n) + " shards missing: " +
                  which + " (rerun those array tasks, e.g. sbatch --array=" + std::to_string(ks.front()) +
                  (ks.size() > 1 ? ",..." : "") + ", then merge again)");
    }
    throw Error("sweep-merge: " + std::to_string(missing.size()) + " of " + std::to_string(R) +
                " runs are in no shard given: runs " + rangesText(missing));
  }
  // Values in run-index order.
  const std::size_t M = res.meta.labels.size();
  res.values.resize(res.meta.columns.size());
  for (std::size_t c = 0; c < res.meta.columns.size(); ++c) {
    const std::size_t block = M * res.meta.columns[c].tau_s.size() * 2;
    auto& v = res.values[c];
    v.resize(R * block);
    for (std::size_t i = 0; i < R; ++i) {
      const auto& src = ins[owner[i]].values[c];
      std::copy(src.begin() + static_cast<std::ptrdiff_t>(pos[i] * block),
                src.begin() + static_cast<std::ptrdiff_t>((pos[i] + 1) * block), v.begin() + static_cast<std::ptrdiff_t>(i * block));
    }
  }
  for (std::size_t i = 0; i < R; ++i) res.run_indices.push_back(i);
  res.shard = Shard{1, 1};
  // Cost figures from the shards' timing files (absent: zero).
  for (const auto& d : dirs) {
    const std::string tp = d + "/timing.json";
    std::ifstream ft(tp);
    if (!ft) continue;
    try {
      json t;
      ft >> t;
      const double steps = t.at("filter_steps").get<double>(), wall = t.at("filter_wall_s").get<double>();
      if (!(steps >= 0.0 && std::isfinite(steps) && wall >= 0.0 && std::isfinite(wall)))
        throw Error(tp + ": filter_steps and filter_wall_s must be finite and >= 0 (not as navimpact writes it)");
      res.filter_steps += steps;
      res.filter_wall_s += wall;
    } catch (const json::exception& e) {
      throw Error(tp + ": not a navimpact shard's timing (" + printable(e.what(), 120) + ")");
    }
  }
  return res;
}

// ---------------------------------------------------------------------------
// Statistics

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One-sided p-value of mean(d) > 0 (paired t-test); 1 when there is no evidence.
double pGreater(double sum, double sum2, std::size_t n) {
  if (n < 2) return 1.0;
  const double N = double(n), mean = sum / N;
  const double var = std::max(0.0, (sum2 - N * mean * mean) / (N - 1.0));
  if (!(var > 0.0)) return mean > 0.0 ? 0.0 : 1.0;
  const double t = mean / std::sqrt(var / N);
  boost::math::students_t dist(N - 1.0);
  return boost::math::cdf(boost::math::complement(dist, t));
}

/// Two-sided p-value of mean(d) != 0.
double pTwoSided(double sum, double sum2, std::size_t n) {
  if (n < 2) return 1.0;
  const double N = double(n), mean = sum / N;
  const double var = std::max(0.0, (sum2 - N * mean * mean) / (N - 1.0));
  if (!(var > 0.0)) return mean != 0.0 ? 0.0 : 1.0;
  const double t = std::abs(mean) / std::sqrt(var / N);
  boost::math::students_t dist(N - 1.0);
  return std::min(1.0, 2.0 * boost::math::cdf(boost::math::complement(dist, t)));
}

/// Access to one column's values.
struct ColumnView {
  const std::vector<double>& v;
  std::size_t M, T;
  double e(std::size_t r, std::size_t m, std::size_t k) const { return v[((r * M + m) * T + k) * 2]; }
  double nees(std::size_t r, std::size_t m, std::size_t k) const { return v[((r * M + m) * T + k) * 2 + 1]; }
};

struct Judge {
  double margin, alpha_each;
  mutable std::map<std::size_t, std::pair<double, double>> bands;  ///< aneesBand(n, 3) by n (a quantile inversion)
  std::pair<double, double> band(std::size_t n) const {
    auto it = bands.find(n);
    if (it == bands.end()) it = bands.emplace(n, aneesBand(n, 3)).first;
    return it->second;
  }
  /// Verdict of model c against r at epoch k over the runs @p rows (indices into the column's runs).
  template <class Rows>
  CandidateVerdict at(const ColumnView& cv, std::size_t c, std::size_t r, std::size_t k, const Rows& rows,
                      std::size_t R, bool tests = true) const {
    CandidateVerdict out;
    const double f = (1.0 + margin) * (1.0 + margin);
    double se2 = 0, sr2 = 0, sd = 0, sd2 = 0, sn = 0, snr = 0, snd = 0, snd2 = 0;
    std::size_t nn = 0, nnr = 0, npair = 0, worse_runs = 0;
    for (std::size_t q = 0; q < R; ++q) {
      const std::size_t i = rows(q);
      const double ec = cv.e(i, c, k), er = cv.e(i, r, k);
      const double d = ec * ec - f * er * er;
      se2 += ec * ec;
      sr2 += er * er;
      sd += d;
      sd2 += d * d;
      worse_runs += d > 0.0 ? 1 : 0;
      const double nc = cv.nees(i, c, k), nr = cv.nees(i, r, k);
      if (std::isfinite(nr)) {
        snr += nr;
        ++nnr;
      }
      if (std::isfinite(nc)) {
        sn += nc;
        ++nn;
        if (std::isfinite(nr)) {
          snd += nc - nr;
          snd2 += (nc - nr) * (nc - nr);
          ++npair;
        }
      }
    }
    out.rms_h_m = std::sqrt(se2 / double(R));
    const double rms_r = std::sqrt(sr2 / double(R));
    out.ratio = rms_r > 0.0 ? out.rms_h_m / rms_r : kNaN;
    out.p_worse = c == r || !tests ? 1.0 : pGreater(sd, sd2, R);
    out.runs_worse = c == r ? 0 : worse_runs;
    out.nees_runs = nn;
    out.anees = nn ? sn / double(nn) : kNaN;
    out.p_nees_vs_ref = c == r || !tests ? 1.0 : pTwoSided(snd, snd2, npair);
    out.worse = out.p_worse < alpha_each;
    if (nn > 0) {
      const auto band = this->band(nn);
      out.band_lo = band.first / (1.0 + margin);
      out.band_hi = band.second * (1.0 + margin);
      out.consistent = out.anees >= out.band_lo && out.anees <= out.band_hi;
      // The reference itself outside the band: "as consistent as the
      // reference" (ANEES within a factor 1 + margin of its ANEES) is the
      // best any model of the set can do.
      if (nnr > 0) {
        const double ar = snr / double(nnr);
        const auto rb = this->band(nnr);
        out.reference_in_band = ar >= rb.first / (1.0 + margin) && ar <= rb.second * (1.0 + margin);
        if (!out.consistent && !out.reference_in_band && out.anees >= ar / (1.0 + margin) &&
            out.anees <= ar * (1.0 + margin)) {
          out.consistent = true;
          out.consistent_as_reference = true;
        }
      }
    }
    out.sufficient = !out.worse && out.consistent;
    return out;
  }
};

std::size_t labelIndex(const SweepMeta& m, const std::string& l) {
  const auto it = std::find(m.labels.begin(), m.labels.end(), l);
  if (it == m.labels.end()) throw Error("sweep: unknown model label '" + l + "'");
  return static_cast<std::size_t>(it - m.labels.begin());
}

}  // namespace

SweepResults judgeSweep(const SweepRuns& runs) {
  SweepResults res;
  res.meta = runs.meta;
  const SweepMeta& meta = runs.meta;
  const std::size_t R = runs.run_indices.size(), M = meta.labels.size();
  if (R < 2) throw Error("sweep: at least 2 runs are needed for the paired tests");
  res.runs = R;
  res.filter_steps = runs.filter_steps;
  res.us_per_filter_step = runs.filter_steps > 0 ? 1e6 * runs.filter_wall_s / runs.filter_steps : 0.0;
  const auto all = [](std::size_t q) { return q; };
  for (std::size_t c = 0; c < meta.columns.size(); ++c) {
    const auto& col = meta.columns[c];
    const ColumnView cv{runs.values[c], M, col.tau_s.size()};
    SweepColumnResult cr;
    for (std::size_t s = 0; s < meta.sets.size(); ++s) {
      const ModelSetSpec& set = meta.sets[s];
      SweepSetResult sr;
      sr.set = set;
      const std::size_t ref = labelIndex(meta, set.reference);
      const std::size_t K = std::max<std::size_t>(1, set.models.size() - 1);
      const Judge judge{meta.margin, meta.alpha / double(K), {}};
      for (std::size_t j = 0; j < meta.durations_s.size(); ++j) {
        SweepCell cell;
        cell.duration_s = meta.durations_s[j];
        const std::size_t k = col.duration_epoch[j];
        int best = std::numeric_limits<int>::max();
        for (const auto& l : set.models) {
          const std::size_t m = labelIndex(meta, l);
          CandidateVerdict v = judge.at(cv, m, ref, k, all, R);
          v.label = l;
          v.states = col.states[m];
          if (m == ref) cell.reference_consistent = v.reference_in_band;
          if (v.sufficient && v.states < best) {
            best = v.states;
            cell.recommended = l;
          }
          cell.models.push_back(std::move(v));
        }
        sr.cells.push_back(std::move(cell));
      }
      // The white-noise threshold: scan the outage epochs.
      WnThreshold& th = sr.threshold;
      th.white_noise = set.white_noise;
      th.reference = set.reference;
      const std::size_t wn = labelIndex(meta, set.white_noise);
      const std::size_t T = col.tau_s.size();
      th.scanned_to_s = T ? col.tau_s.back() : 0.0;
      if (wn != ref && T > 0) {
        th.defined = true;
        // For good: the epoch after the last one where the predicate fails
        // (scan backwards); -1 when it fails at the last epoch.
        const double lim = 1.0 + meta.margin;
        auto departs = [&](const CandidateVerdict& v) { return !(v.ratio <= lim) || !v.consistent; };
        auto forGood = [&](const auto& rows, auto&& bad, bool tests) {
          for (std::size_t q = T; q-- > 0;)
            if (!bad(judge.at(cv, wn, ref, q, rows, R, tests))) return q + 1 < T ? col.tau_s[q + 1] : -1.0;
          return col.tau_s.front();
        };
        th.departs_s = forGood(all, departs, false);
        th.significant_s = forGood(all, [](const CandidateVerdict& v) { return !v.sufficient; }, true);
        for (std::size_t q = 0; q < T; ++q)
          if (departs(judge.at(cv, wn, ref, q, all, R, false))) {
            th.first_departure_s = col.tau_s[q];
            break;
          }
        if (meta.bootstrap > 0) {
          // Seeded per (column, set); resamples drawn in order. Indices by the
          // top 53 bits scaled to [0, R): portable across standard libraries.
          std::mt19937_64 rng(stochastic::deriveSeed(stochastic::deriveSeed(meta.seed, 0x5EE9B007ull),
                                                     c * 1000 + s));
          std::vector<std::size_t> pick(R);
          std::vector<double> stat;
          for (std::size_t b = 0; b < meta.bootstrap; ++b) {
            for (auto& x : pick)
              x = std::min<std::size_t>(R - 1, static_cast<std::size_t>(double(rng() >> 11) * 0x1.0p-53 * double(R)));
            const double g = forGood([&](std::size_t q) { return pick[q]; }, departs, false);
            if (g < 0) ++th.censored;
            stat.push_back(g < 0 ? std::numeric_limits<double>::infinity() : g);
          }
          std::sort(stat.begin(), stat.end());
          const std::size_t B = stat.size();
          const std::size_t ilo = static_cast<std::size_t>(std::floor(0.025 * double(B)));
          const std::size_t ihi = std::min(B - 1, static_cast<std::size_t>(std::ceil(0.975 * double(B))) - 1);
          th.lo_s = std::isfinite(stat[ilo]) ? stat[ilo] : -1.0;
          th.hi_s = std::isfinite(stat[ihi]) ? stat[ihi] : -1.0;
        }
      }
      cr.sets.push_back(std::move(sr));
    }
    res.columns.push_back(std::move(cr));
  }
  return res;
}

}  // namespace navimpact::analysis
