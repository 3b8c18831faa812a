/**
 * @file channels.hpp
 * @brief GMWM on every channel of a recording: the wavelet variance (and
 *        Allan deviation) of each channel, and the fit of one structure, or
 *        the automatic selection, to each channel, giving an ImuModel.
 *        Used by `navimpact wv`, `navimpact fit` and `diagnose --model fit:SPEC`.
 */
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "navimpact/core/imu_series.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::gmwm {

// ---------------------------------------------------------------------------
// Wavelet variance of a recording

/// Wavelet variance of one channel, with its overlapping Allan deviation when asked.
struct ChannelWv {
  std::string name;                 ///< canonical channel name, e.g. "gyro_z"
  units::Quantity quantity{};       ///< fixes the SI unit
  WaveletVariance wv;
  std::vector<double> allan_tau_s;  ///< cluster times m / rate, m = 1, 2, 4, ... <= N/2 [s]
  std::vector<double> adev;         ///< overlapping Allan deviation (IEEE Std 952) [unit]
};

/// Wavelet variances of every channel of a recording.
struct RecordingWv {
  std::string source;               ///< the recording (file path)
  double rate_hz = 0.0;
  std::size_t samples = 0;
  WvOptions options;
  bool allan = false;               ///< Allan deviations computed
  std::vector<ChannelWv> channels;  ///< in the order of the recording's channels
};

/// WV of every channel of @p s (gmwm::waveletVariances) and, with @p allan, its Allan deviation.
RecordingWv recordingWv(const ImuSeries& s, const WvOptions& opt, bool allan);

// ---------------------------------------------------------------------------
// Fit of a recording

/// What to fit (the options of `navimpact fit`).
struct RecordingFitOptions {
  std::string structure = "auto";     ///< "auto" (WIC selection) or a structure, e.g. "WN+GM+GM+DR"
  std::vector<std::string> channels;  ///< channels to fit, canonical names (empty: every channel)
  int max_gm = 3;                     ///< auto: most GM terms among the candidates, 0..3
  std::string weights = "r";          ///< "r" (the R package's), "model" or "efficient"
  std::string intervals = "profile";  ///< 95 % intervals without bootstrap: "profile" or "asymptotic"
  /// Robust GMWM (Guerrier, Molinari & Victoria-Feser 2014): fit the robust
  /// WV (Tukey biweight M-scale at efficiency eff) with its own CI and weights,
  /// of the record with its isolated spikes replaced first (despike()).
  bool robust = false;
  double eff = 0.6;                   ///< robust: efficiency of the robust WV, in (0, 1)
  int bootstrap = 0;                  ///< parametric bootstrap replicates, 0 or [kMinBootstrap (39), 10000]
  std::uint64_t seed = 20190101;      ///< root seed; channel c uses deriveSeed(seed, channelIndex(c))
  bool allow_large = false;           ///< bootstrap above the simulated-sample budget (limits.hpp)
};

/**
 * Check @p opt before any data is read.
 * @throws navimpact::Error naming the option (structure text with its
 *         position, --max-gm, --weights, --intervals, --bootstrap, --channels).
 */
void checkRecordingFitOptions(const RecordingFitOptions& opt);

/// The fit of one channel.
struct ChannelFit {
  std::string name;                  ///< canonical channel name
  units::Quantity quantity{};
  WaveletVariance wv;                ///< the empirical WV the model was fitted to
  std::size_t despiked = 0;          ///< robust: isolated spikes replaced before the robust WV (despike())
  FitResult fit;
  std::vector<bool> negligible;      ///< per term of fit.model (negligibleTerms)
  /// Scales (indices into wv) where the model WV lies outside the WV's 95 % CI (scalesOutsideCi).
  std::vector<int> outside_ci;
  /// Non-empty when GMs with T below stochastic::kWhiteGmMaxSamples samples
  /// carry white noise: which, their lag-1 correlation, their share of the
  /// noise density, and whether the WN term vanished.
  std::string white_noise_note;
  /// Non-empty when a GM is a random walk over this record (slowGmNote).
  std::string slow_gm_note;
  std::vector<RankedModel> ranking;  ///< auto: every candidate, best first
  std::string why;                   ///< auto: why the pick was chosen
};

/**
 * What a fitted model does with the white noise of the data when GMs with T
 * below stochastic::kWhiteGmMaxSamples samples carry it (their PSD is flat up
 * to Nyquist): which GMs, T in seconds and samples, lag-1 correlation phi,
 * their share of the noise density N^2 (stochastic::datasheetFigures) and
 * whether the model's WN term is negligible (@p negligible, one flag per term,
 * from negligibleTerms). Empty when no such GM exists.
 * @throws navimpact::Error when @p negligible does not have one flag per term.
 */
std::string whiteNoiseNote(const stochastic::Model& m, const std::vector<bool>& negligible);

/**
 * What a fitted model says with a GM whose T is so long against the record that
 * over it the GM is a random walk: for each GM with T beyond the record, seen
 * by the data (its WV at least kNegligibleFraction of the CI width at some
 * scale), whose Haar WV and that of
 * RW(gamma = sigma sqrt(1 - phi^2)), phi = exp(-1/(rate T)) (the GM's
 * increment per sample), differ by less than kNegligibleFraction of the WV's
 * 95 % CI width at every scale of @p wv, the note names the GM, its T in s and
 * in records (and whether it sits on the fit's upper bound, 1000 records), the
 * equivalent RW, and that the data fix sigma^2 / T, not sigma, which a filter
 * takes as the term's initial uncertainty. Empty when no such GM exists.
 * (fit --structure WN+GM+GM+GM on 600 s wrote GM(sigma=0.27 m/s^2, T=6e5 s)
 * into model.yaml without a word.)
 */
std::string slowGmNote(const stochastic::Model& m, const WaveletVariance& wv);

/// The fits of a recording.
struct RecordingFit {
  RecordingFitOptions options;
  std::string source;                ///< the recording (file path)
  double rate_hz = 0.0;
  std::size_t samples = 0;
  std::vector<ChannelFit> channels;  ///< fitted channels, in the order asked
  /// Per-axis models at rate_hz (the form model files hold); channels not fitted are "none".
  stochastic::ImuModel model;
};

/**
 * Fit every channel asked of @p s: the structure of @p opt, or with "auto"
 * the candidates of defaultCandidates(max_gm) ranked by the WIC with R's
 * weights (the WIC's optimism is derived for them), the pick refitted with
 * the requested weights.
 * @param[in] progress  optional callback(done, total) after each channel.
 * @throws navimpact::Error "SOURCE: channel NAME: ..." when a fit fails, or
 *         for invalid options (checkRecordingFitOptions) and unknown channels.
 */
RecordingFit fitRecording(const ImuSeries& s, const RecordingFitOptions& opt,
                          const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace navimpact::gmwm
