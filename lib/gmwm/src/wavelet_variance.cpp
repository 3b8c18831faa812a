// Classical Haar MODWT wavelet variance with the eta3 chi-square CI
// (Percival & Walden 2000, §8.3–8.4; R package gmwm 3.0.0, src/dwt.cpp and
// src/wave_variance.cpp, described in shared/reference/gmwm_formulas.md §1–2).
#include "navimpact/gmwm/wavelet_variance.hpp"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#ifdef __linux__
#include <sys/mman.h>
#endif
#include <functional>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/parallel.hpp"
#include "wv_internal.hpp"

namespace navimpact::gmwm {

namespace detail {

int maxLevel(std::size_t n) {
  int J = 0;
  while ((std::size_t{2} << J) <= n) ++J;  // largest J with 2^J <= n
  return J;
}

void checkSeries(const double* x, std::size_t n) {
  if (n < 4)
    throw Error("wavelet variance needs at least 4 samples (two dyadic scales), got " +
                std::to_string(n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      std::ostringstream os;
      os << "wavelet variance: sample " << i << " is not finite (" << x[i] << ")";
      throw Error(os.str());
    }
  }
  const double x0 = x[0];
  if (std::all_of(x, x + n, [x0](double v) { return v == x0; })) {
    std::ostringstream os;
    os << "wavelet variance: the signal is constant (all " << n << " samples equal " << x0
       << "), its wavelet variance is zero at every scale";
    throw Error(os.str());
  }
}

double sumSquares(const double* w, std::size_t m) {
  // Blocked sum with 8 independent partial sums per block (vectorisable);
  // block totals are added in long double. Relative error ~ 1e-15 on 1e6 terms.
  constexpr std::size_t kBlock = 4096;
  long double total = 0.0L;
  for (std::size_t b = 0; b < m; b += kBlock) {
    const std::size_t e = std::min(m, b + kBlock);
    double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    std::size_t i = b;
    for (; i + 8 <= e; i += 8)
      for (int k = 0; k < 8; ++k) acc[k] += w[i + k] * w[i + k];
    double s = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    for (; i < e; ++i) s += w[i] * w[i];
    total += s;
  }
  return static_cast<double>(total);
}

void haarModwtLevels(const double* x, std::size_t n, int J,
                     const std::function<void(int, const double*, std::size_t)>& onLevel) {
  // Haar MODWT pyramid (Percival & Walden 2000, eq. 177a with h~ = (1/2,-1/2),
  // g~ = (1/2,1/2)), V_0 = x:
  //   W_{j,t} = (V_{j-1,t} - V_{j-1,t-s}) / 2,  V_{j,t} = (V_{j-1,t} + V_{j-1,t-s}) / 2,  s = 2^{j-1}.
  // Only coefficients free of the circular boundary are formed ("brick wall"):
  // t = 2^j - 1 .. n-1, M_j = n - 2^j + 1 of them. Those need V_{j-1} only at
  // t >= 2^{j-1} - 1, which is exactly what level j-1 kept, so no wrapping.
  // Arrays are indexed from the first kept t of their level.
  std::vector<double> v(x, x + n);   // V_{j-1}, v[i] = V_{j-1, i + 2^{j-1} - 1}
  std::vector<double> vn(n), w(n);
  std::size_t len = n;
  for (int j = 1; j <= J; ++j) {
    const std::size_t s = std::size_t{1} << (j - 1);
    const std::size_t m = len - s;  // = n - 2^j + 1
    const double* a = v.data() + s;  // V_{j-1,t}
    const double* b = v.data();      // V_{j-1,t-s}
    double* wo = w.data();
    double* vo = vn.data();
    for (std::size_t i = 0; i < m; ++i) {
      wo[i] = 0.5 * (a[i] - b[i]);
      vo[i] = 0.5 * (a[i] + b[i]);
    }
    onLevel(j, wo, m);
    std::swap(v, vn);
    len = m;
  }
}

namespace {

/// Sum of squares of (a[i] - b[i]) and v[i] = a[i] + b[i], i < m (unscaled pyramid, see
/// haarModwtSumSquares).
/// Eight independent partial sums per chunk keep it vectorised; chunk totals
/// go to long double.
inline long double levelStep(const double* __restrict a, const double* __restrict b,
                             double* __restrict v, std::size_t m, std::size_t acc_from) {
  for (std::size_t i = 0; i < std::min(acc_from, m); ++i) v[i] = a[i] + b[i];
  long double total = 0.0L;
  constexpr std::size_t kChunk = 4096;
  for (std::size_t c = acc_from; c < m; c += kChunk) {
    const std::size_t e = std::min(m, c + kChunk);
    double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    std::size_t i = c;
    for (; i + 8 <= e; i += 8) {
      for (int k = 0; k < 8; ++k) {
        const double w = a[i + k] - b[i + k];
        acc[k] += w * w;
        v[i + k] = a[i + k] + b[i + k];
      }
    }
    double sum = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    for (; i < e; ++i) {
      const double w = a[i] - b[i];
      sum += w * w;
      v[i] = a[i] + b[i];
    }
    total += sum;
  }
  return total;
}

/// Same as levelStep with v == b allowed (in place: v[i] = b[i + s] + b[i]
/// with a = b + s). Each chunk of 8 is loaded before it is stored, and a write
/// at i never reaches an element a later step reads (i < i + s), so forward
/// iteration gives the out-of-place result.
inline long double levelStepInPlace(const double* a, const double* b, double* v, std::size_t m) {
  long double total = 0.0L;
  constexpr std::size_t kChunk = 4096;
  for (std::size_t c = 0; c < m; c += kChunk) {
    const std::size_t e = std::min(m, c + kChunk);
    double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    std::size_t i = c;
    for (; i + 8 <= e; i += 8) {
      double ta[8], tb[8];
      for (int k = 0; k < 8; ++k) {
        ta[k] = a[i + k];
        tb[k] = b[i + k];
      }
      for (int k = 0; k < 8; ++k) {
        const double w = ta[k] - tb[k];
        acc[k] += w * w;
        v[i + k] = ta[k] + tb[k];
      }
    }
    double sum = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    for (; i < e; ++i) {
      const double ta = a[i], tb = b[i];
      const double w = ta - tb;
      sum += w * w;
      v[i] = ta + tb;
    }
    total += sum;
  }
  return total;
}

/// Scratch array of n doubles, not zero-filled, backed by transparent huge
/// pages where the kernel offers them (first touch of 8 MB in 4 KiB pages
/// costs ~2000 page faults, a sizeable part of the WV time).
struct Scratch {
  double* p = nullptr;
  explicit Scratch(std::size_t n) {
    constexpr std::size_t kAlign = std::size_t{2} << 20;  // one huge page
    const std::size_t need = std::max<std::size_t>(n, 1) * sizeof(double);
    if (need < 2 * kAlign) {
      p = static_cast<double*>(std::malloc(need));
    } else {
      const std::size_t bytes = ((need + kAlign - 1) / kAlign) * kAlign;
      p = static_cast<double*>(std::aligned_alloc(kAlign, bytes));
#ifdef MADV_HUGEPAGE
      if (p) madvise(p, bytes, MADV_HUGEPAGE);
#endif
    }
    if (!p) throw std::bad_alloc();
  }
  ~Scratch() { std::free(p); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
};

/**
 * Levels jfrom..jto of the Haar MODWT pyramid, cache-blocked over time.
 * @param in   V_{jfrom-1,t} for t = 2^{jfrom-1} - 1 .. n-1.
 * @param out  receives V_{jto,t} for t = 2^{jto} - 1 .. n-1; may be @p in when
 *             jto > jfrom (block b's output overwrites only input that no later
 *             block reads: both start at index t0 - t_out0, and the next block
 *             reads from t0 + block - t_out0 on; the first level of a block reads
 *             all of its input before the last level writes).
 * @param ss   ss[j-1] += sum over kept t of W_{j,t}^2.
 * @param block output samples per block (the lookback 2^jto - 2^{jfrom-1} is recomputed per block).
 */
void pyramidStage(const double* in, double* out, std::size_t n, int jfrom, int jto,
                  std::size_t block, std::vector<double>& buf1, std::vector<double>& buf2,
                  std::vector<long double>& ss) {
  const std::size_t t_in0 = (std::size_t{1} << (jfrom - 1)) - 1;
  const std::size_t t_out0 = (std::size_t{1} << jto) - 1;
  const std::size_t L = t_out0 - t_in0;
  if (buf1.size() < block + L) buf1.resize(block + L);
  if (buf2.size() < block + L) buf2.resize(block + L);
  for (std::size_t t0 = t_out0; t0 < n; t0 += block) {
    const std::size_t t1 = std::min(n, t0 + block);
    std::size_t bs = t0 - L;  // time of element 0 of the current level's buffer
    const double* src = in + (bs - t_in0);
    std::size_t len = t1 - bs;
    for (int j = jfrom; j <= jto; ++j) {
      const std::size_t s = std::size_t{1} << (j - 1);
      const std::size_t m = len - s;
      bs += s;
      double* dst = (j == jto) ? out + (t0 - t_out0) : ((j - jfrom) % 2 == 0 ? buf1.data() : buf2.data());
      // W_{j,t} = (V_{j-1,t} - V_{j-1,t-s}) / 2 for t = bs + k. Each t is counted
      // once: in its own block, except that the first block also counts the
      // kept t < t_out0 of the lower levels (there bs = 2^j - 1, the first kept t).
      ss[j - 1] += levelStep(src + s, src, dst, m, t0 == t_out0 ? 0 : t0 - bs);
      src = dst;
      len = m;
    }
  }
}

}  // namespace

std::vector<long double> haarModwtSumSquares(const double* x, std::size_t n, int J) {
  // Same pyramid as haarModwtLevels, fused (no W array) and blocked so that the
  // small levels run in cache: levels 1..10 in blocks of 16 Ki samples, 11..14
  // in blocks of 64 Ki, the rest unblocked over the whole series.
  // Unscaled pyramid: U_j = 2^j V_j (sums instead of means) and D_j = 2^j W_j,
  // so each step is one add and one subtract; sum W_j^2 = 4^-j sum D_j^2.
  // Scaling by powers of two is exact: the result is bit-identical to the
  // scaled pyramid (no overflow for |x| < 1e290).
  // One scratch array: the first stage reads x, everything after works in place.
  std::vector<long double> ss(J, 0.0L);
  std::vector<double> b1, b2;
  Scratch va(n);
  int j = 1;
  const std::pair<int, std::size_t> stages[] = {{10, 16384}, {14, 65536}};
  for (const auto& st : stages) {
    const int jto = std::min(st.first, J);
    if (jto < j || (j > 1 && jto == j)) continue;  // a single in-place level goes to the streaming loop
    pyramidStage(j == 1 ? x : va.p, va.p, n, j, jto, st.second, b1, b2, ss);
    j = jto + 1;
  }
  // Remaining large levels: one streaming pass each, in place;
  // va[i] = V_{j-1, 2^{j-1} - 1 + i}.
  for (; j <= J; ++j) {
    const std::size_t s = std::size_t{1} << (j - 1);
    const std::size_t m = n - 2 * s + 1;
    ss[j - 1] += j == 1 ? levelStep(x + s, x, va.p, m, 0) : levelStepInPlace(va.p + s, va.p, va.p, m);
  }
  for (int q = 1; q <= J; ++q) ss[q - 1] = std::ldexp(ss[q - 1], -2 * q);
  return ss;
}

WaveletVariance sizedWv(int J, double rate_hz, std::size_t n, bool robust) {
  WaveletVariance r;
  r.tau.resize(J);
  r.wv.resize(J);
  r.ci_low.resize(J);
  r.ci_high.resize(J);
  r.n_coef.resize(J);
  r.eta.resize(J);
  r.rate_hz = rate_hz;
  r.n = n;
  r.robust = robust;
  return r;
}

}  // namespace detail

Eigen::VectorXd WaveletVariance::weights() const {
  // R gmwm "fast" V: Omega_jj = 1 / (CI_high_j - CI_low_j)^2 (gmwm_formulas.md §4).
  return (ci_high - ci_low).array().square().inverse().matrix();
}

void wvConfidenceInterval(double wv, double eta, double alpha, double& low, double& high) {
  if (!(alpha > 0.0 && alpha < 1.0))
    throw Error("wavelet variance CI: alpha must be in (0, 1), got " + formatNumber(alpha));
  if (!(eta > 0.0) || !std::isfinite(eta))
    throw Error("wavelet variance CI: degrees of freedom must be > 0, got " + formatNumber(eta));
  // Percival & Walden 2000, eq. 313c: eta nu^2 / nu_hat^2 ~ chi2(eta).
  const boost::math::chi_squared chi2(eta);
  low = eta * wv / boost::math::quantile(chi2, 1.0 - alpha / 2.0);
  high = eta * wv / boost::math::quantile(chi2, alpha / 2.0);
}

WaveletVariance waveletVariance(const double* x, std::size_t n, double rate_hz, double alpha,
                                int max_j) {
  detail::checkSeries(x, n);
  const int Jmax = detail::maxLevel(n);
  if (max_j < 0 || max_j > Jmax)
    throw Error("wavelet variance: max_j = " + std::to_string(max_j) + " outside 0.." +
                std::to_string(Jmax) + " for " + std::to_string(n) + " samples");
  const int J = max_j == 0 ? Jmax : max_j;

  WaveletVariance r = detail::sizedWv(J, rate_hz, n, false);
  const std::vector<long double> ss = detail::haarModwtSumSquares(x, n, J);
  for (int i = 0; i < J; ++i) {
    const double tau = std::ldexp(1.0, i + 1);
    const double m = static_cast<double>(n) - tau + 1.0;  // M_j
    r.tau[i] = tau;
    r.n_coef[i] = m;
    r.wv[i] = static_cast<double>(ss[i] / static_cast<long double>(m));
    r.eta[i] = std::max(m / tau, 1.0);  // eta3
    wvConfidenceInterval(r.wv[i], r.eta[i], alpha, r.ci_low[i], r.ci_high[i]);
  }
  return r;
}

std::vector<WaveletVariance> waveletVariances(const ImuSeries& s, const WvOptions& opt) {
  const std::size_t nc = s.channels.size();
  std::vector<WaveletVariance> out(nc);
  // Channels in parallel; a failure names its channel (the lowest one that failed).
  parallelFor(nc, static_cast<unsigned>(std::max(opt.threads, 0)), [&](std::size_t c) {
    const auto& ch = s.channels[c];
    try {
      out[c] = opt.robust ? robustWaveletVariance(ch.x.data(), ch.x.size(), s.rate_hz, opt.eff, opt.alpha)
                          : waveletVariance(ch.x.data(), ch.x.size(), s.rate_hz, opt.alpha, opt.max_j);
    } catch (const Error& e) {
      throw Error(s.source + ": channel " + ch.name + ": " + e.what());
    }
  });
  // A non-finite result is an error naming its cause, never a file with inf/null.
  for (std::size_t c = 0; c < nc; ++c) {
    const auto& w = out[c];
    for (Eigen::Index j = 0; j < w.wv.size(); ++j) {
      if (std::isfinite(w.wv[j]) && std::isfinite(w.ci_low[j]) && std::isfinite(w.ci_high[j])) continue;
      const auto& x = s.channels[c].x;
      double big = 0.0;
      for (double v : x) big = std::max(big, std::isfinite(v) ? std::abs(v) : HUGE_VAL);
      char buf[96];
      std::snprintf(buf, sizeof buf, "%g s is not finite (the samples reach |x| = %g)", w.tau[j] / s.rate_hz, big);
      throw Error(s.source + ": channel " + s.channels[c].name + ": wavelet variance at tau = " + buf);
    }
    // ... and so is one that underflows to 0 at every scale (samples of 1e-300: a
    // log-log plot of it has nothing to draw, and no model fits it)
    if (w.wv.size() > 0 && (w.wv.array() == 0.0).all()) {
      double big = 0.0;
      for (double v : s.channels[c].x) big = std::max(big, std::abs(v));
      throw Error(s.source + ": channel " + s.channels[c].name +
                  ": wavelet variance is 0 at every scale (the samples reach only |x| = " + formatNumber(big) +
                  ": their squares underflow; is the unit right?)");
    }
  }
  return out;
}

}  // namespace navimpact::gmwm
