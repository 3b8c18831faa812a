// Helpers shared by the ins tests and the tests of the modules built on ins
// (filter): a navigation state from its values in human units.
#pragma once

#include <Eigen/Core>

#include "navimpact/ins/nav_state.hpp"

namespace instest {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// The state at latitude/longitude [deg], height [m], velocity v_N [m/s] and
/// roll, pitch, yaw [deg] (time 0).
inline navimpact::ins::NavState navState(double lat_deg, double lon_deg, double h_m, const Eigen::Vector3d& v_N,
                                         double roll_deg, double pitch_deg, double yaw_deg) {
  navimpact::ins::NavState x;
  x.lat = lat_deg * kDeg;
  x.lon = lon_deg * kDeg;
  x.h = h_m;
  x.v_N = v_N;
  x.setRollPitchYaw(roll_deg * kDeg, pitch_deg * kDeg, yaw_deg * kDeg);
  return x;
}

}  // namespace instest
