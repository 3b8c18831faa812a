// Robust Haar wavelet variance: Tukey-biweight M-estimator of scale of the
// wavelet coefficients (Guerrier, Molinari & Victoria-Feser 2014, "Robust
// inference for time series models: a wavelet-based framework"; R package
// gmwm 3.0.0, src/robust_components.cpp, gmwm_formulas.md §1–2).
//
// With r = w / sigma and the biweight weight u(r) = (1 - r^2/c^2)^2 for |r| <= c
// (0 beyond), the scale solves  mean( chi(r) ) = a(c),  chi(r) = r^2 u(r)^2,
// a(c) = E[chi(Z)], Z ~ N(0,1) (Fisher consistency at the normal). The constant
// c is chosen so that the estimator of sigma^2 has the requested asymptotic
// efficiency relative to the Gaussian MLE:
//   eff(c) = (E[Z chi'(Z)])^2 / (2 Var chi(Z)) = (E[Z^2 chi(Z)] - a)^2 / (2 (E[chi^2] - a^2))
// (Hampel et al. 1986, §5.3; E[Z chi'] = E[(Z^2 - 1) chi] by Stein's identity).
// The Gaussian moments are computed by quadrature instead of the package's
// closed-form polynomial expansion, which cancels catastrophically for small c.
#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "wv_internal.hpp"

namespace navimpact::gmwm {

namespace {

constexpr double kInvSqrt2Pi = 0.39894228040143267794;

double chi(double r, double c) {
  if (std::fabs(r) > c) return 0.0;
  const double u = 1.0 - r * r / (c * c);
  return r * r * u * u * u * u;
}

/// E[g(Z)] for Z ~ N(0,1) with g vanishing outside [-c, c].
template <class G>
double gaussMoment(G g, double c) {
  const double L = std::min(c, 40.0);
  auto f = [&](double z) { return g(z) * kInvSqrt2Pi * std::exp(-0.5 * z * z); };
  return 2.0 * boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, 0.0, L, 15, 1e-14);
}

double consistencyA(double c) {
  return gaussMoment([c](double z) { return chi(z, c); }, c);
}

double biweightEfficiency(double c) {
  const double a = consistencyA(c);
  const double m = gaussMoment([c](double z) { return z * z * chi(z, c); }, c) - a;
  const double q = gaussMoment([c](double z) { const double v = chi(z, c); return v * v; }, c) - a * a;
  return 0.5 * m * m / q;
}

// Bracket of the tuning constant c. eff(c) is not monotone: it vanishes at
// c0 ~ 2.42, where E[Z chi'(Z)] = E[(Z^2 - 1) chi(Z)] changes sign, and has a
// second branch below it (0.23 at c ~ 1). Below c0 the Gaussian root t = 1 of
// mean chi(t x) = a lies beyond the maximum of the scale equation, not on its
// rising branch where robustScale looks: --eff 0.03 gave c on that branch and a
// WV 2e4 times too large. So c >= 2.5, where eff increases with c, and the
// efficiencies accepted start at kMinEfficiency.
constexpr double kTuningLo = 2.5, kTuningHi = 60.0;
constexpr double kMinEfficiency = 0.05;  // c ~ 2.77

/// Tuning constant c with biweightEfficiency(c) = eff (eff increases with c on the bracket).
double biweightConstant(double eff) {
  checkRobustEfficiency(eff);  // an efficiency the bracket does not reach is an input error, not the solver's exception
  boost::uintmax_t it = 200;
  auto f = [eff](double c) { return biweightEfficiency(c) - eff; };
  auto r = boost::math::tools::toms748_solve(f, kTuningLo, kTuningHi, boost::math::tools::eps_tolerance<double>(50), it);
  return 0.5 * (r.first + r.second);
}

/// mean chi(t x_i) - a.
double scaleEquation(const double* x, std::size_t m, double t, double c, double a) {
  double acc[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= m; i += 4)
    for (int k = 0; k < 4; ++k) acc[k] += chi(t * x[i + k], c);
  double s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  for (; i < m; ++i) s += chi(t * x[i], c);
  return s / static_cast<double>(m) - a;
}

}  // namespace

void checkRobustEfficiency(double eff) {
  static const double hi = biweightEfficiency(kTuningHi);
  if (!(eff >= kMinEfficiency && eff <= hi))
    throw Error("robust wavelet variance: efficiency " + formatNumber(eff, 10) + " is outside what the biweight reaches (" +
                formatNumber(kMinEfficiency, 4) + " .. " + formatNumber(hi, 6) +
                ", tuning constants 2.77 .. 60; below, its scale equation has no consistent root where it is solved)");
}

