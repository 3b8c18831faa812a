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
    // Heavily quantised records: the MAD may vanish; use the classical sd.
    double q = 0;
    for (double v : sub) q += (v - med) * (v - med);
    s = std::sqrt(q / static_cast<double>(std::max<std::size_t>(1, sub.size() - 1)));
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
    const bool have = a1 > a0 && b1 > b0;
    ma = have ? ma / static_cast<double>(a1 - a0) : 0.0;
    mb = have ? mb / static_cast<double>(b1 - b0) : 0.0;
    const double level = 0.5 * (ma + mb);
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
  for (const auto& e : events) {
    const std::size_t a = e.first > opt.pad + 1 ? e.first - opt.pad - 1 : 0;  // kept
    const std::size_t b = std::min(n - 1, e.last + opt.pad + 1);             // kept
    if (b <= a + 1) continue;
    if (!opt.local_fill) {
      const double xa = x[a], xb = x[b];
      for (std::size_t k = a + 1; k < b; ++k)
        x[k] = xa + (xb - xa) * static_cast<double>(k - a) / static_cast<double>(b - a);
      continue;
    }
    const std::size_t len = b - a - 1;  // samples replaced
    // The level on each side is the mean of up to len samples there (the kept
    // neighbour included): across a long span one sample's noise would be a
    // plateau of that size. The replaced samples take the deviations of the
    // len samples before (or after) from their mean, so that the span keeps
    // the short-scale variance of its neighbours instead of a noiseless line.
    const std::size_t a0 = a + 1 >= len ? a + 1 - len : 0, b1 = std::min(n, b + len);
    double ma = 0, mb = 0;
    for (std::size_t k = a0; k <= a; ++k) ma += x[k];
    for (std::size_t k = b; k < b1; ++k) mb += x[k];
    ma /= static_cast<double>(a + 1 - a0);
    mb /= static_cast<double>(b1 - b);
    std::vector<double> dev(len, 0.0);
    if (a + 1 - a0 == len)
      for (std::size_t i = 0; i < len; ++i) dev[i] = x[a0 + i] - ma;
    else if (b1 - b == len)
      for (std::size_t i = 0; i < len; ++i) dev[i] = x[b + i] - mb;
    for (std::size_t k = a + 1; k < b; ++k)
      x[k] = ma + (mb - ma) * static_cast<double>(k - a) / static_cast<double>(b - a) + dev[k - a - 1];
  }
}

}  // namespace navimpact::detect
