// Closed-form Haar wavelet variance (WV) of models. Each kind's formula is in
// processes/<name>.cpp (Guerrier et al. 2013 / R package gmwm
// src/process_to_wv.cpp, see shared/reference/gmwm_formulas.md §3); tau in
// samples, n = tau/2.
#include "navimpact/stochastic/theoretical_wv.hpp"

#include <cmath>

#include "kind.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::stochastic {

namespace detail {

void checkTau(double tau) {
  if (!(tau >= 2.0) || !std::isfinite(tau))
    throw Error("Haar wavelet variance: scale tau = " + formatNumber(tau) +
                " samples is invalid (expected tau >= 2)");
}

}  // namespace detail

// haarWvAr1 (the R package's AR1 form) is with its kind in processes/gm.cpp.

double haarWv(const Process& p, double rate_hz, double tau) {
  detail::checkTau(tau);
  return detail::kindDef(p.kind).haarWv(p, rate_hz, tau);  // processes/<name>.cpp
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
