/**
 * @file run_diagnosis.hpp
 * @brief What the simulation gets wrong on a real run: measured outage errors
 *        of a replayed rawlog against the distribution the simulation with
 *        the IMU model predicts for the same trajectory, filter and outages.
 *
 * Data only (lib/report writes run_diagnosis.json, report.md and figures).
 *
 * The rawlog is read and decoded once (rawlog::readRawlogRecords); every replay
 * below runs from those records (analysis/replay.hpp), and a held-out replay
 * stops after its fold's last held-out outage (the filter is causal).
 *
 * Measured: for each outage duration D the rawlog is replayed (analysis/replay.hpp)
 * with outages laid all along the run as `replay --outages-every P:D` does,
 * P = D + reconverge_s (reconverge_s of GNSS before each outage), and scored
 * against the reference (analysis/scoring.hpp): per outage the error at its end
 * (the last reference epoch <= end), the filter's predicted sigma, the NEES.
 *
 * Simulated: the trajectory of the run, smoothed as the emulation does
 * (emulation::SmoothTrajectory, P-splines), is
 *  - the reference itself when it has velocity and attitude at most 0.25 s apart;
 *  - else the GNSS-aided filter solution of the run without outages, recorded
 *    every 0.1 s (a position-only reference such as an RTK track carries no
 *    attitude); its position is the RTK-aided estimate.
 * Each realisation r = 0..R-1 (seed deriveSeed(seed, r), the same for every
 * duration) adds to the perfect IMU increments of that trajectory the model's
 * simulated errors (emulation::modelImuErrors) or a window of the --static
 * recording (emulation::staticImuErrors, window start from the seed), GNSS fixes
 * at the run's own fix times with the run's own covariances (and velocity where
 * the run's fixes have one), barometer samples likewise, an initial error drawn
 * from the filter's initial covariance; and runs the SAME filter (the replay's
 * NavRunOptions: propagation, gate, aids, lever arm) over the same outages.
 *
 * Comparison per quantity (horizontal position, vertical position; velocity
 * and attitude when the reference has them) and duration, at the outage ends.
 * The outages of one run share its bias and trajectory, so they are not
 * independent: the measured run is ONE draw of a run-level statistic, and the
 * realisations give its distribution. Statistic: RMS over the run's outages
 * of the error magnitude (reference variance 2 s_h^2 horizontal, s_v^2
 * vertical added to the simulated squares). With mu, sd the mean and standard
 * deviation of ln RMS over the R realisations (Gaussian logs assumed):
 *   ratio = RMS_measured / exp(mu);
 *   t = ln(ratio) / (sd sqrt(1 + 1/R)), Student t with R - 1 dof (a
 *   prediction interval): two-sided p-value, and the ratio's interval
 *   exp(ln(ratio) +- t_{1-a/2} sd sqrt(1 + 1/R)) at a = alpha / m.
 * Measured NEES: the mean position NEES over the run's outages tested the
 * same way against the realisations' mean NEES (the chi-square(3K)/K band of
 * independent outages is reported beside it).
 * Verdict: "inadequate" when any of the m tests (all comparisons and all NEES
 * tests) rejects at level a = alpha / m (Bonferroni), so the family-wise
 * false-alarm rate is at most alpha; else "adequate" when every test could
 * have said no to a model mispredicting by less than kResolvableFactor (its
 * interval, exp(+- t_{1-a/2} sd sqrt(1 + 1/R)), lies within that factor), and
 * "undetermined" when one could not (too few realisations: with 2 of them
 * the intervals spanned 1e-305 to 1e305 and the verdict said "adequate").
 *
 * Causes (each fitted on training data and scored on held-out outages): the
 * run is cut into `folds` time blocks; the outages whose midpoint falls in
 * block f are held out, the cause is fitted on everything outside block f
 * (IMU samples, GNSS innovations, or outages that do not overlap block f),
 * the run is replayed with that extension on the measured run's outage
 * windows (replayOnMeasuredOutages: the same start and duration, whatever
 * the extension's filter start) and the held-out outage ends scored. Every outage is held out exactly once. Score per outage: negative
 * log-likelihood 0.5 sum_i (e_i^2 / s_i^2 + ln s_i^2) of the errors at its
 * end, i over the position axes (s_i^2 the filter's predicted variance plus
 * the reference's) and the velocity and attitude axes when the reference has
 * them (diagonal of the filter's covariance); gain = its mean
 * decrease; significance: one-sided paired sign-flip permutation test (seeded,
 * 20000 flips) at alpha / (number of causes).
 *  - in_motion_noise, per channel: white-noise sigma of the IMU residual (real
 *    IMU minus the perfect IMU of the smoothed trajectory) from second
 *    differences (var = 6 sigma^2 for white noise) over the samples where the
 *    trajectory moves (|w_IB_B| > 0.05 rad/s or ||f_B| - g| > 0.3 m/s^2, the
 *    emulation's SensorEffects test); factor = that sigma / the model's white
 *    noise (emulation::whiteNoiseSigma); 99 % interval from 20 batch means
 *    (Student t). Extension: every WN term of the channel times the factor.
 *  - gnss_noise: GNSS position innovations of the aided phases: per axis
 *    group (horizontal, vertical) the scale s of the fix sigma with
 *    mean(dz^2) = mean(S - R) + s^2 mean(R); mean NIS and lag-1 correlation of
 *    the normalised innovations. Extension: the filter's GNSS sigmas set to s
 *    times the median fix sigma (replay noise.sigma_pos_h_m / sigma_pos_v_m).
 *  - bias_instability: an accelerometer bias random walk of density q the
 *    static model lacks: the measured excess of the squared outage-end error
 *    over the simulated mean square grows as q T^5 / 20 per axis (T the
 *    coasting time); q by least squares over the training outages (horizontal
 *    for acc_x, acc_y; vertical for acc_z), clipped at 0; 99 % interval by a
 *    seeded bootstrap over outages. Extension: an RW term of gamma =
 *    sqrt(q / rate) added to those channels.
 *  - scale_factor, misalignment, time_offset, lever_arm: the filter's optional
 *    states (filter::ExtraStates). Fitted by replaying the run with that state
 *    on (GNSS dropped in the held-out block, no other outage; prior sigma half
 *    the effect's documented range, limits.hpp, or the configured one when
 *    larger): the estimate at the end of the run and its 95 % interval from
 *    the filter's covariance. Extension: the filter with that state on,
 *    initialised at the fitted estimate, the group's largest fitted sigma as prior.
 * The top-ranked cause (largest held-out gain) is named when significant;
 * another significant cause is named only if, added to the top cause's
 * extension (fitted per fold on top of it), it gains on the held-out outages
 * against that extension at the same level.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::analysis {

/// A cause's parameter for one channel, fitted on the whole run.
struct RunFinding {
  std::string cause;     ///< in_motion_noise, gnss_noise, bias_instability, scale_factor, misalignment, time_offset, lever_arm
  std::string channel;   ///< gyro_x .. acc_z, gnss (gnss_noise, lever_arm) or all (time_offset)
  std::vector<std::pair<std::string, double>> params;                    ///< SI, names as in the README
  std::vector<std::pair<std::string, std::pair<double, double>>> interval;  ///< per parameter, its interval
  std::string note;      ///< how it was estimated
};

/// One candidate explanation: fitted on training outages, scored on held-out ones.
struct CauseResult {
  std::string cause;
  std::vector<RunFinding> findings;      ///< the whole-run fit, per channel
  std::size_t heldout_outages = 0;       ///< outages scored (each held out once)
  double error_before_m = 0.0;           ///< RMS horizontal error at the held-out outage ends, today's filter [m]
  double error_after_m = 0.0;            ///< the same with the extension fitted without them [m]
  double vertical_before_m = 0.0, vertical_after_m = 0.0;  ///< RMS vertical error [m]
  double anees_before = 0.0, anees_after = 0.0;  ///< mean position NEES at those ends
  double gain = 0.0;                     ///< mean decrease of the position negative log-likelihood per held-out outage
  double p_value = 1.0;                  ///< one-sided paired sign-flip permutation test of gain > 0
  double error_p_value = 1.0;            ///< the same test on the 3-D position error at the ends
  bool significant = false;              ///< gain > 0 and p_value < alpha / (number of causes)
  /// A significant cause other than the top-ranked one, added to the top cause's
  /// extension (fitted per fold on top of it) and scored against it on the
  /// same held-out outages: named (findings) only if that gain is significant too.
  /// The top-ranked cause, when significant, is added to the runner-up's
  /// extension the same way: not adding there, the two are undecided.
  std::string given;                     ///< the cause it was added to ("" = not tested)
  double gain_given = NAN, p_given = NAN;  ///< its held-out gain and p on top of that cause
  bool adds = false;                     ///< gain_given > 0 and p_given < alpha / (number of causes) (the top cause: < alpha)
  std::string extension;                 ///< what the extension changes, in words
  stochastic::ImuModel model_after;      ///< the extended model (whole-run fit; = today's for GNSS causes)
  std::optional<double> gnss_sigma_h_m, gnss_sigma_v_m;  ///< the extended filter's GNSS sigmas (gnss_noise)
  std::optional<filter::ExtraStates> extra_states;  ///< the extended filter's extra states (scale_factor, misalignment, time_offset, lever_arm)
};

/// Options of a run diagnosis.
struct RunDiagnosisOptions {
  ReplayConfig replay;                        ///< rawlog, model and filter settings (as `replay --config`)
  std::vector<double> durations_s{10.0, 30.0, 60.0};  ///< outage durations [s], each > 0
  double reconverge_s = 30.0;                 ///< GNSS time before each outage [s], > 0
  int realisations = 50;                      ///< simulated realisations, >= 2
  std::uint64_t seed = 20261124;              ///< root seed of the simulation
  double alpha = 0.05;                        ///< family-wise false-alarm rate of the verdict, (0, 0.5)
  std::string static_file;                    ///< "" = the model's simulated errors; else a static recording (CSV)
  CsvImuOptions static_csv;                   ///< units, rate, axes of that recording
  int threads = 0;                            ///< worker threads (0 = hardware)
  int folds = 5;                              ///< cross-validation folds (time blocks of the run), >= 2; at most one per outage
  bool allow_large = false;                   ///< run above the work and memory budgets (limits.hpp)
  bool causes = true;                         ///< fit and score the causes (false: comparison only)
  /// Progress (fraction done 0..1, stage); may be empty.
  std::function<void(double, const std::string&)> progress;
};

/// Measured against predicted, one quantity at one outage duration.
struct QuantityComparison {
  std::string quantity;        ///< "horizontal_position", "vertical_position", "velocity", "attitude"
  std::string unit;            ///< "m", "m/s", "rad"
  double duration_s = 0.0;     ///< outage duration [s]
  int dof = 1;                 ///< error components per outage
  std::vector<double> measured;    ///< per measured outage: error magnitude at the end [unit]
  std::vector<double> predicted;   ///< per simulated outage (all realisations): magnitude [unit]
  double measured_rms = 0.0;       ///< sqrt(mean e^2) of the measured [unit]
  double predicted_rms = 0.0;      ///< geometric mean over realisations of the same RMS, reference variance added [unit]
  double predicted_log_sd = 0.0;   ///< spread (sd of ln RMS) of that RMS over realisations
  double predicted_p05 = 0.0, predicted_p50 = 0.0, predicted_p95 = 0.0;  ///< percentiles of the simulated magnitudes
  double ratio = 0.0;              ///< measured_rms / predicted_rms
  double ratio_lo = 0.0, ratio_hi = 0.0;  ///< its (1 - alpha/m) interval (see the file comment)
  double p_value = 1.0;            ///< two-sided test of ratio = 1 against the realisations' spread
  bool rejects = false;            ///< p_value < alpha/m
};

/// One outage duration: the measured outages and the NEES test.
struct DurationDiagnosis {
  double duration_s = 0.0;
  double period_s = 0.0;                   ///< outage every period_s (duration + reconverge)
  std::vector<OutageScore> measured;       ///< the scored outages of the real run
  OutageDistribution distribution;         ///< their distribution (coverage, NEES)
  double anees = 0.0;                      ///< measured mean position NEES
  double anees_lo = 0.0, anees_hi = 0.0;   ///< its band from the realisations at level alpha/m
  double anees_p = 1.0;                    ///< two-sided p of the measured mean NEES against that band
  bool anees_rejects = false;              ///< outside the band
  double chi2_lo = 0.0, chi2_hi = 0.0;     ///< the chi2(3K)/K band of independent outages (for reference)
  double predicted_anees = 0.0;            ///< mean position NEES of the simulated outages
  std::size_t simulated_outages = 0;       ///< realisations x outages
};

/// The widest test interval (a ratio's, or the mean NEES band's, half-width
/// as a factor) under which a run that no test rejects is still "adequate":
/// an order of magnitude; beyond it the verdict is "undetermined".
constexpr double kResolvableFactor = 10.0;

/// Everything a run diagnosis computed.
struct RunDiagnosis {
  std::string rawlog;
  std::string model_source;
  std::string errors_source;               ///< "model" description or the static recording
  std::string trajectory_source;           ///< how the emulated trajectory was made
  double imu_rate_hz = 0.0;
  double aided_from_s = 0.0;               ///< filter start of the real run, from time zero [s]
  double run_end_s = 0.0;                  ///< end of the IMU data, from time zero [s]
  ReferenceInfo reference;
  int realisations = 0;
  std::uint64_t seed = 0;
  double alpha = 0.0;
  double reconverge_s = 0.0;
  std::size_t tests = 0;                   ///< m, the tests of the verdict
  double test_level = 0.0;                 ///< alpha / m
  std::vector<DurationDiagnosis> durations;
  std::vector<QuantityComparison> comparisons;
  std::string verdict;                     ///< "adequate", "inadequate" or "undetermined"
  std::vector<std::string> reasons;        ///< the tests that rejected, or why none could, in words
  /// The largest half-width of the tests' intervals, as a factor (sqrt(hi / lo)):
  /// the misprediction the weakest test could just detect.
  double resolution_factor = 0.0;
  std::vector<std::string> notices;
  int folds = 0;                           ///< cross-validation folds used
  std::vector<CauseResult> causes;         ///< ranked by held-out gain, best first
  int best = -1;                           ///< index of the best significant cause (-1: none)
  std::vector<RunFinding> findings;        ///< of the named causes (the best significant one, and others that add to it), in rank order
  stochastic::ImuModel model_before;       ///< today's model
  double wall_s = 0.0;                     ///< wall-clock time [s]
};

/// An extension's scores on the outages of a measured replay, paired by window.
struct PairedOutageScores {
  /// [k] the extension's score of measured.score->outages[k]: the outage with
  /// the same window (start and duration from time zero); empty when it has
  /// none that is the same outage: the window ends after the stop, or does not
  /// start after the extension's filter start (its GNSS-aided history would differ).
  std::vector<std::optional<OutageScore>> outages;
  /// [k] the nine navigation errors (dp NED, dv NED, psi) and the filter's
  /// sigmas at that outage's end (NaN where outages[k] is empty).
  std::vector<std::pair<filter::Vector9d, filter::Vector9d>> ends;
  double aided_from_s = 0.0;  ///< the extension's filter start, from time zero [s]
};

/**
 * The held-out replay of diagnose --run: @p extension replayed from @p data
 * with the outage windows of @p measured (measured.cfg.outages: the explicit
 * ones and those laid by its outages_every, from time zero), not laid again
 * from the extension's own filter start: an extension that ends the aligning
 * phase elsewhere (larger GNSS sigmas, another heading source) scores the same
 * outages as the measured run, so before and after are paired by window, not
 * by order. With @p stop_after_s the replay stops there (runReplay); only
 * windows ending by then are paired.
 * @throws navimpact::Error when @p measured or the replay has no reference
 *         (score), or errors of the replay.
 */
PairedOutageScores replayOnMeasuredOutages(const ReplayConfig& extension, const ReplayResult& measured,
                                           const rawlog::RawlogRecords& data,
                                           double stop_after_s = std::numeric_limits<double>::infinity());

/**
 * Diagnose a real run (see the file comment).
 * @throws navimpact::Error for a rawlog without reference, a duration that fits
 *         no outage in the run, invalid options, or errors of the replay.
 */
RunDiagnosis diagnoseRun(const RunDiagnosisOptions& opt);

}  // namespace navimpact::analysis