namespace detail {

double robustScale(const double* w, std::size_t m, double eff) {
  if (!(eff > 0.0 && eff < 1.0))
    throw Error("robust wavelet variance: efficiency must be in (0, 1), got " + formatNumber(eff));
  const double c = biweightConstant(eff);
  return robustScale(w, m, c, consistencyA(c));
}

double robustScale(const double* w, std::size_t m, double c, double a, bool* mad_fallback,
                   bool* classical_fallback) {
  if (mad_fallback) *mad_fallback = false;
  if (classical_fallback) *classical_fallback = false;
  if (m == 0) throw Error("robust scale: no values");
  if (m == 1) return w[0] * w[0];  // a single coefficient: nothing to down-weight
  // Classical variance (two-pass) to standardise.
  long double mean = 0;
  for (std::size_t i = 0; i < m; ++i) mean += w[i];
  mean /= m;
  long double ss = 0;
  for (std::size_t i = 0; i < m; ++i) ss += (w[i] - mean) * (w[i] - mean);
  const double var = static_cast<double>(ss / (m - 1));
  if (var == 0.0) return 0.0;
  const double sd = std::sqrt(var);
  std::vector<double> x(m);
  for (std::size_t i = 0; i < m; ++i) x[i] = w[i] / sd;
  // In r = t x, f(t) = mean chi(t x) vanishes at t -> 0 and t -> inf and, for
  // any reasonable sample, rises to one maximum and falls again; f = a has two
  // roots. At the normal the consistent one is t = 1 on the rising branch
  // (chi peaks at |r| = c / sqrt(5), beyond the bulk of the data for the usual
  // c ~ 4), so the M-scale is the smallest root: the first crossing of a from
  // below as t grows. Bracket it with g(lo) < 0 <= g(hi).
  auto g = [&](double t) { return scaleEquation(x.data(), m, t, c, a); };
  const auto noRoot = []() {
    return Error("robust wavelet variance: the biweight scale equation has no root (too many "
                 "identical wavelet coefficients?)");
  };
  // Beyond the biweight's breakdown point mean chi(t x) stays below a for
  // every t: the median absolute value (zero-mean coefficients) still holds.
  const auto madScale = [&]() {
    std::vector<double> ab(m);
    for (std::size_t i = 0; i < m; ++i) ab[i] = std::fabs(w[i]);
    std::nth_element(ab.begin(), ab.begin() + m / 2, ab.end());
    const double s = ab[m / 2] / 0.6744897501960817;
    if (!(s > 1e-9 * sd)) {
      // More than half of the coefficients are zero, to rounding (a record
      // quantised below its quantum): no robust scale is defined, the
      // classical one is used.
      if (classical_fallback) *classical_fallback = true;
      long double q = 0;
      for (std::size_t i = 0; i < m; ++i) q += static_cast<long double>(w[i]) * w[i];
      return static_cast<double>(q / m);
    }
    if (mad_fallback) *mad_fallback = true;
    return s * s;
  };
  double lo = 1.0, hi = 1.0;
  const double g1 = g(1.0);
  int k = 0;
  if (g1 < 0.0 && g(1.01) > g1) {
    // Rising branch, below the root: move right.
    hi = 2.0;
    while (g(hi) < 0.0) {
      lo = hi;
      hi *= 2.0;
      if (++k > 100) return madScale();
    }
  } else {
    if (g1 < 0.0) {
      // Falling branch beyond the maximum: move left into the bump first.
      while (g(hi) < 0.0) {
        hi *= 0.5;
        if (++k > 100) return madScale();
      }
    }
    // Now g(hi) >= 0: move left until below the first root.
    lo = 0.5 * hi;
    while (g(lo) >= 0.0) {
      hi = lo;
      lo *= 0.5;
      if (++k > 200) throw noRoot();
    }
  }
  boost::uintmax_t it = 100;
  auto r = boost::math::tools::toms748_solve(
      g, lo, hi, boost::math::tools::eps_tolerance<double>(40), it);
  const double tr = 0.5 * (r.first + r.second);
  return var / (tr * tr);
}

}  // namespace detail

