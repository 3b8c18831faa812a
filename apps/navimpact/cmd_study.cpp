// navimpact study: Monte Carlo comparison of IMU error models on an emulated flight.
//   navimpact study --config config/paper/study_navchip_uav.yaml --out DIR [--runs N] [--seed S]
//                   [--threads T] [--shard K/N]
//   navimpact study-merge DIR1 DIR2 ... --out DIR
#include <iostream>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "navimpact/analysis/study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/study_report.hpp"

namespace {

namespace an = navimpact::analysis;

struct StudyOpts {
  std::string config, out, shard;
  // overrides of the configuration when given (a sentinel such as -1 let
  // "--seed -1" silently mean "the configuration's seed")
  std::optional<long long> runs;
  std::optional<std::uint64_t> seed;
  std::optional<int> threads;
  bool overwrite = false;
  bool allow_large = false;
};

void printSummary(const an::StudyResults& r, const std::string& dir) {
  std::cout << "study: " << r.acc.runs << " runs x " << r.meta.labels.size() << " models on "
            << r.meta.trajectory << "\n";
  std::cout << "report: " << dir << "/report.md\n";
}

int runStudyCmd(const StudyOpts& o) {
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  an::StudyConfig cfg = an::loadStudyConfig(o.config);
  if (o.runs) cfg.runs = static_cast<std::size_t>(*o.runs);  // (range checked by the flag)
  if (o.seed) cfg.seed = *o.seed;
  if (o.threads) cfg.threads = static_cast<unsigned>(*o.threads);
  const an::Shard shard = o.shard.empty() ? an::Shard{} : an::parseShard(o.shard);

  const auto plan = an::prepareStudy(cfg, NAVIMPACT_VERSION);  // every input error is thrown here
  cfg.threads = an::studyThreads(*plan, shard, cfg.threads);  // all cores: as many as the memory budget holds
  an::checkStudyBudget("study", an::studyWork(*plan, shard, cfg.threads), o.allow_large);
  std::size_t todo = 0;
  for (std::size_t i = 0; i < cfg.runs; ++i) todo += shard.contains(i) ? 1 : 0;
  navimpact::cli::Progress bar("study", todo);
  const an::StudyResults res =
      an::runStudy(plan, shard, cfg.threads, [&bar](std::size_t done, std::size_t) { bar.update(done); });
  bar.finish();

  if (shard.whole()) {
    navimpact::report::writeStudyOutputs(res, out);
    out.commit();
    printSummary(res, o.out);
  } else {
    an::writeShard(res, navimpact::cli::buildId(), out);
    out.commit();
    std::cout << "study shard " << shard.k << "/" << shard.n << ": " << res.acc.runs << " of " << cfg.runs
              << " runs written to " << o.out << "/ (merge with: navimpact study-merge DIR... --out DIR)\n";
  }
  return 0;
}

int runMergeCmd(const navimpact::cli::MergeOpts& o) {
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  const an::StudyResults res = an::mergeShards(o.dirs, navimpact::cli::buildId());
  navimpact::report::writeStudyOutputs(res, out);
  out.commit();
  printSummary(res, o.out);
  return 0;
}

navimpact::cli::Registrar regStudy({"study",
                                    "Monte Carlo emulation study: compare IMU error models in a GNSS/INS filter",
                                    [](CLI::App& app) {
                                      auto o = std::make_shared<StudyOpts>();
                                      app.add_option("--config", o->config, "study YAML (e.g. config/paper/study_navchip_uav.yaml)")
                                          ->required();
                                      app.add_option("--out", o->out, "output folder")->required();
                                      navimpact::cli::addOverwriteFlag(app, o->overwrite);
                                      app.add_flag("--allow-large", o->allow_large,
                                                   "run above the work and memory budgets (IMU steps, workers' memory; "
                                                   "README \"Ranges and budgets\")");
                                      app.add_option("--runs", o->runs, "Monte Carlo runs (overrides the config)")
                                          ->check(CLI::Range(1LL, navimpact::limits::kMaxMonteCarloRuns));
                                      app.add_option("--seed", o->seed, "study seed (overrides the config)")->check(navimpact::cli::seedValue());
                                      app.add_option("--threads", o->threads,
                                                     "worker threads, 0 = all cores (overrides the config)")
                                          ->check(CLI::Range(0, 1024));
                                      app.add_option("--shard", o->shard,
                                                     "K/N: run only the run indices i with i % N == K-1 and write "
                                                     "partial results for study-merge")
                                          ->check(navimpact::cli::parsedBy(
                                              [](const std::string& s) { an::parseShard(s); }, "K/N"));
                                      return [o]() -> int { return runStudyCmd(*o); };
                                    }});

navimpact::cli::Registrar regMerge(navimpact::cli::mergeCommand(
    "study-merge", "Merge study shards (navimpact study --shard K/N) into one study", runMergeCmd));

}  // namespace
