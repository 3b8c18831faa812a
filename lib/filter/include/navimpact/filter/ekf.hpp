/**
 * @file ekf.hpp
 * @brief Error-state (indirect, closed-loop) EKF for GNSS/baro-aided INS with
 *        IMU error states built at run time from a stochastic::ImuModel.
 *
 * API in the spirit of KF-GINS's GIEngine: predict() per IMU sample (runs the
 * mechanization on error-corrected increments and propagates the covariance),
 * update*() per aiding measurement (Kalman update, Joseph form, closed-loop
 * feedback into the navigation state and the IMU-error estimates, error
 * state reset). Measurements apply at the current filter time state().t:
 * the caller predicts up to the measurement epoch first.
 *
 * Typical use (emulation / rawlog replay):
 * @code
 *   filter::EkfConfig cfg;                       // defaults: series discretisation, every sample
 *   filter::ErrorStateEkf ekf(x0, P0_nav, model, cfg);
 *   for (const ins::ImuSample& s : imu) {
 *     ekf.predict(s);
 *     if (gnss_at(s.t)) ekf.updateGnssPosition(z_geodetic, sigma_ned, lever_B);
 *   }
 *   ekf.state(); ekf.sigmas(); ekf.lastUpdate().nis;
 * @endcode
 * Covariance-only analysis (no sensor data): construct, then call
 * predictCovariance() along a nominal trajectory and updateCovariance*()
 * for the aiding epochs.
 *
 * Innovation convention: dz = h(x_est) - z (predicted minus measured; with
 * estimate-minus-truth errors dz = H dx - noise). The NIS is dz' S^-1 dz.
 */
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "navimpact/filter/error_model.hpp"
#include "navimpact/filter/state_layout.hpp"
#include "navimpact/ins/mechanization.hpp"

