#include "navimpact/core/limits.hpp"

#include <cmath>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::limits {

namespace {
std::string g(double v) { return formatNumber(v, 6); }  // %g
}  // namespace

std::string describe(const Range& r) {
  return std::string(r.lo_open ? "(" : "[") + g(r.lo) + ", " + g(r.hi) + "] " + r.unit;
}

double check(const std::string& file, const std::string& key, double v, const Range& r) {
  const bool ok = std::isfinite(v) && (r.lo_open ? v > r.lo : v >= r.lo) && v <= r.hi;
  if (!ok) throw keyError(file, key, "must be in " + describe(r) + ", got " + g(v));
  return v;
}

}  // namespace navimpact::limits
