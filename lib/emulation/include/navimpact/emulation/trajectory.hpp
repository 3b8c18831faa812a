/**
 * @file trajectory.hpp
 * @brief Reference trajectories: CSV import (geodetic or local NED, any rate,
 *        columns and units from configuration), a smooth truth built with
 *        P-splines, and its exact kinematics (position, velocity,
 *        acceleration, attitude, angular rate) at any time.
 *
 * Frames: N = local north-east-down at the current point; L = the fixed
 * tangent-plane NED frame at the origin (GeographicLib::LocalCartesian
 * reordered to NED), in which positions are smoothed; B = body
 * forward-right-down. Attitude: Euler angles yaw-pitch-roll of B w.r.t. N,
 * C_NtoB = R1(roll) R2(pitch) R3(yaw) (Groves 2013 eq. 2.22).
 *
 * Smoothing (see pspline.hpp): the three tangent-plane coordinates and the
 * three unwrapped Euler angles are each fitted by a degree-5 P-spline with a
 * third-difference penalty, cutoffs given in Hz. Euler angles are smooth and
 * unambiguous away from pitch = +-90 deg; trajectories reaching |pitch| >
 * 85 deg are rejected (use a quaternion source there). The smoothed
 * trajectory IS the truth of an emulation: every quantity below is computed
 * analytically from it.
 */
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navimpact/core/config.hpp"
#include "navimpact/core/earth.hpp"
#include "navimpact/emulation/pspline.hpp"

namespace navimpact::emulation {

/// How to read a trajectory CSV (header line with column names, comma separated, gzip ok).
struct TrajectorySpec {
  std::string file;                 ///< path of the CSV (plain or gzip)
  std::string system = "geodetic";  ///< "geodetic" (lat, lon, h) or "ned" (local tangent NED)
  std::string col_time = "time_s";  ///< time column [time_unit]
  std::string col_lat = "lat_rad", col_lon = "lon_rad", col_height = "alt_m";  ///< geodetic
  std::string col_north = "x_N_m", col_east = "x_E_m", col_down = "x_D_m";     ///< ned [m]
  std::string col_roll = "roll_rad", col_pitch = "pitch_rad", col_yaw = "yaw_rad";
  std::string latlon_unit = "rad";    ///< "rad" or "deg"
  std::string attitude_unit = "rad";  ///< "rad" or "deg"
  std::string time_unit = "s";        ///< "s" or "ms"
  /// Origin of the local frame; required for "ned", default first sample for "geodetic".
  std::optional<earth::Geodetic> origin;
  double max_gap_s = 0.25;            ///< largest time step the spline may bridge [s]
  std::optional<double> start_s;      ///< keep samples with time >= start_s (file time) [s]
  std::optional<double> end_s;        ///< keep samples with time <= end_s (file time) [s]
  /// The configuration and the dotted path of the `trajectory:` map that gave
  /// these keys (loadFrom), so that errors about them name the configuration;
  /// "" for a spec built in code (then the CSV is named).
  std::string config_file, config_path;

  /// Read the keys of a `trajectory:` map (file, system, columns, latlon_unit,
  /// attitude_unit, time_unit, origin {lat_deg, lon_deg, height_m}, max_gap_s,
  /// start_s, end_s); the file is resolved against the configuration's folder.
  void loadFrom(const ConfigNode& n);
};

/// Raw samples in SI: tangent-plane NED positions and unwrapped Euler angles.
struct SampledTrajectory {
  std::string source;                   ///< file path, for messages
  earth::Geodetic origin;               ///< origin of the L frame
  std::vector<double> t;                ///< times [s] (file time, strictly increasing)
  std::vector<Eigen::Vector3d> p_L;     ///< position in L (north, east, down) [m]
  std::vector<Eigen::Vector3d> rpy;     ///< roll, pitch, yaw [rad], unwrapped
};

/**
 * Read a trajectory CSV.
 * @throws navimpact::Error naming file and line for: missing column, missing
 *         or extra field, non-number, NaN/Inf, repeated or backwards time,
 *         a time step above max_gap_s, |pitch| > 85 deg, fewer than 8 samples,
 *         unknown system/unit, "ned" without origin.
 */
SampledTrajectory readTrajectoryCsv(const TrajectorySpec& spec);

/// Smoothing choices (cutoffs of the P-splines, see pspline.hpp).
struct SmoothingOptions {
  double position_cutoff_hz = 1.0;  ///< -6 dB cutoff of the position smoother [Hz]
  double attitude_cutoff_hz = 2.0;  ///< -6 dB cutoff of the attitude smoother [Hz]
  double knot_step_s = 0.05;        ///< knot spacing of both splines [s]
  int penalty_order = 3;            ///< difference order of the penalty (3: jerk-like)

