/**
 * @file scenario.hpp
 * @brief An emulation scenario from a YAML configuration, and its run:
 *        trajectory -> smooth truth -> perfect IMU -> IMU errors -> GNSS,
 *        barometer and ground truth records (a navimpact::Recording).
 *
 * Configuration keys (units in the names or stated; relative paths are
 * resolved against the configuration file's folder):
 * @code
 * trajectory:
 *   file: ../../datasets/uav_flight_260s.csv.gz
 *   system: geodetic            # geodetic (lat, lon, h) | ned (tangent-plane NED metres)
 *   columns: {time: time_s, lat: lat_rad, lon: lon_rad, height: alt_m,
 *             north: x_N_m, east: x_E_m, down: x_D_m,
 *             roll: roll_rad, pitch: pitch_rad, yaw: yaw_rad}
 *   latlon_unit: rad            # rad | deg
 *   attitude_unit: rad          # rad | deg
 *   time_unit: s                # s | ms
 *   origin: {lat_deg: 46.5, lon_deg: 6.5, height_m: 400}   # required for ned
 *   max_gap_s: 0.25             # largest time step bridged [s]
 *   start_s: 0                  # optional window, file time [s]
 *   end_s: 260
 * smoothing: {position_cutoff_hz: 1.0, attitude_cutoff_hz: 1.0, knot_step_s: 0.05, penalty_order: 3}
 * imu:
 *   rate_hz: 200                # [Hz]
 *   errors: model               # model | static | none
 *   model: ../models/navchip_table1.yaml:ref
 *   seed: 1
 *   static: {file: ..., gyro_unit: deg/s, acc_unit: g, rate_hz: 100, axes: "x,y,z",
 *            offset_s: 100, seed: 7}
 * gnss: {rate_hz: 1, sigma_pos_h_m: 2, sigma_pos_v_m: 4, sigma_vel_h_mps: 0.05,
 *        sigma_vel_v_mps: 0.10, lever_arm_B_m: [0, 0, 0], seed: 2}
 * baro: {rate_hz: 10, sigma_m: 0.5, seed: 3}
 * effects:                     # sensor effects the model lacks (sensor_effects.hpp), each off by default, SI
 *   gyro_scale: [0.002, 0, 0]   # [ratio], each in [-0.05, 0.05]; acc_scale likewise
 *   gyro_misalignment_rad: [0, 0, 0.001]   # [rad], each in [-0.05, 0.05]; acc_misalignment_rad,
 *                               # gyro_nonorthogonality_rad, acc_nonorthogonality_rad likewise
 *   time_offset_s: 0.02         # t_IMU - t_true [s], in [-0.1, 0.1]
 *   gyro_motion_noise_factor: 3 # white noise x k while moving, [1, 100] (imu.errors: model); acc_ likewise
 *   motion_rate_threshold_rad_s: 0.05   # moving above [rad/s], [1e-3, 10]
 *   motion_acc_threshold_mps2: 0.3      # moving when ||f| - g| above [m/s^2], [0.05, 100]
 *   lever_arm_error_m: [0.3, 0, 0]      # told - true antenna, body FRD [m], each in [-10, 10]
 *   seed: 4                     # of the in-motion noise
 * ground_truth: {rate_hz: 10}   # [Hz]
 * output: {start_utc: "2026-01-01T00:00:00Z"}   # timestamp of the first trajectory time
 * @endcode
 */
#pragma once

#include <string>

#include "navimpact/core/recording.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/emulation/trajectory.hpp"

