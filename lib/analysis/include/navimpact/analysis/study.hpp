/**
 * @file study.hpp
 * @brief The emulation study of Khaghani et al. (2019) as a Monte Carlo model
 *        comparison: one trajectory, one source of true IMU errors, several
 *        candidate filter models, R runs, accuracy and consistency metrics,
 *        figures and a report (`navimpact study`, `navimpact study-merge`).
 *
 * Design:
 *  - The perfect IMU and the truth at the record epochs are computed once per
 *    study and shared by every run and model.
 *  - Run i (0-based) uses seed_i = stochastic::deriveSeed(seed, i); its
 *    streams are deriveSeed(seed_i, s) with s = 0 IMU errors (axis a then
 *    deriveSeed(., a), as emulation::modelImuErrors), 1 GNSS noise, 2 baro
 *    noise, 3 initial navigation error, 4 the window of a measured recording.
 *    The same realisation is fed to every candidate model (paired comparison).
 *  - Each (run, model) is a full EKF run (analysis::runNav) linearised on its
 *    own estimates; nothing is shared between runs but the inputs.
 *  - Metrics are sums over runs added in run-index order, so the results do
 *    not depend on thread count, scheduling or sharding.
 *  - Sharding: shard K/N (1 <= K <= N) runs the indices i with i % N == K - 1
 *    and stores every run's record (errors, sigmas and NEES at every epoch);
 *    mergeShards() re-adds all runs in index order: bit-identical metrics.
 *
 * Metrics per model and epoch over R runs (Cucci, Voirol, Khaghani & Guerrier
 * 2023, "On performance evaluation of inertial navigation systems: the case of
 * stochastic calibration", IEEE TIM: judge a model by Monte Carlo accuracy
 * AND by the consistency of its predicted covariance):
 *  - RMS over runs of the actual error, per component;
 *  - predicted sigma as the root mean square over runs of the filter's sigma;
 *  - average NEES (ANEES) of position, velocity, attitude and all nine, with
 *    the two-sided 95 % band chi2inv(0.025, R n)/R .. chi2inv(0.975, R n)/R
 *    (Bar-Shalom, Li & Kirubarajan 2001, §5.4.2);
 *  - coverage: fraction of runs inside the nominal 68.27 % and 95 % ellipsoids
 *    (NEES <= chi2inv(p, n)), nominal values 0.6827 and 0.95.
 * Per outage: all of these at the outage end, the mean and RMS of the maximum
 * horizontal drift, ANEES averaged over the outage epochs; per model the state
 * count and the cost (wall time per run, per filter step).
 */
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/core/config.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/filter/ekf.hpp"

namespace navimpact::analysis {

/// Where the true IMU errors of the emulation come from.
struct TruthErrorSpec {
  std::string kind = "model";                 ///< "model" (simulated) or "static" (measured recording)
  std::string model;                          ///< FILE[:NAME] for "model"
  emulation::StaticRecordingSpec recording;   ///< for "static"; a window per run chosen by the run seed
};

/// One candidate filter model.
struct CandidateSpec {
  std::string label;          ///< unique name used in tables and figures
  std::string model;          ///< FILE[:NAME]: both sensors from one model, or
  std::string accelerometer;  ///< FILE[:NAME] giving the accelerometer axes ("" = no model)
  std::string gyroscope;      ///< FILE[:NAME] giving the gyroscope axes ("" = no model)
};

/// A group of candidates compared in one table and one set of figures.
struct ModelSetSpec {
  std::string name;                  ///< file-name friendly, e.g. "accelerometer"
  std::string title;                 ///< for figures and the report
  std::vector<std::string> models;   ///< candidate labels in display order
  std::string reference;             ///< label of the reference model ("" = last)
  std::string white_noise;           ///< label of the white-noise-only model ("" = first)
};

/// A whole study, as read from YAML (see config/paper/study_navchip_uav.yaml).
struct StudyConfig {
  std::string config_file;                 ///< path as given
  std::string config_text;                 ///< verbatim YAML (recorded in outputs)
  emulation::TrajectorySpec trajectory;
  emulation::SmoothingOptions smoothing;
  double imu_rate_hz = 200.0;              ///< emulated IMU rate [Hz]
  TruthErrorSpec truth;
  std::vector<CandidateSpec> candidates;
  std::vector<ModelSetSpec> sets;
  emulation::GnssOptions gnss;             ///< seed ignored: per run from the study seed
  emulation::BaroOptions baro;             ///< seed ignored
  bool baro_in_outage = true;
  bool use_baro = true;                    ///< false: the filter gets no barometer at all (sweep axis)
  /// Outages relative to the first trajectory time [s] (start, end]; default (200, 260].
  std::vector<Outage> outages;
  /// The key that gave the outages, named with config_file when one is outside the run ("" = not a key: a sweep's own axis).
  std::string outages_key = "outages";
  /// When set, one per outage, naming it in messages in place of the key (a sweep: "key 'sweep.outage.durations_s[k]': ...").
  std::vector<std::string> outage_names;
  std::size_t runs = 100;                  ///< Monte Carlo runs, >= 1
  std::uint64_t seed = 1;                  ///< study seed
  unsigned threads = 0;                    ///< 0 = all hardware threads
  filter::EkfConfig ekf;                   ///< propagate_every defaults to 10 here
  /// Initial navigation error sigmas [m, m, m, m/s x3, rad x3]; the error of
  /// each run is drawn from them and the filter starts with them as P0.
  filter::Vector9d initial_sigma;
  double record_rate_hz = 1.0;             ///< record epochs outside outages [Hz]
  double outage_record_rate_hz = 5.0;      ///< record epochs inside outages [Hz]
  double margin = 0.25;                    ///< relative margin of the recommendation (0.25 = 25 %)
  double plot_before_s = 30.0;             ///< figure window before an outage [s]
  double plot_after_s = 10.0;              ///< figure window after an outage [s]

