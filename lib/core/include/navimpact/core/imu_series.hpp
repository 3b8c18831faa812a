/**
 * @file imu_series.hpp
 * @brief Uniformly sampled IMU channels in SI units, body axes
 *        forward-right-down (FRD).
 */
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "navimpact/core/units.hpp"

namespace navimpact {

/// Canonical channel names, in this order: gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z.
constexpr std::array<const char*, 6> kChannelNames = {"gyro_x", "gyro_y", "gyro_z",
                                                      "acc_x",  "acc_y",  "acc_z"};

/// Index 0..5 of a canonical channel name, or -1.
int channelIndex(const std::string& name);

/// Quantity measured by a canonical channel ("gyro_*" rate, "acc_*" specific force).
units::Quantity channelQuantity(const std::string& name);

/// Largest |sample| a reader accepts, SI: beyond any IMU, so that garbage
/// (1e300, a wrong unit by 10^6) is an error at the line or entry that holds
/// it instead of an overflow later. Angular rate 1,000 rad/s (57,000 deg/s);
/// specific force 1e5 m/s^2 (10,000 g).
constexpr double kMaxAbsAngularRate = 1.0e3;
constexpr double kMaxAbsSpecificForce = 1.0e5;
inline double maxAbsSample(units::Quantity q) {
  return q == units::Quantity::AngularRate ? kMaxAbsAngularRate : kMaxAbsSpecificForce;
}

/// One channel of samples, SI units (rad/s or m/s^2).
struct ImuChannel {
  std::string name;          ///< canonical name, e.g. "gyro_z"
  units::Quantity quantity;  ///< what it measures (fixes the SI unit)
  std::vector<double> x;     ///< samples, SI, sample k at t0_s + k / rate_hz
};

/// A uniformly sampled multi-channel recording.
struct ImuSeries {
  std::string source;            ///< where it came from (file path), for messages
  double rate_hz = 0.0;          ///< sampling rate [Hz], > 0
  double t0_s = 0.0;             ///< time of the first sample [s]
  /// CSV: the header name of the time column read ("" when the rate was given
  /// instead), recorded in the commands' "input" (t, time_s or time by default).
  std::string time_column;
  std::string time_unit;  ///< CSV: the unit of that column (s, ms, us, ns; "" with no time column)
  std::vector<ImuChannel> channels;

  std::size_t size() const { return channels.empty() ? 0 : channels.front().x.size(); }
  /// Channel by canonical name; throws navimpact::Error naming the source if absent.
  const ImuChannel& channel(const std::string& name) const;
  bool has(const std::string& name) const;
};

/**
 * Cut @p s to the time window [start_s, end_s) in seconds from its first
 * sample: sample k (at k / rate_hz from the start) is kept when
 * start_s <= k / rate_hz < end_s (to 1e-6 of a sample). t0_s moves to the
 * first kept sample. Without @p end_s the window runs to the end.
 * @throws navimpact::Error "SOURCE: --start ..." / "--end ..." naming the
 *         record's duration when start_s is negative, not finite or not
 *         before the end of the record, end_s is not after start_s or beyond
 *         the end of the record, or fewer than 2 samples remain.
 */
void cutWindow(ImuSeries& s, double start_s, std::optional<double> end_s);

}  // namespace navimpact
