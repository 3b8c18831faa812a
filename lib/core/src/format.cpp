// The one number formatter (see format.hpp).
#include "navimpact/core/format.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace navimpact {

namespace {
std::string printfDouble(const char* spec, int digits, double x) {
  char buf[400];  // %.17f of 1e308 needs 327 characters
  std::snprintf(buf, sizeof buf, spec, digits, x);
  return buf;
}
}  // namespace

std::string formatNumber(double x, int significant) { return printfDouble("%.*g", significant, x); }

std::string formatExact(double x) {
  for (int d = 15; d <= 17; ++d) {
    std::string s = printfDouble("%.*g", d, x);
    if (std::strtod(s.c_str(), nullptr) == x) return s;
  }
  return printfDouble("%.*g", 17, x);  // NaN
}

std::string formatFixed(double x, int decimals) {
  if (!std::isfinite(x)) return "n/a";
  return printfDouble("%.*f", decimals, x);
}

std::string formatReadable(double x, int significant) {
  if (!std::isfinite(x)) return "n/a";
  const double a = std::abs(x);
  if (a != 0.0 && (a < 1e-3 || a >= 1e5)) return printfDouble("%.*e", significant - 1, x);
  return printfDouble("%.*g", significant, x);
}

}  // namespace navimpact
