#include "navimpact/detect/null_model.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "navimpact/stochastic/spectrum.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::detect {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

PsdFunction psdOf(const stochastic::Model& m) {
  // stochastic::Spectrum is one-sided; the detectors use the two-sided density.
  auto sp = std::make_shared<stochastic::Spectrum>(m);
  const double nyq = 0.5 * m.rate_hz;
  return [sp, nyq](double f) { return 0.5 * (*sp)(std::min(std::max(f, 1e-300), nyq)); };
}

HaarWvFunction haarWvOf(const stochastic::Model& m) {
  return [m](double tau) {
    double v = 0;
    for (const auto& p : m.terms) v += stochastic::haarWv(p, m.rate_hz, tau);
    return v;
  };
}

double secondDifferenceSd(const stochastic::Model& m) {
  // (1/2pi) int_{-pi}^{pi} S(w) (1 - cos w)^2 dw with S the two-sided density
  // per sample (Spectrum::perSample), midpoint rule on (0, pi].
  const stochastic::Spectrum sp(m);
  const int K = 4096;
  double acc = 0;
  for (int i = 0; i < K; ++i) {
    const double w = (i + 0.5) * kPi / K;
    const double h = 1.0 - std::cos(w);
    const double s2 = std::sin(0.5 * w);
    acc += sp.perSample(s2 * s2) * h * h;
  }
  return std::sqrt(acc / K);
}

}  // namespace navimpact::detect
