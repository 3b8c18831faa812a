/**
 * @file covariance_study.hpp
 * @brief Covariance analysis of navigation uncertainty for a set of IMU error
 *        models (the paper's Figures 5 and 6): static vehicle, no GNSS,
 *        near-perfect altitude, covariance-only propagation of the error-state
 *        EKF (lib/filter), one run per model.
 *
 * Configuration (YAML, every key with its unit in the name), e.g.
 * config/paper/covariance_static.yaml:
 * @code
 *   model_file: ../models/navchip_table1.yaml   # relative to this file
 *   duration_s: 60
 *   imu_rate_hz: 200
 *   output_rate_hz: 10
 *   summary_times_s: [1, 10, 30, 60]
 *   static_state: {lat_deg: 46.52, lon_deg: 6.57, h_m: 400, roll_deg: 0, pitch_deg: 0, yaw_deg: 0}
 *   initial_sigma: {position_m: 0, velocity_mps: 0, attitude_deg: 0}
 *   baro: {rate_hz: 10, sigma_m: 0.001}
 *   filter: {discretization: series, propagate_every: 1}
 *   model_sets:
 *     - {name: accelerometer, title: "...", models: [acc_model1, acc_model2, acc_model3, acc_ref]}
 *     - {name: gyroscope, title: "...", models: [gyro_model1, gyro_model2, gyro_model3, gyro_ref]}
 * @endcode
 */
#pragma once

#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "navimpact/core/config.hpp"
#include "navimpact/filter/ekf.hpp"
#include "navimpact/filter/model_entry.hpp"

namespace navimpact::analysis {

struct ModelSet {
  std::string name;                  ///< e.g. "accelerometer" (file names, CSV column)
  std::string title;                 ///< figure title
  std::vector<std::string> models;   ///< model names inside model_file
};

struct CovarianceStudyConfig {
  std::string source;                ///< configuration file path (for messages)
  std::string model_file;            ///< resolved path of the model file
  double duration_s = 60.0;          ///< horizon [s], > 0
  double imu_rate_hz = 200.0;        ///< propagation rate [Hz], > 0
  double output_rate_hz = 10.0;      ///< rate of the rows written [Hz], > 0, <= imu_rate_hz
  std::vector<double> summary_times_s = {1, 10, 30, 60};  ///< times reported in summary.json [s]
  ins::NavState nominal;             ///< static state (t = 0)
  double sigma0_position_m = 0.0;    ///< initial sigma of each position axis [m], >= 0
  double sigma0_velocity_mps = 0.0;  ///< initial sigma of each velocity axis [m/s], >= 0
  double sigma0_attitude_rad = 0.0;  ///< initial sigma of each attitude axis [rad], >= 0
  double baro_rate_hz = 10.0;        ///< altitude observation rate [Hz], >= 0 (0 = none)
  double baro_sigma_m = 1e-3;        ///< altitude observation sigma [m], > 0
  filter::EkfConfig filter;          ///< discretization, propagate_every
  std::vector<ModelSet> model_sets;
  std::string echo;                  ///< the configuration as JSON text (for summary.json)
  bool allow_large = false;          ///< run even above the work and memory budgets (--allow-large)