namespace navimpact::filter {

/// How the continuous model is discretised over one IMU interval.
enum class Discretization {
  Series,   ///< Phi = I + F dt + F^2 dt^2/2, Qd = Q dt + (FQ + QF') dt^2/2 + F Q F' dt^3/3
  VanLoan,  ///< exact matrix exponential of the Van Loan (1978) block matrix
};
/// "series" or "vanloan"; throws navimpact::Error naming the accepted values.
Discretization parseDiscretization(const std::string& s);

/// Smallest non-zero gate probability of EkfConfig::gate_probability.
inline constexpr double kMinGateProbability = 0.5;

/**
 * Largest attitude sigma [rad] (roll, pitch or yaw) within which the
 * error-state filter's covariance is a valid error bound. The filter's attitude
 * error is first order in psi (C_BtoN_est = (I + [psi x]) C_BtoN_true, and the
 * error dynamics are linearised around it): the neglected second-order part is
 * |psi|/2 of the first-order one (1 - cos psi ~ psi^2/2 against sin psi ~ psi),
 * 7.5 % at |psi| = 0.15 rad, the 3-sigma error at this limit. Beyond it the
 * sigmas are the propagated covariance of a linear model that no longer holds
 * (a 48 h static run of the Table 1 gyro_ref model reaches a yaw sigma of
 * 92 deg), not an error bound; covariance runs say so
 * (analysis::CovarianceRun::small_error_exceeded_s) and replay refuses an IMU gap
 * whose bridge would add more (analysis/replay.hpp).
 */
inline constexpr double kSmallErrorAttitudeSigmaRad = 0.05;

/**
 * Positive definiteness of the covariance, checked after every update (and so
 * before every output of a run with updates). P is judged on the correlation
 * scale, Pc = D^-1/2 P D^-1/2 with D_ii = max(P_ii, floor_i), so that states
 * with small variances are judged as strictly as the metre-level ones while a
 * state known far better than anything navigation resolves (a vertical
 * channel held by a 1 mm barometer; a state decoupled from every noise)
 * does not turn rounding into "correlations" above 1. The floor is the
 * resolution below which a state counts as known: (1 um)^2 for positions,
 * (1 um/s)^2 for velocities, (1 nrad)^2 for attitude, and 1e-12 times the
 * natural variance of an IMU-error or extra state (its initial variance, or
 * its driving noise Qc over 1 s when that is larger).
 *  - smallest eigenvalue of Pc >= -tolerance: accepted (rounding);
 *  - in [-repair_limit, -tolerance): the eigenvalue floor: the negative
 *    eigenvalues of Pc are set to zero and P rebuilt (symmetric, positive
 *    semi-definite; a change of at most repair_limit relative to each
 *    variance). Long runs need it: after 46 h of static propagation with
 *    model acc_model1 the position and attitude errors are correlated to
 *    1 - 1e-10 and rounding leaves an eigenvalue of -1e-9. Every repair is
 *    counted (ErrorStateEkf::pdRepairs) and reported by the runs;
 *  - below -repair_limit: navimpact::Error naming the time, the step and the
 *    state that weighs most in the offending eigenvector (no silent answer).
 */
struct PdCheck {
  static constexpr double tolerance = 1e-9;
  static constexpr double repair_limit = 1e-6;
  static constexpr double position_floor_m2 = 1e-12;
  static constexpr double velocity_floor_m2ps2 = 1e-12;
  static constexpr double attitude_floor_rad2 = 1e-18;
  static constexpr double imu_floor_relative = 1e-12;
};

struct EkfConfig {
  Discretization discretization = Discretization::Series;
  /// Propagate the covariance every k IMU samples (k >= 1). predict() keeps
  /// mechanizing every sample; with k > 1 it accumulates over the interval the
  /// elapsed time T, the integral of the specific force in the navigation frame,
  /// of C_BtoN and of the white-noise PSD rotated to NED, and builds ONE Phi and
  /// Qd over T from the interval means (Groves 2013 §14.2.4 and eqs. 3.34,
  /// 3.46-3.47 applied to the whole interval; linearised at the end-of-interval
  /// state), then propagates P once. The pending interval is flushed before
  /// every update and by flushPropagation() (call it before reading P()).
  /// predictCovariance() (covariance-only analysis) instead accumulates the
  /// product of the k per-step transitions and their process noise exactly.
  /// Accuracy of k = 10 at 200 Hz on a turning flight: see
  /// tests/filter/test_consistency.cpp (LowerRate.*).
  int propagate_every = 1;
  /// Chi-square innovation gate: reject when NIS > quantile(gate_probability, m).
  /// 0 = off (default); else in [kMinGateProbability, 1), e.g. 0.999 (a gate
  /// below the median rejects most innovations of a consistent filter).
  double gate_probability = 0.0;
  /// Re-admission after a lock-out: once this many gated updates in a row were
  /// rejected, the next one that fails the gate is applied after scaling P by
  /// lambda = NIS / gate (> 1), the fading-memory step of Simon (2006) §7.4:
  /// a run of rejections is evidence that the covariance, not the measurement,
  /// is wrong. Without it (0), a filter whose error has outgrown its covariance
  /// rejects every later fix and diverges. 0 = never; else 1..1000. Default 3.
  int gate_readmit_after = 3;
  ImuErrorOptions imu;                 ///< turn-on bias states
  ins::MechanizationOptions mechanization;
};

/**
 * The IMU-error options the filter really uses for @p model: cfg.imu with
 * white_gm_below_s raised to the covariance propagation interval
 * propagate_every / model.rate_hz [s] (the model is expected at the IMU rate).
 * Use it to build the same StateLayout as the filter (state counts, notes).
 */
ImuErrorOptions effectiveImuOptions(const stochastic::ImuModel& model, const EkfConfig& cfg);

/**
 * Values of the extra states (state_layout.hpp, ExtraStates), the quantities of
 * emulation::SensorEffects of the same names, SI; zero for a group that is off.
 */
struct SensorParams {
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Zero();             ///< [ratio]
  Eigen::Vector3d acc_scale = Eigen::Vector3d::Zero();              ///< [ratio]
  Eigen::Vector3d gyro_misalignment_rad = Eigen::Vector3d::Zero();  ///< [rad]
  Eigen::Vector3d acc_misalignment_rad = Eigen::Vector3d::Zero();   ///< [rad]
  Eigen::Vector3d lever_arm_error_B_m = Eigen::Vector3d::Zero();    ///< told - true antenna, body FRD [m]
  double time_offset_s = 0.0;                                       ///< t_IMU - t_true [s]
};

/// Result of one measurement update.
struct UpdateResult {
  bool accepted = true;         ///< false when rejected by the chi-square gate
  Eigen::VectorXd innovation;   ///< dz = h(x_est) - z (metres NED / m/s / m)
  Eigen::MatrixXd S;            ///< innovation covariance H P H' + R
  double nis = 0.0;             ///< dz' S^-1 dz
  double gate = 0.0;            ///< NIS threshold of the chi-square gate (0: gate off)
  double t = 0.0;               ///< filter time [s]
  /// Applied although NIS > gate, after gate_readmit_after rejections in a row;
  /// P was scaled by `inflation` first (nis, S and innovation are those before).
  bool readmitted = false;
  double inflation = 1.0;       ///< lambda = NIS / gate of a re-admission (1 otherwise)
};

class ErrorStateEkf {
 public:
  /**
   * @param[in] x0      initial navigation state (its t is the start time).
   * @param[in] P0_nav  9x9 initial covariance of [dp (m NED), dv (m/s), psi (rad)],
   *                    symmetric positive semi-definite (zero allowed).
   * @param[in] model   IMU error model of the six axes (empty axis = perfect).
   * @param[in] cfg     options.
   * @throws navimpact::Error for invalid options or a non-symmetric/negative P0_nav.
   */
  ErrorStateEkf(const ins::NavState& x0, const Matrix9d& P0_nav,
                const stochastic::ImuModel& model, const EkfConfig& cfg = {});

