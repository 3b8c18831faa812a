#include "navimpact/detect/null_model.hpp"

#include <cmath>

#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::detect {

namespace {
constexpr double kPi = 3.14159265358979323846;

/// Two-sided PSD times fs (i.e. per unit of w / 2 pi) at w in (0, pi].
double psdTimesFs(const stochastic::Model& m, double w) {
  double s = 0;
  const double s2 = std::sin(0.5 * w);
  for (const auto& p : m.terms) {
    switch (p.kind) {
      case stochastic::ProcessKind::WN: s += p.sigma * p.sigma; break;
      case stochastic::ProcessKind::QN: s += 4.0 * p.Q * p.Q * s2 * s2; break;
      case stochastic::ProcessKind::RW: s += p.gamma * p.gamma / (4.0 * s2 * s2); break;
      case stochastic::ProcessKind::GM: {
        const double phi = std::exp(-1.0 / (m.rate_hz * p.T));
        s += p.sigma * p.sigma * (1.0 - phi * phi) / (1.0 - 2.0 * phi * std::cos(w) + phi * phi);
        break;
      }
      case stochastic::ProcessKind::DR:
      case stochastic::ProcessKind::SIN: break;
    }
  }
  return s;
}
}  // namespace

PsdFunction psdOf(const stochastic::Model& m) {
  return [m](double f) {
    const double w = 2.0 * kPi * f / m.rate_hz;
    return psdTimesFs(m, w) / m.rate_hz;
  };
}

HaarWvFunction haarWvOf(const stochastic::Model& m) {
  return [m](double tau) {
    double v = 0;
    for (const auto& p : m.terms) v += stochastic::haarWv(p, m.rate_hz, tau);
    return v;
  };
}

double secondDifferenceSd(const stochastic::Model& m) {
  // (1/2pi) int_{-pi}^{pi} s(w) (1 - cos w)^2 dw, midpoint rule on (0, pi].
  const int K = 4096;
  double acc = 0;
  for (int i = 0; i < K; ++i) {
    const double w = (i + 0.5) * kPi / K;
    const double h = 1.0 - std::cos(w);
    acc += psdTimesFs(m, w) * h * h;
  }
  return std::sqrt(acc / K);
}

}  // namespace navimpact::detect
