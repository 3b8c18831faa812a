/**
 * @file nav_run.hpp
 * @brief One GNSS/baro-aided INS run in memory: feed IMU samples, GNSS fixes
 *        (outside the outage windows) and barometer samples into the
 *        error-state EKF and record, at the truth epochs, the actual errors
 *        (estimate minus truth), the predicted sigmas and the NEES.
 *
 * This is THE navigation loop of navimpact. Both the Monte Carlo emulation
 * study (analysis/study.hpp, `navimpact study`) and the rawlog replay
 * (`navimpact replay`) must run their filters through runNav(): the replay
 * converts its recording (navimpact::Recording) to the inputs below
 * (ImuRecord -> ins::ImuSample::fromRates, GNSS fixes and baro samples as
 * they are, the reference to a TruthSeries) and calls runNav() once. Without ground truth (a real
 * flight's rawlog) the truth pointer is null and only the estimate and the
 * predicted sigmas are recorded.
 *
 * Conventions (see filter/error_model.hpp): errors are estimate minus truth,
 * position in metres along local N, E, D, velocity in NED [m/s], attitude as
 * the small-angle vector psi with C_est = (I + [psi x]) C_true [rad].
 *
 * Timing: measurements apply when the filter time reaches them (to within
 * half an IMU interval), after the prediction to that sample; a GNSS fix
 * between samples is compared with the prediction carried to its own epoch
 * (ErrorStateEkf dt_meas), so fixes need not fall on IMU samples; at one epoch
 * GNSS position, then GNSS velocity, then baro are applied, then the epoch
 * is recorded. GNSS outage windows are half-open on the left: a fix at time
 * t is dropped when start < t <= end, so with fixes at whole seconds and an
 * integer start the last fix used is the one AT start and the error recorded
 * at `end` is after exactly end - start seconds of coasting. The barometer
 * keeps working during outages unless told otherwise (the paper's setting).
 *
 * NEES (normalised estimation error squared, Bar-Shalom et al. 2001 §5.4):
 * e' P^-1 e with e the actual error block and P the filter's marginal
 * covariance of that block, for position (3 dof), velocity (3), attitude (3)
 * and all nine navigation errors (9).
 */
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navimpact/core/recording.hpp"
#include "navimpact/core/outage.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/filter/alignment.hpp"
#include "navimpact/filter/ekf.hpp"
#include "navimpact/ins/nav_state.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::analysis {


/// True states at the epochs where errors are recorded (time-ordered).
struct TruthSeries {
  std::vector<double> t;            ///< epochs [s], strictly increasing
  std::vector<ins::NavState> x;     ///< true navigation state at each epoch
};

/// Inputs of one run. Pointers are non-owning and must outlive the call.
struct NavRunInput {
  ins::NavState x0;                                        ///< initial estimate at x0.t
  const std::vector<ins::ImuSample>* imu = nullptr;        ///< raw samples (with errors), first covers (x0.t, x0.t + dt]
  /// May be null (no GNSS). Every fix used needs cov_pos_N; its velocity is
  /// applied (with use_gnss_velocity) when the fix has one, and then needs cov_vel_N.
  const std::vector<GnssFix>* gnss = nullptr;
  const std::vector<BaroSample>* baro = nullptr;  ///< may be null (no baro); every sample used needs sigma_m
  /// Record epochs and truth. May be null (data without ground truth): the
  /// run then records the estimate and sigmas every NavRunOptions::record_interval_s,
  /// with errors and NEES NaN.
  const TruthSeries* truth = nullptr;
};

