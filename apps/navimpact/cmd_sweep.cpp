// navimpact sweep: the model-sufficiency map of an application.
//   navimpact sweep --config SWEEP.yaml --out DIR [--runs N] [--seed S] [--threads T] [--shard K/N]
//   navimpact sweep --config SWEEP.yaml --emit-slurm DIR --shards N [--partition P --time T --cpus-per-task C
//                   --mem M --module MOD... --setup CMD --work SCRATCH --result DIR --navimpact BIN]
//   navimpact sweep-merge DIR1 DIR2 ... --out DIR
#include <cctype>
#include <chrono>
#include <filesystem>
#include <optional>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/sweep_report.hpp"

namespace {

namespace an = navimpact::analysis;

/// Options of --emit-slurm: where things go on the cluster and what to ask for.
struct SlurmOpts {
  std::string dir;              ///< folder for the scripts (written all-or-nothing)
  long long shards = 0;         ///< array size N
  std::string partition, account, qos, time = "01:00:00", merge_time = "00:30:00", mem;
  int cpus = 1;
  std::vector<std::string> modules;
  std::string setup;            ///< shell lines run before navimpact (e.g. source a venv, export ...)
  std::string work;             ///< shard folders (scratch); default DIR/shards
  std::string result;           ///< merged result; default DIR/result
  std::string navimpact;        ///< the binary on the cluster; default this one
};

struct SweepOpts {
  std::string config, out, shard;
  SlurmOpts slurm;
  std::optional<long long> runs;  // overrides of the configuration when given
  std::optional<std::uint64_t> seed;
  std::optional<int> threads;
  bool overwrite = false;
  bool allow_large = false;
};

void printSummary(const an::SweepResults& r, const std::string& dir) {
  std::cout << "sweep: " << r.meta.columns.size() << " column(s) x " << r.meta.durations_s.size()
            << " outage durations x " << r.meta.labels.size() << " models, " << r.runs << " runs per cell\n";
  for (std::size_t c = 0; c < r.columns.size(); ++c)
    for (const auto& s : r.columns[c].sets) {
      const auto& t = s.threshold;
      if (!t.defined) continue;
      std::cout << "  " << r.meta.columns[c].name << ", " << s.set.title
                << ": white noise departs from the reference from " << navimpact::report::thresholdText(t);
      if (t.lo_s >= 0 || t.hi_s >= 0) std::cout << " (95 % " << navimpact::report::intervalText(t) << ")";
      std::cout << "\n";
    }
  std::cout << "report: " << dir << "/report.md\n";
}

int emitSlurm(const SweepOpts& o, const an::SweepConfig& cfg, const an::SweepMeta& meta);

int runSweepCmd(const SweepOpts& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool emit = !o.slurm.dir.empty();
  if (emit == !o.out.empty())
    throw navimpact::Error(emit ? "give either --out (run here) or --emit-slurm (write Slurm scripts), not both"
                                : "--out is required (or --emit-slurm DIR to write Slurm scripts)");
  if (emit && !o.shard.empty()) throw navimpact::Error("--shard and --emit-slurm exclude each other (use --shards N)");
  std::optional<navimpact::OutputSet> out;
  if (!emit) out.emplace(o.out, navimpact::cli::overwriteMode(o.overwrite));  // refused before any work
  an::SweepConfig cfg = an::loadSweepConfig(o.config);
  if (o.runs) cfg.study.runs = static_cast<std::size_t>(*o.runs);  // (range checked by the flag)
  if (o.seed) cfg.study.seed = *o.seed;
  if (o.threads) cfg.study.threads = static_cast<unsigned>(*o.threads);
  const an::Shard shard = o.shard.empty() ? an::Shard{} : an::parseShard(o.shard);

  const auto plan = an::prepareSweep(cfg, NAVIMPACT_VERSION);  // every input error is thrown here
  if (emit) return emitSlurm(o, cfg, an::sweepMeta(*plan));
  cfg.study.threads = an::sweepThreads(*plan, shard, cfg.study.threads);  // all cores: as many as memory holds
  an::checkStudyBudget("sweep", an::sweepWork(*plan, shard, cfg.study.threads), o.allow_large);
  std::size_t per = 0;
  for (std::size_t i = 0; i < cfg.study.runs; ++i) per += shard.contains(i) ? 1 : 0;
  navimpact::cli::Progress bar("sweep", per * an::sweepMeta(*plan).columns.size());
  const an::SweepRuns runs =
      an::runSweep(plan, shard, cfg.study.threads, [&bar](std::size_t done, std::size_t) { bar.update(done); });
  bar.finish();

  if (shard.whole()) {
    const an::SweepResults res = an::judgeSweep(runs);
    navimpact::report::writeSweepOutputs(res, *out);
    navimpact::report::writeSweepTiming(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                                        res, *out);
    out->commit();
    printSummary(res, o.out);
  } else {
    an::writeSweepShard(runs, navimpact::cli::buildId(), *out);
    navimpact::report::writeSweepShardTiming(runs, *out);
    out->commit();
    std::cout << "sweep shard " << shard.k << "/" << shard.n << ": " << runs.run_indices.size() << " of "
              << cfg.study.runs << " runs x " << runs.meta.columns.size() << " column(s) written to " << o.out
              << "/ (merge with: navimpact sweep-merge DIR... --out DIR)\n";
  }
  return 0;
}

// ---------------------------------------------------------------- Slurm ---

/// A value written into a double-quoted shell string: $VARS expand at job
/// time (e.g. $SCRATCH); quotes, backquotes, backslashes and newlines refused.
std::string shellValue(const std::string& v, const std::string& what) {
  for (char c : v)
    if (c == '"' || c == '`' || c == '\\' || c == '\n' || c == '\r')
      throw navimpact::Error(what + " '" + v + "': quotes, backquotes, backslashes and newlines are not accepted");
  return v;
}

/// An #SBATCH value: no spaces or shell characters.
std::string sbatchValue(const std::string& v, const std::string& what) {
  for (char c : v)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::string("-_:.,=+/@%").find(c) != std::string::npos))
      throw navimpact::Error(what + " '" + v + "': letters, digits and -_:.,=+/@% only");
  return v;
}

