// Datasheet figures (IEEE Std 952-1997 Allan-variance terms) from a model.
#include "navimpact/stochastic/datasheet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "kind.hpp"
#include "navimpact/core/golden_section.hpp"
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

std::string line(const char* label, double v, const std::string& unit) {
  std::string l = label;
  l.resize(std::max<std::size_t>(l.size(), 18), ' ');
  return l + " " + formatNumber(v, 4) + " " + unit + "\n";
}

/// " (incl. 1 GM with T < 4 samples, 97 % of N^2)" when short GMs carry white noise.
std::string whiteNote(const DatasheetFigures& f) {
  if (f.noise_density_gms == 0) return "";
  char buf[120];
  std::snprintf(buf, sizeof buf, " (incl. %d GM%s with T < %g samples, %.0f %% of N^2)", f.noise_density_gms,
                f.noise_density_gms > 1 ? "s" : "", kWhiteGmMaxSamples, 100.0 * f.noise_density_gm_share);
  return buf;
}

}  // namespace

DatasheetFigures datasheetFigures(const Model& m, double max_averaging_s) {
  DatasheetFigures f;
  if (m.terms.empty() || !(m.rate_hz > 0.0) || !std::isfinite(m.rate_hz)) return f;
  const double dt = 1.0 / m.rate_hz;
  // Each kind adds its own figure (processes/<name>.cpp): WN the noise
  // density N = sigma sqrt(dt), a GM with T < kWhiteGmMaxSamples its
  // long-run variance to N, RW the rate random walk K = gamma / sqrt(dt),
  // QN the quantization Q dt, DR the drift rate omega / dt; independent terms
  // of one kind add in variance, drifts add.
  for (const auto& p : m.terms) detail::kindDef(p.kind).addDatasheet(p, m.rate_hz, f);
  if (f.noise_density && *f.noise_density > 0.0)
    f.noise_density_gm_share = std::min(1.0, f.noise_density_gm_n2 / (*f.noise_density * *f.noise_density));

  // Bias instability (IEEE 952): the flat region of the model ADEV, i.e. its
  // lowest local minimum at or beyond kFirstScalesSamples, on a log grid of
  // averaging times (50 points per decade) from 1 sample to the longest
  // averaging time, bounded to 12 decades of samples whatever the rate.
  const double max_s = max_averaging_s > 0.0 ? max_averaging_s : kDefaultMaxAveragingS;
  const double m_max = std::min(max_s * m.rate_hz, 1e12);
  if (!(m_max > 1.0)) return f;
  const int per_decade = 50;
  const int n_pts = static_cast<int>(std::floor(std::log10(m_max) * per_decade)) + 1;
  std::vector<double> lm(n_pts), adev(n_pts);  // log10 m, ADEV
  auto adevAt = [&](double log10m) { return std::sqrt(modelAvar(m, std::pow(10.0, log10m))); };
  for (int i = 0; i < n_pts; ++i) {
    lm[i] = static_cast<double>(i) / per_decade;
    adev[i] = adevAt(lm[i]);
  }
  int best = -1, first = -1;
  for (int i = 1; i + 1 < n_pts; ++i) {
    if (!(adev[i] < adev[i - 1] && adev[i] <= adev[i + 1])) continue;
    if (std::pow(10.0, lm[i]) < kFirstScalesSamples) {
      if (first < 0 || adev[i] < adev[first]) first = i;
    } else if (best < 0 || adev[i] < adev[best]) {
      best = i;
    }
  }
  if (n_pts >= 2 && adev[0] <= adev[1] && (first < 0 || adev[0] < adev[first])) first = 0;  // rises at once
  // Only a minimum at the first scales: it is the reading (with a warning)
  // unless the ADEV ends lower, falling (then no flat region is reached).
  const int pick = best >= 0 ? best : (first >= 0 && adev[first] <= adev[n_pts - 1] ? first : -1);
  char buf[200];
  if (pick < 0) {
    std::snprintf(buf, sizeof buf,
                  "no flat region: the Allan deviation still falls at the longest averaging time (%.3g s)",
                  std::pow(10.0, lm[n_pts - 1]) * dt);
    f.bias_instability_warning = buf;
    return f;
  }
  // Golden-section refinement of the minimum between the grid neighbours.
  double a = lm[std::max(pick - 1, 0)], b = lm[std::min(pick + 1, n_pts - 1)];
  std::tie(a, b) = goldenSectionBracket(adevAt, a, b, 60, 1e-12);
  double x = 0.5 * (a + b), v = adevAt(x);
  if (adev[pick] < v) x = lm[pick], v = adev[pick];
  f.bias_instability = v / 0.664;
  f.bias_instability_tau_s = std::pow(10.0, x) * dt;
  if (best < 0) {
    std::snprintf(buf, sizeof buf,
                  "the Allan deviation minimum sits at the first scales (%.3g samples): not the flat region of "
                  "IEEE Std 952 (quantisation, sub-sample correlation or a short hump, not a bias floor)",
                  std::pow(10.0, x));
    f.bias_instability_warning = buf;
  }
  return f;
}

std::string formatDatasheet(const DatasheetFigures& f, units::Quantity q) {
  using namespace units;
  std::string s;
  if (q == Quantity::AngularRate) {
    // N [rad/sqrt(s)]: angle std after t is N sqrt(t) -> deg/sqrt(h) = N (180/pi) 60.
    if (f.noise_density) s += line("ARW", *f.noise_density / kDeg * kSqrtHour, ("deg/sqrt(h)" + whiteNote(f)).c_str());
    if (f.bias_instability) {
      s += line("bias instability", *f.bias_instability / kDeg * kHour,
                "deg/h (ADEV min at " + formatNumber(*f.bias_instability_tau_s, 3) + " s)");
    }
    if (!f.bias_instability_warning.empty()) s += "  warning: bias instability: " + f.bias_instability_warning + "\n";
    // K [rad/s/sqrt(s)] -> deg/h/sqrt(h) = K (180/pi) 3600 * 60.
    if (f.random_walk) s += line("RRW", *f.random_walk / kDeg * kHour * kSqrtHour, "deg/h/sqrt(h)");
    if (f.quantization) s += line("quantization", *f.quantization / kDeg * 3600.0, "arcsec");
    if (f.drift_rate) s += line("drift rate", *f.drift_rate / kDeg * kHour * kHour, "deg/h/h");
  } else {
    // N [m/s^2*sqrt(s) = m/s/sqrt(s)] -> m/s/sqrt(h) = N 60.
    if (f.noise_density) s += line("VRW", *f.noise_density * kSqrtHour, ("m/s/sqrt(h)" + whiteNote(f)).c_str());
    if (f.bias_instability) {
      s += line("bias instability", *f.bias_instability / kG0 * 1e3,
                "mg (ADEV min at " + formatNumber(*f.bias_instability_tau_s, 3) + " s)");
    }
    if (!f.bias_instability_warning.empty()) s += "  warning: bias instability: " + f.bias_instability_warning + "\n";
    // K [m/s^2/sqrt(s)] -> mg/sqrt(h) = K 60 / g0 * 1e3.
    if (f.random_walk) s += line("acc random walk", *f.random_walk * kSqrtHour / kG0 * 1e3, "mg/sqrt(h)");
    if (f.quantization) s += line("quantization", *f.quantization, "m/s");
    if (f.drift_rate) s += line("drift rate", *f.drift_rate * kHour / kG0 * 1e3, "mg/h");
  }
  if (s.empty()) s = "(no error)\n";
  return s;
}

}  // namespace navimpact::stochastic
