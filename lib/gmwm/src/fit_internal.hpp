// Internal machinery of the GMWM estimator shared by estimator.cpp and
// selection.cpp: parameter layout in the transformed space, the templated
// (autodiff-ready) theoretical Haar WV, and Jacobians.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::gmwm::detail {

using stochastic::Model;
using stochastic::Process;
using stochastic::ProcessKind;

/// Largest number of parameters a structure may have (size of the autodiff Jet).
constexpr int kMaxParams = 16;

/// Number of parameters of one process kind.
inline int paramCount(ProcessKind k) {
  return (k == ProcessKind::GM || k == ProcessKind::SIN) ? 2 : 1;
}

/**
 * Transformed parameter vector theta of a structure, term by term:
 *   WN  log sigma            QN  log Q             RW  log gamma
 *   DR  log |omega|          GM  log sigma, log(T rate)  (T in samples)
 *   SIN log amp, log(freq/rate)  (cycles per sample)
 * Every value is positive after back-transformation; DR loses its sign as in
 * the R package (gmwm_formulas.md §4).
 */
struct Layout {
  std::vector<ProcessKind> kinds;
  std::vector<int> offset;  ///< first parameter of term i
  int p = 0;
  explicit Layout(const std::vector<ProcessKind>& k) : kinds(k) {
    for (ProcessKind x : kinds) {
      offset.push_back(p);
      p += paramCount(x);
    }
  }
};

/// sinh(L) - L, accurate for small L (series), any scalar/Jet type.
template <typename T>
T sinhMinusId(const T& L) {
  using std::sinh;
  if (L >= 1.0) return sinh(L) - L;
  const T L2 = L * L;
  T term = L * L2 / 6.0;
  T sum = term;
  for (int k = 3; k < 40; k += 2) {
    term = term * L2 / ((k + 1.0) * (k + 2.0));
    sum = sum + term;
    if (term <= 1e-18 * sum) break;
  }
  return sum;
}

/// f(x) = 2x - 3 + 4e^{-x} - e^{-2x} (>= 0), series for small x (no cancellation).
template <typename T>
T fAr1(const T& x) {
  using std::exp;
  if (x >= 1.0) return 2.0 * x - 3.0 + 4.0 * exp(-x) - exp(-2.0 * x);
  T xk = x * x * x / 6.0;  // x^k / k!, k = 3
  double two_k = 8.0;
  T sum = -(4.0 - two_k) * xk;
  for (int k = 4; k < 60; ++k) {
    xk = xk * x / double(k);
    two_k *= 2.0;
    const T term = ((k % 2) ? -1.0 : 1.0) * (4.0 - two_k) * xk;
    sum = sum + term;
    using std::abs;
    if (abs(term) <= 1e-18 * sum) break;
  }
  return sum;
}

/**
 * Haar WV of a stationary GM/AR1 with stationary variance s2 and
 * phi = exp(-L), at tau = 2n samples, stable for phi -> 1 (same closed form as
 * stochastic::haarWv; Guerrier et al. 2013 / gmwm_formulas.md §3):
 *   nu^2 = s2 [f(nL) + 2n(sinh L - L)] / (8 n^2 sinh^2(L/2)).
 */
template <typename T>
T gmWv(const T& s2, const T& L, double n) {
  using std::exp;
  using std::sinh;
  if (L > 0.5) {
    const T phi = exp(-L);
    const T num = n - 3.0 * phi - n * phi * phi + 4.0 * exp(-(n + 1.0) * L) - exp(-(2.0 * n + 1.0) * L);
    const T om = 1.0 - phi;
    return s2 * num / (2.0 * n * n * om * om);
  }
  const T sh = sinh(0.5 * L);
  return s2 * (fAr1(n * L) + 2.0 * n * sinhMinusId(L)) / (8.0 * n * n * sh * sh);
}

/// Haar WV at scale tau (samples) of term @p k with transformed parameters @p th.
template <typename T>
T termWv(ProcessKind k, const T* th, double tau) {
  using std::exp;
  using std::sin;
  switch (k) {
    case ProcessKind::WN: return exp(2.0 * th[0]) / tau;
    case ProcessKind::QN: return 6.0 * exp(2.0 * th[0]) / (tau * tau);
    case ProcessKind::RW: return exp(2.0 * th[0]) * ((tau * tau + 2.0) / (12.0 * tau));
    case ProcessKind::DR: return exp(2.0 * th[0]) * (tau * tau / 16.0);
    case ProcessKind::GM: return gmWv(exp(2.0 * th[0]), exp(-th[1]), 0.5 * tau);
    case ProcessKind::SIN: {
      const double n = 0.5 * tau;
      const T w = 2.0 * M_PI * exp(th[1]);
      const T s = sin(0.5 * n * w);
      const T sw = sin(0.5 * w);
      return 0.5 * exp(2.0 * th[0]) * s * s * s * s / (n * n * sw * sw);
    }
  }
  return T(0.0);
}

/// Model WV at every scale.
template <typename T>
void modelWv(const Layout& L, const T* th, const Eigen::VectorXd& tau, T* out) {
  for (Eigen::Index j = 0; j < tau.size(); ++j) {
    T s(0.0);
    for (std::size_t i = 0; i < L.kinds.size(); ++i) s = s + termWv(L.kinds[i], th + L.offset[i], tau[j]);
    out[j] = s;
  }
}

/// Theta -> Model (GM terms kept in layout order).
Model toModel(const Layout& L, const Eigen::VectorXd& th, double rate_hz);
/// Model -> theta (kinds must match L; DR sign dropped).
Eigen::VectorXd fromModel(const Layout& L, const Model& m);
/// A = d nu / d theta (J x p), analytic through Jets.
Eigen::MatrixXd jacobian(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau);
/// Model WV nu(theta).
Eigen::VectorXd wvOf(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau);
/// Pseudo-inverse of the symmetric part of @p M (eigenvalues below 1e-12 of the largest dropped).
Eigen::MatrixXd pinvSym(const Eigen::MatrixXd& M);

}  // namespace navimpact::gmwm::detail
