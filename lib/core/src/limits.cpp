#include "navimpact/core/limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::limits {

namespace {
std::string g(double v) { return formatNumber(v, 6); }  // %g

/// A value refused, as %g when that reads back as it, else every digit it
/// needs (0.1000001 outside [-0.1, 0.1] printed as "got 0.1").
std::string gotText(double v) {
  const std::string s = g(v);
  return !std::isfinite(v) || std::strtod(s.c_str(), nullptr) == v ? s : formatExact(v);
}
}  // namespace

std::string describe(const Range& r) {
  return std::string(r.lo_open ? "(" : "[") + g(r.lo) + ", " + g(r.hi) + "] " + r.unit;
}

double check(const std::string& file, const std::string& key, double v, const Range& r) {
  const bool ok = std::isfinite(v) && (r.lo_open ? v > r.lo : v >= r.lo) && v <= r.hi;
  if (!ok) throw keyError(file, key, "must be in " + describe(r) + ", got " + gotText(v));
  return v;
}

unsigned budgetWorkers(double most, double samples, double fixed_bytes_per_sample, double worker_bytes_per_sample) {
  const double fit = std::floor((kDefaultMemoryBudgetBytes / std::max(samples, 1.0) - fixed_bytes_per_sample) /
                                worker_bytes_per_sample);
  return static_cast<unsigned>(std::max(1.0, std::min(most, fit)));
}

void checkBudget(const std::initializer_list<BudgetEstimate>& estimates, bool allow_large) {
  if (allow_large) return;
  for (const BudgetEstimate& e : estimates) {
    if (e.need <= e.budget) continue;  // NaN is refused too
    const auto n = [](double v) { return formatNumber(v, 3); };
    throw Error(e.place + ": " + e.what + " would need about " + n(e.need) + " " + e.unit +
                (e.how.empty() ? "" : " (" + e.how + ")") + ", above the budget of " + n(e.budget) + " " + e.unit +
                ": " + e.remedy + ", or pass --allow-large");
  }
}

}  // namespace navimpact::limits
