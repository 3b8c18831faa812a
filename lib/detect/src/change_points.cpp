// Level shifts under a correlated noise model (see change_points.hpp).
#include "navimpact/detect/change_points.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <boost/math/distributions/normal.hpp>

#include "navimpact/core/error.hpp"
#include "robust.hpp"

namespace navimpact::detect {

namespace {

struct Scale {
  std::size_t m = 0, stride = 1, positions = 0;
  double sd = 0, threshold = 0;
};

/// Mean of x over [a, b) from prefix sums.
inline double meanOf(const std::vector<double>& S, std::size_t a, std::size_t b) {
  return (S[b] - S[a]) / static_cast<double>(b - a);
}

std::vector<double> prefix(const std::vector<double>& x) {
  std::vector<double> S(x.size() + 1, 0.0);
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(std::max<std::size_t>(1, x.size()));
  for (std::size_t k = 0; k < x.size(); ++k) S[k + 1] = S[k] + (x[k] - mean);
  return S;
}

/// The search's windows: half-widths on a geometric grid from
/// min_half_width to n / 2, positions on a grid of stride max(1, m / 8).
std::vector<Scale> scaleGrid(std::size_t n, const ChangePointOptions& opt) {
  std::vector<Scale> scales;
  for (double mf = static_cast<double>(opt.min_half_width); 2.0 * std::floor(mf) <= static_cast<double>(n);
       mf *= opt.scale_ratio) {
    const std::size_t m = static_cast<std::size_t>(std::floor(mf));
    if (!scales.empty() && scales.back().m == m) continue;
    Scale s;
    s.m = m;
    s.stride = std::max<std::size_t>(1, m / 8);
    s.positions = (n - 2 * m) / s.stride + 1;
    scales.push_back(s);
  }
  return scales;
}

}  // namespace

TransientTest testTransient(const std::vector<double>& x, std::size_t first, std::size_t last,
                            const HaarWvFunction& null_wv, double alpha, const ChangePointOptions& opt) {
  if (!(alpha > 0 && alpha < 1)) throw Error("testTransient: alpha must be in (0, 1)");
  const std::size_t n = x.size();
  if (!(first < last && last < n) || first == 0)
    throw Error("testTransient: span [" + std::to_string(first) + ", " + std::to_string(last) +
                ") is not inside a record of " + std::to_string(n) + " samples");
  TransientTest t;
  const auto scales = scaleGrid(n, opt);
  const double J = static_cast<double>(std::max<std::size_t>(1, scales.size()));
  const std::size_t m = std::min({std::max(opt.min_half_width, last - first), first, n - last});
  t.half_width = m;
  const auto S = prefix(x);
  const double inside = meanOf(S, first, last);
  // Edge contrasts (windows on both sides of each edge; first >= m and
  // last + m <= n by the clipping of m).
  const double d1 = meanOf(S, first, first + m) - meanOf(S, first - m, first);
  const double d2 = meanOf(S, last - m, last) - meanOf(S, last, last + m);
  t.level = inside - 0.5 * (meanOf(S, first - m, first) + meanOf(S, last, last + m));
  const double sd = 2.0 * std::sqrt(std::max(0.0, null_wv(2.0 * static_cast<double>(m))));
  t.z = sd > 0 ? std::max(std::abs(d1), std::abs(d2)) / sd : 0.0;
  const std::size_t stride = std::max<std::size_t>(1, m / 8);
  const double positions = static_cast<double>((n - 2 * std::min(m, n / 2)) / stride + 1);
  t.threshold = twoSidedNormalQuantile(alpha / (J * positions));
  const double p1 = 2.0 * boost::math::cdf(boost::math::complement(boost::math::normal(), t.z));
  t.p_value = std::min(1.0, p1 * J * positions);
  return t;
}

ChangePointResult detectChangePoints(std::vector<double>& x, const HaarWvFunction& null_wv,
                                     double alpha, const ChangePointOptions& opt) {
  if (!(alpha > 0 && alpha < 1)) throw Error("detectChangePoints: alpha must be in (0, 1)");
  const std::size_t n = x.size();
  ChangePointResult res;
  if (n < 4 * std::max<std::size_t>(1, opt.min_half_width)) return res;
  // Scales and their null sd / thresholds (the robust part from the record
  // as given; steps affect few windows at the scales where it is used).
  std::vector<Scale> scales = scaleGrid(n, opt);
  const double J = static_cast<double>(scales.size());
  res.scales_tested = static_cast<int>(scales.size());
  {
    const auto S = prefix(x);
    for (auto& s : scales) {
      const double v = null_wv(2.0 * static_cast<double>(s.m));
      s.sd = 2.0 * std::sqrt(std::max(0.0, v));
      const double indep = static_cast<double>(n) / (2.0 * static_cast<double>(s.m));
      if (indep >= 64) {
        const std::size_t step = std::max<std::size_t>(s.stride, (n - 2 * s.m) / 8192 + 1);
        std::vector<double> d;
        for (std::size_t k = s.m; k + s.m <= n; k += step)
          d.push_back(meanOf(S, k, k + s.m) - meanOf(S, k - s.m, k));
        s.sd = std::max(s.sd, madScale(d));
      }
      s.threshold = twoSidedNormalQuantile(alpha / (J * static_cast<double>(s.positions)));
    }
  }
  // Largest |contrast| per scale, kept between iterations: removing a change
  // at c alters only the windows that straddle c (|k - c| < m), so a scale is
  // rescanned whole only when its maximum was among them.
  std::vector<double> smax(scales.size(), 0.0);
  std::vector<std::size_t> kmax(scales.size(), 0);
  std::vector<char> stale(scales.size(), 1);
  std::size_t last_c = 0;
  bool have_last = false;
  for (int it = 0; it < opt.max_changes; ++it) {
    const auto S = prefix(x);
    ChangePoint best;
    double best_excess = 1.0;
    for (std::size_t si = 0; si < scales.size(); ++si) {
      const auto& s = scales[si];
      if (!(s.sd > 0)) continue;
      auto scan = [&](std::size_t k0, std::size_t k1) {  // grid positions in [k0, k1]
        std::size_t k = s.m;
        if (k0 > s.m) k = s.m + ((k0 - s.m + s.stride - 1) / s.stride) * s.stride;
        for (; k + s.m <= n && k <= k1; k += s.stride) {
          const double d = meanOf(S, k, k + s.m) - meanOf(S, k - s.m, k);
          if (std::abs(d) > std::abs(smax[si])) {
            smax[si] = d;
            kmax[si] = k;
          }
        }
      };
      if (have_last && !stale[si]) {
        const std::size_t lo = last_c > s.m ? last_c - s.m : 0, hi = last_c + s.m;
        if (kmax[si] > lo && kmax[si] < hi) stale[si] = 1;
        else scan(lo, hi);
      }
      if (stale[si]) {
        smax[si] = 0;
        kmax[si] = 0;
        scan(0, n);
        stale[si] = 0;
      }
      const double z = std::abs(smax[si]) / s.sd;
      if (z / s.threshold > best_excess) {
        best_excess = z / s.threshold;
        best.index = kmax[si];
        best.contrast = smax[si];
        best.half_width = s.m;
        best.sd = s.sd;
        best.z = z;
        best.threshold = s.threshold;
        const double p1 = 2.0 * boost::math::cdf(boost::math::complement(boost::math::normal(), z));
        best.p_value = std::min(1.0, p1 * J * static_cast<double>(s.positions));
      }
    }
    if (best.half_width == 0) break;
    // Locate the change inside the detecting window [k - m, k + m) by the
    // likelihood ratio of one change in a mean (CUSUM weighted by
    // sqrt((j - a)(b - j) / (b - a))): the largest contrast over the grid may
    // sit at a window edge when the window cannot be centred on the change.
    {
      const std::size_t m = best.half_width;
      const std::size_t a = best.index - m, b = best.index + m;
      const double tot = S[b] - S[a], len = static_cast<double>(b - a);
      double tbest = -1;
      std::size_t jbest = best.index;
      for (std::size_t j = a + 1; j < b; ++j) {
        const double l = static_cast<double>(j - a);
        const double t = std::abs(S[j] - S[a] - l / len * tot) / std::sqrt(l * (len - l) / len);
        if (t > tbest) {
          tbest = t;
          jbest = j;
        }
      }
      best.index = jbest;
      // The contrast at the located change with the window m clipped to the record.
      const std::size_t mm = std::min({m, jbest, n - jbest});
      if (mm >= 1) best.contrast = meanOf(S, jbest, jbest + mm) - meanOf(S, jbest - mm, jbest);
    }
    // Size from the adjacent segments, bounded by the changes already found
    // and by 4 m on each side (a longer window adds noise of a random walk).
    const std::size_t m = best.half_width;
    std::size_t a = best.index > 4 * m ? best.index - 4 * m : 0;
    std::size_t b = std::min(n, best.index + 4 * m);
    for (const auto& c : res.changes) {
      if (c.index < best.index) a = std::max(a, c.index);
      else b = std::min(b, c.index);
    }
    best.size = (b > best.index && best.index > a)
                    ? meanOf(S, best.index, b) - meanOf(S, a, best.index)
                    : best.contrast;
    for (std::size_t k = best.index; k < n; ++k) x[k] -= best.size;
    res.changes.push_back(best);
    last_c = best.index;
    have_last = true;
  }
  // Clusters of changes closer than their detecting windows.
  std::vector<ChangePoint> byIndex = res.changes;
  std::sort(byIndex.begin(), byIndex.end(),
            [](const ChangePoint& a, const ChangePoint& b) { return a.index < b.index; });
  std::vector<ChangePoint> kept;
  for (std::size_t i = 0; i < byIndex.size();) {
    std::size_t j = i;
    auto linked = [&](std::size_t q) {  // byIndex[q] joins the cluster that ends at q - 1
      return byIndex[q].index - byIndex[q - 1].index <= std::min(byIndex[q - 1].half_width, byIndex[q].half_width) ||
             byIndex[q].index - byIndex[i].index <= opt.max_transient;
    };
    while (j + 1 < byIndex.size() && linked(j + 1)) ++j;
    if (j == i) {
      kept.push_back(byIndex[i]);
      ++i;
      continue;
    }
    double net = 0, level = 0, peak = 0, maxabs = 0;
    std::size_t strongest = i;
    for (std::size_t q = i; q <= j; ++q) {
      net += byIndex[q].size;
      level += byIndex[q].size;
      if (std::abs(level) > std::abs(peak)) peak = level;
      maxabs = std::max(maxabs, std::abs(byIndex[q].size));
      if (byIndex[q].z / byIndex[q].threshold > byIndex[strongest].z / byIndex[strongest].threshold) strongest = q;
    }
    // A cluster at one sample (a change found again in another window and
    // corrected) has no duration: it is one change of its net size.
    if (std::abs(net) < 0.5 * maxabs && byIndex[j].index > byIndex[i].index) {
      Transient t;
      t.first = byIndex[i].index;
      t.last = byIndex[j].index;
      t.peak = peak;
      t.z = byIndex[strongest].z;
      t.threshold = byIndex[strongest].threshold;
      t.p_value = byIndex[strongest].p_value;
      t.half_width = byIndex[strongest].half_width;
      res.transients.push_back(t);
    } else {
      ChangePoint c = byIndex[strongest];
      c.size = net;
      kept.push_back(c);
    }
    i = j + 1;
  }
  // Back to detection order (strongest first) for the changes kept.
  std::vector<ChangePoint> ordered;
  for (const auto& c : res.changes)
    for (const auto& k : kept)
      if (k.index == c.index && k.half_width == c.half_width) ordered.push_back(k);
  res.changes = ordered;
  return res;
}

}  // namespace navimpact::detect