  /// Read the keys of a covariance configuration (see config/paper/covariance_static.yaml),
  /// with the ranges of core/limits.hpp; every model named is loaded once to check it.
  void loadFrom(const ConfigNode& root);
};

/// One model of the study as the filter takes it.
struct CovarianceModel {
  std::string model_set;     ///< ModelSet::name
  std::string model;         ///< its name in model_file
  filter::ModelEntry entry;  ///< layoutFor(model, filter, imu_rate_hz): the model at the rate, its layout, the notes
};

/// Every model of @p cfg, set by set, as the filter takes it (filter::layoutFor
/// with cfg.filter at cfg.imu_rate_hz, so the GMs the filter turns into white
/// noise at cfg.filter.propagate_every are listed as such): the one place the
/// study's models enter the filter, for its runs, its budget and --print-states.
std::vector<CovarianceModel> covarianceModels(const CovarianceStudyConfig& cfg);

/// Work and memory a covariance run needs (checked before it starts).
struct CovarianceBudget {
  double work = 0.0;          ///< floating-point operations, about: steps x (N^2 + 2 N^3 / propagate_every) per model
  double memory_bytes = 0.0;  ///< results held: output rows x 10 doubles per model [bytes]
};

/// Estimate of the work and memory of a run of @p n IMU steps.
CovarianceBudget estimateCovarianceBudget(const CovarianceStudyConfig& cfg, long n);

/// @throws navimpact::Error naming the configuration and key when the run of
///         @p n IMU steps is above limits::kDefaultWorkBudget or
///         limits::kDefaultMemoryBudgetBytes and allow_large is not set.
void checkBudget(const CovarianceStudyConfig& cfg, long n);

/**
 * Read and validate a study configuration.
 * @throws navimpact::Error naming the file and key: unknown keys (with the
 *         accepted ones, so a wrong unit suffix is caught), wrong types,
 *         non-positive durations/rates/sigmas, unknown models in the model file.
 */
CovarianceStudyConfig loadCovarianceStudyConfig(const std::string& path);

/// Sigma history of one model: columns pos N, E, D [m], vel N, E, D [m/s], roll, pitch, yaw [rad].
struct CovarianceRun {
  std::string model_set, model;
  std::string model_text;            ///< the models of the six axes, for the record
  int states = 0;                    ///< filter state dimension
  std::vector<std::string> notes;    ///< how the model entered the filter (filter::layoutFor)
  /// Repairs of the covariance by the eigenvalue floor (filter::PdCheck): how
  /// many, the most negative eigenvalue repaired (correlation scale) and the
  /// time of the first (NaN if none).
  int pd_repairs = 0;
  double pd_worst_eigenvalue = 0.0;
  double pd_first_repair_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> t;             ///< [s]
  std::vector<std::array<double, 9>> sigma;
  /// Where the attitude sigmas leave the small-error range of the filter's
  /// linearisation (kSmallErrorAttitudeSigmaRad): the first output time at
  /// which the roll, pitch or yaw sigma exceeds it (NaN: never), which one
  /// (column index 6, 7 or 8), and the largest attitude sigma of the run [rad].
  double small_error_exceeded_s = std::numeric_limits<double>::quiet_NaN();
  int small_error_column = -1;
  double max_attitude_sigma_rad = 0.0;
};

/// The filter's small-error range (filter/ekf.hpp).
using filter::kSmallErrorAttitudeSigmaRad;

/// Fill run.small_error_* and max_attitude_sigma_rad from run.t and run.sigma.
void assessSmallError(CovarianceRun& run);

struct CovarianceStudyResult {
  std::vector<CovarianceRun> runs;
};

/**
 * Roll, pitch, yaw sigmas from the covariance of psi (N, E, D small angles):
 * d(euler) = M^-1 psi with psi = M d(euler), M = [Rz Ry e_x, Rz e_y, e_z].
 * @param[in] P_psi  3x3 covariance of psi [rad^2].
 * @param[in] x      state (its attitude fixes M); |pitch| < 90 deg.
 */
Eigen::Vector3d eulerSigmas(const Eigen::Matrix3d& P_psi, const ins::NavState& x);

/**
 * Run the study: one covariance-only propagation per model (perfect other sensor).
 * @param[in] progress  optional callback(done, total) after each model.
 */
CovarianceStudyResult runCovarianceStudy(const CovarianceStudyConfig& cfg,
                                         const std::function<void(int, int)>& progress = {});

/**
 * Covariance-only propagation along a trajectory instead of the static state
 * (static_state of the configuration is ignored): the trajectory CSV (columns
 * time_s, lat_rad, lon_rad, alt_m, roll_rad, pitch_rad, yaw_rad, as read by
 * lib/emulation) is smoothed and its kinematics give the nominal state and the
 * perfect IMU rates at every IMU interval, over min(duration_s, trajectory length).
 * @throws navimpact::Error for an unreadable or too short trajectory.
 */
CovarianceStudyResult runCovarianceStudyAlongTrajectory(
    const CovarianceStudyConfig& cfg, const std::string& trajectory_csv,
    const std::function<void(int, int)>& progress = {});

}  // namespace navimpact::analysis
