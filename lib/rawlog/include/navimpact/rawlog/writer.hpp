/**
 * @file writer.hpp
 * @brief Write a navimpact::Recording as an MRPT rawlog (observation-only
 *        format: a sequence of serialized CObservation objects, gzip by
 *        default), and read any such rawlog back as a Recording.
 *
 * Entries, in time order (equal times: GT, IMU, BARO, GNSS):
 *  - first a CObservationComment (label "SCENARIO"): the recording's metadata
 *    (an emulation's scenario as YAML: frames, units, origin, time base,
 *    seeds, models, source files, version);
 *  - label "IMU": CObservationIMU, IMU_WX/WY/WZ [rad/s] and IMU_X_ACC/Y_ACC/Z_ACC
 *    [m/s^2], body FRD, means over the interval ending at the timestamp;
 *  - label "BARO": CObservationIMU with only IMU_ALTITUDE [m above the ellipsoid]
 *    (the sample's sigma is not stored: it belongs to the scenario);
 *  - label "GNSS": CObservationGPS with an NMEA GGA (lat/lon [deg], ellipsoidal
 *    height in altitude_meters, geoidal separation 0) and a TOPCON_PZS carrying
 *    ECEF position [m] and velocity [m/s] and their covariances (ECEF, upper-left
 *    3x3 of the 4x4 matrices; float precision). A fix without velocity has NaN
 *    in the PZS velocity fields; a fix without a covariance leaves hasPosCov /
 *    hasVelCov false;
 *  - label "GT": CObservationRobotPose, the reference in MRPT's conventions:
 *    pose.mean x/y/z = east/north/up [m] in the tangent plane at the comment's
 *    origin, its rotation the vehicle frame (x forward, y left, z up) in that
 *    ENU frame (= C_BtoN with the axes renamed); pose.cov diagonal: position
 *    variances (E, N, U) when the reference has sigmas, else 0; attitude
 *    variances (yaw, pitch, roll), 0 without sigmas, 1e12 rad^2 when the
 *    reference has no attitude (the pose's rotation is then the identity);
 *  - label "GT_VEL" (right after its GT entry, same time, when the reference has
 *    a velocity): CObservationIMU with IMU_X_VEL/Y_VEL/Z_VEL [m/s] local NED.
 *  - the GNSS entries carry the antenna lever arm (Recording::lever_arm_B) as
 *    their sensorPose (MRPT vehicle frame x forward, y left, z up).
 * Rawlogs written before stored GT as a CObservationIMU (IMU_X/Y/Z NED [m],
 * IMU_X_VEL.., IMU_ORI_QUAT_X..W of C_BtoN); readRawlog reads both.
 * Timestamps: start_unix_s + (t - t_start_s), in MRPT's 100 ns ticks, exact.
 */
#pragma once

#include <memory>
#include <string>

#include "navimpact/core/recording.hpp"

namespace navimpact::rawlog {

/// Options of writeRawlog().
struct RawlogWriteOptions {
  bool gzip = true;        ///< gzip-compress the file (MRPT reads both)
  int gzip_level = 6;      ///< 1 (fast) .. 9 (small)
};

/// Options of readRawlog() for rawlogs navimpact did not write.
struct RawlogReadOptions {
  std::string imu_label;   ///< label of the IMU entries; "": the only one present
  std::string gnss_label;  ///< label of the GNSS entries; "": the only one present
};

/**
 * Write @p data to @p path (overwritten).
 * @throws navimpact::Error naming the file when it cannot be written.
 */
void writeRawlog(const std::string& path, const Recording& data, const RawlogWriteOptions& opt = {});

/**
 * A rawlog written in blocks, for a run too long to hold (navimpact emulate):
 * the same file as writeRawlog() of all the blocks joined, with memory bounded
 * by one block. The constructor writes the comment (the header's metadata, time
 * base and lever arm; its records are ignored); append() merges a block's
 * records into the time order above and writes every entry that no later
 * record can precede; close() writes the rest.
 */
class RawlogWriter {
 public:
  /// @throws navimpact::Error naming @p path when it cannot be written.
  RawlogWriter(const std::string& path, const Recording& header, const RawlogWriteOptions& opt = {});
  ~RawlogWriter();  ///< without close(): the file is incomplete (stage it; OutputSet removes it)
  RawlogWriter(const RawlogWriter&) = delete;
  RawlogWriter& operator=(const RawlogWriter&) = delete;

  /**
   * Append @p block: each stream's records in time order and after that stream's
   * records of earlier blocks; every record of time <= @p complete_until_s (s, the
   * records' axis) has been given by now (later blocks hold only later times;
   * infinity: nothing follows).
   */
  void append(const Recording& block, double complete_until_s);

  /// Write what is pending and close the file. @throws navimpact::Error naming it.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/**
 * Read a rawlog. A rawlog navimpact wrote (its first entry is the comment
 * with navimpact_scenario, or an empty comment) is read with the labels above;
 * any other is read as MRPT's drivers record (see "foreign rawlogs" below).
 *
 * Foreign rawlogs (observations or sensory frames): IMU from the
 * CObservationIMU entries of @p opt.imu_label (default: the only label whose
 * entries have angular rates and accelerations) in the sensor's axes, turned
 * into body FRD by the rotation of their sensorPose (the mounting in MRPT's
 * vehicle frame x forward, y left, z up); GNSS from the CObservationGPS
 * entries of @p opt.gnss_label (default: the only one): TOPCON_PZS (ECEF
 * position, velocity, covariances; else its lat/lon/height), else Novatel
 * BESTPOS (height + undulation, lat/lon/height sigmas), else NMEA GGA
 * (altitude + geoidal separation; fix quality > 0); velocity from PZS, else
 * horizontal from NMEA RMC (status A) or VTG with assumed sigmas (kRmcSigmaH,
 * and kRmcSigmaV for the unknown vertical, said in the notices); the antenna
 * lever arm from the GNSS sensorPose. (MRPT 2.5 has no Novatel BESTVEL class.)
 * Time zero is the first chosen entry; the origin the first fix.
 * @throws navimpact::Error listing the labels when more than one could be
 *         meant, or naming the label that is not there.
 *
 * Reading a rawlog navimpact wrote: the labels above (any other entry is skipped, counted in
 * the notices). Times are seconds since the scenario's start (start_unix_s
 * from the comment, t_start_s = 0), or since the first IMU/GNSS/BARO/GT entry
 * when the comment has no time base (then start_unix_s and t_start_s keep
 * that entry's absolute time). GNSS fixes come from the PZS message when
 * present (ECEF position, velocity, covariances; each only when present),
 * else from GGA (position only). The reference (GT) has its velocity and
 * attitude when all their fields are set. source = @p path, metadata = the
 * first comment, origin from the comment (else the first GNSS fix).
 * @throws navimpact::Error "FILE: entry N (label L, t = ...): ..." for a
 *         malformed or truncated entry, timestamps going backwards, a GT entry
 *         without a scenario origin or with only some of its velocity or
 *         attitude fields.
 */
/// (This is rawlog::RawlogReader, reader.hpp, collecting every record; read a
/// long rawlog with that reader to keep memory bounded.)
Recording readRawlog(const std::string& path, const RawlogReadOptions& opt = {});

}  // namespace navimpact::rawlog
