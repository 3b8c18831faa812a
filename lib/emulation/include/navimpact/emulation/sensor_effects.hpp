/**
 * @file sensor_effects.hpp
 * @brief Deterministic and motion-dependent sensor effects that a stochastic
 *        IMU error model lacks, applied to an emulated run: per-axis scale
 *        factors, axis misalignment (and optional non-orthogonality) of each
 *        triad, an IMU-GNSS time offset, white noise inflated while the
 *        vehicle moves, and an antenna lever-arm error.
 *
 * An emulated run is the perfect IMU of a trajectory (perfect_imu.hpp) plus the
 * model's errors (sensors.hpp: modelImuErrors / staticImuErrors) plus GNSS
 * (simulateGnss). applySensorEffects() turns the perfect IMU and the error
 * sequences into the IMU a sensor with these effects outputs; gnssWithEffects()
 * gives the GNSS options of the true antenna. With a default SensorEffects
 * (every effect off) the output is exactly perfect + errors, bit for bit, as
 * analysis::emulateRun adds them.
 *
 * Sensor model (per triad, gyro and accelerometer separately; SI; body FRD):
 * @code
 *   measured(t) = M * true(t - time_offset_s) + errors(t) + n_motion(t)
 *   M = I + diag(scale) + [misalignment x] + N(nonorthogonality)
 *   N(n) = [ 0    n_z  n_y ]
 *          [ n_z  0    n_x ]
 *          [ n_y  n_x  0   ]
 * @endcode
 *  - true() are the mean rates of the perfect increments (w_IB_B [rad/s],
 *    f_B [m/s^2]); M acts on the increments (exactly the same, M is constant).
 *  - scale s_i: dimensionless ratio (2000 ppm = 0.002); axis i reads
 *    (1 + s_i) times the true value.
 *  - misalignment m [rad]: [m x] v = m x v, i.e. the triad's axes are the body
 *    axes rotated by -m (C_BtoS = I + [m x] to first order). A filter
 *    corrects to first order with (I - [m x]) (I - diag(s)) measured
 *    (filter/state_layout.hpp states the filter's convention).
 *  - non-orthogonality n [rad] (optional, default 0): the symmetric
 *    off-diagonal part; axis pairs (y,z), (x,z), (x,y) leaning towards each
 *    other by n_x, n_y, n_z.
 *  - M is the first-order (linear) form: all entries small (limits.hpp ranges).
 *  - time offset d [s] = t_IMU - t_true: the IMU sample stamped t holds the
 *    motion of true time t - d (d > 0: the IMU stamps are late against GNSS
 *    and the truth). The shifted increments over (t - dt - d, t - d] are the
 *    difference of the cumulative perfect increments interpolated by 4-point
 *    Lagrange at the shifted times (exact when d is a whole number of
 *    samples; error ~ |d^4 C''''| / 24 with C the cumulative integral, e.g.
 *    6e-6 relative for a 2 Hz sinusoid at 200 Hz). Before the first or after
 *    the last sample the first or last sample's rate is held.
 *  - in-motion white noise: while a sample is "moving" (below), white noise of
 *    per-sample sigma white_sigma_i * sqrt(k^2 - 1) is added to axis i, so the
 *    white noise of the output is k times the model's (variances add:
 *    sigma^2 + (k^2 - 1) sigma^2 = k^2 sigma^2). A sample is moving when the
 *    true |w_IB_B| exceeds motion_rate_threshold_rad_s or | |f_B| - 9.80665 |
 *    exceeds motion_acc_threshold_mps2 (judged on the time-shifted true
 *    sample; normal gravity varies by <= 0.03 m/s^2 with latitude and height,
 *    below the smallest threshold 0.05). A vehicle at constant velocity in a
 *    straight line is "not moving" by this test.
 *  - lever-arm error e [m] (body FRD) = told - true: the filter is told the
 *    antenna at lever_arm_B, the true antenna is at lever_arm_B - e
 *    (estimate-minus-truth, the README convention).
 */
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navimpact/emulation/sensors.hpp"
#include "navimpact/ins/nav_state.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::emulation {