  StudyConfig();
  /// Read the keys of a study file (see config/paper/study_navchip_uav.yaml and
  /// README), with the ranges of core/limits.hpp; top-level keys in
  /// @p extra_keys are accepted and left to the caller (`sweep`).
  void loadFrom(const ConfigNode& root, const std::vector<std::string>& extra_keys = {});
};

/**
 * Read a study configuration. Relative paths are resolved against the file's
 * folder. @throws navimpact::Error naming the file and key for unknown keys,
 * wrong types, missing keys, invalid values, unknown candidate labels in a set.
 */
StudyConfig loadStudyConfig(const std::string& path);
/// As above, accepting (and ignoring) the extra top-level keys @p extra_keys,
/// which a caller reads itself from the same file (`navimpact sweep`).
StudyConfig loadStudyConfig(const std::string& path, const std::vector<std::string>& extra_keys);

/// Runs i with i % n == k - 1 (k in 1..n); 1/1 = all.
struct Shard {
  unsigned k = 1, n = 1;
  bool contains(std::size_t run) const { return run % n == k - 1; }
  bool whole() const { return n == 1; }
};
/// Parse "K/N". @throws navimpact::Error unless 1 <= K <= N.
Shard parseShard(const std::string& text);

class StudyPlan;  // prepared inputs (opaque)
struct StudyResults;

/**
 * Prepare everything before the first run: read the trajectory, smooth it,
 * load and check every model and the measured recording, compute the perfect
 * IMU and the truth at the record epochs, check the outages lie inside the
 * trajectory. Every bad input throws here.
 * @param[in] cfg      configuration (runs >= 1).
 * @param[in] version  navimpact version string, recorded in the outputs.
 */
std::shared_ptr<const StudyPlan> prepareStudy(const StudyConfig& cfg, const std::string& version);

/// Work and memory of running the runs of @p shard of a prepared study on
/// @p threads workers (0 = all hardware threads): IMU steps = runs x samples x
/// (1 emulation + the models' filters); memory = (workers x 120 + 100) bytes
/// per IMU sample (measured: 63 bytes per sample and worker at 200 Hz, 115 at 10 kHz).
struct StudyWork {
  double runs = 0.0, samples = 0.0, filters = 0.0, workers = 0.0, columns = 1.0;  ///< columns: a sweep's studies
  double steps = 0.0, bytes = 0.0;
};
StudyWork studyWork(const StudyPlan& plan, const Shard& shard, unsigned threads);

/// The workers a study uses for @p requested threads: @p requested when given;
/// for 0 (all cores) the most, up to the hardware's, whose memory (studyWork)
/// stays within limits::kDefaultMemoryBudgetBytes, at least 1 (the results do not
/// depend on it; a 64-core machine would otherwise be refused at 10 kHz).
unsigned studyThreads(const StudyPlan& plan, const Shard& shard, unsigned requested);

/// The budgets of `study` and `sweep` (README "Ranges and budgets"): @p steps
/// IMU steps above limits::kDefaultFilterStepBudget or @p bytes above
/// limits::kDefaultMemoryBudgetBytes are refused unless @p allow_large.
/// @p command "study" or "sweep" names the refusal.
void checkStudyBudget(const std::string& command, const StudyWork& w, bool allow_large);

struct StudyMeta;
/// The description of a prepared study (labels, states, epochs, outages, notices).
const StudyMeta& studyMeta(const StudyPlan& plan);

/// Called from worker threads (serialised) with runs done and runs to do.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/**
 * Run the Monte Carlo study (or one shard of it) on a pool of threads.
 * @param[in] plan      from prepareStudy().
 * @param[in] shard     subset of run indices.
 * @param[in] threads   worker threads (0 = all hardware threads); the results do not depend on it.
 * @param[in] progress  may be empty.
 */
struct RunRecord;
/// Receives every run record in run-index order (serialised).
using RunSink = std::function<void(const RunRecord&)>;

StudyResults runStudy(const std::shared_ptr<const StudyPlan>& plan, const Shard& shard, unsigned threads,
                      const ProgressFn& progress = {});
/**
 * As above, handing every run record to @p sink (in run-index order) instead
 * of keeping it in StudyResults::records: callers that need a few values per
 * run keep only those (`navimpact sweep`).
 */
StudyResults runStudy(const std::shared_ptr<const StudyPlan>& plan, const Shard& shard, unsigned threads,
                      const ProgressFn& progress, const RunSink& sink);

/// Per-run record of every model (errors, sigmas, NEES at every epoch; outage drifts; cost).
struct RunRecord {
  std::uint64_t index = 0, seed = 0;
  struct Model {
    std::vector<double> epochs;     ///< 22 values per epoch: err[9], sigma[9], nees[4]
    std::vector<double> drift;      ///< 2 per outage: max horizontal, max 3-D drift [m]
    double wall_s = 0.0;            ///< filter run time [s]
    std::uint64_t steps = 0;        ///< IMU samples processed
  };
  std::vector<Model> models;        ///< in StudyMeta candidate order
};

/// Description of the study needed to interpret and write results (JSON-serialisable).
/// What a study and a sweep both record of themselves (in their shards and
/// results): versions, configuration, seed, run count, the candidates and the
/// model sets, the margin. One JSON writer and reader for both (study.cpp).
struct StudyHeader {
  std::string version, config_file, config_text;
  std::vector<std::pair<std::string, std::string>> versions;  ///< navimpact + libraries (core/build_info.hpp)
  std::uint64_t seed = 0;
  std::size_t runs_total = 0;
  std::vector<std::string> labels;            ///< candidates, in config order
  std::vector<ModelSetSpec> sets;
  double margin = 0.25;                       ///< relative accuracy margin of the judgement
};

struct StudyMeta : StudyHeader {
  double t0 = 0.0;                            ///< first trajectory time [s]
  double duration_s = 0.0;                    ///< trajectory duration [s]
  double imu_rate_hz = 0.0;
  std::string trajectory, truth_description;
  std::vector<std::string> notices;
  std::vector<std::string> sources;           ///< each candidate's model text
  std::vector<int> states;                    ///< EKF state count per candidate
  std::vector<Outage> outages;                ///< absolute filter time [s]
  std::vector<double> epochs;                 ///< record epochs, absolute [s]
  double plot_before_s = 30.0, plot_after_s = 10.0;
  std::string settings;                       ///< GNSS/baro/filter settings, one line each
};

/// Sums over runs, added in run-index order.
struct StudyAccumulator {
  std::size_t runs = 0;
  struct Model {
    // per epoch (E x k, row-major): sums over runs
    std::vector<double> e, e2, s2;            ///< 9 per epoch
    std::vector<double> nees;                 ///< 4 per epoch (valid runs only)
    std::vector<double> n_valid, in68, in95;  ///< 4 per epoch
    std::vector<double> drift_h, drift_h2, drift_3d;  ///< 1 per outage
    double wall_s = 0.0, steps = 0.0;
  };
  std::vector<Model> models;
  /// Add one run (must be the next index when exact reproducibility matters).
  void add(const RunRecord& r, std::size_t n_epochs, std::size_t n_outages);
};

/// Everything a study (or shard) produced.
struct StudyResults {
  StudyMeta meta;
  StudyAccumulator acc;
  Shard shard;
  std::vector<std::uint64_t> run_indices;     ///< runs included, increasing
  std::vector<RunRecord> records;             ///< kept only for shards (to merge exactly)
};

/**
 * Write a shard's partial results to DIR: shard.json (meta, shard, indices)
 * and runs.bin (every run record, native little-endian doubles); @p build_id
 * names the program that wrote it (mergeShards refuses another).
 */
void writeShard(const StudyResults& r, const std::string& build_id, OutputSet& out);

/**
 * Merge shard folders into the results of one unsharded run: checks that the
 * shards come from the same configuration, seed and run count and that their
 * runs are disjoint and complete and were written by the build @p build_id
 * (the merging program's), then adds the runs in index order.
 * @throws navimpact::Error naming the folder for any mismatch or missing file.
 */
StudyResults mergeShards(const std::vector<std::string>& dirs, const std::string& build_id);

/// Two-sided 95 % band of the average NEES of @p runs runs with @p dof dof.
std::pair<double, double> aneesBand(std::size_t runs, int dof, double confidence = 0.95);

}  // namespace navimpact::analysis
