#include "navimpact/ins/nav_state.hpp"

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"

namespace navimpact::ins {

Eigen::Quaterniond quatFromRollPitchYaw(double roll, double pitch, double yaw) {
  // C_BtoN = Rz(yaw) Ry(pitch) Rx(roll) (Groves 2.22)
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .normalized();
}

Eigen::Vector3d rollPitchYaw(const Eigen::Matrix3d& C) {
  // Groves 2.23
  const double roll = std::atan2(C(2, 1), C(2, 2));
  // clamped against rounding; NaN stays NaN (std::min(1.0, NaN) is 1: an
  // unknown attitude read as pitch -90 deg, found by a probe)
  const double pitch = std::isnan(C(2, 0)) ? C(2, 0) : -std::asin(std::max(-1.0, std::min(1.0, C(2, 0))));
  const double yaw = std::atan2(C(1, 0), C(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw);
}

NavState navStateOf(const ReferenceRecord& r, const earth::Geodetic& origin) {
  if (!r.v_N || !r.q_BtoN) {
    std::ostringstream m;
    m.precision(10);
    m << "reference at t = " << r.t << " s has no " << (r.v_N ? "attitude" : "velocity");
    throw Error(m.str());
  }
  NavState x;
  x.t = r.t;
  const earth::Geodetic p = earth::nedToGeodetic(origin, r.p_L);
  x.lat = p.lat;
  x.lon = p.lon;
  x.h = p.h;
  x.v_N = *r.v_N;
  x.q_BtoN = r.q_BtoN->normalized();
  return x;
}

Eigen::Vector3d NavState::rollPitchYaw() const { return ins::rollPitchYaw(C_BtoN()); }

void NavState::setRollPitchYaw(double roll, double pitch, double yaw) {
  q_BtoN = quatFromRollPitchYaw(roll, pitch, yaw);
}

Eigen::Quaterniond quatFromRotVec(const Eigen::Vector3d& phi) {
  const double a2 = phi.squaredNorm();
  double s, c;  // sin(a/2)/a, cos(a/2)
  if (a2 < 2.5e-3) {
    // Taylor series in x^2 = a^2/4 to x^8 (the next terms are below 1e-18
    // relative for |a| < 0.05 rad): sin(x)/x and cos(x).
    const double x2 = 0.25 * a2;
    s = 0.5 * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0 - x2 / 362880.0))));
    c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0 - x2 / 40320.0)));
  } else {
    const double a = std::sqrt(a2);
    s = std::sin(0.5 * a) / a;
    c = std::cos(0.5 * a);
  }
  return Eigen::Quaterniond(c, s * phi.x(), s * phi.y(), s * phi.z()).normalized();
}

double wrapAngle(double a) {
  double r = std::remainder(a, 2.0 * 3.14159265358979323846);
  if (r <= -3.14159265358979323846) r += 2.0 * 3.14159265358979323846;
  return r;
}

}  // namespace navimpact::ins
