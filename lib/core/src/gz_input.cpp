#include "navimpact/core/gz_input.hpp"

#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string_view>

#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact {

namespace {
constexpr std::size_t kChunk = std::size_t(1) << 20;
}

struct GzInput::Z {
  z_stream s{};
  bool init = false;
  ~Z() {
    if (init) inflateEnd(&s);
  }
};

GzInput::GzInput(std::string path) : path_(std::move(path)), z_(std::make_unique<Z>()) {
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0) throw Error(path_ + ": " + (errno == ENOENT ? "file not found" : std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) throw Error(path_ + ": is a folder, not a file");
  noteInput(path_);  // an output replaced whole must not hold it (output.hpp)
  f_ = std::fopen(path_.c_str(), "rb");
  if (!f_) throw Error(path_ + ": cannot open (" + std::strerror(errno) + ")");
  fileSize_ = S_ISREG(st.st_mode) ? static_cast<std::uint64_t>(st.st_size) : 0;
  // buffers of at most one chunk, no larger than a small file needs (+1 byte
  // so that a full read also tells the end of the file)
  const std::size_t first = fileSize_ > 0 && fileSize_ < kChunk ? static_cast<std::size_t>(fileSize_) + 1 : kChunk;
  in_.resize(first);
  inEnd_ = std::fread(in_.data(), 1, in_.size(), f_);
  inEof_ = inEnd_ < in_.size();
  gzip_ = inEnd_ >= 2 && in_[0] == 0x1f && in_[1] == 0x8b;
  statedSize_ = fileSize_;
  if (gzip_) {
    if (fileSize_ >= 18) {  // ISIZE: the last 4 bytes, little endian
      unsigned char t[4];
      if (::pread(fileno(f_), t, 4, static_cast<off_t>(fileSize_ - 4)) == 4) {
        const std::uint64_t isize = t[0] | (t[1] << 8) | (t[2] << 16) | (std::uint64_t(t[3]) << 24);
        // deflate expands at most 1032:1, so a larger claim is a lie of the file (RFC 1951)
        statedSize_ = std::max(std::min(isize, std::uint64_t(1032) * fileSize_), fileSize_);
      }
    }
    out_.resize(statedSize_ > 0 ? static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, statedSize_ + 1)) : kChunk);
    if (inflateInit2(&z_->s, 15 + 16) != Z_OK) throw Error(path_ + ": cannot start gzip decompression");
    z_->init = true;
  } else {  // the bytes read to sniff the format are the first data
    std::swap(in_, out_);  // (in_ is not used again)
    outEnd_ = inEnd_;
    inHead_ = inEnd_ = 0;
  }
}

GzInput::~GzInput() {
  if (f_) std::fclose(f_);
}

bool GzInput::fill() {
  outHead_ = outEnd_ = 0;
  if (done_) return false;
  if (!gzip_) {  // plain file: read straight into the output buffer
    if (inEof_) {
      done_ = true;
      return false;
    }
    const std::size_t got = std::fread(out_.data(), 1, out_.size(), f_);
    if (got == 0 && std::ferror(f_)) throw Error(path_ + ": read error (" + std::strerror(errno) + ")");
    inEof_ = got < out_.size();
    outEnd_ = got;
    if (got == 0) done_ = true;
    return got > 0;
  }
  auto z = &z_->s;
  while (outEnd_ == 0) {
    // Input for the next step: refill when consumed, keeping unconsumed bytes.
    if (inEnd_ - inHead_ < 2 && !inEof_) {
      const std::size_t keep = inEnd_ - inHead_;
      std::memmove(in_.data(), in_.data() + inHead_, keep);
      inOffset_ += inHead_;
      inHead_ = 0;
      const std::size_t got = std::fread(in_.data() + keep, 1, in_.size() - keep, f_);
      if (got == 0 && std::ferror(f_)) throw Error(path_ + ": read error (" + std::strerror(errno) + ")");
      inEnd_ = keep + got;
      inEof_ = got < in_.size() - keep;
    }
    const std::size_t avail = inEnd_ - inHead_;
    if (!memberOpen_) {
      if (avail == 0) {
        done_ = true;
        return false;
      }
      if (avail < 2 || in_[inHead_] != 0x1f || in_[inHead_ + 1] != 0x8b) {
        const std::uint64_t at = inOffset_ + inHead_;
        throw Error(path_ + ": " + std::to_string(fileSize_ > at ? fileSize_ - at : avail) +
                    " bytes of trailing garbage after the gzip data (from byte " + std::to_string(at) +
                    "; a gzip file must end with its last member)");
      }
      if (inflateReset(z) != Z_OK) throw Error(path_ + ": cannot restart gzip decompression");
      memberOpen_ = true;
    }
    if (avail == 0) {
      throw Error(path_ + ": truncated gzip data (the file ends inside the compressed stream, at byte " +
                  std::to_string(inOffset_ + inHead_) + ")");
    }
    z->next_in = in_.data() + inHead_;
    z->avail_in = static_cast<uInt>(avail);
    z->next_out = out_.data();
    z->avail_out = static_cast<uInt>(out_.size());
    const int r = inflate(z, Z_NO_FLUSH);
    inHead_ = static_cast<std::size_t>(z->next_in - in_.data());
    outEnd_ = out_.size() - z->avail_out;
    if (r == Z_STREAM_END) {
      memberOpen_ = false;  // CRC and length of the member verified by zlib
    } else if (r == Z_BUF_ERROR || (r == Z_OK && outEnd_ == 0 && inHead_ == inEnd_)) {
      if (inEof_ && inHead_ == inEnd_)
        throw Error(path_ + ": truncated gzip data (the file ends inside the compressed stream, at byte " +
                    std::to_string(inOffset_ + inHead_) + ")");
    } else if (r != Z_OK) {
      throw Error(path_ + ": corrupt gzip data near byte " + std::to_string(inOffset_ + inHead_) + " (zlib: " +
                  (z->msg ? z->msg : "error " + std::to_string(r)) + ")");
    }
  }
  return true;
}

