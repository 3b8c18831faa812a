// Helpers shared by the detector tests.
#pragma once

#include <cmath>
#include <cstddef>
#include <random>

#include "navimpact/stochastic/process.hpp"

namespace detecttest {

/// A value log-uniform in [a, b]: a (b/a)^u, u uniform in [0, 1) from @p rng.
inline double logUniform(std::mt19937_64& rng, double a, double b) {
  return a * std::pow(b / a, std::uniform_real_distribution<double>(0, 1)(rng));
}

/// A record of white noise drawn at random: its length log-uniform in
/// [n_lo, n_hi] samples, its rate in [50, 1000] Hz, the sigma in [1e-4, 0.1]
/// (drawn in that order).
struct WhiteRecord {
  navimpact::stochastic::Model model;
  std::size_t n = 0;
  double sigma = 0.0;
};
inline WhiteRecord drawWhiteRecord(std::mt19937_64& rng, double n_lo, double n_hi) {
  WhiteRecord w;
  w.n = static_cast<std::size_t>(std::lround(logUniform(rng, n_lo, n_hi)));
  w.model.rate_hz = logUniform(rng, 50, 1000);
  w.sigma = logUniform(rng, 1e-4, 1e-1);
  w.model.terms = {navimpact::stochastic::Process::wn(w.sigma)};
  return w;
}

}  // namespace detecttest