  // ---- prediction -------------------------------------------------------
  /**
   * One raw IMU sample: correct it by the estimated sensor errors, run the
   * mechanization, propagate the IMU-error estimates and the covariance.
   * @param[in] raw  increments over (t - dt, t], dt > 0.
   */
  void predict(const ins::ImuSample& raw);

  /**
   * The body rates the measurement models use (antenna velocity, carrying a
   * fix to its epoch, the time-offset column) before the first predict(): the
   * corrected output of @p first, the sample whose interval starts at the
   * initial state. Without it they would use zero rates: a GNSS velocity at
   * the initial epoch with a lever arm set the velocity off by w x l (1.8 m/s
   * for a 3 m lever arm at 0.6 rad/s), a transient the lever-arm and
   * time-offset states kept ~2 % of for good. The state and P are unchanged.
   */
  void primeRates(const ins::ImuSample& first);

  /**
   * With a time-offset state d = t_IMU - t_true: the initial state came from
   * data on the true clock (a reference, GNSS), while the state at the IMU's
   * stamp t0 is the truth at t0 - d. Carries the initial state by the offset's
   * initial estimate d0 (x0 - xdot d0) and couples its errors to the offset's:
   * dx_nav -> dx_nav - J dd with J = xdot = (v_N, a_N, w_NB_N) (P -> T P T').
   * Without it a reference start with an 84 ms offset began with an attitude
   * error of w d (up to 3 deg) outside P0, a transient the offset kept 2 % of.
   * After primeRates(); nothing without a time-offset state.
   */
  void carryInitialStateToImuClock();

  /**
   * Covariance-only propagation over @p dt along a given nominal state (the
   * navigation state is set to @p nominal and not integrated).
   * @param[in] nominal  linearisation point at the end of the interval.
   * @param[in] w_IB_B   nominal angular rate [rad/s].
   * @param[in] f_B      nominal specific force [m/s^2].
   * @param[in] dt       interval [s], > 0.
   */
  void predictCovariance(const ins::NavState& nominal, const Eigen::Vector3d& w_IB_B,
                         const Eigen::Vector3d& f_B, double dt);

  /// Apply any pending (accumulated) covariance propagation now.
  void flushPropagation();

