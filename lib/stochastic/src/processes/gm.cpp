// GM(sigma, T): first-order Gauss-Markov process, sigma its stationary standard
// deviation, T its correlation time [s]; sampled at dt it is the AR(1)
// x_k = phi x_{k-1} + e_k, phi = exp(-dt/T), var(e) = sigma^2 (1 - phi^2).
// Also read as AR1(phi, sigma2) in the R package gmwm's form (sigma2 = the
// innovation variance), stored as the equivalent GM.
#include <cmath>
#include <string>

#include "../kind.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::stochastic {

namespace {

/// f(x) = 2x - 3 + 4 e^{-x} - e^{-2x} >= 0, accurate for all x >= 0.
/// For small x the direct form cancels (f ~ 2x^3/3), so use its Taylor series
/// f(x) = sum_{k>=3} (-1)^k (4 - 2^k) x^k / k!  (entire; |terms| shrink fast for x < 1).
double fAr1(double x) {
  if (x >= 1.0) return 2.0 * x - 3.0 + 4.0 * std::exp(-x) - std::exp(-2.0 * x);
  double sum = 0.0;
  double xk_over_kfact = x * x * x / 6.0;  // x^k/k! for k = 3
  double two_k = 8.0;
  for (int k = 3; k < 60; ++k) {
    const double term = ((k % 2) ? -1.0 : 1.0) * (4.0 - two_k) * xk_over_kfact;
    sum += term;
    if (std::fabs(term) <= 1e-19 * std::fabs(sum)) break;
    xk_over_kfact *= x / (k + 1);
    two_k *= 2.0;
  }
  return sum;
}

/// sinh(L) - L >= 0, accurate for small L (series L^3/3! + L^5/5! + ...).
double sinhMinusId(double L) {
  if (L >= 1.0) return std::sinh(L) - L;
  const double L2 = L * L;
  double term = L * L2 / 6.0, sum = 0.0;
  for (int k = 3; k < 40; k += 2) {
    sum += term;
    if (term <= 1e-19 * sum) break;
    term *= L2 / ((k + 1.0) * (k + 2.0));
  }
  return sum;
}

/**
 * Haar WV of a stationary AR1 / GM with stationary variance @p s2 and
 * phi = exp(-L), at scale tau = 2n samples.
 *
 * R's form: nu^2 = sigma2 [n - 3phi - n phi^2 + 4 phi^{n+1} - phi^{2n+1}] /
 * [2 n^2 (1-phi)^2 (1-phi^2)], sigma2 = s2 (1 - phi^2). With a = phi^n the
 * numerator is n(1-phi^2) - phi(3 - 4a + a^2); multiplying by e^L = 1/phi and
 * writing x = nL:
 *     numerator * e^L = 2n sinh(L) - 3 + 4e^{-x} - e^{-2x}
 *                     = f(x) + 2n (sinh L - L),   f(x) = 2x - 3 + 4e^{-x} - e^{-2x},
 * a sum of two NON-NEGATIVE terms, each evaluated without cancellation (series
 * for small arguments). The denominator e^L (1-phi)^2 = 4 sinh^2(L/2). So
 *     nu^2 = s2 [f(nL) + 2n(sinh L - L)] / (8 n^2 sinh^2(L/2)),
 * relative accuracy ~1e-15 for every phi in (0,1) and every n, where the
 * literal formula loses ~ -2 log10(n (1-phi)) digits as phi -> 1.
 */
double haarWvStationaryAr1(double s2, double L, double n) {
  if (L > 0.5) {
    // phi < 0.61: the literal formula has no harmful cancellation here (and
    // sinh(L) could overflow for huge L).
    const double phi = std::exp(-L);
    const double num = n - 3.0 * phi - n * phi * phi + 4.0 * std::pow(phi, n + 1.0) -
                       std::pow(phi, 2.0 * n + 1.0);
    return s2 * num / (2.0 * n * n * (1.0 - phi) * (1.0 - phi));
  }
  const double sh = std::sinh(0.5 * L);
  return s2 * (fAr1(n * L) + 2.0 * n * sinhMinusId(L)) / (8.0 * n * n * sh * sh);
}

}  // namespace

