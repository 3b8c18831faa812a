/**
 * @file error_model.hpp
 * @brief Linearised INS error model in the local-navigation frame and the
 *        error-state conventions, Groves 2013 §14.2.4 (eqs. 14.63-14.71),
 *        with position errors in metres NED instead of curvilinear errors.
 *
 * Error state (every error = estimate minus truth):
 *  - dp = [(R_N+h) dlat, (R_E+h) cos(lat) dlon, -dh] [m],
 *  - dv = v_est - v_true [m/s],
 *  - psi with C_BtoN_est = (I + [psi x]) C_BtoN_true [rad] (Groves 5.109's
 *    small-angle attitude error; for a level vehicle psi_D ~ yaw_est - yaw_true).
 * Sensor error inputs (estimate minus truth of the corrected output):
 *  df_B = f_est - f_true, dw_B = w_est - w_true.
 * Continuous dynamics d(dx)/dt = F dx + [0; C_BtoN df_B; C_BtoN dw_B]:
 *  - d(psi)/dt = -w_IN x psi + C dw_B - dw_IN(dp, dv)                  (Groves 14.64)
 *  - d(dv)/dt  = -[f_N x] psi + C df_B + dg(dp) + [v x](2 dw_IE + dw_EN)
 *                - [(2 w_IE + w_EN) x] dv                               (Groves 14.65-14.69)
 *  - d(dp)/dt  = dv + transport terms of the metre parametrisation     (Groves 14.70-14.71)
 */
#pragma once

#include <Eigen/Core>

#include "navimpact/ins/nav_state.hpp"

namespace navimpact::filter {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;

/**
 * The 9x9 navigation block F_nn of the continuous error dynamics.
 * @param[in] x    navigation state (linearisation point), |lat| < 89.9 deg.
 * @param[in] f_B  specific force at x, corrected [m/s^2].
 * @return F_nn [1/s and mixed units of the state].
 */
Matrix9d navErrorDynamics(const ins::NavState& x, const Eigen::Vector3d& f_B);

/**
 * Same as navErrorDynamics() with the specific force already resolved in NED
 * (e.g. the mean over a propagation interval).
 * @param[in] x    navigation state (linearisation point), |lat| < 89.9 deg.
 * @param[in] f_N  specific force in NED [m/s^2].
 */
Matrix9d navErrorDynamicsN(const ins::NavState& x, const Eigen::Vector3d& f_N);

/// Error of @p est relative to @p truth in the convention above (9 values).
Vector9d navError(const ins::NavState& est, const ins::NavState& truth);

/// The estimate that has error @p dx w.r.t. @p truth (inverse of navError to first order).
ins::NavState applyNavError(const ins::NavState& truth, const Vector9d& dx);

/**
 * Closed-loop feedback (Groves 14.7-14.9 with our signs): remove the estimated
 * error @p dx from @p est, i.e. return est "minus" dx.
 */
ins::NavState correctNav(const ins::NavState& est, const Vector9d& dx);

}  // namespace navimpact::filter