  /**
   * Sensor uncertainty the error model does not hold, over the last sample's
   * interval @p dt: white angular-rate and specific-force noise of PSD
   * @p psd_w [(rad/s)^2/Hz] and @p psd_f [(m/s^2)^2/Hz] on every axis, to
   * first order in dt (P_psi += psd_w dt I, P_v += psd_f dt I; C I C' = I).
   * For samples the IMU did not measure (a gap crossed with interpolated
   * rates); call it after their predict(). Flushes the pending propagation.
   */
  void addSensorNoise(double dt, double psd_w, double psd_f);

  // ---- measurement updates ----------------------------------------------
  /**
   * GNSS position of the antenna (Groves 14.? loosely coupled, lever arm 14.110).
   * @param[in] z          measured antenna position (geodetic).
   * @param[in] sigma_NED  1-sigma noise along N, E, D [m], > 0.
   * @param[in] lever_B    antenna position w.r.t. the IMU in body axes [m] (as told; with
   *                       the lever-arm state on, lever_B - e_est is used).
   * @param[in] dt_meas    measurement epoch minus filter time state().t [s] (with the
   *                       time-offset state on, dt_meas + d_est is used): a fix
   *                       between IMU samples is compared with the predicted antenna
   *                       position carried to its epoch with the antenna velocity,
   *                       p_ant + v_ant dt_meas (first order; |dt_meas| is at most
   *                       an IMU interval in practice). H = H_pos + dt_meas H_vel.
   */
  UpdateResult updateGnssPosition(const earth::Geodetic& z, const Eigen::Vector3d& sigma_NED,
                                  const Eigen::Vector3d& lever_B = Eigen::Vector3d::Zero(),
                                  double dt_meas = 0.0);
  /**
   * GNSS velocity of the antenna in NED (lever arm: v + C (w_IB_B x l) - w_IE_N x (C l), Groves 14.111).
   * @param[in] z_N        measured velocity [m/s].
   * @param[in] sigma_NED  1-sigma noise [m/s], > 0.
   * @param[in] lever_B    lever arm [m].
   * @param[in] dt_meas    measurement epoch minus filter time [s]: the predicted
   *                       velocity is carried with the IMU acceleration
   *                       dv/dt = C f_B + g_N - (2 w_IE_N + w_EN_N) x v_N (Groves 5.54);
   *                       H = H_vel + dt_meas F_vel (the velocity rows of F).
   */
  UpdateResult updateGnssVelocity(const Eigen::Vector3d& z_N, const Eigen::Vector3d& sigma_NED,
                                  const Eigen::Vector3d& lever_B = Eigen::Vector3d::Zero(),
                                  double dt_meas = 0.0);
  /**
   * Zero-velocity update (ZUPT): the IMU is at rest w.r.t. the Earth, z = 0,
   * dz = v_N_est, H = [0 I 0 ...] (Groves 2013 §15.3.1).
   * @param[in] sigma_mps  1-sigma of the pseudo-measurement per axis [m/s], > 0.
   */
  UpdateResult updateZeroVelocity(double sigma_mps);
  /**
   * Non-holonomic constraint of a ground vehicle (Groves 2013 §15.4.1; Dissanayake
   * et al. 2001): the point P at @p point_B (body FRD, from the IMU) moves neither
   * sideways nor vertically in the body frame, z = [0, 0] for
   * v_P_B = C_NtoB v_N + w_EB_B x l,  w_EB_B = w_IB_B - C_NtoB w_IE_N,
   * components right (y) and down (z).
   * @param[in] sigma_lateral_mps   1-sigma of the lateral component [m/s], > 0.
   * @param[in] sigma_vertical_mps  1-sigma of the vertical component [m/s], > 0.
   * @param[in] point_B             P w.r.t. the IMU in body axes [m] (e.g. the rear axle).
   */
  UpdateResult updateNonHolonomic(double sigma_lateral_mps, double sigma_vertical_mps,
                                  const Eigen::Vector3d& point_B = Eigen::Vector3d::Zero());
  /**
   * Barometric altitude, taken as ellipsoidal height of the IMU, on the true
   * clock as GNSS (with a time-offset state it is the height at IMU time
   * t + d); carried to its epoch h - v_D tau, tau = dt_meas + d.
   * @param[in] h_meas   measured height [m].
   * @param[in] sigma    1-sigma noise [m], > 0.
   * @param[in] dt_meas  its epoch minus the filter time [s] (0 on a sample).
   */
  UpdateResult updateBaro(double h_meas, double sigma, double dt_meas = 0.0);