std::size_t despike(std::vector<double>& x, double alpha) {
  if (!(alpha > 0.0 && alpha < 1.0))
    throw Error("despike: alpha must be in (0, 1), got " + formatNumber(alpha));
  const std::size_t n = x.size();
  if (n < 8) return 0;
  auto d = [&](std::size_t k) { return x[k] - 0.5 * (x[k - 1] + x[k + 1]); };
  std::vector<double> v(n - 2);
  for (std::size_t k = 1; k + 1 < n; ++k) v[k - 1] = d(k);
  auto median = [](std::vector<double>& a) {
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    return a[a.size() / 2];
  };
  const double med = median(v);
  for (double& e : v) e = std::fabs(e - med);
  const double scale = 1.482602218505602 * median(v);
  if (!(scale > 0.0)) return 0;
  const double z = boost::math::quantile(boost::math::complement(boost::math::normal(), 0.5 * alpha / static_cast<double>(n)));
  const double thr = z * scale;
  // The end samples have one neighbour: x[0] - x[1] (the second difference
  // with x[-1] mirrored to x[1]), scaled to the central one's white-noise
  // variance (2 sigma^2 against 1.5 sigma^2). Without them a spike on the first
  // or last sample was never replaced and dragged its neighbour along, pass
  // after pass (36,426 "replaced" in an 8,192-sample record).
  const double kEnd = std::sqrt(0.75);
  auto a0 = [&] { return kEnd * std::fabs(x[0] - x[1] - med); };
  auto aN = [&] { return kEnd * std::fabs(x[n - 1] - x[n - 2] - med); };
  std::vector<bool> touched(n, false);
  std::vector<std::size_t> hit;
  for (int pass = 0; pass < 1000; ++pass) {
    hit.clear();
    if (const double a = a0(); a > thr && a >= std::fabs(d(1) - med)) hit.push_back(0);
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const double a = std::fabs(d(k) - med);
      if (!(a > thr)) continue;
      const double l = k >= 2 ? std::fabs(d(k - 1) - med) : a0(), r = k + 2 < n ? std::fabs(d(k + 1) - med) : aN();
      if (a >= l && a >= r) hit.push_back(k);
    }
    if (const double a = aN(); a > thr && a >= std::fabs(d(n - 2) - med)) hit.push_back(n - 1);
    if (hit.empty()) break;
    for (std::size_t k : hit) {
      x[k] = k == 0 ? x[1] : k == n - 1 ? x[n - 2] : 0.5 * (x[k - 1] + x[k + 1]);
      touched[k] = true;
    }
  }
  return static_cast<std::size_t>(std::count(touched.begin(), touched.end(), true));
}

WaveletVariance robustWaveletVariance(const double* x, std::size_t n, double rate_hz, double eff,
                                      double alpha) {
  if (!(eff > 0.0 && eff < 1.0))
    throw Error("robust wavelet variance: efficiency must be in (0, 1), got " + formatNumber(eff));
  detail::checkSeries(x, n);
  const int J = detail::maxLevel(n);
  WaveletVariance r = detail::sizedWv(J, rate_hz, n, true);
  r.eff = eff;
  const double c = biweightConstant(eff);
  const double a = consistencyA(c);
  double min_low = std::numeric_limits<double>::infinity();
  detail::haarModwtLevels(x, n, J, [&](int j, const double* w, std::size_t m) {
    const int i = j - 1;
    const double tau = std::ldexp(1.0, j);
    r.tau[i] = tau;
    r.n_coef[i] = static_cast<double>(m);
    r.eta[i] = std::max(static_cast<double>(m) / tau, 1.0);
    bool mad = false, classical = false;
    const double nu = detail::robustScale(w, m, c, a, &mad, &classical);
    r.wv[i] = nu;
    if (mad) r.mad_scales.push_back(i);
    if (classical) r.classical_scales.push_back(i);
    // The MAD scale has its own (lower) efficiency: a wider interval.
    const double inflate = classical ? 1.0 : 1.0 / std::sqrt(mad ? detail::kMadEfficiency : eff);
    // gmwm_formulas.md §2 (ci_eta3_robust): the classical relative half-widths,
    // inflated by 1/sqrt(eff), around the robust estimate.
    double lo1, hi1;
    wvConfidenceInterval(1.0, r.eta[i], alpha, lo1, hi1);
    double low = nu * (1.0 - (1.0 - lo1) * inflate);
    const double high = nu * (1.0 + (hi1 - 1.0) * inflate);
    if (low <= 0.0) low = std::min(nu / 2.0, min_low);
    min_low = std::min(min_low, low);
    r.ci_low[i] = low;
    r.ci_high[i] = high;
  });
  return r;
}

}  // namespace navimpact::gmwm
