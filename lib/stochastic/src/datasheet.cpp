// Datasheet figures (IEEE Std 952-1997 Allan-variance terms) from a model.
#include "navimpact/stochastic/datasheet.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include "kind.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::stochastic {

namespace {

/// Model Allan variance at averaging time m samples (real m >= 1), from the
/// Haar WV relation nu^2(tau = 2m) = AVAR(m) / 2 (Percival & Walden 2000;
/// shared/reference/gmwm_formulas.md §1).
double modelAvar(const Model& m, double m_samples) {
  double wv = 0.0;
  for (const auto& p : m.terms) wv += haarWv(p, m.rate_hz, 2.0 * m_samples);
  return 2.0 * wv;
}

std::string line(const char* label, double v, const char* unit) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-18s %.4g %s\n", label, v, unit);
  return buf;
}

}  // namespace

DatasheetFigures datasheetFigures(const Model& m) {
  DatasheetFigures f;
  if (m.terms.empty() || !(m.rate_hz > 0.0)) return f;
  const double dt = 1.0 / m.rate_hz;
  // Each kind adds its own figure (processes/<name>.cpp): WN the noise
  // density N = sigma sqrt(dt), RW the rate random walk K = gamma / sqrt(dt),
  // QN the quantization Q dt, DR the drift rate omega / dt; independent terms
  // of one kind add in variance, drifts add.
  for (const auto& p : m.terms) detail::kindDef(p.kind).addDatasheet(p, m.rate_hz, f);

  // Bias instability: first local minimum of the model ADEV on a log grid of
  // averaging times from 1 sample to 1e6 s (50 points per decade), divided by
  // 0.664 = sqrt(2 ln 2 / pi) (IEEE 952, flicker floor). Empty when the ADEV
  // has no interior local minimum on the grid (e.g. WN alone, or WN + GM whose
  // curve only decreases). The first local minimum is the datasheet reading
  // (the floor after the white-noise slope), even if a later GM with a very
  // long T bends the curve down again beyond 1e6 s.
  const double m_max = 1e6 * m.rate_hz;
  const int per_decade = 50;
  std::vector<double> ms;
  for (int i = 0;; ++i) {
    const double mm = std::pow(10.0, static_cast<double>(i) / per_decade);
    if (mm > m_max) break;
    ms.push_back(mm);
  }
  std::vector<double> adev(ms.size());
  for (std::size_t i = 0; i < ms.size(); ++i) adev[i] = std::sqrt(modelAvar(m, ms[i]));
  for (std::size_t i = 1; i + 1 < ms.size(); ++i) {
    if (adev[i] < adev[i - 1] && adev[i] <= adev[i + 1]) {
      f.bias_instability = adev[i] / 0.664;
      f.bias_instability_tau_s = ms[i] * dt;
      break;
    }
  }
  return f;
}

std::string formatDatasheet(const DatasheetFigures& f, units::Quantity q) {
  using namespace units;
  std::string s;
  char buf[64];
  if (q == Quantity::AngularRate) {
    // N [rad/sqrt(s)]: angle std after t is N sqrt(t) -> deg/sqrt(h) = N (180/pi) 60.
    if (f.noise_density) s += line("ARW", *f.noise_density / kDeg * kSqrtHour, "deg/sqrt(h)");
    if (f.bias_instability) {
      std::snprintf(buf, sizeof buf, "deg/h (ADEV min at %.3g s)", *f.bias_instability_tau_s);
      s += line("bias instability", *f.bias_instability / kDeg * kHour, buf);
    }
    // K [rad/s/sqrt(s)] -> deg/h/sqrt(h) = K (180/pi) 3600 * 60.
    if (f.random_walk) s += line("RRW", *f.random_walk / kDeg * kHour * kSqrtHour, "deg/h/sqrt(h)");
    if (f.quantization) s += line("quantization", *f.quantization / kDeg * 3600.0, "arcsec");
    if (f.drift_rate) s += line("drift rate", *f.drift_rate / kDeg * kHour * kHour, "deg/h/h");
  } else {
    // N [m/s^2*sqrt(s) = m/s/sqrt(s)] -> m/s/sqrt(h) = N 60.
    if (f.noise_density) s += line("VRW", *f.noise_density * kSqrtHour, "m/s/sqrt(h)");
    if (f.bias_instability) {
      std::snprintf(buf, sizeof buf, "mg (ADEV min at %.3g s)", *f.bias_instability_tau_s);
      s += line("bias instability", *f.bias_instability / kG0 * 1e3, buf);
    }
    // K [m/s^2/sqrt(s)] -> mg/sqrt(h) = K 60 / g0 * 1e3.
    if (f.random_walk) s += line("acc random walk", *f.random_walk * kSqrtHour / kG0 * 1e3, "mg/sqrt(h)");
    if (f.quantization) s += line("quantization", *f.quantization, "m/s");
    if (f.drift_rate) s += line("drift rate", *f.drift_rate * kHour / kG0 * 1e3, "mg/h");
  }
  if (s.empty()) s = "(no error)\n";
  return s;
}

}  // namespace navimpact::stochastic
