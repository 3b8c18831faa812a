// One reader of rawlog entries for every rawlog reader of navimpact (internal to lib/rawlog).
#pragma once

#include <mrpt/io/CStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>

#include <memory>
#include <optional>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/core/gz_input.hpp"

namespace navimpact::rawlog::detail {

/// While it lives, file descriptor 2 (stderr) goes to /dev/null: MRPT prints
/// warnings of its own while it deserialises some classes (e.g. a 3D range
/// scan's "autofixing incorrect camera resolution"), and library code prints
/// nothing. Used only around entries of classes navimpact does not read.
class StderrSilence {
 public:
  StderrSilence();
  ~StderrSilence();
  StderrSilence(const StderrSilence&) = delete;
  StderrSilence& operator=(const StderrSilence&) = delete;

 private:
  int saved_ = -1;
};

/// navimpact::GzInput as an MRPT input stream; its errors are kept, not thrown
/// through MRPT (which would wrap them in its own multi-line text).
class GzCStream : public mrpt::io::CStream {
 public:
  explicit GzCStream(GzInput& in) : in_(in) {}
  size_t Read(void* out, size_t n) override;
  size_t Write(const void*, size_t) override;
  uint64_t Seek(int64_t, mrpt::io::CStream::TSeekOrigin) override;
  uint64_t getTotalBytesCount() const override { return in_.statedSize(); }
  uint64_t getPosition() const override { return in_.position(); }
  std::optional<Error> error;
  /// Set while an object of a class navimpact does not read is decoded (see
  /// StderrSilence); EntryReader::next ends it with the entry.
  std::optional<StderrSilence> quiet;

 private:
  GzInput& in_;
  /// Length of the class name MRPT reads next, or 0. Its object header is one
  /// byte 0x80 | L, then the L bytes of the name in one read; or, in MRPT's
  /// old format, one byte L < 0x80, three zero bytes, then the name.
  std::size_t name_len_ = 0;
  std::size_t old_len_ = 0;  ///< an old-format L waiting for its three zero bytes, or 0
  /// The last class name looked up and what it is (entries repeat a few classes).
  std::string last_name_;
  bool last_registered_ = false, last_abstract_ = false, last_read_ = false;
};

/**
 * Reads the objects of a rawlog (plain or gzip) one entry at a time with the
 * checks every reader needs: corrupt, truncated or garbage-trailed gzip data,
 * a length field asking for more than the file can hold (every single
 * allocation while decoding an entry is capped at max(64 MiB, the file's
 * stated decompressed size)), and MRPT's errors as one-line causes. Every
 * error names the file and the entry.
 */
class EntryReader {
 public:
  explicit EntryReader(const std::string& path);
  /// The next object, or nullptr at the clean end of the file.
  mrpt::serialization::CSerializable::Ptr next();
  /// 0-based index of the entry last returned.
  std::size_t entry() const { return entry_; }
  const std::string& path() const { return in_.path(); }
  /// Cap of a single allocation while an entry is decoded [bytes].
  std::size_t allocationCap() const;

 private:
  [[noreturn]] void fail(const std::string& what) const;
  GzInput in_;
  GzCStream stream_;
  mrpt::serialization::CArchiveStreamBase<GzCStream> arch_;
  std::size_t entry_ = static_cast<std::size_t>(-1);
};

}  // namespace navimpact::rawlog::detail