std::string absolute(const std::string& p) {
  if (p.empty() || p[0] == '/' || p[0] == '$') return p;
  return std::filesystem::absolute(p).lexically_normal().string();
}

int emitSlurm(const SweepOpts& o, const an::SweepConfig& cfg, const an::SweepMeta& meta) {
  const SlurmOpts& s = o.slurm;
  if (s.shards < 1 || s.shards > 100000)
    throw navimpact::Error("--shards must be in 1..100000 (the Slurm array size), got " + std::to_string(s.shards));
  if (static_cast<std::size_t>(s.shards) > cfg.study.runs)
    throw navimpact::Error("--shards " + std::to_string(s.shards) + " is more than the " +
                           std::to_string(cfg.study.runs) + " runs: some shards would hold no run");
  if (s.cpus < 1 || s.cpus > 1024) throw navimpact::Error("--cpus-per-task must be in 1..1024");
  const std::string N = std::to_string(s.shards);
  const std::string dir = absolute(s.dir);
  const std::string work = shellValue(absolute(s.work.empty() ? dir + "/shards" : s.work), "--work");
  const std::string result = shellValue(absolute(s.result.empty() ? dir + "/result" : s.result), "--result");
  const std::string logs = dir + "/logs";
  const std::string ni = shellValue(absolute(s.navimpact.empty() ? navimpact::cli::executablePath() : s.navimpact),
                                    "--navimpact");
  const std::string config = shellValue(absolute(o.config), "--config");
  shellValue(dir, "--emit-slurm");
  std::string overrides;
  if (o.runs) overrides += " --runs " + std::to_string(*o.runs);
  if (o.seed) overrides += " --seed " + std::to_string(*o.seed);

  std::ostringstream common;
  if (!s.partition.empty()) common << "#SBATCH --partition=" << sbatchValue(s.partition, "--partition") << "\n";
  if (!s.account.empty()) common << "#SBATCH --account=" << sbatchValue(s.account, "--account") << "\n";
  if (!s.qos.empty()) common << "#SBATCH --qos=" << sbatchValue(s.qos, "--qos") << "\n";
  std::ostringstream env;
  env << "set -euo pipefail\n";
  for (const auto& m : s.modules) env << "module load " << sbatchValue(m, "--module") << "\n";
  if (!s.setup.empty()) env << s.setup << "\n";

  const std::size_t per_task = (cfg.study.runs + static_cast<std::size_t>(s.shards) - 1) / static_cast<std::size_t>(s.shards);

  std::ostringstream arr;
  arr << "#!/bin/bash\n"
      << "# navimpact sweep as a Slurm job array: task K runs shard K/" << N << " of\n# " << config << "\n"
      << "# into " << work << "/shard_K. A task whose shard is complete exits at once, so\n"
      << "# resubmitting (all tasks, or some: sbatch --array=3,7 sweep_array.sbatch)\n# redoes only what is missing.\n"
      << "#SBATCH --job-name=navimpact-sweep\n"
      << "#SBATCH --array=1-" << N << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --cpus-per-task=" << s.cpus << "\n"
      << "#SBATCH --time=" << sbatchValue(s.time, "--time") << "\n";
  if (!s.mem.empty()) arr << "#SBATCH --mem=" << sbatchValue(s.mem, "--mem") << "\n";
  arr << common.str() << "#SBATCH --output=" << logs << "/shard_%A_%a.out\n"
      << env.str() << "K=${SLURM_ARRAY_TASK_ID}\n"
      << "SHARD=\"" << work << "/shard_${K}\"\n"
      << "if [ -f \"${SHARD}/sweep_shard.json\" ]; then echo \"shard ${K}/" << N
      << " already complete: ${SHARD}\"; exit 0; fi\n"
      << "mkdir -p \"" << work << "\"\n"
      << "exec \"" << ni << "\" sweep --config \"" << config << "\"" << overrides << " --shard \"${K}/" << N
      << "\" --threads \"${SLURM_CPUS_PER_TASK:-1}\" --out \"${SHARD}\" --overwrite --allow-large\n";

  std::ostringstream mrg;
  mrg << "#!/bin/bash\n"
      << "# Merge the " << N << " shards into the map (runs after the array succeeded;\n"
      << "# names the missing shards otherwise).\n"
      << "#SBATCH --job-name=navimpact-sweep-merge\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --cpus-per-task=1\n"
      << "#SBATCH --time=" << sbatchValue(s.merge_time, "--merge-time") << "\n";
  if (!s.mem.empty()) mrg << "#SBATCH --mem=" << s.mem << "\n";
  mrg << common.str() << "#SBATCH --output=" << logs << "/merge_%j.out\n"
      << env.str() << "SHARDS=()\n"
      << "for K in $(seq 1 " << N << "); do SHARDS+=(\"" << work << "/shard_${K}\"); done\n"
      << "exec \"" << ni << "\" sweep-merge \"${SHARDS[@]}\" --out \"" << result << "\" --overwrite\n";

  std::ostringstream sub;
  sub << "#!/bin/bash\n"
      << "# Submit the sweep: the job array (all " << N << " tasks, or the array indices\n"
      << "# given, e.g. 'bash submit.sh 3,7' to rerun failed tasks) and the merge job,\n"
      << "# which starts when the array has succeeded (--dependency=afterok).\n"
      << "set -euo pipefail\n"
      << "cd \"$(dirname \"$0\")\"\n"
      << "mkdir -p \"" << logs << "\" \"" << work << "\"\n"
      << "ARRAY=${1:-1-" << N << "}\n"
      << "A=$(sbatch --parsable --array=\"${ARRAY}\" sweep_array.sbatch)\n"
      << "A=${A%%;*}\n"
      << "M=$(sbatch --parsable --dependency=afterok:\"${A}\" --kill-on-invalid-dep=yes sweep_merge.sbatch)\n"
      << "M=${M%%;*}\n"
      << "echo \"${A} ${M}\" >> jobs.txt\n"
      << "echo \"submitted array job ${A} (tasks ${ARRAY} of " << N << ") and merge job ${M} (afterok:${A})\"\n"
      << "echo \"result: " << result << "/report.md; logs: " << logs << "\"\n"
      << "echo \"a failed task K: look at " << logs << "/shard_${A}_K.out, then: bash $0 K\"\n";

  navimpact::OutputSet out(s.dir, navimpact::cli::overwriteMode(o.overwrite));
  out.writeText("sweep_array.sbatch", arr.str());
  out.writeText("sweep_merge.sbatch", mrg.str());
  out.writeText("submit.sh", sub.str());
  for (const char* f : {"sweep_array.sbatch", "sweep_merge.sbatch", "submit.sh"})
    std::filesystem::permissions(out.stagingDir() / f, std::filesystem::perms::owner_exec | std::filesystem::perms::group_exec,
                                 std::filesystem::perm_options::add);
  out.commit();
  std::cout << "slurm: " << N << " array tasks of about " << per_task << " runs x " << meta.columns.size()
            << " column(s) x " << meta.labels.size() << " models, then the merge\n"
            << "  submit:  bash " << s.dir << "/submit.sh\n"
            << "  rerun:   bash " << s.dir << "/submit.sh K[,K...]   (failed array indices only)\n"
            << "  result:  " << result << "/report.md\n";
  return 0;
}

