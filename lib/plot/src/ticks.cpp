// Tick locations: 1-2-5 steps for linear axes, decades with minor ticks 2..9
// for log10 axes (the conventions of matplotlib's MaxNLocator / LogLocator).
#include "ticks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "navimpact/core/format.hpp"

namespace navimpact::plot::detail {

double niceStep(double raw) {
  const double k = std::floor(std::log10(raw));
  const double p = std::pow(10.0, k);
  const double f = raw / p;
  double m = 10.0;
  if (f <= 1.0 + 1e-9) m = 1.0;
  else if (f <= 2.0 + 1e-9) m = 2.0;
  else if (f <= 5.0 + 1e-9) m = 5.0;
  return m * p;
}

std::string typographicMinus(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 4);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool lead = i == 0;
    const bool expo = i > 0 && (s[i - 1] == 'e' || s[i - 1] == 'E');
    if (s[i] == '-' && (lead || expo)) out += "\xE2\x88\x92";  // U+2212
    else out += s[i];
  }
  return out;
}

std::string formatLinear(double v, double step, double maxAbs) {
  if (std::abs(v) < step * 1e-6) v = 0.0;
  char buf[64];
  const bool sci = maxAbs >= 1e6 || (maxAbs > 0 && maxAbs < 1e-3);
  if (!sci) {
    const int dec = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
    std::snprintf(buf, sizeof buf, "%.*f", dec, v);
  } else if (v == 0.0) {
    std::snprintf(buf, sizeof buf, "0");
  } else {
    // One exponent for the whole axis (that of the largest magnitude) so that
    // all labels share the same mantissa format: 0.5e6, 1.0e6, 1.5e6.
    const int e = static_cast<int>(std::floor(std::log10(maxAbs) + 1e-9));
    const int ks = static_cast<int>(std::floor(std::log10(step) + 1e-9));
    const int dec = std::clamp(e - ks, 0, 6);
    const double m = v / std::pow(10.0, e);
    std::snprintf(buf, sizeof buf, "%.*fe%d", dec, m, e);
  }
  return typographicMinus(buf);
}

std::vector<Tick> linearTicks(double lo, double hi, int maxTicks) {
  std::vector<Tick> ticks;
  if (!(hi > lo) || maxTicks < 1) return ticks;
  const double step = niceStep((hi - lo) / std::max(1, maxTicks));
  const double i0 = std::ceil(lo / step - 1e-9), i1 = std::floor(hi / step + 1e-9);
  const double maxAbs = std::max(std::abs(lo), std::abs(hi));
  // Count-bounded loop: with huge offsets (1e20 + small range) i += 1 would stall.
  const double count = std::min(i1 - i0, 200.0);
  for (double k = 0; k <= count; k += 1.0) {
    Tick t;
    t.value = (i0 + k) * step;
    t.major = true;
    t.labeled = true;
    t.label.base = formatLinear(t.value, step, maxAbs);
    ticks.push_back(t);
  }
  return ticks;
}

namespace {
std::string plainDecimal(double v) { return formatNumber(v, 10); }
}  // namespace

std::vector<Tick> logTicks(double lo, double hi, int labelStride, bool withMinor,
                           int maxLinearTicks, bool labelMinor) {
  std::vector<Tick> ticks;
  if (!(lo > 0) || !(hi > lo)) return ticks;
  const double l0 = std::log10(lo), l1 = std::log10(hi);
  const int e0 = static_cast<int>(std::ceil(l0 - 1e-9));
  const int e1 = static_cast<int>(std::floor(l1 + 1e-9));
  if (e1 - e0 < 1) {
    // Less than two decade lines in view: nice linear values on the log scale.
    std::vector<Tick> lin = linearTicks(lo, hi, maxLinearTicks);
    for (auto& t : lin)
      if (t.value > 0) ticks.push_back(t);
    return ticks;
  }
  labelStride = std::max(1, labelStride);
  for (int e = e0 - 1; e <= e1; ++e) {
    const double p = std::pow(10.0, e);
    if (e >= e0) {
      Tick t;
      t.value = p;
      t.major = true;
      t.labeled = (e % labelStride) == 0;
      if (labelMinor) {
        t.label.base = plainDecimal(p);
      } else {
        t.label.base = "10";
        t.label.sup = typographicMinus(std::to_string(e));
      }
      ticks.push_back(t);
    }
    if (withMinor || labelMinor)
      for (int m = 2; m <= 9; ++m) {
        const double v = m * p;
        if (v < lo * (1 - 1e-12) || v > hi * (1 + 1e-12)) continue;
        Tick t;
        t.value = v;
        t.major = false;
        t.labeled = labelMinor && (m == 2 || m == 5);
        if (t.labeled) t.label.base = plainDecimal(v);
        ticks.push_back(t);
      }
  }
  return ticks;
}

}  // namespace navimpact::plot::detail
