/**
 * @file state_layout.hpp
 * @brief Error-state layout of the EKF, built at run time from an IMU error model.
 *
 * Index layout (KF-GINS style, P_ID = 0, V_ID = 3, PHI_ID = 6, then IMU errors):
 *  -  0.. 2  dp  position error, metres along N, E, D (estimate minus truth)
 *  -  3.. 5  dv  velocity error in NED [m/s]
 *  -  6.. 8  psi attitude error about N, E, D [rad]: C_BtoN_est = (I + [psi x]) C_BtoN_true
 *  -  9..    IMU error states, axis by axis in kChannelNames order
 *            (gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z), for each axis the
 *            optional turn-on bias first, then one block per process of the
 *            axis model in model order: GM 1 state, RW 1, DR 2 (bias, rate),
 *            SIN 2 (oscillator); WN and QN have no state (process noise only).
 *  -  then the optional extra states (ExtraStates; each group present only
 *            when its prior sigma is > 0), in this order: gyro scale factors
 *            x,y,z; accelerometer scale factors x,y,z; gyro misalignment
 *            angles x,y,z; accelerometer misalignment angles x,y,z; antenna
 *            lever-arm error x,y,z (body FRD); IMU-GNSS time offset.
 * The IMU error states are estimate minus truth as well: the filter's
 * corrected sensor output is raw - H x_imu_est.
 *
 * Extra states (random constants: no process noise; prior sigma as given).
 * Each state holds the filter's estimate of the quantity of the sensor model
 * below, the same quantity emulation::SensorEffects sets, so an estimate is
 * compared with the hidden value directly; its error is estimate minus truth.
 *  - Sensor model per triad (gyro with w_IB_B, accelerometer with f_B):
 *      raw = M true + b + noise,  M = I + diag(s) + [m x]
 *    s: scale factors [ratio] (2000 ppm = 0.002); m: misalignment angles [rad]
 *    ([m x] v = m x v: the triad's axes are the body axes rotated by -m).
 *  - Corrected output (ErrorStateEkf::predict): corrected = M_est^-1 (raw - b_est)
 *    with M_est = I + diag(s_est) + [m_est x]; to first order
 *    (I - [m_est x] - diag(s_est)) (raw - b_est). Hence, with ds = s_est - s and
 *    dm = m_est - m, corrected - true = -diag(true) ds + [true x] dm - db, and
 *    (Groves 2013 eqs. 14.64-14.65 with the sensor-error inputs expanded):
 *      d(psi)/dt += -C_BtoN diag(w_IB_B) ds_g + C_BtoN [w_IB_B x] dm_g
 *      d(dv)/dt  += -C_BtoN diag(f_B) ds_a   + C_BtoN [f_B x] dm_a
 *  - Lever-arm error e [m, body FRD] = told - true: the filter uses the antenna
 *    at l = lever_B - e_est (lever_B as passed to the GNSS updates). With
 *    de = e_est - e, l_used - l_true = -de, so the GNSS position rows get
 *    -C_BtoN and the velocity rows -(C_BtoN [w_IB_B x] - [w_IE_N x] C_BtoN)
 *    (Groves 2013 eqs. 14.110-14.111 differentiated w.r.t. the lever arm).
 *  - Time offset d [s] = t_IMU - t_true: the filter state at IMU time t is the
 *    truth at t - d, so a GNSS fix (stamped in GNSS = true time) is compared
 *    with the prediction carried forward by d_est: position p_ant + v_ant d_est,
 *    velocity v_ant + a_N d_est (a_N = C_BtoN f_B + g_N - (2 w_IE_N + w_EN_N) x v_N,
 *    Groves 2013 eq. 5.54); H column v_ant resp. a_N. v_ant carries the rate of
 *    the attitude through the lever arm, C_BtoN (w_IB_B x l) (Groves 2013
 *    eq. 14.111). First order in d: the error of a measurement taken d late is
 *    its rate times d; the neglected a d^2 / 2 and (da/dt) d^2 / 2 bias the
 *    estimate by a few percent at d = 0.3 s on a manoeuvring flight
 *    (tests/filter/test_extra_states.cpp), hence the range +-0.1 s (limits.hpp).
 */
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "navimpact/core/config.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/state_space.hpp"