  /**
   * Generic linear update dz = H dx - noise with the caller's residual (used
   * by the updates above, by covariance-only analysis and by tests).
   * @param[in] dz  residual h(x_est) - z (size m).
   * @param[in] H   m x size() Jacobian.
   * @param[in] R   m x m noise covariance, positive definite.
   * @param[in] feedback  apply closed-loop correction (false: covariance only).
   */
  UpdateResult update(const Eigen::VectorXd& dz, const Eigen::MatrixXd& H,
                      const Eigen::MatrixXd& R, bool feedback = true);

  // ---- residuals dz = h(x_est) - z at the current state (public for tests) --
  /// GNSS position residual in metres N, E, D (antenna, lever arm @p lever_B [m],
  /// measurement epoch dt_meas [s] after the filter time).
  Eigen::VectorXd residualGnssPosition(const earth::Geodetic& z, const Eigen::Vector3d& lever_B,
                                       double dt_meas = 0.0) const;
  /// GNSS velocity residual [m/s] (antenna, lever arm @p lever_B [m], epoch dt_meas [s]).
  Eigen::VectorXd residualGnssVelocity(const Eigen::Vector3d& z_N, const Eigen::Vector3d& lever_B,
                                       double dt_meas = 0.0) const;
  /// Non-holonomic residual [m/s]: right and down components of v_P_B (see updateNonHolonomic).
  Eigen::Vector2d residualNonHolonomic(const Eigen::Vector3d& point_B) const;

  // ---- Jacobians (public for tests and covariance-only analysis) --------
  Eigen::MatrixXd H_gnssPosition(const Eigen::Vector3d& lever_B, double dt_meas = 0.0) const;  ///< 3 x size()
  Eigen::MatrixXd H_gnssVelocity(const Eigen::Vector3d& lever_B, double dt_meas = 0.0) const;  ///< 3 x size()
  Eigen::MatrixXd H_baro(double dt_meas = 0.0) const;                    ///< 1 x size()
  Eigen::MatrixXd H_zeroVelocity() const;                                ///< 3 x size()
  Eigen::MatrixXd H_nonHolonomic(const Eigen::Vector3d& point_B) const;  ///< 2 x size()
  /// Continuous F (size() square) at the current state and last f_B.
  Eigen::MatrixXd F() const;
  /// Continuous driving-noise PSD matrix (size() square) at the current state.
  Eigen::MatrixXd Qc() const;
  /// Discrete Phi, Qd over dt with the configured method at the current state.
  void discretize(double dt, Eigen::MatrixXd& Phi, Eigen::MatrixXd& Qd) const;