int runMergeCmd(const navimpact::cli::MergeOpts& o) {
  const auto t0 = std::chrono::steady_clock::now();
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  const an::SweepRuns runs = an::mergeSweepShards(o.dirs, navimpact::cli::buildId());
  const an::SweepResults res = an::judgeSweep(runs);
  navimpact::report::writeSweepOutputs(res, out);
  navimpact::report::writeSweepTiming(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), res,
                                      out);
  out.commit();
  printSummary(res, o.out);
  return 0;
}

navimpact::cli::Registrar regSweep(
    {"sweep", "Model-sufficiency map: paired studies over outage duration, GNSS quality, barometer, IMU rate",
     [](CLI::App& app) {
       auto o = std::make_shared<SweepOpts>();
       app.add_option("--config", o->config, "sweep YAML (e.g. config/sweep/navchip_uav_sweep.yaml)")->required();
       app.add_option("--out", o->out, "output folder (or --emit-slurm)");
       app.add_option("--runs", o->runs, "Monte Carlo runs per cell, >= 2 for its paired tests (overrides the config)")
           ->check(CLI::Range(2LL, navimpact::limits::kMaxMonteCarloRuns));
       app.add_option("--seed", o->seed, "sweep seed (overrides the config)")->check(navimpact::cli::seedValue());
       app.add_option("--threads", o->threads, "worker threads, 0 = all cores (overrides the config)")
           ->check(CLI::Range(0, 1024));
       app.add_option("--shard", o->shard,
                      "K/N: run only the run indices i with i % N == K-1 (in every column) and write partial "
                      "results for sweep-merge")
           ->check(navimpact::cli::parsedBy([](const std::string& s) { an::parseShard(s); }, "K/N"));
       navimpact::cli::addOverwriteFlag(app, o->overwrite);
       app.add_flag("--allow-large", o->allow_large,
                    "run above the work and memory budgets (IMU steps, workers' memory; README \"Ranges and budgets\"); "
                    "the scripts of --emit-slurm pass it, their shards sized by --shards");
       SlurmOpts& sl = o->slurm;
       app.add_option("--emit-slurm", sl.dir,
                      "write Slurm scripts to DIR instead of running: a job array of --shards tasks (one shard "
                      "each), a dependent merge job and submit.sh");
       app.add_option("--shards", sl.shards, "Slurm: array size N (shards K/N, K = 1..N)");
       app.add_option("--partition", sl.partition, "Slurm: partition (default: the cluster's)");
       app.add_option("--account", sl.account, "Slurm: account to charge");
       app.add_option("--qos", sl.qos, "Slurm: quality of service");
       app.add_option("--time", sl.time, "Slurm: time limit per array task (default 01:00:00)");
       app.add_option("--merge-time", sl.merge_time, "Slurm: time limit of the merge job (default 00:30:00)");
       app.add_option("--cpus-per-task", sl.cpus, "Slurm: CPUs per task = navimpact threads (default 1)");
       app.add_option("--mem", sl.mem, "Slurm: memory per task, e.g. 2G (default: the cluster's)");
       app.add_option("--module", sl.modules, "Slurm: environment module to load (repeatable)");
       app.add_option("--setup", sl.setup, "Slurm: shell lines run before navimpact in every job");
       app.add_option("--work", sl.work,
                      "Slurm: folder of the shard outputs, e.g. '$SCRATCH/sweep' (default DIR/shards)");
       app.add_option("--result", sl.result, "Slurm: folder of the merged map (default DIR/result)");
       app.add_option("--navimpact", sl.navimpact, "Slurm: navimpact binary on the nodes (default: this one)");
       return [o]() -> int { return runSweepCmd(*o); };
     }});

navimpact::cli::Registrar regMerge(navimpact::cli::mergeCommand(
    "sweep-merge", "Merge sweep shards (navimpact sweep --shard K/N) into the map of the whole sweep", runMergeCmd));

}  // namespace