double haarWvAr1(double phi, double sigma2_innov, double tau) {
  detail::checkTau(tau);
  const double n = 0.5 * tau;
  if (phi > 0.0 && phi < 1.0) {
    const double L = -std::log1p(phi - 1.0);  // phi - 1 exact near 1 (Sterbenz)
    const double s2 = sigma2_innov / (-std::expm1(-2.0 * L));  // sigma2 / (1 - phi^2)
    return haarWvStationaryAr1(s2, L, n);
  }
  if (!(phi > -1.0 && phi <= 0.0))
    throw Error("AR1 wavelet variance: phi = " + formatNumber(phi, 10) +
                " outside the stationary range (-1, 1)");
  // phi <= 0: literal R formula (no cancellation for non-positive phi).
  const double num = n - 3.0 * phi - n * phi * phi + 4.0 * std::pow(phi, n + 1.0) -
                     std::pow(phi, 2.0 * n + 1.0);
  return sigma2_innov * num / (2.0 * n * n * (1.0 - phi) * (1.0 - phi) * (1.0 - phi * phi));
}

Process Process::ar1(double phi, double sigma2_innov, double rate_hz) {
  if (!(phi > 0.0 && phi < 1.0))
    throw Error("AR1(phi=" + formatNumber(phi, 10) +
                "): phi must be in (0, 1) to be a Gauss-Markov process");
  if (!(sigma2_innov > 0.0) || !std::isfinite(sigma2_innov))
    throw Error("AR1: sigma2 must be a finite number > 0");
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
    throw Error("AR1: a positive rate_hz is needed to convert AR1 to GM");
  // phi = exp(-dt/T)  =>  T = -dt / ln(phi); ln(phi) = log1p(phi - 1) is exact
  // for phi near 1 because phi - 1 is computed without rounding (Sterbenz).
  const double dt = 1.0 / rate_hz;
  const double T = -dt / std::log1p(phi - 1.0);
  // Stationary variance of x_k = phi x_{k-1} + e_k: sigma2 / (1 - phi^2).
  const double one_minus_phi2 = (1.0 - phi) * (1.0 + phi);
  return gm(std::sqrt(sigma2_innov / one_minus_phi2), T);
}

