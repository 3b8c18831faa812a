#include "gz_member_sink.hpp"

#include <zlib.h>

#include <algorithm>
#include <thread>

#include "navimpact/core/error.hpp"

namespace navimpact::rawlog::detail {

namespace {

// One complete gzip member (header, deflate data, CRC-32 and length trailer) of @p in.
std::string gzipMember(const std::string& in, int level) {
  z_stream z{};
  // windowBits 15 + 16: gzip wrapper; memLevel 8 and the default strategy, as gzopen
  if (deflateInit2(&z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("zlib: cannot start a gzip member");
  std::string out(deflateBound(&z, static_cast<uLong>(in.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  const std::size_t n = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw Error("zlib: gzip member not complete");
  out.resize(n);
  return out;
}

}  // namespace

GzMemberSink::GzMemberSink(const std::string& path, int level)
    : path_(path), level_(std::clamp(level, 0, 9)) {
  f_ = std::fopen(path.c_str(), "wb");
  if (!f_) throw Error(path + ": cannot open the rawlog for writing");
  block_.reserve(kBlock);
  maxPending_ = std::max(2u, std::thread::hardware_concurrency());
}

GzMemberSink::~GzMemberSink() {
  if (f_) std::fclose(f_);  // (pending std::async futures wait in their own destructors)
}

size_t GzMemberSink::Write(const void* buf, size_t n) {
  pos_ += n;
  if (!failure_.empty()) return n;  // the file is lost already: failure() tells the writer
  const char* p = static_cast<const char*>(buf);
  size_t left = n;
  try {
    while (left > 0) {
      const size_t take = std::min(left, kBlock - block_.size());
      block_.append(p, take);
      p += take;
      left -= take;
      if (block_.size() == kBlock) submit();
    }
  } catch (const std::exception& e) {
    failure_ = e.what();
    block_.clear();
  }
  return n;
}

size_t GzMemberSink::Read(void*, size_t) { throw Error(path_ + ": the rawlog is being written, not read"); }
uint64_t GzMemberSink::Seek(int64_t, CStream::TSeekOrigin) { throw Error(path_ + ": cannot seek a gzip stream being written"); }

void GzMemberSink::submit() {
  if (pending_.size() >= maxPending_) writeFront();
  pending_.push_back(std::async(std::launch::async, [b = std::move(block_), lvl = level_] { return gzipMember(b, lvl); }));
  block_ = std::string();
  block_.reserve(kBlock);
}

void GzMemberSink::writeFront() {
  const std::string m = pending_.front().get();
  pending_.pop_front();
  if (std::fwrite(m.data(), 1, m.size(), f_) != m.size()) throw Error(path_ + ": cannot write the rawlog (disk full?)");
}

void GzMemberSink::close() {
  if (!failure_.empty()) {
    pending_.clear();  // (their futures wait in their destructors)
    if (f_) std::fclose(f_);
    f_ = nullptr;
    throw Error(failure_);
  }
  if (!f_) return;
  if (!block_.empty() || (pos_ == 0 && pending_.empty())) submit();  // an empty stream is one empty member
  while (!pending_.empty()) writeFront();
  const bool ok = std::fflush(f_) == 0;
  const bool closed = std::fclose(f_) == 0;
  f_ = nullptr;
  if (!ok || !closed) throw Error(path_ + ": cannot write the rawlog (disk full?)");
}

}  // namespace navimpact::rawlog::detail
