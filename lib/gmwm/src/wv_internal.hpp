// Internal helpers shared by the wavelet-variance sources (not installed).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "navimpact/gmwm/wavelet_variance.hpp"

namespace navimpact::gmwm::detail {

/// A WV of @p J scales with every per-scale vector sized (values to fill),
/// the rate, the samples used and whether it is the robust estimator.
WaveletVariance sizedWv(int J, double rate_hz, std::size_t n, bool robust);

/// Largest J with 2^J <= n (floor(log2 n)).
int maxLevel(std::size_t n);

/// Throws navimpact::Error for n < 4, a non-finite sample or a constant signal.
void checkSeries(const double* x, std::size_t n);

/// Sum of squares of m values, accurate to ~1e-15 relative.
double sumSquares(const double* w, std::size_t m);

/**
 * Tukey-biweight M-estimate of the variance of @p m values (not centred) at
 * asymptotic Gaussian efficiency @p eff in (0, 1). Returns 0 when all values are equal,
 * w[0]^2 for a single value.
 */
double robustScale(const double* w, std::size_t m, double eff);

/// Same with the biweight constant @p c and its consistency constant @p a = E[chi(Z)].
/// When the biweight scale equation has no root (more outlying values than its
/// breakdown point, e.g. isolated spikes spread over tau coefficients at scale tau),
/// returns the median-absolute-value scale (median |w| / 0.6745)^2 and sets
/// @p mad_fallback (Gaussian efficiency of that estimator: kMadEfficiency).
/// When that is zero too (more than half of the values are zero: a record
/// quantised below its quantum) returns the classical mean of w^2 and sets
/// @p classical_fallback.
double robustScale(const double* w, std::size_t m, double c, double a, bool* mad_fallback = nullptr,
                   bool* classical_fallback = nullptr);

/// Asymptotic Gaussian efficiency of the MAD scale (Hampel et al. 1986): 0.3674.
constexpr double kMadEfficiency = 0.3674;

/**
 * Sums of squares of the kept Haar MODWT coefficients of levels 1..J
 * (element j-1 for level j), computed cache-blocked without storing W.
 */
std::vector<long double> haarModwtSumSquares(const double* x, std::size_t n, int J);

/**
 * Haar MODWT pyramid, levels 1..J; calls onLevel(j, W_j, M_j) with the M_j =
 * n - 2^j + 1 boundary-free coefficients of level j (buffer valid during the call).
 */
void haarModwtLevels(const double* x, std::size_t n, int J,
                     const std::function<void(int, const double*, std::size_t)>& onLevel);

}  // namespace navimpact::gmwm::detail
