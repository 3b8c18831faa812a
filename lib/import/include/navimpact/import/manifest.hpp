/**
 * @file manifest.hpp
 * @brief Import a measured run described by a YAML manifest (README, "Import"):
 *        IMU, GNSS, barometer and reference streams in CSV (plain or gzip)
 *        become one navimpact::Recording in SI, body FRD, NED and ellipsoidal
 *        heights, on one time axis that keeps the files' times.
 *
 * Time axis: a stream's time is its column (times its unit) or start_s + k/rate_hz,
 * plus time_offset_s of the stream. With time_zero_unix_s (the UTC Unix time of
 * time 0 of the files) the recording's start_unix_s is the whole second at or
 * before the earliest record and every t counts from it; without it, t is the
 * files' time and start_unix_s = 0 (a rawlog then stamps t seconds after
 * 1970-01-01 UTC).
 */
#pragma once

#include <string>

#include "navimpact/core/recording.hpp"

namespace navimpact::import {

/// What the import found, beside the recording (for the console).
struct ImportReport {
  std::string imu_file, gnss_file, baro_file, reference_file;  ///< resolved paths ("" when absent)
  double imu_rate_hz = 0.0;                                     ///< nominal IMU rate [Hz]
  double imu_max_gap_s = 0.0;                                   ///< largest IMU time step [s]
  bool time_base_known = false;                                 ///< time_zero_unix_s given
};

/**
 * Read @p manifestPath and every stream it names (relative paths are taken
 * from the manifest's folder). The recording's metadata is YAML: the key
 * navimpact_scenario (origin, time base, IMU rate, what the reference has,
 * the GNSS lever arm) that rawlog readers use, and navimpact_import with the
 * manifest text.
 * @throws navimpact::Error naming the manifest and key (unknown or duplicate
 *         key, unknown unit, value out of range, axes that are not a proper
 *         signed permutation) or the stream file, line and key (missing
 *         column, NaN, a value that is not a number, time going backwards or
 *         repeated, a gap larger than max_gap_s).
 */
Recording importManifest(const std::string& manifestPath, ImportReport* report = nullptr);

}  // namespace navimpact::import