  // ---- outputs ----------------------------------------------------------
  const ins::NavState& state() const { return mech_.state(); }
  const Eigen::MatrixXd& P() const { return P_; }
  Eigen::VectorXd sigmas() const { return P_.diagonal().cwiseSqrt(); }
  /// Estimated IMU error states (size imuSize()).
  const Eigen::VectorXd& imuStates() const { return x_imu_; }
  /// Estimated sensor errors now, gyro_x..acc_z [rad/s, m/s^2].
  Eigen::Matrix<double, 6, 1> sensorErrors() const;
  /// Estimates of the extra states (zero for groups that are off).
  SensorParams extraEstimates() const;
  /// Their 1-sigma from P (zero for groups that are off).
  SensorParams extraSigmas() const;
  /// With the time-offset state on, the state at IMU time t is the truth at
  /// t - d_est (state_layout.hpp); the navigation solution at true time t is
  /// the state carried forward to IMU time t + d_est. Returns the first-order
  /// change over @p tau of (dp NED [m], dv NED [m/s], psi [rad]): (v_N, a_N,
  /// C_BtoN w_NB_B) tau (Groves 2013 eq. 5.54 for a_N).
  Vector9d carry(double tau) const;
  /// Covariance of the nine navigation errors against the truth at true time
  /// (the error scored when the state is carried to the IMU epoch of t + d_est):
  /// with the time-offset state that error is dx_nav + J (d_est - d), J the
  /// state's rate (carry), so P_true = T P T' with T = [I_9 .. J in d's column].
  /// Without the state, the navigation block of P.
  Matrix9d navCovarianceOnTrueClock() const;
  /// The time-offset state's estimate d = t_IMU - t_true [s]; 0 when it is off.
  double timeOffsetEstimate() const;
  const StateLayout& layout() const { return layout_; }
  int size() const { return layout_.size(); }
  const UpdateResult& lastUpdate() const { return last_; }
  int rejections() const { return rejections_; }
  /// Repairs of P by the eigenvalue floor (see PdCheck) since construction,
  /// the most negative eigenvalue repaired (correlation scale; 0 if none) and
  /// the filter time of the first repair (NaN if none).
  int pdRepairs() const { return pd_repairs_; }
  double pdWorstRepaired() const { return pd_worst_; }
  double pdFirstRepairTime() const { return pd_first_t_; }
  /// Variance floor of each state (the resolution below which it counts as known; PdCheck).
  const Eigen::VectorXd& varianceFloor() const { return floor_; }
  const EkfConfig& config() const { return cfg_; }
  /// Overwrite the IMU-error and extra-state estimates (size imuSize(); tests, warm
  /// starts); P is unchanged. @throws navimpact::Error on a size mismatch or a non-finite value.
  void setImuStates(const Eigen::VectorXd& x);
  /// Overwrite the navigation state (e.g. alignment); P is unchanged.
  void setState(const ins::NavState& x) { mech_.setState(x); }
  /// Last corrected angular rate and specific force [rad/s, m/s^2].
  const Eigen::Vector3d& w_IB_B() const { return w_IB_B_; }
  const Eigen::Vector3d& f_B() const { return f_B_; }
  /// IMU samples mechanized since the covariance was last propagated (0..k-1).
  int pendingSamples() const { return std::max(pending_, iv_n_); }

 private:
  struct Transition;  // structured Phi: [A B; 0 D], D block-diagonal
  /// Linearisation of one propagation interval: F_nn, the C_BtoN that couples
  /// the sensor errors in, and the white-noise PSDs rotated to NED [unit^2 s].
  struct Lin {
    Matrix9d Fnn;
    Eigen::Matrix3d C, Qv, Qa;
    // extra states only: C diag(w_IB_B), C [w_IB_B x], C diag(f_B), C [f_B x]
    Eigen::Matrix3d CDw, CSw, CDf, CSf;
  };
  /// Couplings of the extra sensor states into F (rows psi and dv), written
  /// into X at column (full-state index - col0).
  void addExtraCouplings(const Lin& L, Eigen::Ref<Eigen::MatrixXd> X, int col0) const;
  /// Value of an extra state (component i of the group; 0 when the group is off).
  double extra(Extra g, int i = 0) const;
  Eigen::Vector3d extra3(Extra g) const { return {extra(g, 0), extra(g, 1), extra(g, 2)}; }
  /// Jacobian (3 x size()) of the antenna velocity v_ant for the lever arm @p l used.
  Eigen::MatrixXd H_antennaVelocity(const Eigen::Vector3d& l) const;
  /// Antenna velocity v + C (w x l) - w_IE x (C l) (Groves 14.111) and the
  /// acceleration a_N (Groves 5.54) at the current state.
  Eigen::Vector3d antennaVelocity(const Eigen::Vector3d& l) const;
  Eigen::Vector3d accelerationN() const;
  Lin currentLin() const;
  Eigen::MatrixXd assembleF(const Lin& L) const;
  Eigen::MatrixXd assembleQc(const Lin& L) const;
  void buildTransition(const Lin& L, double dt, Transition& T) const;
  void accumulate(const Transition& T);
  void applyInterval();
  void applyTransition();
  void propagate(const Matrix9d& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& D,
                 const Eigen::MatrixXd& Q);
  void checkP(const char* where) const;
  /// The positive-definiteness check of PdCheck on P, repairing it within the floor.
  void checkPositiveDefinite(const char* where);