/// Sensor effects of an emulated run; every field off by default. SI; the
/// documented range of each field (limits.hpp) is checked by validateEffects().
struct SensorEffects {
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Zero();  ///< gyro scale factors x,y,z [ratio], each in [-0.05, 0.05]
  Eigen::Vector3d acc_scale = Eigen::Vector3d::Zero();   ///< accelerometer scale factors [ratio], each in [-0.05, 0.05]
  Eigen::Vector3d gyro_misalignment_rad = Eigen::Vector3d::Zero();  ///< gyro triad small angles [rad], each in [-0.05, 0.05]
  Eigen::Vector3d acc_misalignment_rad = Eigen::Vector3d::Zero();   ///< accelerometer triad small angles [rad], each in [-0.05, 0.05]
  Eigen::Vector3d gyro_nonorthogonality_rad = Eigen::Vector3d::Zero();  ///< optional, [rad], each in [-0.05, 0.05]
  Eigen::Vector3d acc_nonorthogonality_rad = Eigen::Vector3d::Zero();   ///< optional, [rad], each in [-0.05, 0.05]
  double time_offset_s = 0.0;  ///< t_IMU - t_true [s], in [-0.1, 0.1]
  /// White-noise factor k while moving (1 = off), per sensor, in [1, 100].
  double gyro_motion_noise_factor = 1.0;
  double acc_motion_noise_factor = 1.0;  ///< as gyro_motion_noise_factor, for the accelerometers
  double motion_rate_threshold_rad_s = 0.05;  ///< moving when |w_IB_B| above [rad/s], in [1e-3, 10]
  double motion_acc_threshold_mps2 = 0.3;     ///< moving when ||f_B| - 9.80665| above [m/s^2], in [0.05, 100]
  Eigen::Vector3d lever_arm_error_B_m = Eigen::Vector3d::Zero();  ///< told - true antenna, body FRD [m], each in [-10, 10]

  /// True when every effect is off (the output is then perfect + errors exactly).
  bool none() const;
  /// M of one triad (see the file comment): I + diag(scale) + [m x] + N(n).
  Eigen::Matrix3d gyroMatrix() const;
  Eigen::Matrix3d accMatrix() const;  ///< M of the accelerometer triad
};

/**
 * Check every field against its documented range (limits.hpp).
 * @param[in] where  file (or context) named in the message.
 * @param[in] prefix key prefix, e.g. "effects." -> key "effects.gyro_scale[2]".
 * @throws navimpact::Error (keyError) naming where, the key and the range.
 */
void validateEffects(const SensorEffects& fx, const std::string& where, const std::string& prefix = "");

/// One line describing the effects that are on, in SI ("none" when none()), for logs and reports.
std::string describeEffects(const SensorEffects& fx);

/**
 * Per-sample white-noise sigma of each axis (kChannelNames order) of @p model
 * at @p imu_rate_hz: the root sum of squares of its WN terms after exact rate
 * conversion (stochastic::convertRate), 0 for an axis without WN. Other terms
 * (QN, GM with a short T) are not counted as white noise.
 */
std::array<double, 6> whiteNoiseSigma(const stochastic::ImuModel& model, double imu_rate_hz);

/// The IMU of an emulated run with the effects applied.
struct EffectedImu {
  std::vector<ins::ImuSample> imu;   ///< same times and intervals as the perfect IMU
  std::size_t moving_samples = 0;    ///< samples judged moving (all samples count, used or not)
  std::string description;           ///< describeEffects() plus the moving share
};

/**
 * Apply @p fx to a run: measured = M (true shifted by time_offset_s) + err +
 * in-motion noise (file comment).
 * @param[in] perfect      perfect IMU increments (perfectImu), uniform or not.
 * @param[in] err          per-axis errors in rate units, one value per sample
 *                         (ImuErrors::axis); each vector empty (= 0) or of size n.
 * @param[in] fx           the effects (validated here).
 * @param[in] white_sigma  per-sample white-noise sigma per axis (whiteNoiseSigma) the
 *                         motion factors inflate; unused when both factors are 1.
 * @param[in] seed         seed of the in-motion noise: axis i draws
 *                         standardNormal(n, stochastic::deriveSeed(seed, i)).
 * @throws navimpact::Error for an invalid field or an err vector of the wrong size.
 */
EffectedImu applySensorEffects(const std::vector<ins::ImuSample>& perfect,
                               const std::array<std::vector<double>, 6>& err, const SensorEffects& fx,
                               const std::array<double, 6>& white_sigma, std::uint64_t seed);

/**
 * The GNSS options of the true antenna: @p told with lever_arm_B replaced by
 * told.lever_arm_B - fx.lever_arm_error_B_m. Simulate the fixes with these and
 * give the filter told.lever_arm_B.
 */
GnssOptions gnssWithEffects(const GnssOptions& told, const SensorEffects& fx);

/// Time-shifted increments alone (the time-offset part of applySensorEffects):
/// sample k of the result covers the true interval (t_k - dt_k - d, t_k - d].
std::vector<ins::ImuSample> shiftImuTime(const std::vector<ins::ImuSample>& perfect, double time_offset_s);

}  // namespace navimpact::emulation