  /// Read the keys of a `smoothing:` map (position_cutoff_hz, attitude_cutoff_hz
  /// in (0, 10000] Hz, knot_step_s a duration, penalty_order 1..4).
  void loadFrom(const ConfigNode& n);
};

/// The true state and its derivatives at one instant (all SI).
struct TruthState {
  double t = 0.0;                    ///< time [s]
  earth::Geodetic pos;               ///< geodetic position
  Eigen::Vector3d p_L;               ///< position in the origin's tangent NED frame [m]
  Eigen::Vector3d v_N;               ///< velocity w.r.t. Earth, resolved in N [m/s]
  Eigen::Vector3d a_N;               ///< d v_N / dt (rate of the N-resolved components) [m/s^2]
  Eigen::Vector3d rpy;               ///< roll, pitch, yaw [rad] (yaw unwrapped)
  Eigen::Matrix3d C_BtoN;            ///< attitude
  Eigen::Vector3d w_NB_B;            ///< body rate w.r.t. N, resolved in B [rad/s]
  Eigen::Vector3d w_IE_N, w_EN_N;    ///< Earth rate and transport rate in N [rad/s]
  Eigen::Vector3d g_N;               ///< normal gravity in N [m/s^2]
  Eigen::Vector3d f_B;               ///< specific force [m/s^2]
  Eigen::Vector3d w_IB_B;            ///< inertial angular rate [rad/s]
};

/// The smooth truth and its kinematics.
class SmoothTrajectory {
 public:
  SmoothTrajectory(const SampledTrajectory& samples, const SmoothingOptions& opt);

  double tBegin() const { return t0_; }
  double tEnd() const { return t1_; }
  const earth::Geodetic& origin() const { return origin_; }
  const SmoothingOptions& options() const { return opt_; }

  /**
   * Full state at time @p t in [tBegin, tEnd]:
   *  f_B    = C_NtoB (a_N - g_N + (2 w_IE_N + w_EN_N) x v_N)   (Groves 2013 eq. 5.54 solved for f)
   *  w_IB_B = w_NB_B + C_NtoB (w_IE_N + w_EN_N)                 (Groves 2013 eq. 5.45 rearranged)
   * with a_N = C_LtoN a_L - w_EN_N x v_N, because N turns w.r.t. the
   * Earth-fixed L at w_EN (dC_LtoN/dt = -[w_EN_N x] C_LtoN).
   */
  TruthState at(double t) const;

  /**
   * Exact IMU increments over (ta, tb]: dv_B = int f_B dt, dth_B = int w_IB_B dt,
   * by 3-point Gauss-Legendre quadrature on each piece between spline knots
   * (the integrands are smooth there; error far below 1e-12 relative at 200 Hz).
   */
  void increments(double ta, double tb, Eigen::Vector3d& dv_B, Eigen::Vector3d& dth_B) const;

 private:
  void kinematics(double t, bool full, TruthState& s) const;
  PSpline pos_, att_;
  earth::Geodetic origin_;
  Eigen::Vector3d r0_E_;
  Eigen::Matrix3d C_LtoE_;
  double t0_ = 0.0, t1_ = 0.0;
  SmoothingOptions opt_;
};

/// C_NtoB from roll, pitch, yaw: R1(roll) R2(pitch) R3(yaw) (Groves 2013 eq. 2.22).
Eigen::Matrix3d eulerToC_NtoB(double roll, double pitch, double yaw);

}  // namespace navimpact::emulation
