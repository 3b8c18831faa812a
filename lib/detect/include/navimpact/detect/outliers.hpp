/**
 * @file outliers.hpp
 * @brief Outlier events: spikes and short bursts (a knock), robust and calibrated.
 *
 * Statistic: the second difference r_k = x_k - (x_{k-1} + x_{k+1}) / 2, a
 * linear filter whose null variance follows from the model's PSD
 * (var r = integral of S(f) (1 - cos 2 pi f / fs)^2 df). Its scale is
 * s = max(model sd, 1.4826 MAD of r): the MAD is robust to the outliers
 * themselves, and the maximum keeps the null level when the model understates
 * the noise. Where the MAD vanishes (a channel quantised below its quantum,
 * mostly on one level) the robust part is max(classical sd of r, the smallest
 * non-zero step between samples): a level change of one quantum is not an
 * outlier. |r_k - median| > z s is an exceedance, z for alpha by Bonferroni
 * over the N samples (two-sided normal). Exceedances closer than @c gap
 * samples form one event (a burst of consecutive spikes, a knock) instead of
 * several findings.
 */
#pragma once

#include <cstddef>
#include <vector>

namespace navimpact::detect {

struct OutlierOptions {
  std::size_t gap = 10;  ///< exceedances at most this many samples apart are one event
  std::size_t pad = 2;   ///< samples on each side also replaced by cleanOutliers()
  /// cleanOutliers() fill: false = the straight line between the kept
  /// neighbours (spikes and bursts: a few samples); true = the local level and
  /// noise (long excursions such as a knock, where one neighbour's noise would
  /// become a plateau and a noiseless line a variance deficit).
  bool local_fill = false;
};

struct OutlierEvent {
  std::size_t first = 0, last = 0;  ///< first and last exceeding sample
  std::size_t peak = 0;             ///< sample of the largest |r|
  double peak_value = 0;            ///< x[peak] - local level [unit]
  double peak_z = 0;                ///< |r| / s at the peak
  int exceedances = 0;              ///< samples beyond the threshold
};

struct OutlierResult {
  std::vector<OutlierEvent> events;
  double scale = 0;      ///< s [unit]
  double threshold = 0;  ///< z
  /// The MAD of r vanished: more than half of the samples sit on their
  /// neighbours' level, a channel quantised below its quantum.
  bool sub_quantum = false;
  double quantum = 0;    ///< with sub_quantum: the smallest non-zero step between samples [unit]
};

/**
 * @param[in] x           record.
 * @param[in] model_r_sd  null sd of the second difference (0 = robust scale only).
 * @param[in] alpha       family-wise level over the samples, in (0, 1).
 */
OutlierResult detectOutliers(const std::vector<double>& x, double model_r_sd, double alpha,
                             const OutlierOptions& opt = {});

/// Replace each event (padded, len samples) by the straight line between its
/// neighbours, or with OutlierOptions::local_fill by the line between the
/// means of up to len samples on each side plus the deviations of the len
/// samples before it (after it near the start) from their mean: the local
/// level with the neighbours' short-scale noise.
void cleanOutliers(std::vector<double>& x, const std::vector<OutlierEvent>& events,
                   const OutlierOptions& opt = {});

}  // namespace navimpact::detect
