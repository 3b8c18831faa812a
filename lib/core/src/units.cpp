#include "navimpact/core/units.hpp"

#include "navimpact/core/error.hpp"

namespace navimpact::units {

const char* siUnit(Quantity q) {
  return q == Quantity::AngularRate ? "rad/s" : "m/s^2";
}

namespace {
struct UnitEntry {
  const char* name;
  double factor;
};
constexpr UnitEntry kRateUnits[] = {
    {"rad/s", 1.0}, {"deg/s", kDeg}, {"deg/h", kDeg / kHour}, {"mrad/s", 1e-3}};
constexpr UnitEntry kForceUnits[] = {
    {"m/s2", 1.0}, {"m/s^2", 1.0}, {"g", kG0}, {"mg", 1e-3 * kG0}, {"ug", 1e-6 * kG0}};
constexpr UnitEntry kTimeUnits[] = {{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"ns", 1e-9}};
}  // namespace

std::vector<std::string> acceptedTimeUnits() {
  std::vector<std::string> out;
  for (const auto& e : kTimeUnits) out.emplace_back(e.name);
  return out;
}

double secondsPer(std::string_view unit) {
  for (const auto& e : kTimeUnits)
    if (unit == e.name) return e.factor;
  throw Error("unknown time unit '" + printable(unit, 40) + "' (expected one of: s, ms, us, ns)");
}

double toSiFactor(Quantity q, std::string_view unit) {
  if (q == Quantity::AngularRate) {
    for (const auto& e : kRateUnits)
      if (unit == e.name) return e.factor;
  } else {
    for (const auto& e : kForceUnits)
      if (unit == e.name) return e.factor;
  }
  std::string list;
  for (const auto& n : acceptedUnits(q)) list += (list.empty() ? "" : ", ") + n;
  throw Error("unknown " +
              std::string(q == Quantity::AngularRate ? "angular-rate" : "specific-force") +
              " unit '" + printable(unit, 40) + "' (expected one of: " + list + ")");
}

std::vector<std::string> acceptedUnits(Quantity q) {
  std::vector<std::string> out;
  if (q == Quantity::AngularRate)
    for (const auto& e : kRateUnits) out.emplace_back(e.name);
  else
    for (const auto& e : kForceUnits) out.emplace_back(e.name);
  return out;
}

}  // namespace navimpact::units
