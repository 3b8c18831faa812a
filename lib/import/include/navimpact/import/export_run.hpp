/**
 * @file export_run.hpp
 * @brief The inverse of importManifest(): a Recording as CSV streams and the
 *        manifest that imports them again (SI units, body FRD axes, NED
 *        velocities, ellipsoidal heights, degrees for angles, the recording's
 *        time axis and time zero).
 *
 * What a CSV column cannot hold is left out and said in the returned notes:
 * off-diagonal covariance terms (only the N, E, D sigmas are written), GNSS
 * sigmas when some fixes lack them, the metadata text (e.g. an emulation's IMU
 * model: give the replay its model).
 */
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "navimpact/core/recording.hpp"

namespace navimpact::import {

/**
 * Write imu.csv.gz, gnss.csv, baro.csv, reference.csv (the streams @p rec has)
 * and manifest.yaml into the existing folder @p dir.
 * @return notes on what was left out.
 * @throws navimpact::Error when a file cannot be written or @p rec has no IMU data.
 */
std::vector<std::string> exportRun(const Recording& rec, const std::filesystem::path& dir);

}  // namespace navimpact::import
