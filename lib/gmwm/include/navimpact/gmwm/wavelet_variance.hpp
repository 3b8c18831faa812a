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
 */
WaveletVariance robustWaveletVariance(const double* x, std::size_t n, double rate_hz,
                                      double eff = 0.6, double alpha = 0.05);

/// Chi-square CI of a WV estimate with eta degrees of freedom.
void wvConfidenceInterval(double wv, double eta, double alpha, double& low, double& high);

/**
 * Overlapping Allan variance (IEEE Std 952) at cluster times @p m_samples
 * (each 1 <= m <= (n-1)/2). AVAR(m) = 1/(2 m^2 (n-2m)) sum_k (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2
 * with theta the cumulative sum / rate (integrated signal).
 */
Eigen::VectorXd allanVariance(const double* x, std::size_t n, const Eigen::VectorXd& m_samples);

}  // namespace navimpact::gmwm