  EkfConfig cfg_;
  StateLayout layout_;
  ins::Mechanization mech_;
  Eigen::MatrixXd P_;
  Eigen::VectorXd x_imu_;
  Eigen::Vector3d w_IB_B_ = Eigen::Vector3d::Zero(), f_B_ = Eigen::Vector3d::Zero();
  // The body rate at the end of the last sample's interval and the angular
  // acceleration, for the antenna's velocity and acceleration: the sample's
  // rate is its interval's mean (dt/2 late, which a time-offset state took
  // for part of the offset, 3 ms at 100 Hz with a 10 m lever arm). The
  // acceleration from the rates kRateSpanS apart (noise / (span/dt) of a
  // difference of consecutive samples), the end rate the sample's plus it dt/2.
  static constexpr double kRateSpanS = 0.05;
  static constexpr int kRateRing = 64;
  std::array<Eigen::Vector3d, kRateRing> rate_ring_{};
  int ring_next_ = 0, ring_count_ = 0;
  Eigen::Vector3d w_end_IB_B_ = Eigen::Vector3d::Zero();  ///< [rad/s]
  Eigen::Vector3d dw_IB_B_ = Eigen::Vector3d::Zero();     ///< [rad/s^2]
  void pushRate(const Eigen::Vector3d& w, double dt);
  /// The body rate w.r.t. the Earth at the sample's end, w_end_IB_B - C' w_IE_N [rad/s].
  Eigen::Vector3d w_EB_B(const Eigen::Matrix3d& C_BtoN) const;
  /// The antenna's acceleration in N for lever arm @p l [m/s^2].
  Eigen::Vector3d antennaAcceleration(const Eigen::Vector3d& l) const;
  /// Jacobian of the lever arm's rotation terms of antennaAcceleration (3 x size()).
  Eigen::MatrixXd H_antennaRotationAcceleration(const Eigen::Vector3d& l) const;
  /// @p raw corrected by the estimated sensor errors (closed loop).
  ins::ImuSample corrected(const ins::ImuSample& raw) const;
  /// Time derivative of (position NED [m], velocity [m/s], attitude [rad]) at
  /// the state: v_N, a_N (Groves 2013 eq. 5.54) and C_BtoN w_NB_B.
  Vector9d stateRate() const;
  // accumulated transition
  Eigen::Matrix<double, 9, 9> A_acc_;
  Eigen::MatrixXd B_acc_, D_acc_, Q_acc_;
  int pending_ = 0;
  // interval accumulated by predict() when propagate_every > 1
  int iv_n_ = 0;
  double iv_dt_ = 0.0;
  Eigen::Vector3d iv_fN_ = Eigen::Vector3d::Zero();  // sum C f_B dt [m/s]
  Eigen::Matrix3d iv_C_ = Eigen::Matrix3d::Zero();   // sum C dt [s]
  Eigen::Matrix3d iv_Qv_ = Eigen::Matrix3d::Zero(), iv_Qa_ = Eigen::Matrix3d::Zero();  // sum C diag(psd) C' dt
  // extra states only: sums of C diag(w) dt, C [w x] dt, C diag(f) dt, C [f x] dt
  Eigen::Matrix3d iv_CDw_ = Eigen::Matrix3d::Zero(), iv_CSw_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d iv_CDf_ = Eigen::Matrix3d::Zero(), iv_CSf_ = Eigen::Matrix3d::Zero();
  UpdateResult last_;
  int rejections_ = 0;
  int consecutive_rejections_ = 0;  ///< gated rejections since the last applied update
  Eigen::VectorXd floor_;           ///< variance floor per state (PdCheck)
  int pd_repairs_ = 0;
  double pd_worst_ = 0.0, pd_first_t_ = std::numeric_limits<double>::quiet_NaN();
  // cache for covariance-only propagation along a constant nominal
  struct Cache;
  std::shared_ptr<Cache> cache_;
};

}  // namespace navimpact::filter
