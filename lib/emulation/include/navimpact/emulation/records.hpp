/**
 * @file records.hpp
 * @brief The time-stamped records an emulation produces and a replay consumes
 *        (one type per rawlog label: IMU, GNSS, BARO, GT), all SI.
 */
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navimpact/core/earth.hpp"
#include "navimpact/emulation/sensors.hpp"

namespace navimpact::emulation {

/// IMU output over (t - dt, t]: mean angular rate and mean specific force, body FRD.
struct ImuRecord {
  double t = 0.0;                   ///< end of the interval [s]
  Eigen::Vector3d w_IB_B;           ///< [rad/s] (increment / dt)
  Eigen::Vector3d f_B;              ///< [m/s^2] (increment / dt)
};

/// Ground truth at time t.
struct TruthRecord {
  double t = 0.0;                   ///< [s]
  Eigen::Vector3d p_L;              ///< position in the origin's tangent NED frame [m]
  Eigen::Vector3d v_N;              ///< velocity w.r.t. Earth in local NED [m/s]
  Eigen::Quaterniond q_BtoN;        ///< attitude C_BtoN (Hamilton, active)
};

/// Everything an emulation run produces, time-ordered within each stream.
struct EmulationData {
  earth::Geodetic origin;           ///< origin of the tangent frame of TruthRecord::p_L
  double imu_rate_hz = 0.0;         ///< [Hz]
  long long start_unix_s = 0;       ///< UTC (Unix seconds) of time t_start_s, for rawlog timestamps
  double t_start_s = 0.0;           ///< time [s] that start_unix_s stands for (first trajectory time)
  std::vector<ImuRecord> imu;
  std::vector<GnssFix> gnss;
  std::vector<BaroSample> baro;
  std::vector<TruthRecord> truth;
  std::string scenario_yaml;        ///< the scenario as YAML text (rawlog comment)
  std::vector<std::string> notices; ///< notes for the user (rate conversions, windows)
};

}  // namespace navimpact::emulation