namespace navimpact::filter {

constexpr int kPos = 0;   ///< index of dp_N
constexpr int kVel = 3;   ///< index of dv_N
constexpr int kAtt = 6;   ///< index of psi_N
constexpr int kNav = 9;   ///< number of navigation error states

/// One process block of one sensor axis inside the state vector.
struct ProcessBlock {
  int channel = 0;       ///< 0..5 in kChannelNames order (0..2 gyro, 3..5 acc)
  int offset = 0;        ///< first state index in the full error state
  stochastic::StateSpaceBlock ss;  ///< continuous model (n = ss.n states)
};

/**
 * Optional extra error states (see the file comment for the model and the
 * convention), each group off by default and on when its prior sigma is > 0.
 * All are random constants. Prior sigmas in SI, finite, >= 0.
 */
struct ExtraStates {
  double gyro_scale_sigma = 0.0;             ///< gyro scale factors x,y,z [ratio]
  double acc_scale_sigma = 0.0;              ///< accelerometer scale factors x,y,z [ratio]
  double gyro_misalignment_sigma_rad = 0.0;  ///< gyro misalignment angles x,y,z [rad]
  double acc_misalignment_sigma_rad = 0.0;   ///< accelerometer misalignment angles x,y,z [rad]
  double lever_arm_sigma_m = 0.0;            ///< antenna lever-arm error x,y,z, body FRD [m]
  double time_offset_sigma_s = 0.0;          ///< IMU-GNSS time offset [s]
  /// Initial estimates (prior means) of the groups that are on, SI, within the
  /// effects' ranges (limits.hpp); zero by default (used only where the group is on).
  Eigen::Vector3d gyro_scale0 = Eigen::Vector3d::Zero();             ///< [ratio]
  Eigen::Vector3d acc_scale0 = Eigen::Vector3d::Zero();              ///< [ratio]
  Eigen::Vector3d gyro_misalignment0_rad = Eigen::Vector3d::Zero();  ///< [rad]
  Eigen::Vector3d acc_misalignment0_rad = Eigen::Vector3d::Zero();   ///< [rad]
  Eigen::Vector3d lever_arm_error0_m = Eigen::Vector3d::Zero();      ///< told - true, body FRD [m]
  double time_offset0_s = 0.0;                                       ///< t_IMU - t_true [s]
  /**
   * Read the `extra_states` map of a filter section (every group optional;
   * the initial estimates optional, default 0):
   * @code
   * extra_states:
   *   scale_factor: {gyro_sigma: 0.005, acc_sigma: 0.005,          # [ratio], (0, 0.05]
   *                  gyro: [0, 0, 0], acc: [0, 0, 0]}              # initial [ratio], [-0.05, 0.05]
   *   misalignment: {gyro_sigma_rad: 0.003, acc_sigma_rad: 0.003,  # [rad], (0, 0.05]
   *                  gyro_rad: [0, 0, 0], acc_rad: [0, 0, 0]}      # initial [rad], [-0.05, 0.05]
   *   lever_arm: {sigma_m: 0.5, error_m: [0, 0, 0]}                # [m], (0, 10]; initial [-10, 10]
   *   time_offset: {sigma_s: 0.05, offset_s: 0}                    # [s], (0, 0.1]; initial [-0.1, 0.1]
   * @endcode
   * @throws navimpact::Error naming the file and dotted key (unknown key, out of range).
   */
  void loadFrom(const ConfigNode& n);
  /// True when any group is on.
  bool any() const {
    return gyro_scale_sigma > 0 || acc_scale_sigma > 0 || gyro_misalignment_sigma_rad > 0 ||
           acc_misalignment_sigma_rad > 0 || lever_arm_sigma_m > 0 || time_offset_sigma_s > 0;
  }
};

/// The groups of extra states (ExtraStates), in their order in the state vector.
enum class Extra { GyroScale, AccScale, GyroMisalignment, AccMisalignment, LeverArm, TimeOffset };
constexpr int kExtraGroups = 6;

/// Options for the IMU-error part of the state.
struct ImuErrorOptions {
  /// Add a random-constant turn-on bias state per axis (prior sigma below).
  /// Useful on real data; off for emulated data with known error models.
  bool turn_on_bias = false;
  /// Prior sigma of the turn-on bias per channel (gyro_x..acc_z) [rad/s, m/s^2], > 0.
  std::array<double, 6> turn_on_sigma{{0, 0, 0, 0, 0, 0}};
  /// Gauss-Markov terms with T <= this [s] enter the filter as white noise of
  /// the same long-run variance, sigma_wn^2 = sigma^2 (1 + phi) / (1 - phi) per
  /// sample, phi = exp(-dt/T) (the AR(1) spectrum at zero frequency), instead of
  /// a state: over a covariance propagation interval longer than T such a state
  /// is white at the filter's resolution, and the truncated-series coupling
  /// terms (Groves 3.34/3.46, expansions in dt/T) stop being valid and make P
  /// indefinite (GMWM puts the quantisation noise of sensors like the ADIS16405
  /// into GMs with T = 3-6 ms). ErrorStateEkf raises it to its propagation
  /// interval; 0 = keep every GM as a state. Reported by StateLayout::notes().
  double white_gm_below_s = 0.0;
  /// Optional extra states (scale factor, misalignment, lever arm, time offset); all off by default.
  ExtraStates extra;
};

/// Names and positions of all error states.
class StateLayout {
 public:
  StateLayout() = default;
  /**
   * Build the layout from a six-axis model (axes with an empty model have no
   * states and no noise: a perfect sensor).
   * @throws navimpact::Error if a turn-on sigma is not finite and positive
   *         while turn_on_bias is set, or an extra-state sigma is not finite and >= 0.
   */
  static StateLayout build(const stochastic::ImuModel& model, const ImuErrorOptions& opt = {});