/// Options of one run.
struct NavRunOptions {
  filter::EkfConfig ekf;                        ///< filter options (propagate_every, ...)
  filter::Matrix9d P0_nav = filter::Matrix9d::Identity();  ///< initial nav covariance [m, m/s, rad]^2
  std::vector<Outage> outages;                  ///< GNSS outages, absolute filter time [s]
  Eigen::Vector3d lever_arm_B = Eigen::Vector3d::Zero();   ///< GNSS antenna in body FRD [m]
  bool baro_in_outage = true;                   ///< keep baro updates during GNSS outages
  bool use_gnss_velocity = true;                ///< apply GNSS velocity besides position
  /// The point the truth / reference positions refer to, body FRD from the IMU [m]
  /// (e.g. a reference that is the GNSS antenna track): position errors are
  /// (estimate + C_BtoN_est l) - reference.
  Eigen::Vector3d reference_lever_B = Eigen::Vector3d::Zero();
  /// Record interval without truth [s], > 0: epochs at the IMU samples nearest
  /// x0.t + k * record_interval_s (ignored when NavRunInput::truth is given).
  double record_interval_s = 0.1;
  /// Ground-vehicle aids, off by default (Groves 2013 §15.3-15.4).
  /// Zero-velocity update at every IMU sample where the static detector
  /// (filter/alignment.hpp) says "at rest", at most every zupt_interval_s.
  bool zupt = false;
  filter::StaticDetectorOptions zupt_detector;  ///< at-rest sigmas of the IMU, window, false alarm
  double zupt_sigma_mps = 0.02;                 ///< pseudo-measurement 1-sigma per axis [m/s], > 0
  double zupt_interval_s = 0.1;                 ///< [s], > 0
  /// Non-holonomic constraint every nhc_interval_s while moving faster than
  /// nhc_min_speed_mps (no sideways or vertical velocity of the point nhc_point_B).
  bool nhc = false;
  double nhc_sigma_lateral_mps = 0.1, nhc_sigma_vertical_mps = 0.1;  ///< [m/s], > 0
  double nhc_interval_s = 0.1;                  ///< [s], > 0
  double nhc_min_speed_mps = 0.5;               ///< [m/s], >= 0
  Eigen::Vector3d nhc_point_B = Eigen::Vector3d::Zero();  ///< constrained point, body FRD from the IMU [m]
};

/// An update the chi-square gate rejected, or re-admitted after a run of
/// rejections with P scaled by `inflation` (filter::EkfConfig::gate_readmit_after).
struct RejectedUpdate {
  double t = 0.0;        ///< filter time [s]
  std::string kind;      ///< "gnss_position", "gnss_velocity", "baro", "zupt", "nhc"
  double nis = 0.0;      ///< its NIS
  double gate = 0.0;     ///< the gate's threshold
  double inflation = 1.0;  ///< re-admitted: the factor P was scaled by (NIS / gate); rejected: 1
};

/// One GNSS position update's innovation (NED), for innovation statistics.
struct GnssInnovation {
  double t = 0.0;                                   ///< fix time [s]
  Eigen::Vector3d dz = Eigen::Vector3d::Zero();     ///< innovation h(x_est) - z, N E D [m]
  Eigen::Vector3d S_diag = Eigen::Vector3d::Zero(); ///< diagonal of its covariance H P H' + R [m^2]
  Eigen::Vector3d R_diag = Eigen::Vector3d::Zero(); ///< diagonal of the fix's R [m^2]
  bool accepted = true;                             ///< passed the chi-square gate
};

/// Errors, sigmas and NEES at one record epoch.
struct NavEpoch {
  double t = 0.0;                   ///< [s]
  ins::NavState est;                ///< the filter's estimate at t (after the updates of t)
  /// estimate minus truth: dp NED [m], dv NED [m/s], psi [rad]; NaN without truth
  filter::Vector9d err = filter::Vector9d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// predicted 1-sigma of the same nine errors (NaN until set)
  filter::Vector9d sigma = filter::Vector9d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix3d P_pos = Eigen::Matrix3d::Zero();  ///< predicted position covariance N, E, D [m^2]
  std::array<double, 4> nees{};     ///< position (3 dof), velocity (3), attitude (3), all (9); NaN if P singular or no truth
};

