/**
 * @file sweep.hpp
 * @brief The model-sufficiency map of an application (`navimpact sweep`,
 *        `navimpact sweep-merge`): for every outage duration, GNSS quality,
 *        barometer setting and IMU rate, the simplest candidate IMU model whose
 *        navigation error and consistency are indistinguishable from the
 *        reference model's, and per sensor the outage duration from which white
 *        noise alone stops being enough (the paper's "at least 10 s"), with its
 *        bootstrap interval.
 *
 * Design:
 *  - A sweep config is a study config (trajectory, truth, candidates, sets,
 *    gnss, baro, filter, monte_carlo, record, report) plus a `sweep:` block
 *    with the axes (loadSweepConfig). Its `outages` key is refused: outages
 *    come from the axes.
 *  - A column is one (GNSS quality, barometer, IMU rate) combination: one
 *    paired Monte Carlo study (analysis/study.hpp, same seed in every column,
 *    so every column sees the same IMU error, GNSS and initial-error streams:
 *    common random numbers across the map). The GNSS outage starts at
 *    `sweep.outage.start_s` and lasts the longest duration; it is given to
 *    the study as contiguous windows ending at every duration, so the error
 *    at the end of each window is recorded. An outage of d seconds is the
 *    first d seconds of the longest one: up to start + d the filter receives
 *    exactly the same inputs and records the same epochs, so the values are
 *    bit-identical to a study with that single outage (tested). One run per
 *    column thus serves every duration.
 *  - Per run, model and epoch inside the outage (at record.outage_rate_hz and
 *    at every duration's end) two values are kept: the horizontal position
 *    error and the position NEES. Shards keep them per run; statistics are
 *    computed from all runs in run-index order, so any partition of shards
 *    merges to the unsharded result bit for bit.
 *
 * Judgement of candidate c against the set's reference r at one epoch over R
 * runs, with margin m (report.margin) and level alpha (sweep.alpha):
 *  - accuracy: c is *worse* when the one-sided paired t-test on
 *    d_i = e_c,i^2 - (1+m)^2 e_r,i^2 (horizontal error at the epoch) rejects
 *    "mean square error of c <= (1+m)^2 that of r" at level alpha / K, K the
 *    number of non-reference models of the set (Bonferroni);
 *  - consistency: c is *consistent* when its position ANEES lies inside the
 *    two-sided 95 % chi-square band of R runs (3 dof), widened by the margin:
 *    [lo / (1+m), hi (1+m)]; when the reference itself is outside its band
 *    (e.g. a set that leaves the other sensor unmodelled), the best any model
 *    of the set can do is to be as consistent as the reference, and c is
 *    consistent when its ANEES is within a factor 1+m of the reference's
 *    (flagged: consistent_as_reference, reference_consistent = false);
 *  - c is *sufficient* when it is not worse and consistent. The cell's answer
 *    is the sufficient model with the fewest filter states (ties: set order).
 * The white-noise threshold of a set (the paper's "at least 10 s") is the
 * time into the outage from which the set's white-noise model departs from
 * the reference at every later outage epoch ("for good"): its RMS horizontal
 * error exceeds (1+m) times the reference's, or it loses consistency (same
 * consistency rule as the cells). It is the estimated effect crossing the
 * margin, a quantity that converges as runs are added; its 95 % interval is
 * the percentile interval over bootstrap resamples of the runs (seeded,
 * recorded). Beside it, significant_s is where the cell test itself finds
 * the WN model insufficient for good (it needs evidence, so it comes later
 * with few runs): a cell after the threshold but before significant_s can
 * still read "sufficient" - not yet shown to be worse.
 */
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::analysis {

/// One GNSS quality of the sweep: name and the GNSS options it sets.
struct GnssQuality {
  std::string name;            ///< label in tables and file names
  emulation::GnssOptions gnss;  ///< rate and sigmas (lever arm from the study's gnss block)
};

/// A whole sweep, as read from YAML (see config/sweep/navchip_uav_sweep.yaml).
struct SweepConfig {
  std::string config_file, config_text;
  StudyConfig study;                     ///< base study (its outages are replaced per column)
  double outage_start_s = 200.0;         ///< s from the trajectory start, >= 0
  std::vector<double> durations_s;       ///< strictly increasing, > 0
  std::vector<GnssQuality> gnss;         ///< >= 1 (default: the study's gnss block, named "base")
  std::vector<bool> baro;                ///< >= 1 (true: barometer used); default {true}
  std::vector<double> imu_rates_hz;      ///< >= 1; default {study.imu_rate_hz}
  double alpha = 0.05;                   ///< level of the accuracy test per cell, (0, 0.5]
  std::size_t bootstrap = 200;           ///< bootstrap resamples for the threshold interval, 0..100000
};

/**
 * Read a sweep configuration (a study config plus a `sweep:` block). Every
 * key carries its unit; ranges are checked here.
 * @throws navimpact::Error naming the file and key.
 */
SweepConfig loadSweepConfig(const std::string& path);

/// One column of the map: indices into the axes.
struct SweepColumn {
  std::size_t gnss = 0, baro = 0, rate = 0;
};

/// What a sweep needs to interpret its per-run values (and what shards must share).
struct SweepMeta : StudyHeader {
  std::string inputs_hash;          ///< FNV-1a 64 of the config and every file it reads (hex)
  double outage_start_s = 0.0;
  std::vector<double> durations_s;
  std::vector<GnssQuality> gnss;
  std::vector<bool> baro;
  std::vector<double> imu_rates_hz;
  double alpha = 0.05;
  std::size_t bootstrap = 0;
  struct Column {
    SweepColumn axes;
    std::string name;               ///< e.g. "gnss=Table 2, baro on, 200 Hz"
    std::string settings;           ///< the study's settings text
    std::vector<std::string> notices;
    std::vector<int> states;        ///< per candidate
    std::vector<double> tau_s;      ///< outage epochs: time into the outage [s], increasing
    std::vector<std::size_t> duration_epoch;  ///< index into tau_s of each duration's end
  };
  std::vector<Column> columns;
};

class SweepPlan;  // prepared studies of every column (opaque)

/**
 * Prepare every column (models, trajectory, perfect IMU, epochs): every bad
 * input throws here, before any run.
 */
std::shared_ptr<const SweepPlan> prepareSweep(const SweepConfig& cfg, const std::string& version);

/// The meta of a prepared sweep.
const SweepMeta& sweepMeta(const SweepPlan& plan);

/// The work of a sweep's shard (studyWork()): steps summed over its columns,
/// memory of the largest column (the columns run one after another).
StudyWork sweepWork(const SweepPlan& plan, const Shard& shard, unsigned threads);
/// studyThreads() for the largest column of a sweep.
unsigned sweepThreads(const SweepPlan& plan, const Shard& shard, unsigned requested);

/// Per-run values of a sweep (or a shard of it).
struct SweepRuns {
  SweepMeta meta;
  Shard shard;
  std::vector<std::uint64_t> run_indices;  ///< increasing
  /// Per column: values[((r * M + m) * T + k) * 2 + v], r = position in
  /// run_indices, m = candidate, k = outage epoch (T = tau_s.size()),
  /// v = 0 horizontal error [m], 1 position NEES.
  std::vector<std::vector<double>> values;
  double filter_steps = 0.0;  ///< IMU samples processed by all filters (for the cost figures)
  double filter_wall_s = 0.0; ///< their wall time
};

/// Called with runs done and runs to do (over all columns).
using SweepProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/// Run the sweep (or one shard: the run indices i with i % N == K - 1 in every column)
/// on @p threads worker threads (0 = all hardware threads; the results do not depend on it).
SweepRuns runSweep(const std::shared_ptr<const SweepPlan>& plan, const Shard& shard, unsigned threads,
                   const SweepProgressFn& progress = {});

/**
 * Write a shard: sweep_shard.json (meta, shard, run indices, @p build_id) and
 * sweep_runs.bin (the values, native little-endian doubles). Its cost figures
 * (filter_steps, filter_wall_s) go to timing.json beside them
 * (report::writeSweepShardTiming); mergeSweepShards adds them up where present.
 */
void writeSweepShard(const SweepRuns& r, const std::string& build_id, OutputSet& out);

/**
 * Merge shard folders into the runs of one unsharded sweep. Refuses shards of
 * another config (text or input files), seed, run count or build (also when
 * @p build_id, the merging program's, differs), overlapping shards, and names
 * the missing shards (K/N) or runs.
 * @throws navimpact::Error naming the folder.
 */
SweepRuns mergeSweepShards(const std::vector<std::string>& dirs, const std::string& build_id);

/// Verdict of one candidate at one epoch against the set's reference.
struct CandidateVerdict {
  std::string label;
  int states = 0;
  double rms_h_m = 0.0;          ///< RMS horizontal error over runs [m]
  double ratio = 0.0;            ///< rms_h_m / the reference's
  double p_worse = 1.0;          ///< one-sided paired t-test p-value (see @file)
  std::size_t runs_worse = 0;    ///< runs with e_c > (1+m) e_r
  double anees = 0.0;            ///< position ANEES (finite NEES only)
  std::size_t nees_runs = 0;     ///< runs with a finite NEES
  double band_lo = 0.0, band_hi = 0.0;  ///< the margin-widened 95 % band
  double p_nees_vs_ref = 1.0;    ///< two-sided paired t-test of NEES_c - NEES_r (information)
  bool worse = false, consistent = false, sufficient = false;
  bool reference_in_band = false;        ///< the reference's ANEES is inside its widened band
  bool consistent_as_reference = false;  ///< consistent only through the reference rule (see @file)
};

/// One cell: a set at one duration in one column.
struct SweepCell {
  double duration_s = 0.0;
  std::vector<CandidateVerdict> models;  ///< in set order
  std::string recommended;               ///< "" = no sufficient model
  bool reference_consistent = false;    ///< the reference's ANEES is inside its widened band
};

/// The white-noise threshold of a set in one column (see @file).
struct WnThreshold {
  bool defined = false;              ///< false: the set has no white-noise model distinct from its reference
  std::string white_noise, reference;
  /// The threshold: time into the outage from which the WN model departs from
  /// the reference at every later epoch: RMS ratio > 1 + m or consistency lost
  /// (the effect, estimated from the runs; -1: still within at the last epoch).
  double departs_s = -1;
  double lo_s = -1, hi_s = -1;       ///< 95 % bootstrap percentile interval of departs_s (-1: beyond the scan)
  std::size_t censored = 0;          ///< bootstrap resamples where WN never departs for good
  double first_departure_s = -1;     ///< first epoch where the effect departs (-1: never)
  /// From here on the cell test finds WN insufficient at every epoch (needs
  /// evidence, so it comes later with few runs; -1: not at the last epoch).
  double significant_s = -1;
  double scanned_to_s = 0.0;         ///< last outage epoch scanned
};

struct SweepSetResult {
  ModelSetSpec set;
  std::vector<SweepCell> cells;  ///< per duration
  WnThreshold threshold;
};

struct SweepColumnResult {
  std::vector<SweepSetResult> sets;
};

/// Statistics of a sweep (data only; lib/report writes them).
struct SweepResults {
  SweepMeta meta;
  std::size_t runs = 0;
  std::vector<SweepColumnResult> columns;
  double us_per_filter_step = 0.0;  ///< cost (not written into the result files)
  double filter_steps = 0.0;
};

/// Verdicts, recommendations and thresholds from all runs (deterministic).
SweepResults judgeSweep(const SweepRuns& runs);

}  // namespace navimpact::analysis
