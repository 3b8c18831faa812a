/**
 * @file run_plan.hpp
 * @brief The plan of emulated navigation runs along a trajectory, built once:
 *        the smoothed trajectory (the truth), the IMU sample count, the GNSS
 *        outages checked against it, the perfect IMU, the record epochs with
 *        their true states, and the filter options every run shares.
 *
 * The Monte Carlo study (analysis/study.hpp), the sweep built on it, the
 * navigation gain of the diagnosis (analysis/diagnosis.hpp) and the simulated
 * realisations of a run diagnosis (analysis/run_diagnosis.hpp) plan their runs
 * here and nowhere else; each run then adds its own IMU errors (emulate()) and
 * goes through runNav() (nav_run.hpp).
 *
 * Times: the run starts at t0, the trajectory's first time (or start_s when
 * later); the IMU samples end at t0 + k / rate, k = 1..n,
 * n = floor((tEnd - t0) * rate); outages are given in run time (from t0) and
 * held in absolute filter time in nav.outages.
 * Record epochs are IMU sample indices k (t = t0 + k / rate): every
 * rate / record_rate_hz samples over the whole run, every
 * rate / outage_record_rate_hz samples inside each outage (a rate of 0: none),
 * and each outage end.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/core/outage.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/filter/ekf.hpp"
#include "navimpact/filter/error_model.hpp"

namespace navimpact::analysis {

/// What a run plan is made from.
struct RunPlanOptions {
  emulation::TrajectorySpec trajectory;   ///< reference trajectory (smoothed = truth)
  emulation::SmoothingOptions smoothing;
  /// The truth already smoothed (a run diagnosis: the reference or the filter
  /// solution of a replayed run); when set, trajectory and smoothing are not read.
  std::shared_ptr<const emulation::SmoothTrajectory> smoothed;
  std::optional<double> start_s;          ///< run start [s, trajectory time] when later than its first time
  double imu_rate_hz = 0.0;               ///< emulated IMU rate [Hz], > 0
  std::vector<Outage> outages;            ///< GNSS outages in run time (from the trajectory start) [s]
  std::string outage_name = "outage";     ///< how an outage is named in messages ("--outage" on the command line)
  std::vector<std::string> outage_names;  ///< where set, outage i is named outage_names[i] in place of "outage_name S:D"
  double record_rate_hz = 1.0;            ///< error epochs over the whole run [Hz]; 0 = none
  double outage_record_rate_hz = 5.0;     ///< error epochs inside outages [Hz]; 0 = their ends only
  emulation::GnssOptions gnss;            ///< GNSS of every run (its seed is replaced per run); lever arm for the filter
  emulation::BaroOptions baro;            ///< barometer of every run (its seed is replaced per run)
  bool use_baro = true;                   ///< feed the barometer to the filter
  bool baro_in_outage = true;             ///< keep barometer updates during GNSS outages
  filter::EkfConfig ekf;                  ///< filter options of every run
  /// Initial navigation error sigmas [m x3, m/s x3, rad x3]: drawn per run, P0 of the filter.
  filter::Vector9d initial_sigma = filter::Vector9d::Ones();
};

/// Runs planned once; read-only and shared by every run (and thread).
struct RunPlan {
  RunPlanOptions opt;
  std::shared_ptr<const emulation::SmoothTrajectory> traj;  ///< the truth
  double rate_hz = 0.0, t0 = 0.0, t1 = 0.0;         ///< IMU rate [Hz]; run span [s] (t1 = t0 + n / rate)
  std::vector<ins::ImuSample> perfect;              ///< n perfect increments over (t0, t1]
  TruthSeries truth;                                ///< record epochs and true states
  ins::NavState truth0;                             ///< true state at t0
  std::vector<std::size_t> outage_end_epoch;        ///< index into truth of each outage's end
  /// Filter options: opt.ekf, P0 = diag(initial_sigma^2), the outages in
  /// absolute time, the GNSS lever arm, baro_in_outage.
  NavRunOptions nav;

  std::size_t samples() const { return perfect.size(); }  ///< n
  double duration_s() const { return t1 - t0; }           ///< n / rate [s]
  /// One emulated run: @p err (per axis gyro_x..acc_z rate errors, n samples
  /// each) added to the perfect IMU, GNSS, barometer and initial error drawn
  /// from @p run_seed (emulateRun()).
  EmulatedRun emulate(const std::array<std::vector<double>, 6>& err, std::uint64_t run_seed) const;
  /// runNav() inputs of @p run against the planned truth (no barometer unless use_baro).
  NavRunInput input(const EmulatedRun& run) const;
  NavRunInput input(const EmulatedRun&& run) const = delete;  ///< the inputs point into @p run: keep it alive
};

/// Start of a run along @p tr [s]: its first time, or @p start_s when later.
double runStart(const emulation::SmoothTrajectory& tr, std::optional<double> start_s);

/// Whole IMU intervals of a run over [t0, t_end] at @p rate_hz: floor((t_end - t0) rate), 0 when t_end <= t0.
std::size_t imuSamples(double t0, double t_end, double rate_hz);

/**
 * Read and smooth the trajectory, count the IMU samples, check the outages
 * against the run (checkOutages, named opt.outage_name), compute the perfect
 * IMU, the record epochs and their truth, and the filter options.
 * @throws navimpact::Error for an unreadable trajectory, a rate <= 0, a start
 *         after the trajectory's end or an outage outside the run
 *         ("... after the end of the trajectory FILE (D s)").
 */
RunPlan planRuns(const RunPlanOptions& opt);

}  // namespace navimpact::analysis
