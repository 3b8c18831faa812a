/**
 * @file lines.hpp
 * @brief Spectral line (sinusoid) test against a noise model's own PSD.
 *
 * Statistic (Whittle / Fisher): the Hann-tapered periodogram of the whole
 * record, I_k = |sum_t w_t x_t e^{-i 2 pi k t / N}|^2 / (fs sum w_t^2), is
 * under a Gaussian stationary null with two-sided PSD S asymptotically
 * E_k * Exp(1), E_k = S convolved with the taper's spectral window
 * (Brillinger 1981 §5.2; Percival & Walden 1993 §6.6). The ratio
 * R_k = I_k / max(E_k, B_k) is tested at every bin from a few cycles per
 * record up to Nyquist, B_k being the record's own local level: a
 * least-squares line of log I against log f over +-100 bins (the +-3 bins
 * around k left out) plus Euler's gamma (E log Exp(1) = -gamma), which
 * follows power-law slopes. max(E, B) >= E, so under the null
 * P(R_k > c) <= e^{-c} exactly as for the model alone, and a broadband misfit
 * of the model (a missing Gauss-Markov process, more white noise) raises B
 * instead of making lines; where B is the larger, the threshold is raised
 * for B's own estimation noise (log-normal, variance 1.5 pi^2 / 6 / m). Family-wise level alpha by Bonferroni over the
 * K tested bins: c = ln(K / alpha). Lines are found one at a time
 * (strongest first), refined on the whole record (zoomed DFT), fitted by
 * least squares and subtracted; harmonics of a line are tagged.
 */
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace navimpact::detect {

/// Two-sided PSD of the null model [unit^2/Hz] at f [Hz], 0 < f <= fs/2.
using PsdFunction = std::function<double(double f_hz)>;

struct LineTestOptions {
  double min_cycles = 4.0;        ///< lowest frequency tested [cycles per record]
  int max_lines = 12;             ///< most lines found per record
  int background_half_width = 100;///< local background half width [bins]
  int guard_bins = 3;             ///< bins on each side left out of the local background
  std::vector<double> exclude_hz; ///< lines the model already has (+-4 bins not tested)
  int max_harmonic = 12;          ///< highest harmonic number tagged
};

struct SpectralLine {
  double freq_hz = 0;       ///< refined frequency [Hz]
  double amplitude = 0;     ///< least-squares amplitude on the whole record [unit]
  double phase_rad = 0;     ///< phase of amplitude * sin(2 pi f t + phase), t from sample 0
  double amp_se = 0;        ///< standard error of the amplitude under the background [unit]
  double freq_se_hz = 0;    ///< standard error of the frequency (Rife & Boorstyn 1974) [Hz]
  double ratio = 0;         ///< I / max(E, B) at the detecting bin
  double model_ratio = 0;   ///< I / E (against the model alone)
  double local_ratio = 0;   ///< I / B (against the record's own neighbourhood)
  double p_value = 1;       ///< Bonferroni-adjusted: min(1, K e^{-ratio})
  double background_psd = 0;///< max(E, B) at the line [unit^2/Hz, two-sided]
  /// Least-squares amplitude and phase on each half of the record (a sinusoid
  /// keeps both; narrow-band noise does not).
  double amp_half[2] = {0, 0}, phase_half[2] = {0, 0};
  int harmonic_of = -1;     ///< index (in the result) of its fundamental, -1 if none
  int harmonic_number = 1;
};

struct LineTestResult {
  std::vector<SpectralLine> lines;  ///< in order of detection (strongest first)
  double threshold = 0;             ///< on the ratio R
  int bins_tested = 0;
  double bin_hz = 0;                ///< fs / N
  double f_min_hz = 0, f_max_hz = 0;///< tested band
  /// Decimated spectrum for plots (<= 4000 points, block maxima of I): two-sided.
  std::vector<double> plot_freq_hz, plot_psd, plot_background;
};

/**
 * Find the spectral lines of @p x against the null PSD @p null_psd.
 * @param[in,out] x      record (any mean); the lines found are subtracted.
 * @param[in] fs         sampling rate [Hz].
 * @param[in] null_psd   two-sided PSD of the null model; may return 0 (then
 *                       only the record's own neighbourhood is the background).
 * @param[in] alpha      family-wise level of this search, in (0, 1).
 * @throws navimpact::Error for fewer than 64 samples or invalid arguments.
 */
LineTestResult detectLines(std::vector<double>& x, double fs, const PsdFunction& null_psd,
                           double alpha, const LineTestOptions& opt = {});

}  // namespace navimpact::detect
