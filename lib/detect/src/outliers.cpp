// Outlier events: second-difference exceedances, clustered (see outliers.hpp).
#include "navimpact/detect/outliers.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "navimpact/core/error.hpp"
#include "robust.hpp"

namespace navimpact::detect {

OutlierResult detectOutliers(const std::vector<double>& x, double model_r_sd, double alpha,
                             const OutlierOptions& opt) {
  if (!(alpha > 0 && alpha < 1)) throw Error("detectOutliers: alpha must be in (0, 1)");
  OutlierResult out;
  const std::size_t n = x.size();
  if (n < 16) return out;
  std::vector<double> r(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) r[k] = x[k] - 0.5 * (x[k - 1] + x[k + 1]);
  // Robust scale from a subsample (every s-th value, <= 2^18 values).
  const std::size_t stride = std::max<std::size_t>(1, (n - 2) >> 18);
  std::vector<double> sub;
  sub.reserve((n - 2) / stride + 1);
  for (std::size_t k = 1; k + 1 < n; k += stride) sub.push_back(r[k]);
  double med = 0;
  double s = madScale(sub, &med);
  if (!(s > 0)) {
    // More than half of r equal: a channel quantised below its quantum (a
    // still gyro at 0.1 deg/s resolution sits on one level). The classical sd
    // is then set by the few level changes, which would all exceed its
    // threshold and be cleaned out down to a constant record. Nothing finer
    // than the quantum -- the smallest non-zero step between samples -- is
    // resolved, so the scale is at least that.
    double q = 0, quantum = 0;
    for (double v : sub) q += (v - med) * (v - med);
    s = std::sqrt(q / static_cast<double>(std::max<std::size_t>(1, sub.size() - 1)));
    for (std::size_t k = 1; k < n; ++k) {
      const double d = std::abs(x[k] - x[k - 1]);
      if (d > 0 && (quantum == 0 || d < quantum)) quantum = d;
    }
    s = std::max(s, quantum);
    out.sub_quantum = true;
    out.quantum = quantum;
  }
  s = std::max(s, model_r_sd);
  out.scale = s;
  out.threshold = twoSidedNormalQuantile(alpha / static_cast<double>(n - 2));
  if (!(s > 0)) return out;
  const double thr = out.threshold * s;
  std::vector<std::size_t> exc;
  for (std::size_t k = 1; k + 1 < n; ++k)
    if (std::abs(r[k] - med) > thr) exc.push_back(k);
  // Cluster exceedances; an event whose two sides sit at different levels is
  // the edge of a level shift, not an outlier: left to the change-point test.
  for (std::size_t i = 0; i < exc.size();) {
    std::size_t j = i;
    while (j + 1 < exc.size() && exc[j + 1] - exc[j] <= opt.gap) ++j;
    OutlierEvent e;
    e.first = exc[i];
    e.last = exc[j];
    e.exceedances = static_cast<int>(j - i + 1);
    double best = -1;
    for (std::size_t q = i; q <= j; ++q) {
      const double a = std::abs(r[exc[q]] - med);
      if (a > best) {
        best = a;
        e.peak = exc[q];
      }
    }
    e.peak_z = best / s;
    // Local levels on both sides (windows of max(32, 4 x event length)).
    const std::size_t len = e.last - e.first + 1;
    const std::size_t w = std::max<std::size_t>(32, 4 * len);
    const std::size_t a0 = e.first >= w + 1 ? e.first - 1 - w : 0, a1 = e.first > 0 ? e.first - 1 : 0;
    const std::size_t b0 = std::min(n, e.last + 2), b1 = std::min(n, e.last + 2 + w);
    double ma = 0, mb = 0;
    for (std::size_t k = a0; k < a1; ++k) ma += x[k];
    for (std::size_t k = b0; k < b1; ++k) mb += x[k];
    const bool has_a = a1 > a0, has_b = b1 > b0, have = has_a && has_b;
    ma = has_a ? ma / static_cast<double>(a1 - a0) : 0.0;
    mb = has_b ? mb / static_cast<double>(b1 - b0) : 0.0;
    const double level = have ? 0.5 * (ma + mb) : has_a ? ma : mb;
    // r is not defined at the end samples: a spike on one shows only next to
    // it, so an event there takes the end sample when that is further from
    // the level.
    if (e.first == 1 && std::abs(x[0] - level) > std::abs(x[e.peak] - level)) {
      if (e.last == 1) e.last = 0;  // the exceedance was the spike's neighbour
      e.first = e.peak = 0;
    }
    if (e.last == n - 2 && std::abs(x[n - 1] - level) > std::abs(x[e.peak] - level)) {
      if (e.first == n - 2) e.first = n - 1;
      e.last = e.peak = n - 1;
    }
    e.peak_value = x[e.peak] - level;
    // r at a step of size S is +-S/2 on two samples, so |mb - ma| ~ 2 |r|; at
    // a spike or a burst it is ~0.
    const bool step_like = have && std::abs(mb - ma) > 0.5 * std::abs(r[e.peak] - med);
    if (!step_like) out.events.push_back(e);
    i = j + 1;
  }
  return out;
}

void cleanOutliers(std::vector<double>& x, const std::vector<OutlierEvent>& events,
                   const OutlierOptions& opt) {
  const std::size_t n = x.size();
  // The statistic r is not defined at the two end samples, so a spike on one
  // shows as an exceedance next to it, and a padded span may reach past the
  // end: an event within max(pad, 1) samples of an end takes the end sample
  // with it and is filled from its one kept side.
  const std::size_t reach = std::max<std::size_t>(opt.pad, 1);
  for (const auto& e : events) {
    if (n < 3 || e.last >= n) continue;
    const bool open_start = e.first <= reach;
    const bool open_end = e.last + reach >= n - 1;
    if (open_start && open_end) continue;  // no kept sample on either side
    // Replaced: samples lo..hi-1; kept neighbours lo-1 (unless open_start) and hi (unless open_end).
    const std::size_t lo = open_start ? 0 : e.first - opt.pad;
    const std::size_t hi = open_end ? n : e.last + opt.pad + 1;
    const std::size_t len = hi - lo;
    if (!opt.local_fill) {
      const double xa = open_start ? x[hi] : x[lo - 1], xb = open_end ? x[lo - 1] : x[hi];
      for (std::size_t k = lo; k < hi; ++k)
        x[k] = xa + (xb - xa) * static_cast<double>(k - lo + 1) / static_cast<double>(len + 1);
      continue;
    }
    // The level on each side is the mean of up to len samples there (the kept
    // neighbour included): across a long span one sample's noise would be a
    // plateau of that size. The replaced samples take the deviations of the
    // len samples before (or after) from their mean, so that the span keeps
    // the short-scale variance of its neighbours instead of a noiseless line.
    const std::size_t a0 = lo >= len ? lo - len : 0, b1 = std::min(n, hi + len);
    double ma = 0, mb = 0;
    for (std::size_t k = a0; k < lo; ++k) ma += x[k];
    for (std::size_t k = hi; k < b1; ++k) mb += x[k];
    if (!open_start) ma /= static_cast<double>(lo - a0);
    if (!open_end) mb /= static_cast<double>(b1 - hi);
    if (open_start) ma = mb;
    if (open_end) mb = ma;
    std::vector<double> dev(len, 0.0);
    if (lo - a0 == len)
      for (std::size_t i = 0; i < len; ++i) dev[i] = x[a0 + i] - ma;
    else if (b1 - hi == len)
      for (std::size_t i = 0; i < len; ++i) dev[i] = x[hi + i] - mb;
    for (std::size_t k = lo; k < hi; ++k)
      x[k] = ma + (mb - ma) * static_cast<double>(k - lo + 1) / static_cast<double>(len + 1) + dev[k - lo];
  }
}

}  // namespace navimpact::detect
