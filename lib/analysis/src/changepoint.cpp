// Time-domain effects the wavelet variance is blind to or distorted by:
// isolated spikes (outliers) and level shifts (steps).
#include <algorithm>
#include <cmath>
#include <numeric>

#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/error.hpp"

namespace navimpact::analysis {

namespace {

/// Median of v (copied, partially sorted).
double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// Robust standard deviation 1.4826 MAD (consistent for the Gaussian), and the median.
double robustScale(const std::vector<double>& v, double* med_out = nullptr) {
  const double med = median(v);
  std::vector<double> d(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) d[i] = std::abs(v[i] - med);
  if (med_out) *med_out = med;
  double s = 1.4826 * median(std::move(d));
  if (!(s > 0.0)) {
    // Heavily quantised data: MAD may be 0; fall back to the standard deviation.
    double m = 0, q = 0;
    for (double a : v) m += a;
    m /= static_cast<double>(v.size());
    for (double a : v) q += (a - m) * (a - m);
    s = std::sqrt(q / static_cast<double>(std::max<std::size_t>(v.size() - 1, 1)));
  }
  return s;
}

}  // namespace

SpikeResult detectSpikes(const std::vector<double>& x, double z_threshold) {
  SpikeResult out;
  out.threshold = z_threshold;
  const std::size_t n = x.size();
  if (n < 5) return out;
  // r_k = x_k - (x_{k-1} + x_{k+1})/2: a spike of height A at k gives r_k = A and
  // r_{k+-1} = -A/2; a step of size S between k-1 and k gives -S/2, +S/2 (no middle).
  std::vector<double> r(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) r[k] = x[k] - 0.5 * (x[k - 1] + x[k + 1]);
  std::vector<double> inner(r.begin() + 1, r.end() - 1);
  double med = 0;
  out.scale = robustScale(inner, &med);
  const double thr = z_threshold * out.scale;
  for (std::size_t k = 2; k + 2 < n; ++k) {
    const double a = r[k] - med;
    if (std::abs(a) <= thr) continue;
    const double l = r[k - 1] - med, rr = r[k + 1] - med;
    if (std::abs(a) < std::abs(l) || std::abs(a) < std::abs(rr)) continue;  // local max
    const bool opposite = (l * a < 0.0) && (rr * a < 0.0);
    const double fl = std::abs(l) / std::abs(a), fr = std::abs(rr) / std::abs(a);
    if (!opposite || fl < 0.1 || fl > 0.9 || fr < 0.1 || fr > 0.9) continue;
    out.index.push_back(k);
    out.size.push_back(a);
  }
  return out;
}

std::vector<StepResult> detectSteps(std::vector<double>& x, double alpha,
                                    int max_steps, int* levels_tested) {
  std::vector<StepResult> found;
  const std::size_t n = x.size();
  if (n < 1024) {
    if (levels_tested) *levels_tested = 0;
    return found;
  }
  // Haar coefficient at level j (m = 2^{j-1}): W_t = (mean(x[t-m+1..t]) -
  // mean(x[t-2m+1..t-m])) / 2 (Percival & Walden 2000, eq. 173 for the Haar
  // MODWT). A step of size S at sample s gives |W| = S/2 at t = s + m - 1,
  // a triangle around it; stationary parts give W with a robust scale that
  // the data themselves provide (so unmodelled GM, RW, sinusoids do not
  // trigger it). Levels 3.. while at least 256 windows of 2m fit.
  int jmax = 3;
  while ((n >> (jmax + 1)) >= 256) ++jmax;
  const int levels = std::max(0, jmax - 2);
  if (levels_tested) *levels_tested = levels;
  const double alpha_per_scale = alpha / std::max(1, levels);
  for (int it = 0; it < max_steps; ++it) {
    double mean = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(n);
    std::vector<double> S(n + 1, 0.0);
    for (std::size_t k = 0; k < n; ++k) S[k + 1] = S[k] + (x[k] - mean);
    StepResult best;
    double best_excess = 1.0;  // z / threshold
    for (int j = 3; j <= jmax; ++j) {
      const std::size_t m = std::size_t(1) << (j - 1);
      const std::size_t M = n - 2 * m + 1;
      std::vector<double> W(M);
      for (std::size_t i = 0; i < M; ++i) {
        const std::size_t t1 = i + 2 * m;  // exclusive end
        const double after = S[t1] - S[t1 - m];
        const double before = S[t1 - m] - S[t1 - 2 * m];
        W[i] = (after - before) / (2.0 * static_cast<double>(m));
      }
      const std::size_t stride = std::max<std::size_t>(1, m / 4);
      std::vector<double> sub;
      sub.reserve(M / stride + 1);
      for (std::size_t i = 0; i < M; i += stride) sub.push_back(W[i]);
      double med = 0;
      double s = robustScale(sub, &med);
      // Quantised data can make the MAD of short averages far smaller than
      // their spread: never use less than the classical rms of the
      // coefficients (a few steps hardly change it; Gaussian noise gives both equal).
      double ms = 0;
      for (double w : sub) ms += (w - med) * (w - med);
      s = std::max(s, std::sqrt(ms / static_cast<double>(sub.size())));
      if (!(s > 0.0)) continue;
      // Threshold: Bonferroni over the M positions; the scale is estimated
      // (MAD, 37 % efficient, from about M/m independent windows), hence a
      // Student t with that many effective degrees of freedom.
      const double df = std::max(5.0, 0.37 * static_cast<double>(M) / static_cast<double>(m));
      const double p = alpha_per_scale / (2.0 * static_cast<double>(M));
      const double c = boost::math::quantile(
          boost::math::complement(boost::math::students_t(df), p));
      std::size_t imax = 0;
      double zmax = 0;
      for (std::size_t i = 0; i < M; ++i) {
        const double z = std::abs(W[i] - med) / s;
        if (z > zmax) {
          zmax = z;
          imax = i;
        }
      }
      if (zmax / c > best_excess) {
        best_excess = zmax / c;
        best.index = imax + m;  // first sample of the "after" half
        best.size = 2.0 * (W[imax] - med);
        best.z = zmax;
        best.threshold = c;
        best.level = j;
      }
    }
    if (best.level == 0) break;
    // Refine the location at the detecting scale: the maximum of |W| over the
    // triangle is at the step; re-estimate the size from the two windows of
    // length 4m (clipped to the record) around it.
    const std::size_t m = std::size_t(1) << (best.level - 1);
    const std::size_t L = std::min({4 * m, best.index, n - best.index});
    if (L >= 1) {
      double a = 0, b = 0;
      for (std::size_t k = best.index; k < best.index + L; ++k) a += x[k];
      for (std::size_t k = best.index - L; k < best.index; ++k) b += x[k];
      best.size = (a - b) / static_cast<double>(L);
    }
    if (!(std::abs(best.size) > 0.0)) break;  // nothing left to remove
    for (std::size_t k = best.index; k < n; ++k) x[k] -= best.size;
    found.push_back(best);
  }
  return found;
}

}  // namespace navimpact::analysis
