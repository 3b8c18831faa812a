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
 * The IMU error states are estimate minus truth as well: the filter's
 * corrected sensor output is raw - H x_imu_est.
 */
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

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
};

/// Names and positions of all error states.
class StateLayout {
 public:
  StateLayout() = default;
  /**
   * Build the layout from a six-axis model (axes with an empty model have no
   * states and no noise: a perfect sensor).
   * @throws navimpact::Error if a turn-on sigma is not finite and positive
   *         while turn_on_bias is set.
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
  /// Initial covariance of the IMU error states (imuSize() square).
  Eigen::MatrixXd imuP0() const;
  /// One line per state: "index name".
  std::string describe() const;
  const stochastic::ImuModel& model() const { return model_; }
  /// What build() changed in the model (GMs entered as white noise), one line each.
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  std::vector<std::string> names_;
  std::vector<ProcessBlock> blocks_;
  std::array<double, 6> white_psd_{{0, 0, 0, 0, 0, 0}};
  std::array<Eigen::RowVectorXd, 6> h_;
  stochastic::ImuModel model_;
  std::vector<std::string> notes_;
};

}  // namespace navimpact::filter
