// navimpact sweep: the model-sufficiency map of an application.
//   navimpact sweep --config SWEEP.yaml --out DIR [--runs N] [--seed S] [--threads T] [--shard K/N]
//   navimpact sweep-merge DIR1 DIR2 ... --out DIR
#include <chrono>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/sweep_report.hpp"

namespace {

namespace an = navimpact::analysis;

struct SweepOpts {
  std::string config, out, shard;
  long long runs = -1, seed = -1;
  int threads = -1;
  bool overwrite = false;
};

struct MergeOpts {
  std::vector<std::string> dirs;
  std::string out;
  bool overwrite = false;
};

std::string timingJson(double wall_s, const an::SweepResults& r) {
  nlohmann::json t;
  t["wall_s"] = wall_s;
  t["filter_steps"] = r.filter_steps;
  t["us_per_filter_step"] = r.us_per_filter_step;
  return t.dump(1) + "\n";
}

void printSummary(const an::SweepResults& r, const std::string& dir) {
  std::cout << "sweep: " << r.meta.columns.size() << " column(s) x " << r.meta.durations_s.size()
            << " outage durations x " << r.meta.labels.size() << " models, " << r.runs << " runs per cell\n";
  for (std::size_t c = 0; c < r.columns.size(); ++c)
    for (const auto& s : r.columns[c].sets) {
      const auto& t = s.threshold;
      if (!t.defined) continue;
      std::cout << "  " << r.meta.columns[c].name << ", " << s.set.title << ": white noise departs from the reference from ";
      if (t.departs_s < 0) std::cout << "> " << t.scanned_to_s << " s";
      else std::cout << t.departs_s << " s";
      if (t.lo_s >= 0 || t.hi_s >= 0)
        std::cout << " (95 % " << t.lo_s << " to " << (t.hi_s < 0 ? std::string("beyond") : [&] {
          std::ostringstream x;
          x << t.hi_s;
          return x.str();
        }()) << " s)";
      std::cout << "\n";
    }
  std::cout << "report: " << dir << "/report.md\n";
}

int runSweepCmd(const SweepOpts& o) {
  const auto t0 = std::chrono::steady_clock::now();
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));  // refused before any work
  an::SweepConfig cfg = an::loadSweepConfig(o.config);
  if (o.runs >= 0) {
    if (o.runs < 2) throw navimpact::Error("--runs must be >= 2 for a sweep, got " + std::to_string(o.runs));
    cfg.study.runs = static_cast<std::size_t>(o.runs);
  }
  if (o.seed >= 0) cfg.study.seed = static_cast<std::uint64_t>(o.seed);
  if (o.threads >= 0) cfg.study.threads = static_cast<unsigned>(o.threads);
  const an::Shard shard = o.shard.empty() ? an::Shard{} : an::parseShard(o.shard);
  unsigned threads = cfg.study.threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());

  const auto plan = an::prepareSweep(cfg, NAVIMPACT_VERSION);  // every input error is thrown here
  std::size_t per = 0;
  for (std::size_t i = 0; i < cfg.study.runs; ++i) per += shard.contains(i) ? 1 : 0;
  navimpact::cli::Progress bar("sweep", per * an::sweepMeta(*plan).columns.size());
  const an::SweepRuns runs =
      an::runSweep(plan, shard, threads, [&bar](std::size_t done, std::size_t) { bar.update(done); });
  bar.finish();

  if (shard.whole()) {
    const an::SweepResults res = an::judgeSweep(runs);
    navimpact::report::writeSweepOutputs(res, out);
    out.writeText("timing.json",
                  timingJson(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), res));
    out.commit();
    printSummary(res, o.out);
  } else {
    an::writeSweepShard(runs, navimpact::cli::buildId(), out);
    out.commit();
    std::cout << "sweep shard " << shard.k << "/" << shard.n << ": " << runs.run_indices.size() << " of "
              << cfg.study.runs << " runs x " << runs.meta.columns.size() << " column(s) written to " << o.out
              << "/ (merge with: navimpact sweep-merge DIR... --out DIR)\n";
  }
  return 0;
}

int runMergeCmd(const MergeOpts& o) {
  const auto t0 = std::chrono::steady_clock::now();
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  const an::SweepRuns runs = an::mergeSweepShards(o.dirs, navimpact::cli::buildId());
  const an::SweepResults res = an::judgeSweep(runs);
  navimpact::report::writeSweepOutputs(res, out);
  out.writeText("timing.json",
                timingJson(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), res));
  out.commit();
  printSummary(res, o.out);
  return 0;
}

navimpact::cli::Registrar regSweep(
    {"sweep", "Model-sufficiency map: paired studies over outage duration, GNSS quality, barometer, IMU rate",
     [](CLI::App& app) {
       auto o = std::make_shared<SweepOpts>();
       app.add_option("--config", o->config, "sweep YAML (e.g. config/sweep/navchip_uav_sweep.yaml)")->required();
       app.add_option("--out", o->out, "output folder")->required();
       app.add_option("--runs", o->runs, "Monte Carlo runs per cell (overrides the config)");
       app.add_option("--seed", o->seed, "sweep seed (overrides the config)");
       app.add_option("--threads", o->threads, "worker threads, 0 = all cores (overrides the config)");
       app.add_option("--shard", o->shard,
                      "K/N: run only the run indices i with i % N == K-1 (in every column) and write partial "
                      "results for sweep-merge");
       navimpact::cli::addOverwriteFlag(app, o->overwrite);
       return [o]() -> int { return runSweepCmd(*o); };
     }});

navimpact::cli::Registrar regMerge({"sweep-merge",
                                    "Merge sweep shards (navimpact sweep --shard K/N) into the map of the whole sweep",
                                    [](CLI::App& app) {
                                      auto o = std::make_shared<MergeOpts>();
                                      app.add_option("dirs", o->dirs, "shard folders")->required();
                                      app.add_option("--out", o->out, "output folder")->required();
                                      navimpact::cli::addOverwriteFlag(app, o->overwrite);
                                      return [o]() -> int { return runMergeCmd(*o); };
                                    }});

}  // namespace
