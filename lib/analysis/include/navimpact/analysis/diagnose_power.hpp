/**
 * @file diagnose_power.hpp
 * @brief Detection power of `navimpact diagnose` (`navimpact diagnose-power`):
 *        records with hidden effects drawn at random over documented ranges,
 *        diagnosed, and judged against the truth.
 *
 * Every hidden effect is scaled to a multiple of its detection limit (the
 * "signal-to-noise" of the table), defined per cause from the detector's own
 * threshold under the record's model (alpha = 1 % for six channels):
 *  - WN, QN, RW, DR, GM: the effect's Haar WV over the model's, in standard
 *    errors of the WV estimate (sqrt(eta_j / 2)), at the best scale; the limit
 *    is the Bonferroni z of the WV test (alpha 0.4 %/(6 J)) for WN and QN,
 *    4x that for RW and DR, 6x for GM (identification, not only detection:
 *    their excess sits in the coarsest scales);
 *  - sinusoid: amplitude over sqrt(6 c S(f) fs / (0.72 N)), the amplitude
 *    whose Hann periodogram peak reaches the threshold c = ln(N / 2 / alpha_s)
 *    with the worst scalloping;
 *  - level shift: size over the smallest threshold x null sd of the window
 *    contrasts that fit around the change;
 *  - outliers: height over the threshold x null sd of the second difference.
 * Draws: rate log-uniform in [50, 1000] Hz, duration or length log-uniform,
 * white noise log-uniform, base model WN, WN+GM or WN+RW, channel, and per
 * cause: sinusoid frequency log-uniform 5/record .. 0.45 rate, GM T
 * log-uniform 2/rate .. record/5, level shift uniform in the middle 80 %,
 * 1-20 outlier events (single spikes or bursts of 2-20 samples).
 */
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"

namespace navimpact::analysis::power {

struct DrawRanges {
  double min_rate_hz = 50, max_rate_hz = 1000;
  /// Record length: durations [s] when max_duration_s > 0, else samples.
  double min_duration_s = 0, max_duration_s = 0;
  std::size_t min_samples = 1 << 16, max_samples = 1 << 18;
  double min_wn = 1e-4, max_wn = 1e-1;  ///< white-noise sigma per sample [SI]
  /// Hidden GM correlation time drawn log-uniform from max(2/rate, this x
  /// record) to record/5 (0: from 2/rate, the whole documented range).
  double min_gm_T_record = 0.0;
};

/// One hidden effect and its truth.
struct Hidden {
  Cause cause = Cause::WhiteNoise;
  std::vector<std::pair<std::string, double>> truth;  ///< as the finding's params
  double snr = 0;        ///< multiple of the detection limit
  int events = 0;        ///< outliers: number of events
  double get(const std::string& key) const;
};

struct Case {
  ImuSeries data;
  stochastic::ImuModel model;
  int channel = 0;             ///< index in data.channels holding the effects
  std::vector<Hidden> hidden;
  std::string text;            ///< the draws, for logs
};

/**
 * Draw a record with the effects @p causes (empty: a null record) on one
 * random channel, each at @p snr_factor x its detection limit.
 * @param[in] channels  1 (a random channel name) or 6 (all, effects on one).
 */
Case drawCase(const std::vector<Cause>& causes, const DrawRanges& ranges, double snr_factor,
              std::uint64_t seed, int channels = 1);

struct Outcome {
  std::vector<bool> detected;  ///< per hidden effect: its channel was called inadequate
  /// ... with a finding of the right cause and parameters, and nothing else.
  /// Parameters: WN sigma, QN Q within 30 %; RW gamma, DR omega within 30 %
  /// or inside the finding's 95 % interval; GM T within a factor 1.5;
  /// sinusoid frequency within 2 bins and amplitude within 30 %; level shift
  /// time within 2 % of the record and size within 30 %; outliers: the count.
  std::vector<bool> right;
  std::string why;             ///< what was wrong (empty when all right)
};

Outcome judge(const Case& c, const Diagnosis& d);

/// " [channel cause key=value ...]" for every finding.
std::string describe(const Diagnosis& d);

/// Options of the sweep (navimpact diagnose-power).
struct PowerOptions {
  std::vector<Cause> causes;          ///< default: all eight
  int runs_per_cause = 40;
  int null_runs = 40;
  double min_snr = 0.25, max_snr = 10;///< snr factor drawn log-uniform in this range
  DrawRanges ranges;
  std::uint64_t seed = 20261124;
  double alpha = 0.01;
  int simulations = 4;
  int threads = 0;
  bool allow_large = false;           ///< run above the work and memory budgets (limits.hpp)
  std::function<void(double)> progress;
};

/**
 * The ranges and budgets of a power sweep, checked before any record is drawn:
 * run counts [0, 1e6] (at least one record in all), SNR (0, 1000], rates within
 * limits::kImuRateHz, records of at least 4096 samples, causes once each,
 * threads [0, 1024], simulations 0 or [2, 1e6]; the simulated samples
 * (records x largest record x channels x (1 + simulations)) within
 * limits::kDefaultSimulatedSampleBudget and the records the workers hold at once
 * within limits::kDefaultMemoryBudgetBytes, unless allow_large.
 * @throws navimpact::Error naming the flag.
 */
void checkPowerOptions(const PowerOptions& opt);

/// The workers of a power sweep: opt.threads when given; for 0 (all cores) the
/// most, up to the hardware's, whose records fit in limits::kDefaultMemoryBudgetBytes,
/// at least 1 (the results do not depend on it).
unsigned powerThreads(const PowerOptions& opt);

struct PowerRun {
  Cause cause = Cause::WhiteNoise;
  double snr = 0, rate_hz = 0, duration_s = 0;
  bool detected = false, right = false;
  std::string why;
};

struct PowerResult {
  PowerOptions options;
  std::vector<PowerRun> runs;     ///< effect runs
  int null_runs = 0, null_alarms = 0;
  double cpu_s = 0, wall_s = 0;
  /// SNR bins (lower edges) of the table.
  std::vector<double> bins = {0.25, 0.5, 1, 2, 5, 10, 20};
};

PowerResult runPower(const PowerOptions& opt);

}  // namespace navimpact::analysis::power
