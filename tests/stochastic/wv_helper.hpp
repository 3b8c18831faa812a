// Small independent helpers for the stochastic tests (no dependency on lib/gmwm).
#pragma once

#include <cstddef>
#include <vector>

namespace navimpact::test {

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
