/**
 * @file diagnosis.hpp
 * @brief `navimpact diagnose`: what a simulation with the user's IMU error
 *        model gets wrong on a measured static recording, why, and how much an
 *        extended model gains.
 *
 * Pipeline per channel (all channels in parallel, see diagnose()); the
 * detectors are lib/detect's, each calibrated under the user's model:
 *  1. outlier events: second-difference exceedances (scale max(model, MAD)),
 *     clusters of consecutive spikes (a knock) are one event; interpolated out;
 *  2. spectral lines: Hann periodogram of the whole record against
 *     max(model PSD, the record's local level), Bonferroni over bins, from 4
 *     cycles per record to Nyquist; harmonics are one finding; subtracted;
 *  3. level shifts: equal-window contrasts scaled by the model's Haar WV
 *     (valid under random walks and Gauss-Markov noise), detect-and-remove;
 *     each accepted only when significant against the best stochastic
 *     explanation without shifts (RW, DR or GM added to the model, fitted to
 *     the WV): exact likelihood ratio of block means, chi2_1 at a fixed time,
 *     Bonferroni over the block boundaries (detect/step_test.hpp);
 *  4. WV: measured Haar WV of the cleaned record against the model's WV with
 *     its chi-square CI (eta_j = max(M_j / 2^j, 1), Percival & Walden 2000
 *     §8.4; lowered to the dof seen in the model's own simulations where
 *     those are fewer), Bonferroni over scales; the excess is matched against
 *     every extension by one process family (add WN, QN, RW, DR, GM with
 *     T <= record/5, or retune one term) or by two fitted jointly (every term
 *     refitted with the others held: backfitting), by the chi-square (gamma)
 *     deviance on the whole cleaned record, chosen by AIC = deviance + 2 p (a
 *     pair only when it beats every one-term explanation by the 1 %
 *     chi-square margin); when the winner is slow (RW, DR, long GM) the sets
 *     differing only in their slow terms are ranked again by AIC on the exact
 *     Gaussian likelihood of ~512 block means (more terms only by a nested
 *     likelihood-ratio test at 1 %); the runner-up is reported; a term that
 *     changes the WV by less than the CI width at every scale, or has a
 *     vanishing parameter, is not a finding;
 *  5. gain: the first-half extension and the user's model are judged on the
 *     SECOND half (held out): GMWM objective, deviance, and a one-sided
 *     paired (Vuong-type) z test of the per-scale deviances; "significant"
 *     only when both held-out criteria improved and the test rejects.
 *
 * The family-wise level alpha (default 1 % for the whole record) is split over
 * the four test families (WV 40 %, spectrum 20 %, level shifts 20 %, outliers
 * 20 %), each Bonferroni-corrected over its channels and elements, so that data
 * drawn from the model itself are called adequate with probability >= 1 - alpha
 * (up to the asymptotic approximations of each detector).
 * Events at the same time on several channels (a knock, a temperature jump)
 * are listed once in Diagnosis::events and still as a finding per channel.
 */
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::analysis {

/// Vocabulary of causes, in the order they are listed in reports.
enum class Cause {
  WhiteNoise,         ///< "white_noise", params sigma [unit, per sample]
  QuantizationNoise,  ///< "quantization_noise", params Q [unit]
  RandomWalk,         ///< "random_walk", params gamma [unit, per sample]
  Drift,              ///< "drift", params omega [unit/sample]
  GaussMarkov,        ///< "gauss_markov", params sigma [unit], T [s]
  Sinusoid,           ///< "sinusoid", params amplitude [unit], freq_hz [Hz]
  LevelShift,         ///< "level_shift", params size [unit], t_s [s]
  Outliers,           ///< "outliers", params count, times_s [s]
};

/// Snake-case name of a cause as written in diagnosis.json ("gauss_markov", ...).
const char* causeName(Cause c);

/// One named cause of misfit on one channel.
struct Finding {
  std::string channel;                                  ///< e.g. "gyro_z"
  Cause cause = Cause::WhiteNoise;
  std::vector<std::pair<std::string, double>> params;   ///< fixed keys (see Cause), SI
  std::vector<double> times_s;                          ///< outliers: times [s]
  /// Where it shows: "scales_s" (WV scales [s]), "freq_hz" (spectrum) or "t_s" (time).
  std::string range_key = "scales_s";
  double range_lo = 0.0, range_hi = 0.0;
  /// 95 % profile interval of T (gauss_markov) [s]; empty otherwise.
  std::optional<std::pair<double, double>> T_interval_s;
  /// "missing" (the model lacks it / understates it) or "overstated".
  std::string direction = "missing";
  std::string explanation;                              ///< one sentence
  std::string action;                                   ///< what to do about it
  double statistic = 0.0;   ///< test statistic that triggered it (z or ratio)
  double threshold = 0.0;   ///< its family-wise threshold
  double p_value = 1.0;     ///< family-wise adjusted p-value of the detection
  /// 95 % intervals of parameters, by key (e.g. "freq_hz", "amplitude", "T", "gamma").
  std::vector<std::pair<std::string, std::pair<double, double>>> intervals;
  /// Why this cause and not the runner-up explanation (one sentence).
  std::string evidence;
  /// The runner-up explanation: its cause(s) in the vocabulary of `cause`
  /// ('+' between several; "" when none was compared), in words, and the
  /// margin of the winner on the criterion that chose (AIC units; NaN when
  /// the choice was a detector's test).
  std::string runner_up;
  std::string runner_up_detail;
  double aic_margin = std::numeric_limits<double>::quiet_NaN();
  /// Slow explanations (random walk, drift, long Gauss-Markov): how often the
  /// runner-up, fitted and simulated (parametric bootstrap of the exact block
  /// likelihood), gives a margin at least the observed one; the finding is
  /// decided only when this is <= 5 %. NaN when not simulated.
  double runner_up_p = std::numeric_limits<double>::quiet_NaN();
  int runner_up_draws = 0;  ///< simulated records behind runner_up_p
  /// false: the evidence between the finding and its runner-up is not
  /// decisive (AIC margin below 2); the report says "undecided between".
  bool decided = true;
  std::vector<double> harmonics_hz;  ///< sinusoid: harmonics of the line found with it [Hz]
  int event = -1;                    ///< index in Diagnosis::events (cross-channel), -1 if none
  double get(const std::string& key) const;             ///< params lookup (NaN if absent)
};

/// Measured vs model WV at one scale.
struct ScaleCheck {
  double tau_s = 0;          ///< scale [s]
  double measured = 0;       ///< empirical WV [unit^2]
  double model = 0;          ///< model's theoretical WV [unit^2]
  double ci_low = 0;         ///< 95 % CI of the measured WV under the model [unit^2]
  double ci_high = 0;
  double env_low = 0;        ///< simulation envelope (min over simulations) [unit^2]
  double env_high = 0;       ///< (max over simulations)
  double dof = 0;            ///< chi-square degrees of freedom used
  double ratio = 0;          ///< measured / model
  double ci_widths = 0;      ///< distance outside the CI in CI widths (signed, 0 inside)
  double p_value = 1;        ///< two-sided per-scale p-value
  bool outside95 = false;    ///< outside the per-scale 95 % CI
  bool significant = false;  ///< outside at the family-wise level
};

/// Spectrum of a channel and its line test (decimated for plots).
struct SpectrumCheck {
  std::vector<double> freq_hz;     ///< frequencies [Hz]
  std::vector<double> psd;         ///< Hann periodogram, block maxima, two-sided [unit^2/Hz]
  std::vector<double> background;  ///< max(model PSD, local level) [unit^2/Hz]
  double threshold_ratio = 0;      ///< family-wise line threshold on psd/background
  int bins_tested = 0;
  double bin_hz = 0, f_min_hz = 0, f_max_hz = 0;
};

/// Held-out comparison of the model before and after extension.
struct GainCheck {
  std::string basis;                 ///< "second_half" or "full_record" (cleaning only)
  double objective_before = 0, objective_after = 0;   ///< GMWM objective (fast weights)
  double deviance_before = 0, deviance_after = 0;     ///< chi-square (gamma) deviance
  int outside_before = 0, outside_after = 0;          ///< scales outside the 95 % CI
  int scales = 0;
  int added_params = 0;
  std::string test;                  ///< the test used, in words
  double z = 0;                      ///< its statistic (positive: after fits better)
  double p_value = 1;                ///< one-sided p-value (H1: the extension fits better)
  std::string direction;             ///< "better", "worse" or "mixed" (deviance and objective)
  bool significant = false;          ///< both criteria better AND p_value < 0.05
};

/// Diagnosis of one channel.
struct ChannelDiagnosis {
  std::string name;
  bool adequate = true;
  std::vector<Finding> findings;
  stochastic::Model model_before;       ///< the user's model (at the data rate)
  stochastic::Model model_after;        ///< extended model (whole-record fit)
  stochastic::Model model_after_half;   ///< extension fitted on the first half
  std::vector<ScaleCheck> scales;       ///< raw record vs model_before
  std::vector<ScaleCheck> scales_after; ///< cleaned record vs model_after
  std::vector<double> wv_cleaned;       ///< WV of the cleaned record [unit^2]
  SpectrumCheck spectrum;
  std::vector<double> line_freqs_hz;    ///< lines found (for plots)
  GainCheck gain;
  double wv_threshold_p = 0;            ///< per-scale p-value threshold used
  /// How the extended structure was refitted by GMWM (whole record / first half):
  /// "gmwm (...)" or "start kept (...)"; empty when nothing was added.
  std::string refit_full, refit_half;
  std::vector<std::string> notes;       ///< e.g. candidate steps explained by a random walk
  /// The misfit no cause explains: scales of the cleaned record against the
  /// extension (scales_after) that the family-wise WV test rejects and that are
  /// material: a factor 2 off or at least one CI width outside the 95 % CI
  /// (smaller misfits are not acted on), e.g. a model overstating the noise.
  /// Any makes the channel inadequate.
  struct Unexplained {
    int scales = 0;                      ///< such scales
    double tau_lo_s = 0, tau_hi_s = 0;   ///< their range [s]
    double ratio = 1;                    ///< measured / model at the scale farthest off
  } unexplained;
  /// Outlier events of this channel: start [s], length [s], peak deviation [SI].
  struct OutlierSpan {
    double t_s = 0, duration_s = 0, size = 0;
  };
  std::vector<OutlierSpan> outlier_events;
};

/// One event seen at the same time on several channels (listed once).
struct Event {
  Cause cause = Cause::Outliers;        ///< level_shift or outliers
  double t_s = 0, duration_s = 0;       ///< start [s] and length [s]
  std::vector<std::string> channels;
  std::vector<double> sizes;            ///< per channel: step size or peak deviation [SI]
};

/// Options of diagnose().
struct DiagnoseOptions {
  int simulations = 8;           ///< Monte-Carlo simulations of the model per channel (0 or >= 2)
  std::uint64_t seed = 20261121; ///< root seed (simulations: deriveSeed(seed, 1000 c + s))
  double alpha = 0.01;           ///< family-wise level for the whole record, in (0, 0.5)
  int max_terms = 3;             ///< most processes added per channel
  int threads = 0;               ///< worker threads over channels (0 = hardware)
  bool allow_large = false;      ///< run above the work budget (limits.hpp)
  /// Called from worker threads with (fraction done 0..1, stage); may be empty.
  std::function<void(double, const std::string&)> progress;
};

// ---------------------------------------------------------------------------
// Navigation gain (optional, with a trajectory)

/// Options of the navigation part: emulate navigation along a trajectory with
/// the MEASURED static errors as the truth (Khaghani et al. 2019), and run the
/// filter with the model before and after the extension over the same data.
struct NavGainOptions {
  emulation::TrajectorySpec trajectory;     ///< reference trajectory (smoothed = truth)
  emulation::SmoothingOptions smoothing;
  /// GNSS outages relative to the first trajectory time, (start, end] [s] (navimpact::parseOutage).
  std::vector<Outage> outages;
  int runs = 10;                  ///< paired realisations (>= 2): recording window + GNSS/baro noise
  std::uint64_t seed = 20261121;  ///< run r: deriveSeed(seed, r), streams 1 GNSS, 2 baro, 3 initial error
  emulation::GnssOptions gnss;    ///< defaults: Table 2 (seed ignored)
  emulation::BaroOptions baro;    ///< defaults: Table 2 (seed ignored)
  bool baro_in_outage = true;
  /// Covariance propagation every k IMU samples (0 = rate / 20 Hz, as the ADIS study).
  int propagate_every = 0;
  /// Initial navigation error sigmas [m x3, m/s x3, rad x3]; drawn per run, P0 of both filters.
  filter::Vector9d initial_sigma = (filter::Vector9d() << 1.0, 1.0, 1.0, 0.1, 0.1, 0.1,
                                    0.2 * 0.017453292519943295, 0.2 * 0.017453292519943295,
                                    1.0 * 0.017453292519943295).finished();
  int threads = 0;                ///< worker threads over runs (0 = hardware)
  bool allow_large = false;       ///< run above the work and memory budgets (limits.hpp)
  double record_rate_hz = 1.0;          ///< error epochs outside outages [Hz]
  double outage_record_rate_hz = 5.0;   ///< error epochs inside outages [Hz]
};

/// Trajectory, perfect IMU and truth prepared once (prepareNavGain()).
struct NavGainPlan;
struct Diagnosis;

/// One outage, before (user's model) and after (extension), over the runs.
struct NavOutageGain {
  double start_s = 0, duration_s = 0;            ///< relative to the trajectory start
  /// Per run: horizontal / vertical error at the outage end, max horizontal drift [m].
  std::vector<double> h_before, h_after, v_before, v_after, drift_before, drift_after;
  /// Per run: position NEES (3 dof) at the outage end.
  std::vector<double> nees_before, nees_after;
  double mean_h_before = 0, mean_h_after = 0;    ///< mean over runs [m]
  double mean_v_before = 0, mean_v_after = 0;
  double mean_drift_before = 0, mean_drift_after = 0;
  double anees_before = 0, anees_after = 0;      ///< mean position NEES at the end
  std::pair<double, double> nees_band{0, 0};     ///< two-sided 95 % band of that mean (chi2(3R)/R)
  int wins = 0;                                  ///< runs where the extension's horizontal error is smaller
  double sign_p = 1;                             ///< exact two-sided sign-test p-value on wins
  double t_p = 1;                                ///< paired t-test p-value on h_before - h_after
  bool significant = false;                      ///< sign_p < 0.05
};

/// Navigation gain of the extension.
struct NavGain {
  std::string trajectory;                 ///< file and duration used
  std::string truth;                      ///< how the measured errors were taken
  std::string filter_after;               ///< which extended model the filter used and why
  std::string settings;                   ///< GNSS, baro, EKF settings (one paragraph)
  std::string filter_note;                ///< how the models were adapted for the filter ("" = as given)
  double imu_rate_hz = 0, duration_s = 0;
  int runs = 0;
  std::uint64_t seed = 0;
  std::vector<double> window_offsets_s;   ///< start of each run's window in the recording [s]
  std::vector<NavOutageGain> outages;
  /// Time series for the figure: epochs [s from start], RMS over runs of the
  /// horizontal and vertical error, RMS predicted 1-sigma, before and after.
  std::vector<double> t_s, rms_h_before, rms_h_after, rms_v_before, rms_v_after,
      sig_h_before, sig_h_after;
  double wall_s = 0;
};

/**
 * Read and smooth the trajectory, check the outages and that the recording
 * (@p samples at @p rate_hz) is long enough, and precompute the perfect IMU and
 * the truth. Call before the (long) diagnosis so bad input fails first.
 * @throws navimpact::Error for an unreadable trajectory, outages outside it,
 *         or a recording too short for the emulation (names both durations).
 */
std::shared_ptr<const NavGainPlan> prepareNavGain(const NavGainOptions& opt, double rate_hz,
                                                  std::size_t samples);

/**
 * Navigation gain: R paired runs; run r takes a window of the measured
 * recording (evenly spaced offsets over the HELD-OUT second half when it is
 * long enough, else over the whole record, with a notice), its mean removed per
 * axis, as the true IMU errors, and seeded GNSS/baro noise and initial error;
 * the filter runs with d.model_before and with the first-half extension
 * (d.channels[i].model_after_half; the whole-record extension when the second
 * half is too short). Stores the result in d.navigation.
 * @param[in] progress  called (serialised) with the fraction done 0..1; may be empty.
 */
void addNavigationGain(Diagnosis& d, const ImuSeries& data, const NavGainPlan& plan,
                       const std::function<void(double)>& progress = {});

/// Whole diagnosis.
struct Diagnosis {
  std::string source;                 ///< input file
  double rate_hz = 0;
  std::size_t samples = 0;
  bool adequate = true;
  std::vector<ChannelDiagnosis> channels;
  stochastic::ImuModel model_before;  ///< at the data rate
  stochastic::ImuModel model_after;
  std::vector<std::string> notices;   ///< e.g. rate conversion
  std::vector<Event> events;          ///< events on two or more channels at once
  DiagnoseOptions options;
  std::optional<NavGain> navigation;  ///< with a trajectory (addNavigationGain)
  double wall_s = 0;                  ///< wall time of diagnose() (timing.json only: never in a result file)
};

/**
 * The options of diagnose() for a record of @p channels x @p samples: alpha,
 * the simulation count (0 or [2, limits::kMaxMonteCarloRuns]) and their work
 * against limits::kDefaultSimulatedSampleBudget unless allow_large. diagnose()
 * calls it; a caller may call it before reading or fitting the data.
 * @throws navimpact::Error naming the option.
 */
void checkDiagnoseOptions(const DiagnoseOptions& opt, std::size_t channels, std::size_t samples);

/**
 * Diagnose @p data against @p model (converted to the data rate, with a notice,
 * when its rate differs).
 * @param[in] data   static recording, SI, >= 2^12 samples per channel.
 * @param[in] model  the user's model.
 * @param[in] opt    see DiagnoseOptions.
 * @throws navimpact::Error for too short records, non-finite samples, a
 *         constant channel or invalid options.
 */
Diagnosis diagnose(const ImuSeries& data, const stochastic::ImuModel& model,
                   const DiagnoseOptions& opt = {});

/// Unit name of a channel's SI unit ("rad/s" or "m/s^2").
std::string channelUnit(const std::string& channel);

}  // namespace navimpact::analysis
