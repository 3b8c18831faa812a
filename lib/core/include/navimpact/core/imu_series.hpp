/**
 * @file imu_series.hpp
 * @brief Uniformly sampled IMU channels in SI units, body axes
 *        forward-right-down (FRD).
 */
#pragma once

#include <array>
#include <cstddef>
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
  std::vector<ImuChannel> channels;

  std::size_t size() const { return channels.empty() ? 0 : channels.front().x.size(); }
  /// Channel by canonical name; throws navimpact::Error naming the source if absent.
  const ImuChannel& channel(const std::string& name) const;
  bool has(const std::string& name) const;
};

}  // namespace navimpact
