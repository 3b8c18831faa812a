// Small independent helpers for the stochastic tests (no dependency on lib/gmwm).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::test {

/// The model of @p terms at @p rate Hz.
inline stochastic::Model model(double rate, std::vector<stochastic::Process> terms) {
  stochastic::Model m;
  m.rate_hz = rate;
  m.terms = std::move(terms);
  return m;
}

/// Covariance of @p n consecutive samples of a term's sampled form, written
/// out from its definition: x = C [z_{-1}, e_0 .. e_{n-1}]',
/// Cov x = C diag(p0, q, ..., q) C'.
inline Eigen::MatrixXd sampledFormCovariance(const stochastic::SampledArma& a, int n) {
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(n + 1, n + 1);  // row t+1: z_t; row 0: z_{-1}
  Z(0, 0) = 1.0;
  for (int t = 0; t < n; ++t) {
    Z.row(t + 1) = a.phi * Z.row(t);
    Z(t + 1, t + 1) += 1.0;
  }
  Eigen::MatrixXd C(n, n + 1);
  for (int t = 0; t < n; ++t) C.row(t) = Z.row(t + 1) - a.mu * Z.row(t);
  Eigen::VectorXd D = Eigen::VectorXd::Constant(n + 1, a.q);
  D(0) = a.p0;
  return C * D.asDiagonal() * C.transpose();
}

/// Empirical Haar MODWT WV from the definition (R gmwm, gmwm_formulas.md §1):
/// W_t = (mean of the last n samples - mean of the n before) / 2, n = tau/2,
/// over all M = N - tau + 1 full windows; nu^2 = mean of W_t^2 (no mean removal).
inline double empiricalHaarWv(const std::vector<double>& x, std::size_t tau, std::size_t* M_out = nullptr) {
  const std::size_t n = tau / 2;
  std::vector<double> c(x.size() + 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) c[i + 1] = c[i] + x[i];
  double s = 0.0;
  std::size_t M = 0;
  for (std::size_t t = tau; t <= x.size(); ++t, ++M) {
    const double w = ((c[t] - c[t - n]) - (c[t - n] - c[t - tau])) / (2.0 * static_cast<double>(n));
    s += w * w;
  }
  if (M_out) *M_out = M;
  return s / static_cast<double>(M);
}

}  // namespace navimpact::test
