/**
 * @file change_points.hpp
 * @brief Level shifts (change points in the mean) under a correlated noise model.
 *
 * Statistic: the equal-window contrast D(k, m) = mean(x[k, k+m)) -
 * mean(x[k-m, k)), i.e. twice the Haar MODWT coefficient at scale tau = 2m,
 * whose variance under ANY null model with stationary increments (white
 * noise, quantisation, Gauss-Markov, random walk) is 4 nu^2(2m), nu^2 the
 * model's Haar wavelet variance (Percival & Walden 2000 §8.1): the contrast
 * is the likelihood-ratio statistic of one change in the window scaled by the
 * model's own long-window variance, valid where a CUSUM scaled by a finite
 * long-run variance is not (random walk). Half-widths m on a geometric grid
 * (ratio sqrt 2) from @c min_half_width to N/2, positions on a grid of
 * stride max(1, m/8) (loss at most 1/16 of the contrast); z = |D| / sd with
 * sd = max(2 nu(2m), robust sd of D at that scale where at least 64
 * independent windows exist), so a broadband misfit of the model cannot make
 * steps and the null level still holds. Family-wise level alpha: alpha/J per
 * half-width, Bonferroni over its P_m grid positions (two-sided normal).
 * Multiple changes by detect-and-remove (binary segmentation's greedy
 * variant): the most significant change is removed from the rest of the
 * record and the search repeated. Changes closer than their detecting
 * windows whose sizes cancel are reported as one transient; those whose
 * sizes do not cancel are merged into one change.
 */
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace navimpact::detect {

/// Haar wavelet variance of the null model at scale tau [samples] (tau = 2m, m >= 1).
using HaarWvFunction = std::function<double(double tau_samples)>;

struct ChangePointOptions {
  int max_changes = 10;            ///< most changes found
  std::size_t min_half_width = 8;  ///< smallest window on each side [samples]
  double scale_ratio = 1.41421356237;
  /// Changes within this many samples of the first of their cluster are one
  /// cluster too (besides those closer than the smaller of their windows): a
  /// short excursion's edges may be found in windows shorter than it. 0: off.
  std::size_t max_transient = 0;
};

struct ChangePoint {
  std::size_t index = 0;       ///< first sample after the change
  double size = 0;             ///< mean after - mean before [unit] (adjacent segments)
  double contrast = 0;         ///< D at the detecting window [unit]
  std::size_t half_width = 0;  ///< detecting window m [samples]
  double sd = 0;               ///< null sd of D at that window [unit]
  double z = 0;                ///< |D| / sd
  double threshold = 0;        ///< Bonferroni threshold on z at that window
  double p_value = 1;          ///< Bonferroni-adjusted p-value
};

/// Changes closer together than their detecting windows (or within
/// ChangePointOptions::max_transient of the first) whose sizes cancel (net below half the largest): a transient (a knock, a
/// bump), not shifts.
struct Transient {
  std::size_t first = 0, last = 0;  ///< first and last change index
  double peak = 0;                  ///< largest level reached relative to before [unit]
  double z = 0, threshold = 0, p_value = 1;  ///< of its strongest change
  std::size_t half_width = 0;       ///< detecting window of its strongest change [samples]
};

struct ChangePointResult {
  std::vector<ChangePoint> changes;  ///< in order of detection (transients taken out)
  std::vector<Transient> transients;
  int scales_tested = 0;
};

/// A transient candidate [first, last) judged on its own under a null model.
struct TransientTest {
  std::size_t half_width = 0;  ///< window matched to the duration, max(min_half_width, last - first) [samples]
  double level = 0;            ///< mean inside minus the mean of the windows on both sides [unit]
  double z = 0;                ///< larger |edge contrast| over its null sd 2 nu(2m)
  double threshold = 0;        ///< the search's threshold at that window (Bonferroni as detectChangePoints)
  double p_value = 1;          ///< Bonferroni-adjusted p-value
  bool significant() const { return z > threshold; }
};

/**
 * Judge the transient [first, last) of @p x (the record as searched, the
 * transient still in it) under the null whose Haar WV is @p null_wv: the
 * equal-window contrasts at its two edges with the window m matched to its
 * duration (m = max(min_half_width, last - first), clipped to the record), so
 * that the excursion is measured at its own scale whatever window first
 * found it. The threshold is detectChangePoints' at that window (alpha over
 * the scales and their grid positions): the candidate came out of that search.
 * @throws navimpact::Error for an empty or out-of-range span or invalid alpha.
 */
TransientTest testTransient(const std::vector<double>& x, std::size_t first, std::size_t last,
                            const HaarWvFunction& null_wv, double alpha, const ChangePointOptions& opt = {});

/**
 * Detect level shifts in @p x under the null whose Haar WV is @p null_wv.
 * @param[in,out] x  record; each change found is removed (x[k >= index] -= size).
 * @param[in] alpha  family-wise level of the search, in (0, 1).
 * @throws navimpact::Error for fewer than 4 min_half_width samples or invalid alpha.
 */
ChangePointResult detectChangePoints(std::vector<double>& x, const HaarWvFunction& null_wv,
                                     double alpha, const ChangePointOptions& opt = {});

}  // namespace navimpact::detect