namespace navimpact::emulation {

/// A parsed emulation configuration (all paths absolute or relative to the CWD).
struct EmulationConfig {
  std::string config_file;          ///< where it came from ("" if built in code)
  TrajectorySpec trajectory;
  SmoothingOptions smoothing;
  double imu_rate_hz = 200.0;       ///< [Hz]
  std::string imu_errors = "model"; ///< "model", "static" or "none"
  std::string model_spec;           ///< FILE[:NAME] for "model"
  std::uint64_t imu_seed = 1;       ///< seed of the simulated IMU errors
  StaticRecordingSpec static_rec;   ///< for "static"
  GnssOptions gnss;                 ///< lever_arm_B: the antenna the rawlog states (told)
  BaroOptions baro;
  SensorEffects effects;            ///< effects the model lacks (all off by default)
  std::uint64_t effects_seed = 4;   ///< seed of the in-motion noise
  double truth_rate_hz = 10.0;      ///< ground-truth record rate [Hz]
  std::string start_utc = "2026-01-01T00:00:00Z";  ///< UTC of the first trajectory time
  bool allow_large = false;         ///< run above the budget of emulationBudget (--allow-large)
};

/// Budget of one emulation (navimpact emulate), in IMU samples: 10^8 (about
/// 6 days at 200 Hz or 2.8 h at 10 kHz; a rawlog of about 6.7 GB and about
/// 8 minutes of one core here). The IMU samples stream, so their memory does
/// not grow with the run; the budget bounds its time and disk use
/// (--allow-large lifts it). README "Ranges and budgets".
inline constexpr double kSampleBudget = 1.0e8;
/// Measured cost per IMU sample of an emulation (24 h at 200 Hz with GNSS 1 Hz,
/// baro and ground truth 10 Hz, gzip level 1: 1.149 GB, 86 s of CPU), and the
/// bytes held per sample when sensor effects make the run be held in memory
/// (perfect and shifted increments, errors, in-motion noise, records).
inline constexpr double kRawlogBytesPerSample = 67.0;
inline constexpr double kCpuSecondsPerSample = 5.0e-6;
inline constexpr double kEffectsBytesPerSample = 350.0;

/// Size of an emulated run, known before it runs (emulationBudget).
struct EmulationBudget {
  double duration_s = 0.0;      ///< span of the trajectory used [s]
  double imu_samples = 0.0;     ///< IMU samples (duration x imu.rate_hz)
  double rawlog_bytes = 0.0;    ///< expected rawlog size (gzip level 1) [bytes]
  double work_s = 0.0;          ///< expected CPU time on one core [s]
  double memory_bytes = 0.0;    ///< memory that grows with the run (0 when it streams) [bytes]
};

/**
 * The size of the run of @p cfg over a trajectory of @p duration_s seconds, and
 * a check against the documented budget (kSampleBudget IMU samples; with sensor
 * effects, which are applied to the whole run in memory, also
 * limits::kDefaultMemoryBudgetBytes).
 * @throws navimpact::Error (keyError naming imu.rate_hz) above the budget
 *         unless cfg.allow_large.
 */
EmulationBudget emulationBudget(const EmulationConfig& cfg, double duration_s);

/**
 * Receives an emulated run in time order (runEmulation with a sink): begin()
 * once with the recording's header (origin, time base, IMU rate, metadata,
 * notices, lever arm; no records), then append() with consecutive blocks: each
 * stream's records continue those of the earlier blocks, and every record of
 * time <= complete_until_s has been given (infinity with the last block).
 */
class RecordingSink {
 public:
  virtual ~RecordingSink() = default;
  virtual void begin(const Recording& header) = 0;
  virtual void append(const Recording& block, double complete_until_s) = 0;
};

/**
 * Read a configuration file.
 * @throws navimpact::Error naming the file and key for unknown keys, wrong
 *         types, missing required keys, invalid values.
 */
EmulationConfig loadEmulationConfig(const std::string& path);

/**
 * Run a scenario.
 * @param[in] cfg      configuration.
 * @param[in] version  navimpact version string, recorded in the scenario text.
 * @return the recording: IMU at imu_rate_hz, GNSS fixes with velocity and
 *         covariances, baro with sigma, the truth as its reference (position,
 *         velocity, attitude) at ground_truth.rate_hz, times on the
 *         trajectory's axis (t_start_s = first trajectory time), the scenario
 *         YAML as its metadata.
 * @throws navimpact::Error for any bad input (trajectory, model, recording).
 */
Recording runEmulation(const EmulationConfig& cfg, const std::string& version);

/**
 * Run a scenario block by block into @p sink (the records of runEmulation(cfg,
 * version), bit for bit): memory is bounded by a block (2^16 IMU samples) and
 * the trajectory, whatever the duration; a run with sensor effects is made
 * whole first (see emulationBudget). Checks emulationBudget before the run.
 */
void runEmulation(const EmulationConfig& cfg, const std::string& version, RecordingSink& sink);

}  // namespace navimpact::emulation
