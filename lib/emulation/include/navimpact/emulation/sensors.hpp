/**
 * @file sensors.hpp
 * @brief Sensor outputs of an emulation: IMU errors (simulated from a model
 *        or taken from a measured static recording), GNSS fixes and barometer.
 *
 * IMU errors are per-axis sequences in SI rate units (rad/s, m/s^2) at the
 * IMU rate, added to the mean rates of each interval (increment / dt), i.e.
 * what an integrating IMU outputs. Axes in kChannelNames order
 * (gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z), body FRD.
 */
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/recording.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::emulation {

/// Six error sequences (kChannelNames order) and what was done to make them.
struct ImuErrors {
  std::array<std::vector<double>, 6> axis;  ///< SI rate units, one value per IMU sample
  std::vector<std::string> notices;         ///< human-readable notes (rate conversions, windows)
  std::string description;                  ///< one line: source and parameters
};

/**
 * Simulate IMU errors from a model: axis i uses stochastic::simulate with
 * stochastic::deriveSeed(seed, i). A model at another rate is converted
 * exactly to the IMU rate first (stochastic::convertRate) with a notice.
 * @param[in] model    per-axis composite models.
 * @param[in] imu_rate_hz  IMU rate [Hz], > 0.
 * @param[in] n        number of IMU samples.
 * @param[in] seed     master seed.
 */
ImuErrors modelImuErrors(const stochastic::ImuModel& model, double imu_rate_hz, std::size_t n,
                         std::uint64_t seed);

/// Where to take measured IMU errors from.
struct StaticRecordingSpec {
  std::string file;                 ///< CSV of a static recording (navimpact::readImuCsv format)
  CsvImuOptions csv;                ///< units, rate, axes of that file
  std::optional<double> offset_s;   ///< start of the window in the recording [s]; unset: from the seed
  std::uint64_t seed = 0;           ///< picks the window start uniformly when offset_s is unset

  /// Read file (relative to the configuration's folder, required), gyro_unit,
  /// acc_unit (units::acceptedUnits), rate_hz (IMU rate), axes and, when
  /// @p with_window, offset_s (a duration from the recording's start) and seed.
  void loadFrom(const ConfigNode& n, bool with_window);
};

/**
 * Measured IMU errors: a window of a static recording, mean of the window
 * removed per axis (removes gravity, Earth rate and the turn-on bias of that
 * window). The recording's rate must equal the IMU rate or be an exact
 * integer multiple of it; then blocks of m samples are averaged (what an
 * integrating IMU at the lower rate would output).
 * @throws navimpact::Error "static recording is at 100 Hz, emulation at 200 Hz"
 *         when the rates do not fit, or naming the needed and available
 *         durations when the recording is too short, or when the offset
 *         leaves too little.
 */
ImuErrors staticImuErrors(const StaticRecordingSpec& spec, double imu_rate_hz, std::size_t n);

/**
 * Same as above on a recording already loaded (e.g. once for many Monte Carlo
 * runs); @p spec.file is used only in messages, @p spec.csv is ignored.
 */
ImuErrors staticImuErrors(const ImuSeries& rec, const StaticRecordingSpec& spec, double imu_rate_hz,
                          std::size_t n);

/**
 * The IMU errors of modelImuErrors / staticImuErrors in consecutive blocks, for a
 * run too long to hold them (the blocks joined are those sequences bit for bit):
 * a model's axes are stochastic::ModelStream's; a static recording's window mean
 * is computed first (one pass), its block means then come block by block.
 */
class ImuErrorStream {
 public:
  /// As modelImuErrors (the model converted to the IMU rate, notice in notices()).
  static ImuErrorStream fromModel(const stochastic::ImuModel& model, double imu_rate_hz, std::size_t n,
                                  std::uint64_t seed);
  /// As staticImuErrors; keeps @p rec (shared) until the end. @throws as staticImuErrors.
  static ImuErrorStream fromStatic(std::shared_ptr<const ImuSeries> rec, const StaticRecordingSpec& spec,
                                   double imu_rate_hz, std::size_t n);
  /// No error (a perfect IMU).
  static ImuErrorStream none(std::size_t n);

  const std::vector<std::string>& notices() const { return notices_; }
  const std::string& description() const { return description_; }
  std::size_t size() const { return n_; }   ///< samples in all
  std::size_t done() const { return k_; }   ///< samples given so far

  /// The next @p count samples (at most size() - done()) of every axis, into out[a] (resized to count).
  void next(std::size_t count, std::array<std::vector<double>, 6>& out);

 private:
  ImuErrorStream() = default;
  std::size_t n_ = 0, k_ = 0;
  std::vector<std::string> notices_;
  std::string description_;
  int kind_ = 0;  // 0 none, 1 model, 2 static
  std::vector<std::optional<stochastic::ModelStream>> model_;  // per axis (empty: no error)
  std::shared_ptr<const ImuSeries> rec_;
  std::size_t start_ = 0, m_ = 1;
  std::array<bool, 6> has_{};
  std::array<double, 6> mean_{};
};

/// GNSS receiver options (defaults: Khaghani & Skaloud 2019 Table 2).
struct GnssOptions {
  double rate_hz = 1.0;             ///< fix rate [Hz]
  double sigma_pos_h_m = 2.0;       ///< horizontal position noise, each of N and E [m]
  double sigma_pos_v_m = 4.0;       ///< vertical position noise [m]
  double sigma_vel_h_mps = 0.05;    ///< horizontal velocity noise, each axis [m/s]
  double sigma_vel_v_mps = 0.10;    ///< vertical velocity noise [m/s]
  Eigen::Vector3d lever_arm_B = Eigen::Vector3d::Zero();  ///< antenna in body FRD from the IMU [m]
  std::uint64_t seed = 2;           ///< noise seed

  /// Read the keys of a `gnss:` map: rate_hz (aiding rate), sigma_pos_h_m,
  /// sigma_pos_v_m (position sigmas), sigma_vel_h_mps, sigma_vel_v_mps (velocity
  /// sigmas), lever_arm_B_m (each component a lever arm) and, when @p with_seed, seed.
  void loadFrom(const ConfigNode& n, bool with_seed = true);
};

/// Barometer options (defaults: Table 2).
struct BaroOptions {
  double rate_hz = 10.0;   ///< [Hz]
  double sigma_m = 0.5;    ///< height noise [m]
  std::uint64_t seed = 3;  ///< noise seed

  /// Read rate_hz (aiding rate), sigma_m (altitude sigma) and, when @p with_seed,
  /// seed of a `baro:` map; keys in @p extra_keys are accepted and left to the caller.
  void loadFrom(const ConfigNode& n, bool with_seed = true, const std::vector<std::string>& extra_keys = {});
};

/**
 * The fixes of simulateGnss (or samples of simulateBaro) in consecutive blocks
 * (the blocks joined are its result bit for bit): next() gives the records of
 * time <= t_until that are not given yet.
 */
class GnssSimulator {
 public:
  GnssSimulator(const SmoothTrajectory& tr, const GnssOptions& opt, double t_start, double t_end);
  std::size_t size() const { return n_; }  ///< fixes in all
  /// Append the fixes of time <= @p t_until not given yet (all the rest for t_until = infinity) to @p out.
  void next(double t_until, std::vector<GnssFix>& out);

 private:
  const SmoothTrajectory& tr_;
  GnssOptions opt_;
  double t_start_;
  std::size_t n_ = 0, k_ = 0;
  stochastic::ModelStream z_;
};

/// The samples of simulateBaro in blocks (as GnssSimulator).
class BaroSimulator {
 public:
  BaroSimulator(const SmoothTrajectory& tr, const BaroOptions& opt, double t_start, double t_end);
  std::size_t size() const { return n_; }  ///< samples in all
  /// Append the samples of time <= @p t_until not given yet to @p out.
  void next(double t_until, std::vector<BaroSample>& out);

 private:
  const SmoothTrajectory& tr_;
  BaroOptions opt_;
  double t_start_;
  std::size_t n_ = 0, k_ = 0;
  stochastic::ModelStream z_;
};

/**
 * GNSS fixes at t_start + k / rate_hz (k = 0, 1, ...) up to t_end, each with
 * its velocity and diagonal covariances (white noise of GnssOptions). The antenna
 * is at r_IMU + C_BtoN l_B, moving at v_N + C_BtoN (w_NB_B x l_B) (Groves 2013
 * eq. 14.121 without the small Earth-rate term of the lever arm).
 */
std::vector<GnssFix> simulateGnss(const SmoothTrajectory& tr, const GnssOptions& opt, double t_start,
                                  double t_end);

/// Barometer samples at t_start + k / rate_hz up to t_end, with their sigma.
std::vector<BaroSample> simulateBaro(const SmoothTrajectory& tr, const BaroOptions& opt, double t_start,
                                     double t_end);

/// n independent N(0,1) draws from a seed (stochastic white noise, reproducible).
std::vector<double> standardNormal(std::size_t n, std::uint64_t seed);

}  // namespace navimpact::emulation
