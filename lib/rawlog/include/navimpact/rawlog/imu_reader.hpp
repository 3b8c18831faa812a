/**
 * @file imu_reader.hpp
 * @brief Read the IMU stream of an MRPT rawlog into a uniformly sampled ImuSeries.
 *
 * A rawlog (MRPT's dataset format, plain or gzip) is a sequence of serialized
 * objects, either observation-only (CObservation...) or alternating
 * CSensoryFrame / CActionCollection. This reader streams it object by object
 * (never loading the whole file) and keeps the CObservationIMU entries with a
 * given sensor label. MRPT's IMU fields are SI already (rad/s, m/s^2), in the
 * sensor's own axes.
 */
#pragma once

#include <string>

#include "navimpact/core/imu_series.hpp"

namespace navimpact::rawlog {

/**
 * Read the IMU observations labelled @p label from a rawlog.
 * @param[in] path   rawlog file (plain or gzip-compressed).
 * @param[in] label  CObservationIMU::sensorLabel to keep, e.g. "IMU".
 * @return series with channels gyro_x..acc_z (from IMU_WX..IMU_WZ and
 *         IMU_X_ACC..IMU_Z_ACC, SI), rate_hz = (n - 1) / (t_last - t_first),
 *         t0_s = first timestamp [s since the Unix epoch], source = @p path.
 * @throws navimpact::Error "PATH: ..." when the file cannot be opened, an entry
 *         is truncated or malformed ("entry K"), an IMU observation lacks one
 *         of the six fields, timestamps go backwards or leave a gap (entry and
 *         time named; steps must stay within 1 % of the median step), fewer
 *         than 2 observations carry the label, or none does ("no
 *         CObservationIMU with label 'X' (labels found: ...)").
 */
ImuSeries readImuRawlog(const std::string& path, const std::string& label = "IMU");

/**
 * True when @p path looks like a rawlog: extension ".rawlog" (optionally
 * followed by ".gz"), or content (after gzip decompression) starting with a
 * non-text byte, as serialized MRPT objects do.
 * @throws navimpact::Error when the file cannot be opened.
 */
bool isRawlogFile(const std::string& path);

}  // namespace navimpact::rawlog
