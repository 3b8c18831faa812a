/**
 * @file units.hpp
 * @brief Physical constants and the one place where human units become SI.
 *
 * Everything inside navimpact is SI (rad, rad/s, m, m/s, m/s^2, s). Human
 * units (deg/s, deg/h, g, mg, deg/sqrt(h), ...) exist only at the edges:
 * they are converted here, once, when data enter or reports leave.
 */
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace navimpact::units {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;      ///< one degree [rad]
constexpr double kG0 = 9.80665;           ///< standard gravity [m/s^2] (CGPM 1901)
constexpr double kHour = 3600.0;          ///< one hour [s]
constexpr double kSqrtHour = 60.0;        ///< sqrt(1 h) [sqrt(s)]

/// The physical quantity a sensor channel measures.
enum class Quantity {
  AngularRate,     ///< gyroscope, SI unit rad/s
  SpecificForce,   ///< accelerometer, SI unit m/s^2
};

/// SI unit name of a quantity ("rad/s" or "m/s^2").
const char* siUnit(Quantity q);

/**
 * Factor that turns a value in @p unit into SI: value_SI = value * factor.
 * @param[in] q     quantity the unit must measure.
 * @param[in] unit  angular rate: "rad/s", "deg/s", "deg/h", "mrad/s";
 *                  specific force: "m/s2", "m/s^2", "g", "mg", "ug".
 * @throws navimpact::Error naming the unit and the accepted names.
 */
double toSiFactor(Quantity q, std::string_view unit);

/// Accepted unit names for a quantity (for help texts and error messages).
std::vector<std::string> acceptedUnits(Quantity q);

/// Units of a time stamp column: "s", "ms", "us", "ns" (in this order).
std::vector<std::string> acceptedTimeUnits();

/**
 * Seconds per one @p unit of time (e.g. 1e-3 for "ms").
 * @throws navimpact::Error naming the unit and the accepted names.
 */
double secondsPer(std::string_view unit);

}  // namespace navimpact::units
