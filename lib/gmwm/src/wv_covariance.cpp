// Asymptotic covariance of the empirical Haar MODWT wavelet variance across
// scales under a Gaussian composite model (Percival 1995; Percival & Walden
// 2000, §8.3 and eq. 308a generalised to two scales):
//
//   Cov(nu_hat_j, nu_hat_k) ~ 2 / max(M_j, M_k) * int_{-1/2}^{1/2} |H_j(f)|^2 |H_k(f)|^2 S(f)^2 df,
//
// with H_j the level-j Haar MODWT wavelet filter (tau_j = 2 n_j samples,
// coefficients +-1/tau_j): |H_j(f)|^2 = sin^4(pi f n_j) / (n_j^2 sin^2(pi f)),
// and S the two-sided spectral density per sample of the random terms.
//
// The integrand oscillates with periods 1/n_j and 1/n_k in f; the coarsest
// filter at 4.3 M samples would need ~10^7 grid points. Above A periods of a
// filter, where the remaining factors vary by less than 1/A over one period,
// the oscillating factor sin^4(pi f n) is replaced by its mean over a period:
// 3/8 for one filter, and for the product of two filters with n_b = 2^d n_a
// (whose product is periodic in 1/n_a): 35/128 (d = 0), 7/64 (d = 1), 9/64
// (d >= 2) (expand sin^4 x = 3/8 - cos 2x / 2 + cos 4x / 8). Below, the
// integrand is evaluated exactly on a grid of P points per period; the whole
// range uses a geometric step of at most 2 % of f (from 1e-7 / n_max up),
// which resolves the Lorentzian corner of a GM far below 1 / n. Midpoint rule.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/stochastic/spectrum.hpp"

namespace navimpact::gmwm {

using stochastic::Model;

namespace {

constexpr double kA = 16.0;     // periods integrated exactly before averaging
constexpr double kP = 16.0;     // grid points per period in the exact part
constexpr double kRel = 0.02;   // largest geometric step (fraction of f)

/// Two-sided spectral density per sample of the random terms of a model
/// (stochastic::Spectrum: WN, QN, RW pseudo-spectrum, GM; DR and SIN are
/// deterministic and have no density), as a function of s1sq = sin^2(pi f).
struct Spectrum {
  stochastic::Spectrum s;
  explicit Spectrum(const Model& m) : s(m) {}
  double operator()(double s1sq) const { return s.perSample(s1sq); }
};

/// Mean over a period of sin^4(x) sin^4(2^d x).
double pairMean(int d) { return d == 0 ? 35.0 / 128.0 : (d == 1 ? 7.0 / 64.0 : 9.0 / 64.0); }

/**
 * 2 * int_0^{1/2} prod_i |H_{n_i}(f)|^2 S(f)^p df for one filter (nb = 0) or
 * two filters na <= nb (in samples, powers of two).
 */
double integrate(const Spectrum& S, double na, double nb, int p) {
  const bool pair = nb > 0;
  const double nmax = pair ? nb : na;
  const int d = pair ? static_cast<int>(std::lround(std::log2(nb / na))) : 0;
  const double f1 = kA / nmax;            // below: everything exact
  const double f2 = pair ? kA / na : f1;  // between f1 and f2: coarse filter averaged
  const double q2 = pairMean(d);
  double sum = 0.0;
  double f = 1e-7 / nmax;  // the integrand vanishes at 0 (|H|^2 ~ f^2; RW: finite): the part below is < 1e-7
  while (f < 0.5) {
    double h = kRel * f;
    if (f < f1)
      h = std::min(h, 1.0 / (kP * nmax));
    else if (f < f2)
      h = std::min(h, 1.0 / (kP * na));
    const double b = std::min(f + h, 0.5);
    const double fm = 0.5 * (f + b);
    const double s1 = std::sin(M_PI * fm);
    const double s1sq = s1 * s1;
    const double Sf = S(s1sq);
    double g;
    if (!pair) {
      const double q = fm < f1 ? std::pow(std::sin(M_PI * fm * na), 4) : 3.0 / 8.0;
      g = q / (na * na * s1sq);
    } else {
      double q;
      if (fm < f1)
        q = std::pow(std::sin(M_PI * fm * na), 4) * std::pow(std::sin(M_PI * fm * nb), 4);
      else if (fm < f2)
        q = std::pow(std::sin(M_PI * fm * na), 4) * 3.0 / 8.0;
      else
        q = q2;
      g = q / (na * na * nb * nb * s1sq * s1sq);
    }
    sum += g * (p == 1 ? Sf : Sf * Sf) * (b - f);
    f = b;
  }
  return 2.0 * sum;
}

}  // namespace

double spectralWv(const Model& m, double tau) {
  if (!(tau >= 2.0)) throw Error("spectralWv: scale " + formatNumber(tau) + " below 2 samples");
  return integrate(Spectrum(m), 0.5 * tau, 0.0, 1);
}

Eigen::MatrixXd wvCovariance(const Model& m, const WaveletVariance& wv) {
  if (!(m.rate_hz > 0.0)) throw Error("wvCovariance: the model has no rate");
  const int J = wv.scales();
  const Spectrum S(m);
  Eigen::MatrixXd V(J, J);
  for (int j = 0; j < J; ++j) {
    const double Mj = wv.n_coef.size() == J ? wv.n_coef[j] : double(wv.n) - wv.tau[j] + 1.0;
    for (int k = j; k < J; ++k) {
      const double Mk = wv.n_coef.size() == J ? wv.n_coef[k] : double(wv.n) - wv.tau[k] + 1.0;
      const double M = std::max(std::max(Mj, Mk), 1.0);
      V(j, k) = V(k, j) = 2.0 / M * integrate(S, 0.5 * wv.tau[j], 0.5 * wv.tau[k], 2);
    }
  }
  return V;
}

}  // namespace navimpact::gmwm