std::size_t GzInput::read(void* out, std::size_t n) {
  auto* dst = static_cast<unsigned char*>(out);
  std::size_t done = 0;
  while (done < n) {
    if (outHead_ == outEnd_ && !fill()) break;
    const std::size_t k = std::min(n - done, outEnd_ - outHead_);
    std::memcpy(dst + done, out_.data() + outHead_, k);
    outHead_ += k;
    done += k;
  }
  pos_ += done;
  return done;
}

int GzInput::peek() {
  if (outHead_ == outEnd_ && !fill()) return -1;
  return out_[outHead_];
}

std::string packedFormat(std::string_view head) {
  struct Magic {
    std::string_view bytes;
    const char* what;
  };
  static constexpr Magic kMagic[] = {
      {std::string_view("\xFD" "7zXZ\0", 6), "xz-compressed (unxz -k FILE)"},
      {std::string_view("\x28\xB5\x2F\xFD", 4), "zstd-compressed (unzstd FILE)"},
      {std::string_view("PK\x03\x04", 4), "a zip archive (unzip FILE)"},
      {std::string_view("7z\xBC\xAF\x27\x1C", 6), "a 7-Zip archive (7z x FILE)"},
      {std::string_view("\x04\x22\x4D\x18", 4), "lz4-compressed (unlz4 FILE)"},
      {std::string_view("\x1F\x8B", 2), "gzip-compressed twice (gunzip it once)"},  // only met inside gzip
  };
  for (const Magic& m : kMagic)
    if (head.size() >= m.bytes.size() && head.compare(0, m.bytes.size(), m.bytes) == 0) return m.what;
  // bzip2: "BZh", the block size 1-9, then a block's magic (pi) or the end of an empty stream (sqrt(pi))
  if (head.size() >= 10 && head.compare(0, 3, "BZh") == 0 && head[3] >= '1' && head[3] <= '9' &&
      (head.compare(4, 6, std::string_view("1AY&SY", 6)) == 0 ||
       head.compare(4, 6, std::string_view("\x17\x72\x45\x38\x50\x90", 6)) == 0))
    return "bzip2-compressed (bunzip2 -k FILE)";
  return {};
}

std::string packedError(const std::string& packed) {
  const auto open = packed.find(" (");
  return "the file is " + packed.substr(0, open) + ": navimpact reads plain text or gzip; unpack it first" +
         packed.substr(open);
}

LineReader::LineReader(const std::string& path, std::size_t max_line) : in_(path), maxLine_(max_line) {
  const std::uint64_t n = in_.statedSize();  // 0: not known (not a regular file)
  buf_.resize(n > 0 ? static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, n + 1)) : kChunk);
}

bool LineReader::next(std::string_view& line) {
  line_.clear();
  bool any = false;
  for (;;) {
    if (head_ == end_) {
      end_ = in_.read(buf_.data(), buf_.size());
      head_ = 0;
      if (end_ == 0) {
        if (!any) return false;
        line = line_;
        break;
      }
    }
    any = true;
    const char* b = buf_.data() + head_;
    const auto* nl = static_cast<const char*>(std::memchr(b, '\n', end_ - head_));
    const std::size_t seg = nl ? static_cast<std::size_t>(nl - b) : end_ - head_;
    if (line_.size() + seg > maxLine_)
      throw fileError(in_.path(), lineNo_ + 1,
                      "line longer than " + std::to_string(maxLine_) + " bytes (not a table of samples)");
    if (nl && line_.empty()) {  // the whole line is in the buffer: no copy
      line = std::string_view(b, seg);
      head_ += seg + 1;
      break;
    }
    line_.append(b, seg);
    head_ += seg + (nl ? 1 : 0);
    if (nl) {
      line = line_;
      break;
    }
  }
  ++lineNo_;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (first_) {
    first_ = false;
    if (line.size() >= 3 && static_cast<unsigned char>(line[0]) == 0xEF &&
        static_cast<unsigned char>(line[1]) == 0xBB && static_cast<unsigned char>(line[2]) == 0xBF)
      line.remove_prefix(3);
    // text the lines cannot be read from: named rather than read as one odd line
    if (const std::string packed = packedFormat(line); !packed.empty())
      throw fileError(in_.path(), 1, packedError(packed));
    if (line.find('\0') != std::string_view::npos ||
        (line.size() >= 2 && ((line[0] == '\xFF' && line[1] == '\xFE') || (line[0] == '\xFE' && line[1] == '\xFF'))))
      throw fileError(in_.path(), 1,
                      "zero bytes or a UTF-16 byte-order mark in the first line: no UTF-8 text (UTF-16 or UTF-32 "
                      "text: save it as UTF-8)");
    if (line.find('\r') != std::string_view::npos)
      throw fileError(in_.path(), 1,
                      "line breaks are carriage returns alone (old Mac text): save it with LF or CR LF line breaks");
  }
  return true;
}

}  // namespace navimpact