/// What one outage did to this run.
struct OutageSummary {
  Outage window;                    ///< the outage, absolute filter time [s]
  int end_epoch = -1;               ///< index of the last recorded epoch in (start, end] (-1: none)
  NavEpoch end;                     ///< that epoch (kept also when the epochs are not)
  double max_drift_h = 0.0;         ///< max horizontal position error over the epochs in (start, end] [m]
  double max_drift_v = 0.0;         ///< max |vertical position error| over the same epochs [m]
  double max_drift_3d = 0.0;        ///< max 3-D position error over the same epochs [m]
  std::size_t gnss_dropped = 0;     ///< GNSS fixes the outage withheld (0: no fix fell inside it)
};

/// Result of one run.
struct NavRunResult {
  bool has_truth = true;            ///< false: errors, NEES and outage drifts are absent (NaN / 0)
  std::vector<NavEpoch> epochs;     ///< one per truth epoch inside the IMU span (or per record interval); empty when not kept
  /// Truth epochs inside the IMU span that are not scored because a positive
  /// time-offset estimate d puts their IMU epoch t + d past the last sample
  /// (at most d times the truth rate, at the end of the run).
  std::size_t epochs_past_imu_clock = 0;
  std::vector<OutageSummary> outages;  ///< one per NavRunOptions::outages
  int states = 0;                   ///< EKF state count
  std::size_t steps = 0;            ///< IMU samples processed
  std::size_t gnss_updates = 0;     ///< GNSS fixes applied
  std::size_t baro_updates = 0;     ///< baro samples applied
  int rejections = 0;               ///< updates rejected by the chi-square gate
  std::vector<RejectedUpdate> rejected;  ///< each of them
  std::vector<RejectedUpdate> readmitted;  ///< updates applied after a lock-out, P inflated first
  std::vector<GnssInnovation> gnss_innovations;  ///< every GNSS position update, in time order
  std::size_t zupt_updates = 0;     ///< zero-velocity updates applied
  std::size_t nhc_updates = 0;      ///< non-holonomic updates applied
  double wall_s = 0.0;              ///< wall-clock time of the run [s]
  /// Estimates and 1-sigma of the filter's extra states at the end of the run
  /// (filter::ErrorStateEkf::extraEstimates / extraSigmas; zero when off).
  filter::SensorParams extra_estimates, extra_sigmas;
};

/**
 * Run the filter over the inputs.
 * @param[in] in     data (see NavRunInput); the IMU samples must be contiguous.
 * @param[in] model  the IMU error model the FILTER uses (need not be the truth's).
 * @param[in] opt    options.
 * @throws navimpact::Error when inputs are missing, times are not increasing,
 *         a truth epoch does not fall on an IMU sample (to half an interval),
 *         or a GNSS fix or baro sample used lacks its covariance / sigma.
 */
NavRunResult runNav(const NavRunInput& in, const stochastic::ImuModel& model,
                    const NavRunOptions& opt);

/**
 * The navigation loop of runNav() fed one IMU sample at a time, for data that
 * are not held in memory (a long rawlog read record by record). runNav() is
 * this runner over vectors, so both give the same numbers.
 *
 * Contract: measurements of each kind are added in time order, and every GNSS
 * fix, barometer sample and truth epoch with t <= s.t + s.dt / 2 is added
 * before step(s) (before start() for those at x0.t + dt0 / 2); an outage is
 * added before any fix it covers is reached. Measurements are kept only until
 * the filter time reaches them, so memory is bounded by what the caller adds
 * ahead (plus the epochs when keep_epochs).
 */
class NavRunner {
 public:
  /// @param x0        initial estimate at x0.t.
  /// @param dt0       interval of the first IMU sample [s] (> 0).
  /// @param has_truth epochs at the truth epochs with errors (true), or every record_interval_s.
  /// @throws navimpact::Error as runNav() for bad options.
  NavRunner(const ins::NavState& x0, double dt0, bool has_truth, const stochastic::ImuModel& model,
            const NavRunOptions& opt);
  ~NavRunner();
  NavRunner(const NavRunner&) = delete;
  NavRunner& operator=(const NavRunner&) = delete;

