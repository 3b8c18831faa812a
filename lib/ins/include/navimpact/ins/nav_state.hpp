/**
 * @file nav_state.hpp
 * @brief Navigation state and IMU sample types of the strapdown INS.
 *
 * Conventions (README "Conventions"): navigation frame N = local NED;
 * body frame B = forward-right-down; attitude is C_BtoN (quaternion q_BtoN,
 * Hamilton, active: v_N = q_BtoN * v_B); Euler angles are ZYX yaw-pitch-roll
 * with C_BtoN = Rz(yaw) Ry(pitch) Rx(roll) (Groves 2.22).
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navimpact/core/earth.hpp"
#include "navimpact/core/recording.hpp"

namespace navimpact::ins {

/// Position, velocity and attitude at time t.
struct NavState {
  double t = 0.0;                 ///< time [s]
  double lat = 0.0;               ///< geodetic latitude [rad], |lat| < pi/2
  double lon = 0.0;               ///< longitude [rad]
  double h = 0.0;                 ///< ellipsoidal height [m]
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();            ///< velocity w.r.t. Earth in NED [m/s]
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();  ///< attitude, unit quaternion

  Eigen::Matrix3d C_BtoN() const { return q_BtoN.toRotationMatrix(); }
  earth::Geodetic geodetic() const { return {lat, lon, h}; }
  /// Roll, pitch, yaw [rad] (ZYX; roll, yaw in (-pi, pi], pitch in [-pi/2, pi/2]).
  Eigen::Vector3d rollPitchYaw() const;
  /// Set the attitude from roll, pitch, yaw [rad] (ZYX, Groves 2.22).
  void setRollPitchYaw(double roll, double pitch, double yaw);
};

/**
 * Navigation state of a reference record (the truth of an emulation):
 * position from its tangent-plane NED offset at @p origin
 * (earth::nedToGeodetic), velocity, attitude normalised, t = r.t.
 * @throws navimpact::Error "reference at t = T s has no velocity|attitude".
 */
NavState navStateOf(const ReferenceRecord& r, const earth::Geodetic& origin);

/// Quaternion of the ZYX Euler angles roll, pitch, yaw [rad].
Eigen::Quaterniond quatFromRollPitchYaw(double roll, double pitch, double yaw);

/// Roll, pitch, yaw [rad] of a rotation matrix C_BtoN.
Eigen::Vector3d rollPitchYaw(const Eigen::Matrix3d& C_BtoN);

/// Rotation vector -> unit quaternion (exact, stable for small angles).
Eigen::Quaterniond quatFromRotVec(const Eigen::Vector3d& phi);

/// Skew-symmetric matrix [a x] with [a x] b = a x b.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

/// Angle difference a - b wrapped to (-pi, pi] [rad].
double wrapAngle(double a);

/**
 * One IMU output over the interval (t - dt, t]: integrated angular rate and
 * integrated specific force (increments), body frame FRD.
 */
struct ImuSample {
  double t = 0.0;    ///< end of the interval [s]
  double dt = 0.0;   ///< interval length [s], > 0
  Eigen::Vector3d dtheta_B = Eigen::Vector3d::Zero();  ///< angle increment [rad]
  Eigen::Vector3d dv_B = Eigen::Vector3d::Zero();      ///< velocity increment [m/s]

  /**
   * Sample from rates held constant over the interval.
   * @param[in] t       end time [s].
   * @param[in] dt      interval [s], > 0.
   * @param[in] w_IB_B  angular rate [rad/s].
   * @param[in] f_B     specific force [m/s^2].
   */
  static ImuSample fromRates(double t, double dt, const Eigen::Vector3d& w_IB_B,
                             const Eigen::Vector3d& f_B) {
    return ImuSample{t, dt, w_IB_B * dt, f_B * dt};
  }
  Eigen::Vector3d w_IB_B() const { return dtheta_B / dt; }  ///< mean rate [rad/s]
  Eigen::Vector3d f_B() const { return dv_B / dt; }          ///< mean specific force [m/s^2]
};

}  // namespace navimpact::ins
