/**
 * @file recording.hpp
 * @brief A navigation recording in memory: time-stamped IMU samples, GNSS
 *        fixes, barometer samples and a reference trajectory, with its
 *        origin, time base and metadata. What a rawlog reader returns and what
 *        an emulation produces; the navigation runs (replay, studies) read it.
 *
 * Conventions (README): SI units; body axes forward-right-down (FRD),
 * navigation frame NED; attitude as C_BtoN (Hamilton quaternion, active).
 * Data in other axes or units are converted before they enter a Recording.
 *
 * Time: every record carries t [s] on the recording's own time axis, strictly
 * non-decreasing within each stream. The absolute time of t is
 * start_unix_s + (t - t_start_s) seconds UTC (Unix epoch), when known.
 *
 * What a record may lack is optional per record, so that measured data
 * (GNSS fixes without velocity or without a covariance, a reference without
 * attitude) need no invented values: the consumer decides (e.g. the replay
 * takes missing GNSS sigmas from its configuration and refuses a reference
 * without attitude). Configuration that belongs to the installation, not to
 * the data (the GNSS antenna lever arm, the IMU error model), is not here.
 */
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navimpact/core/earth.hpp"

namespace navimpact {

/// IMU output over the interval (t - dt, t] (dt from the previous sample):
/// mean angular rate and mean specific force, body FRD, i.e. increments / dt.
struct ImuRecord {
  double t = 0.0;                   ///< end of the interval [s]
  Eigen::Vector3d w_IB_B;           ///< angular rate of the body w.r.t. inertial space [rad/s]
  Eigen::Vector3d f_B;              ///< specific force [m/s^2]
};

/// One GNSS fix of the antenna (not of the IMU: the lever arm is configuration).
struct GnssFix {
  double t = 0.0;                                 ///< [s]
  earth::Geodetic pos;                            ///< antenna position (lat, lon [rad], ellipsoidal h [m])
  std::optional<Eigen::Vector3d> v_N;             ///< antenna velocity w.r.t. Earth, NED [m/s]; absent: position-only fix
  std::optional<Eigen::Matrix3d> cov_pos_N;       ///< position covariance, NED [m^2]; absent: not reported
  std::optional<Eigen::Matrix3d> cov_vel_N;       ///< velocity covariance, NED [m^2/s^2]; absent: not reported
};

/// One barometric height sample.
struct BaroSample {
  double t = 0.0;                   ///< [s]
  double h = 0.0;                   ///< height above the WGS84 ellipsoid [m]
  std::optional<double> sigma_m;    ///< its standard deviation [m], > 0; absent: not reported
};

/// One sample of the reference trajectory (the truth of an emulation; a
/// reference system or RTK solution for measured data).
struct ReferenceRecord {
  double t = 0.0;                                 ///< [s]
  Eigen::Vector3d p_L;                            ///< IMU position in the tangent NED frame at Recording::origin [m]
  std::optional<Eigen::Vector3d> v_N;             ///< IMU velocity w.r.t. Earth, local NED [m/s]
  std::optional<Eigen::Quaterniond> q_BtoN;       ///< attitude C_BtoN (Hamilton, active)
  std::optional<Eigen::Vector3d> sigma_p_L;       ///< 1-sigma of p_L per axis N, E, D [m]
  std::optional<Eigen::Vector3d> sigma_v_N;       ///< 1-sigma of v_N per axis [m/s]
  std::optional<Eigen::Vector3d> sigma_att;       ///< 1-sigma of the attitude error psi about N, E, D [rad]
};

/// A recording: the streams, time-ordered within each, and what they need.
struct Recording {
  std::string source;                 ///< where it came from (file path, or a description), for messages
  earth::Geodetic origin;             ///< origin of the tangent frame of ReferenceRecord::p_L
  double imu_rate_hz = 0.0;           ///< nominal IMU rate [Hz] from the metadata; 0: unknown (use the time stamps)
  long long start_unix_s = 0;         ///< UTC (Unix seconds) of time t_start_s; 0 with t_start_s = 0: unknown
  double t_start_s = 0.0;             ///< time on the recording's axis [s] that start_unix_s stands for
  /// GNSS antenna position relative to the IMU, body FRD [m], when the data
  /// state it (an import manifest's gnss.lever_arm_m, a rawlog's GNSS
  /// sensorPose); absent: unknown (the replay takes its configuration's).
  std::optional<Eigen::Vector3d> lever_arm_B;
  std::vector<ImuRecord> imu;
  std::vector<GnssFix> gnss;
  std::vector<BaroSample> baro;
  std::vector<ReferenceRecord> reference;
  /// Free text stored with the data: an emulation writes its scenario here as
  /// YAML (key navimpact_scenario); a rawlog reader returns its first comment.
  std::string metadata;
  std::vector<std::string> notices;   ///< notes for the user (rate conversions, skipped entries, ...)
};

/// Physical ranges of a record's values, beyond any vehicle and sensor
/// navimpact navigates (README "Ranges and budgets"), applied by every reader
/// (rawlog, import) so that what navimpact writes it reads back:
/// IMU rates and forces as imu_series.hpp (kMaxAbsAngularRate, kMaxAbsSpecificForce);
/// reference positions within 10^4 km of the origin; heights [-12 km, 1000 km]; velocity components [-1e4, 1e4] m/s (orbital
/// speed is 7.8 km/s); standard deviations of positions and heights
/// [0.1 mm, 1000 km], of velocities [0.1 mm/s, 1000 km/s], of attitudes (0, pi] rad.
inline constexpr double kMinHeightM = -12000.0;
inline constexpr double kMaxHeightM = 1.0e6;
inline constexpr double kMaxAbsSpeedMps = 1.0e4;
inline constexpr double kMinRecordSigma = 1.0e-4;
inline constexpr double kMaxRecordSigma = 1.0e6;

/// What is physically impossible in a record, as "what = value is ... (accepted)";
/// empty when nothing is. Times are the reader's to check (their order, their axis).
std::string recordProblem(const ImuRecord& r);
std::string recordProblem(const GnssFix& r);
std::string recordProblem(const BaroSample& r);
std::string recordProblem(const ReferenceRecord& r);

/// The nominal interval of IMU time stamps from their successive @p steps [s]
/// (at least one): the median step, which a gap cannot move; but when the
/// steps shorter than 1.75 medians (no lost sample among them: steps of
/// quantised stamps reach 1.5 medians, one lost sample makes 2) average more
/// than 1 % away from it, their mean. Stamps quantised coarser than the
/// step (400 Hz at 1 ms: 2, 3, 2, 3 ms) or alternating (9, 11 ms) have a
/// median of one of their values (333 or 500 Hz; 91 or 111 Hz) but the mean
/// of the true rate (400 Hz; 100 Hz). Not > 0 when the median is not.
double nominalStep(const std::vector<double>& steps);

}  // namespace navimpact