  void addGnss(const GnssFix& f);
  void addBaro(const BaroSample& b);
  void addTruth(double t, const ins::NavState& x);
  /// A GNSS outage (absolute filter time), appended to NavRunResult::outages.
  void addOutage(const Outage& o);
  /// The measurements at x0.t and the first epoch; once, before step().
  /// @p first: the first IMU sample (its interval starts at x0.t), whose
  /// rates the measurements at x0.t use (ErrorStateEkf::primeRates).
  void start(const ins::ImuSample& first);
  /// One IMU sample (contiguous with the previous one).
  void step(const ins::ImuSample& s);
  /// A sample the IMU did not measure (in a gap, rates interpolated): step(s),
  /// plus white rate and force noise of PSDs @p psd_w, @p psd_f over its
  /// interval (ErrorStateEkf::addSensorNoise).
  void stepUnmeasured(const ins::ImuSample& s, double psd_w, double psd_f);
  /// The result; the runner is done.
  NavRunResult finish();

  /// Called with each recorded epoch and the truth state at it (nullptr without truth).
  std::function<void(const NavEpoch& e, const ins::NavState* truth)> on_epoch;
  /// Keep the epochs in NavRunResult::epochs (false: only on_epoch sees them).
  bool keep_epochs = true;
  /// The outages added so far (absolute filter time).
  const std::vector<Outage>& outages() const;
  /// Epochs recorded so far.
  std::size_t epochCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The data of one emulated run, owned; input() points a NavRunInput at them.
struct EmulatedRun {
  std::vector<ins::ImuSample> imu;           ///< perfect increments + IMU errors
  std::vector<GnssFix> gnss;                 ///< seeded GNSS fixes
  std::vector<BaroSample> baro;              ///< seeded barometer samples
  ins::NavState x0;                          ///< truth at t0 with the seeded initial error
  /// Inputs for runNav over this run against @p truth (which must outlive the call).
  NavRunInput input(const TruthSeries& truth) const;
};

/**
 * One emulated run in the paper's manner, shared by the Monte Carlo study and
 * the diagnosis' navigation gain: the IMU errors added to the perfect
 * increments (rate errors times dt), GNSS and barometer simulated along the
 * trajectory over [t0, t1] and an initial navigation error drawn per run.
 * Streams from @p run_seed: deriveSeed(run_seed, 1) GNSS noise, 2 baro noise,
 * 3 initial error (the IMU error streams are the caller's).
 * @param[in] perfect        perfect increments of the trajectory, first ending after t0.
 * @param[in] err            per axis (gyro_x..acc_z) rate errors [rad/s, m/s^2],
 *                           at least perfect.size() samples each.
 * @param[in] traj           the smoothed trajectory (truth).
 * @param[in] t0, t1         emulated span [s], t0 < t1.
 * @param[in] gnss, baro     sensor options (their seeds are replaced).
 * @param[in] truth0         true navigation state at t0.
 * @param[in] initial_sigma  1-sigma initial error [m, m/s, rad] per nav state.
 * @param[in] run_seed       the run's seed.
 */
EmulatedRun emulateRun(const std::vector<ins::ImuSample>& perfect,
                       const std::array<std::vector<double>, 6>& err,
                       const emulation::SmoothTrajectory& traj, double t0, double t1,
                       emulation::GnssOptions gnss, emulation::BaroOptions baro,
                       const ins::NavState& truth0, const filter::Vector9d& initial_sigma,
                       std::uint64_t run_seed);

/**
 * NEES of the four blocks for an error @p err and covariance @p P9 (the 9x9
 * navigation block): e' P^-1 e by Cholesky; NaN when a block is not positive
 * definite.
 */
std::array<double, 4> navNees(const filter::Vector9d& err, const filter::Matrix9d& P9);

}  // namespace navimpact::analysis
