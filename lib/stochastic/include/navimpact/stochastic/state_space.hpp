/**
 * @file state_space.hpp
 * @brief State-space (Kalman filter) form of each process, used by the
 *        error-state EKF to build its IMU-error states at run time.
 *
 * Continuous time: x' = F x + G w, E[w w^T] = Qc delta(t); sensor error = H x
 * (+ white noise of PSD white_psd). Exact discrete form over dt:
 * Phi = exp(F dt), Qd = int_0^dt exp(F s) Qc exp(F s)^T ds. Each kind's block
 * is defined in lib/stochastic/src/processes/<name>.cpp:
 *  - WN, QN: no state; white_psd = sigma^2 dt_model (QN: 2 Q^2 dt_model, its
 *    per-sample variance, a conservative white approximation).
 *  - GM: 1 state, F = -1/T, Qc = 2 sigma^2 / T, P0 = sigma^2 (stationary).
 *  - RW: 1 state, F = 0, Qc = gamma^2 / dt_model, P0 = 0.
 *  - DR: 2 states [bias, rate], bias' = rate, rate' = 0; P0 = diag(0, (omega/dt)^2)
 *    (the GMWM loses the drift's sign, so the rate is a zero-mean prior).
 *  - SIN: 2 states, oscillator [a sin, a cos] at w = 2 pi f, F = [0 w; -w 0],
 *    Qc = 0, P0 = diag(amp^2/2, amp^2/2), H = [1 0].
 */
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

struct StateSpaceBlock {
  int n = 0;                          ///< number of states (0 for WN, QN)
  Eigen::MatrixXd F;                  ///< n x n continuous dynamics [1/s]
  Eigen::MatrixXd Qc;                 ///< n x n driving-noise PSD
  Eigen::RowVectorXd H;               ///< 1 x n: sensor error = H x
  Eigen::MatrixXd P0;                 ///< n x n initial covariance
  double white_psd = 0.0;             ///< white part added to sensor noise [unit^2 s]
  /// One label per state, appended to the term's name "<channel>.<KIND><k>" by
  /// the filter: "(T=3.22s)" (GM), "" (RW), ".bias"/".rate" (DR), "(f=1.3Hz).a"/".b" (SIN).
  std::vector<std::string> names;

  /// Exact transition over dt [s].
  Eigen::MatrixXd Phi(double dt) const;
  /// Exact discrete process-noise covariance over dt [s].
  Eigen::MatrixXd Qd(double dt) const;
};

/// State-space block of one process of a model sampled at @p rate_hz.
StateSpaceBlock stateSpace(const Process& p, double rate_hz);

}  // namespace navimpact::stochastic
