/**
 * @file reader.hpp
 * @brief A rawlog read one record at a time (bounded memory): the records of
 *        a rawlog in file order, the recording's header (origin, time base,
 *        metadata) before the first one. readRawlog() (writer.hpp) is this
 *        reader collecting every record into a Recording.
 *
 * Records come in time order (a rawlog whose timestamps go backwards is an
 * error at that entry), with the same checks, conversions and messages as
 * readRawlog(). A reference pose (GT) is returned once its velocity entry
 * (GT_VEL, same time) could still follow, i.e. when an entry with a later time
 * or another GT has been read, or at the end of the file; so every record with
 * a time <= t has been returned once a record with a time > t has.
 *
 * Memory: a rawlog navimpact wrote is read entry by entry (one 1 MiB buffer,
 * one decoded entry, one pending GT). A rawlog navimpact did not write is
 * read whole first (its IMU and GNSS labels and time zero are chosen over
 * the whole file: see readRawlog), then returned record by record.
 */
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "navimpact/core/recording.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace navimpact::rawlog {

/// One record of a rawlog.
struct RawlogRecord {
  enum class Kind : unsigned char { Imu, Gnss, Baro, Reference };
  Kind kind = Kind::Imu;
  double t = 0.0;               ///< its time on the recording's axis [s]
  ImuRecord imu;                ///< Kind::Imu
  GnssFix gnss;                 ///< Kind::Gnss
  BaroSample baro;              ///< Kind::Baro
  ReferenceRecord reference;    ///< Kind::Reference (velocity included when a GT_VEL entry gives it)
  RawlogRecord() {
    imu.w_IB_B.setZero();
    imu.f_B.setZero();
    reference.p_L.setZero();
  }
};

/// A rawlog read record by record (see the file comment).
class RawlogReader {
 public:
  /// Open @p path and read its first entry (the scenario comment of a rawlog navimpact wrote).
  /// @throws navimpact::Error as readRawlog().
  explicit RawlogReader(const std::string& path, const RawlogReadOptions& opt = {});
  ~RawlogReader();
  RawlogReader(const RawlogReader&) = delete;
  RawlogReader& operator=(const RawlogReader&) = delete;

  /// The recording without its streams: source, metadata, origin (from the
  /// scenario comment; else the first GNSS fix once it is read), time base,
  /// imu_rate_hz, lever_arm_B (the scenario's, else the first GNSS entry's
  /// sensorPose once read). Its notices are complete at the end of the file.
  const Recording& header() const;

  /// The next record in file order; false at the clean end of the file.
  /// @throws navimpact::Error "FILE: entry N (label L, t = ...): ..." as readRawlog().
  bool next(RawlogRecord& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/**
 * A rawlog read once into memory and read again record by record, in file
 * order, as often as needed (a run replayed many times, e.g. by
 * `diagnose --run`, is read and decoded once). The records are kept by kind
 * in a Recording (what readRawlog() returns) plus the order of their kinds,
 * so memory is that of readRawlog() and one byte per record.
 */
struct RawlogRecords {
  Recording data;                              ///< header as RawlogReader::header() at the end of the file, and every record
  std::vector<RawlogRecord::Kind> order;       ///< the kind of each record, in file order
};

/// Read every record of @p path. @throws navimpact::Error as RawlogReader.
RawlogRecords readRawlogRecords(const std::string& path, const RawlogReadOptions& opt = {});

/// The records of a RawlogRecords again, in file order (the same sequence
/// RawlogReader::next() returned). Holds a reference: @p r must outlive it.
class RawlogRecordCursor {
 public:
  explicit RawlogRecordCursor(const RawlogRecords& r) : r_(r) {}
  /// The next record; false after the last.
  bool next(RawlogRecord& out);

 private:
  const RawlogRecords& r_;
  std::size_t pos_ = 0, imu_ = 0, gnss_ = 0, baro_ = 0, ref_ = 0;
};

}  // namespace navimpact::rawlog
