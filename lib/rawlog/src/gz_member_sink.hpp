// An MRPT output stream that writes gzip in independent members, compressed
// on worker threads (the pigz scheme): the serialised entries are cut into
// blocks of kBlock bytes, each block becomes one complete gzip member (RFC 1952
// allows any number of members; zlib's gzread, hence MRPT's CFileGZInputStream
// and rawlog-edit, and navimpact's GzInput read them as one stream). The file
// does not depend on the number of threads: block boundaries are fixed.
#pragma once

#include <mrpt/io/CStream.h>

#include <cstdio>
#include <deque>
#include <future>
#include <string>

namespace navimpact::rawlog::detail {

class GzMemberSink : public mrpt::io::CStream {
 public:
  static constexpr std::size_t kBlock = std::size_t(4) << 20;  ///< uncompressed bytes per member
  /// @param level zlib level 0 (stored) .. 9. @throws Error naming @p path.
  GzMemberSink(const std::string& path, int level);
  ~GzMemberSink() override;
  /// Compress what is left, write everything, close; @throws Error naming the file.
  void close();

  size_t Write(const void* buf, size_t n) override;
  size_t Read(void*, size_t) override;
  uint64_t Seek(int64_t, CStream::TSeekOrigin) override;
  uint64_t getTotalBytesCount() const override { return pos_; }
  uint64_t getPosition() const override { return pos_; }
  std::string getStreamDescription() const override { return path_; }
  /// The first write failure ("FILE: cannot write the rawlog (disk full?)"), or
  /// "". Write() never throws through MRPT's archive (which would wrap the
  /// message in its own multi-line text): it records the failure, drops what
  /// follows, and the writer checks failure() after each batch; close() throws it.
  const std::string& failure() const { return failure_; }

 private:
  void submit();       // hand the current block to a worker
  void writeFront();   // wait for the oldest member and write it
  std::string path_;
  std::string failure_;
  int level_;
  std::FILE* f_ = nullptr;
  std::string block_;
  std::deque<std::future<std::string>> pending_;
  std::size_t maxPending_ = 2;
  uint64_t pos_ = 0;
};

}  // namespace navimpact::rawlog::detail
