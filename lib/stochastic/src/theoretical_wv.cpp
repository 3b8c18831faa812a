// Closed-form Haar wavelet variance (WV) of the latent processes.
// Formulas: Guerrier et al. 2013 / R package gmwm src/process_to_wv.cpp, see
// shared/reference/gmwm_formulas.md §3; tau in samples, n = tau/2.
#include "navimpact/stochastic/theoretical_wv.hpp"

#include <cmath>

#include "navimpact/core/error.hpp"

namespace navimpact::stochastic {

namespace {

constexpr double kPi = 3.14159265358979323846;

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

void checkTau(double tau) {
  if (!(tau >= 2.0) || !std::isfinite(tau))
    throw Error("Haar wavelet variance: scale tau = " + std::to_string(tau) +
                " samples is invalid (expected tau >= 2)");
}

}  // namespace

double haarWvAr1(double phi, double sigma2_innov, double tau) {
  checkTau(tau);
  const double n = 0.5 * tau;
  if (phi > 0.0 && phi < 1.0) {
    const double L = -std::log1p(phi - 1.0);  // phi - 1 exact near 1 (Sterbenz)
    const double s2 = sigma2_innov / (-std::expm1(-2.0 * L));  // sigma2 / (1 - phi^2)
    return haarWvStationaryAr1(s2, L, n);
  }
  if (!(phi > -1.0 && phi <= 0.0))
    throw Error("AR1 wavelet variance: phi = " + std::to_string(phi) +
                " outside the stationary range (-1, 1)");
  // phi <= 0: literal R formula (no cancellation for non-positive phi).
  const double num = n - 3.0 * phi - n * phi * phi + 4.0 * std::pow(phi, n + 1.0) -
                     std::pow(phi, 2.0 * n + 1.0);
  return sigma2_innov * num / (2.0 * n * n * (1.0 - phi) * (1.0 - phi) * (1.0 - phi * phi));
}

double haarWv(const Process& p, double rate_hz, double tau) {
  checkTau(tau);
  switch (p.kind) {
    case ProcessKind::WN: return p.sigma * p.sigma / tau;                       // sigma^2/tau
    case ProcessKind::QN: return 6.0 * p.Q * p.Q / (tau * tau);                 // 6 Q^2/tau^2
    case ProcessKind::RW: return p.gamma * p.gamma * (tau * tau + 2.0) / (12.0 * tau);
    case ProcessKind::DR: return p.omega * p.omega * tau * tau / 16.0;         // omega^2 tau^2/16
    case ProcessKind::GM: {
      // AR1 with phi = exp(-dt/T) and innovation variance sigma^2 (1 - phi^2);
      // L = dt/T is used directly (no rounding through phi).
      if (!(rate_hz > 0.0) || !(p.T > 0.0))
        throw Error("GM wavelet variance: needs rate_hz > 0 and T > 0");
      const double L = 1.0 / (rate_hz * p.T);
      return haarWvStationaryAr1(p.sigma * p.sigma, L, 0.5 * tau);
    }
    case ProcessKind::SIN: {
      // Random-phase sinusoid A sin(w k + theta), w = 2 pi f / rate [rad/sample].
      // The mean of n consecutive samples is A D sin(w c + theta) with
      // D = sin(n w/2) / (n sin(w/2)); two adjacent means differ by a phase
      // n w, so W = A D sin(n w/2) cos(.), and averaging cos^2 over the phase:
      //   nu^2 = (A^2/2) sin^4(n w/2) / (n^2 sin^2(w/2)).
      if (!(rate_hz > 0.0)) throw Error("SIN wavelet variance: needs rate_hz > 0");
      const double w = 2.0 * kPi * p.freq_hz / rate_hz;
      const double n = 0.5 * tau;
      const double s = std::sin(0.5 * n * w);
      const double sw = std::sin(0.5 * w);
      return 0.5 * p.amp * p.amp * s * s * s * s / (n * n * sw * sw);
    }
  }
  return 0.0;
}

Eigen::VectorXd haarWv(const Model& m, const Eigen::VectorXd& tau) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(tau.size());
  for (const auto& p : m.terms)
    for (Eigen::Index j = 0; j < tau.size(); ++j) out[j] += haarWv(p, m.rate_hz, tau[j]);
  return out;
}

Eigen::MatrixXd haarWvTerms(const Model& m, const Eigen::VectorXd& tau) {
  Eigen::MatrixXd out(tau.size(), static_cast<Eigen::Index>(m.terms.size()));
  for (std::size_t i = 0; i < m.terms.size(); ++i)
    for (Eigen::Index j = 0; j < tau.size(); ++j)
      out(j, static_cast<Eigen::Index>(i)) = haarWv(m.terms[i], m.rate_hz, tau[j]);
  return out;
}

Eigen::VectorXd dyadicScales(int J) {
  if (J < 1 || J > 62) throw Error("dyadicScales: J = " + std::to_string(J) + " outside 1..62");
  Eigen::VectorXd tau(J);
  for (int j = 0; j < J; ++j) tau[j] = std::ldexp(1.0, j + 1);
  return tau;
}

}  // namespace navimpact::stochastic
