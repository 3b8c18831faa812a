/**
 * @file wavelet_variance.hpp
 * @brief Empirical Haar MODWT wavelet variance with the R package's 95 % CI,
 *        Allan variance and a robust wavelet variance.
 *
 * Scales tau_j = 2^j samples, j = 1..floor(log2 N); boundary coefficients
 * dropped ("brick wall"), M_j = N - 2^j + 1 kept; CI from a chi-square with
 * eta_j = max(M_j / 2^j, 1) degrees of freedom (Percival's eta3), as in the R
 * package gmwm 3.0.0 (shared/reference/gmwm_formulas.md §1–2).
 */
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "navimpact/core/imu_series.hpp"

namespace navimpact::gmwm {

struct WaveletVariance {
  Eigen::VectorXd tau;       ///< scales [samples], 2^j
  Eigen::VectorXd wv;        ///< wavelet variance [unit^2]
  Eigen::VectorXd ci_low;    ///< lower bound of the (1 - alpha) CI [unit^2]
  Eigen::VectorXd ci_high;   ///< upper bound [unit^2]
  Eigen::VectorXd n_coef;    ///< M_j, kept coefficients per scale
  Eigen::VectorXd eta;       ///< equivalent degrees of freedom per scale
  double rate_hz = 0.0;      ///< to express tau in seconds: tau / rate_hz
  std::size_t n = 0;         ///< samples used
  bool robust = false;
  /// Asymptotic efficiency of the estimator relative to the classical WV at
  /// the Gaussian (1 classical; robust: its eff): Var(wv_j) = 2 wv_j^2 / (eta_j eff).
  /// The GMWM's model-based and efficient weights and its asymptotic intervals use it.
  double eff = 1.0;
  /// Robust: scales (indices) where the biweight broke down (more outlying
  /// coefficients than it tolerates) and the MAD scale was used instead.
  std::vector<int> mad_scales;
  /// Robust: scales where more than half of the coefficients are zero (a
  /// record quantised below its quantum), so that neither scale is defined
  /// and the classical WV (no robustness, classical CI) is used.
  std::vector<int> classical_scales;

  int scales() const { return static_cast<int>(tau.size()); }
  Eigen::VectorXd tauSeconds() const { return tau / rate_hz; }
  /// GMWM "fast" weights of the R package: 1 / (ci_high - ci_low)^2.
  Eigen::VectorXd weights() const;
};

/**
 * Classical Haar MODWT WV of @p n samples.
 * @param[in] x       samples (any unit; WV is in its square).
 * @param[in] n       number of samples, >= 4 (two scales).
 * @param[in] rate_hz sampling rate [Hz], stored for conversions.
 * @param[in] alpha   CI level, default 0.05 for 95 %.
 * @param[in] max_j   largest level (0 = floor(log2 n)).
 * @throws navimpact::Error for fewer than 4 samples, non-finite values or a constant signal.
 */
WaveletVariance waveletVariance(const double* x, std::size_t n, double rate_hz,
                                double alpha = 0.05, int max_j = 0);

/**
 * Robust WV: Tukey-biweight M-estimator of scale of the wavelet coefficients
 * at efficiency @p eff (0.6 as in the R package), CI inflated by 1/sqrt(eff).
 * Where the biweight breaks down (its scale equation has no root: isolated
 * spikes touch tau coefficients at scale tau, so their share grows with the
 * scale) the MAD scale (median |w| / 0.6745)^2 is used, CI inflated by
 * 1/sqrt(0.3674), and the scale is listed in mad_scales. Where the MAD is
 * zero too (more than half of the coefficients zero: a record quantised below
 * its quantum) the classical WV is used and the scale is listed in
 * classical_scales.
 */
WaveletVariance robustWaveletVariance(const double* x, std::size_t n, double rate_hz,
                                      double eff = 0.6, double alpha = 0.05);

/**
 * The efficiencies the biweight reaches with tuning constants c in
 * [2.77, 60] (0.05 .. 0.999985): what robustWaveletVariance accepts. Smaller
 * c (below c0 ~ 2.42 the efficiency rises again) put the Gaussian root of the
 * scale equation on the branch that is not solved: the WV came out 1e4-1e5 too large.
 * @throws navimpact::Error "efficiency E is outside what the biweight reaches
 *         (lo .. hi)" for any other @p eff (NaN included); a CLI checks --eff
 *         with it before reading a file.
 */
void checkRobustEfficiency(double eff);

/**
 * Replace isolated spikes in place, before a robust WV: the second difference
 * d_k = x_k - (x_{k-1} + x_{k+1}) / 2 against its robust scale (1.4826 x the
 * median absolute deviation, taken once), Bonferroni over the n - 2 samples
 * at @p alpha (two-sided); a sample whose |d - median d| exceeds it and is a
 * local maximum of |d| is replaced by the mean of its neighbours, repeated
 * until none exceeds (a burst of spikes goes sample by sample).
 *
 * Why: a spike of amplitude A touches tau coefficients at scale tau with
 * A / tau each, so the biweight down-weights it only at the finest scales
 * (tau <~ (A / sigma)^2 / c^2); beyond, its variance enters the robust WV like
 * white noise that starts at a middle scale, which a GM takes up with a much
 * shorter T. Gaussian data keep every sample with probability >= 1 - alpha.
 * The first and last samples are tested against their one neighbour.
 * @return the number of samples replaced (each counted once).
 */
std::size_t despike(std::vector<double>& x, double alpha = 0.01);

/// Chi-square CI of a WV estimate with eta degrees of freedom.
void wvConfidenceInterval(double wv, double eta, double alpha, double& low, double& high);

/**
 * Overlapping Allan variance (IEEE Std 952) at cluster times @p m_samples
 * (each an integer, 1 <= m <= n/2), in sample units (cluster time m / rate_hz):
 * AVAR(m) = 1/(2 m^2 K) sum_{k=0}^{K-1} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2,
 * K = n - 2m + 1, theta_k = sum_{i<k} x_i (integrated signal, theta_0 = 0).
 * With this count AVAR(m) = 2 nu^2(tau = 2m) exactly (same terms as the WV).
 * @param[in] x          samples (any unit; AVAR is in its square).
 * @param[in] n          number of samples, >= 4.
 * @param[in] m_samples  cluster sizes [samples].
 * @return AVAR for each m [unit^2].
 * @throws navimpact::Error for bad data (as waveletVariance) or a bad m.
 */
Eigen::VectorXd allanVariance(const double* x, std::size_t n, const Eigen::VectorXd& m_samples);

/// Options of the batch computation over the channels of a series.
struct WvOptions {
  double alpha = 0.05;  ///< CI level (0.05 for 95 %), in (0, 1)
  bool robust = false;  ///< Tukey-biweight robust WV instead of the classical one
  double eff = 0.6;     ///< efficiency of the robust estimator, in (0, 1)
  int max_j = 0;        ///< largest level for the classical WV (0 = floor(log2 n))
  int threads = 0;      ///< worker threads (0 = hardware concurrency), channels in parallel
};

/**
 * WV of every channel of @p s, in channel order, channels processed in parallel.
 * @param[in] s    series (SI units); its rate_hz is stored in each result.
 * @param[in] opt  see WvOptions.
 * @return one WaveletVariance per channel of @p s.
 * @throws navimpact::Error "SOURCE: channel NAME: ..." for the first channel
 *         (in channel order) with bad data.
 */
std::vector<WaveletVariance> waveletVariances(const ImuSeries& s, const WvOptions& opt = {});

}  // namespace navimpact::gmwm