  int size() const { return static_cast<int>(names_.size()); }
  int imuSize() const { return size() - kNav; }
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<ProcessBlock>& blocks() const { return blocks_; }
  /// White-noise PSD per channel (sum over WN and QN terms) [unit^2 s].
  const std::array<double, 6>& whitePsd() const { return white_psd_; }
  /// Row vector h_c (size imuSize()) with sensor error of channel c = h_c x_imu.
  const Eigen::RowVectorXd& sensorRow(int channel) const { return h_[channel]; }
  /// The gyro rows h_0..h_2 stacked (3 x imuSize()): gyro error e_w = Hg x_imu [rad/s].
  Eigen::MatrixXd gyroRows() const;
  /// Initial covariance of the IMU error states (imuSize() square).
  Eigen::MatrixXd imuP0() const;
  /// One line per state: "index name".
  std::string describe() const;
  const stochastic::ImuModel& model() const { return model_; }
  /// What build() changed in the model (GMs entered as white noise), one line each.
  const std::vector<std::string>& notes() const { return notes_; }
  /// Full-state index of the first state of an extra group (3 states, 1 for
  /// TimeOffset), or -1 when the group is off.
  int extraIndex(Extra g) const { return extra_[static_cast<int>(g)]; }
  /// True when any extra state is on.
  bool hasExtra() const { return has_extra_; }

 private:
  std::vector<std::string> names_;
  std::vector<ProcessBlock> blocks_;
  std::array<double, 6> white_psd_{{0, 0, 0, 0, 0, 0}};
  std::array<Eigen::RowVectorXd, 6> h_;
  stochastic::ImuModel model_;
  std::vector<std::string> notes_;
  std::array<int, kExtraGroups> extra_{{-1, -1, -1, -1, -1, -1}};
  bool has_extra_ = false;
};

}  // namespace navimpact::filter