namespace detail {

namespace {

class GaussMarkov final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::GM, "GM",
        {{"sigma", &Process::sigma, "u (stationary)", true,
          [](double, double) { return std::make_pair(1e-6, 10.0); }, "1e-6 .. 10 u"},
         {"T", &Process::T, "s", true,
          [](double rate, double dur) { return std::make_pair(2.0 / rate, dur / 5.0); },
          "2/rate .. duration/5 s (longer: a random walk over the record)"}},
        {{"AR1", {"phi", "sigma2"}}}, SpectralForm::Density, true};
    return i;
  }

  Process fromAlias(std::size_t, const double* v, double rate_hz) const override {
    // AR1(phi, sigma2) in the R package's form, stored as GM.
    const double phi = v[0], s2 = v[1];
    if (!(phi > 0.0 && phi < 1.0))
      throw AliasValueError{0, "phi in (0, 1) (an AR1 stored as Gauss-Markov)",
                            "phi=" + formatNumber(phi, 10)};
    if (!(s2 > 0.0)) throw AliasValueError{1, "sigma2 > 0", "sigma2=" + formatNumber(s2)};
    if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
      throw AliasValueError{-1, "a model rate (rate_hz > 0) to convert AR1 to GM", "no rate"};
    return Process::ar1(phi, s2, rate_hz);
  }

  void convertRate(Process&, double) const override {
    // The same continuous GM process (stationary sigma, correlation time T
    // in seconds) sampled at another rate: both unchanged, phi = exp(-dt/T)
    // follows dt. (Its discrete Haar WV in seconds is invariant only up to
    // O((dt/T)^2) and O(dt/tau_s)^2 sampling effects.)
  }
  double conversionWvBound(const Process& p, double rate_a, double rate_b,
                           double tau_s) const override {
    // At x = tau_s / (2T) and L = dt/T the sampled WV is the continuous one,
    // sigma^2 f(x) / (2 x^2), times 1 + d(L) with d(L) = L^2 (x / (3 f(x)) -
    // 1/12) + O(L^4) >= 0 (f(x) <= 2x), growing with L: the conversion changes
    // the WV in seconds by at most d at the slower rate, evaluated exactly here.
    const double rate = std::min(rate_a, rate_b);
    const double n = 0.5 * tau_s * rate, L = 1.0 / (rate * p.T), x = n * L;
    return haarWvStationaryAr1(1.0, L, n) * 2.0 * x * x / fAr1(x) - 1.0 + 1e-13;
  }

  double haarWv(const Process& p, double rate_hz, double tau) const override {
    // AR1 with phi = exp(-dt/T) and innovation variance sigma^2 (1 - phi^2);
    // L = dt/T is used directly (no rounding through phi).
    if (!(rate_hz > 0.0) || !(p.T > 0.0))
      throw Error("GM wavelet variance: needs rate_hz > 0 and T > 0");
    const double L = 1.0 / (rate_hz * p.T);
    return haarWvStationaryAr1(p.sigma * p.sigma, L, 0.5 * tau);
  }

  void simulateAdd(const Process& p, double rate_hz, Rng& rng, SimState& st, double* out,
                   std::size_t n) const override {
    // Exact discretisation: phi = exp(-dt/T), innovation std sigma sqrt(1-phi^2);
    // stationary start x_0 ~ N(0, sigma^2). st.x: the next sample.
    const double L = 1.0 / (rate_hz * p.T);
    const double phi = std::exp(-L);
    const double q = p.sigma * std::sqrt(-std::expm1(-2.0 * L));
    if (st.k == 0) st.x = p.sigma * rng.normal();
    double x = st.x;
    for (std::size_t k = 0; k < n; ++k) {
      out[k] += x;
      x = phi * x + q * rng.normal();
    }
    st.x = x;
    st.k += n;
  }

  std::optional<SampledArma> sampledArma(const Process& p, double rate_hz) const override {
    // AR(1), phi = exp(-dt/T), innovation variance sigma^2 (1 - phi^2), stationary start.
    const double L = 1.0 / (rate_hz * p.T);
    const double s2 = p.sigma * p.sigma;
    return SampledArma{std::exp(-L), 0.0, s2 * -std::expm1(-2.0 * L), s2};
  }

  int stateCount() const override { return 1; }
  void stateSpace(const Process& p, double, StateSpaceBlock& b) const override {
    // x' = -x/T + w with Qc = 2 sigma^2 / T keeps var(x) = sigma^2 in steady state
    // (first-order Gauss-Markov, Brown & Hwang "Introduction to Random Signals").
    b.F(0, 0) = -1.0 / p.T;
    b.Qc(0, 0) = 2.0 * p.sigma * p.sigma / p.T;
    b.H(0) = 1.0;
    b.P0(0, 0) = p.sigma * p.sigma;
    b.names = {"(T=" + formatNumber(p.T, 4) + "s)"};
  }

  std::function<double(double)> density(const Process& p, double rate_hz) const override {
    // AR(1), phi = exp(-L): S = s2 (1 - phi^2) / ((1 - phi)^2 + 4 phi s), stable for phi -> 1.
    const double L = 1.0 / (p.T * rate_hz);
    const double om = -std::expm1(-L);
    const double g0 = p.sigma * p.sigma * (-std::expm1(-2.0 * L)), g1 = om * om,
                 g2 = 4.0 * std::exp(-L);
    return [g0, g1, g2](double s) { return g0 / (g1 + g2 * s); };
  }
  // A GM with T below kWhiteGmMaxSamples samples is white noise at every
  // averaging time beyond a few samples: its flat PSD level (the AR(1)
  // density at f = 0, the long-run variance sigma^2 (1+phi)/(1-phi) per
  // sample) adds to the noise density N^2 = dt S(0). Longer GMs show in the
  // bias instability of the model's Allan deviation (datasheet.cpp).
  void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const override {
    if (!(p.T > 0.0) || !(p.T * rate_hz < kWhiteGmMaxSamples)) return;
    const double n2 = density(p, rate_hz)(0.0) / rate_hz;
    const double prev = f.noise_density ? *f.noise_density * *f.noise_density : 0.0;
    f.noise_density = std::sqrt(prev + n2);
    f.noise_density_gm_n2 += n2;
    ++f.noise_density_gms;
  }
};

}  // namespace

const KindDef& kindGM() {
  static const GaussMarkov k;
  return k;
}

}  // namespace detail
}  // namespace navimpact::stochastic
