/**
 * @file gz_input.hpp
 * @brief Streaming input of plain or gzip files with strict checks, and a
 *        line reader with a line-length cap on top of it.
 *
 * GzInput reads a file as a byte stream; a gzip file (magic 1f 8b, any name)
 * is decompressed member by member with its CRC and length checked. Corrupt
 * data, a file that ends inside a gzip member, and bytes after the last member
 * that are not another member ("trailing garbage") are errors naming the file
 * and the byte offset. Memory is one 1 MiB buffer whatever the file size.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace navimpact {

class GzInput {
 public:
  /// @throws Error naming @p path when it does not exist or cannot be opened.
  explicit GzInput(std::string path);
  ~GzInput();
  GzInput(const GzInput&) = delete;
  GzInput& operator=(const GzInput&) = delete;

  /// Up to @p n bytes into @p out; 0 only at the clean end of the data.
  /// @throws Error on corrupt or truncated gzip data and trailing garbage.
  std::size_t read(void* out, std::size_t n);
  /// Look at the next byte without consuming it; -1 at the end.
  int peek();
  /// True when no byte is left (reads ahead if needed).
  bool atEnd() { return peek() < 0; }

  const std::string& path() const { return path_; }
  bool compressed() const { return gzip_; }
  /// Size of the file on disk [bytes].
  std::uint64_t fileSize() const { return fileSize_; }
  /// Decompressed bytes the file says it holds: its size when plain; for gzip
  /// the length recorded in the last member's trailer (exact for one member
  /// below 4 GiB, the usual case), at least the compressed size.
  std::uint64_t statedSize() const { return statedSize_; }
  /// Decompressed bytes consumed so far.
  std::uint64_t position() const { return pos_; }

 private:
  bool fill();  // refill out_ (decompressing); false at the clean end
  std::size_t readRaw(unsigned char* dst, std::size_t n);

  std::string path_;
  std::FILE* f_ = nullptr;
  bool gzip_ = false;
  std::uint64_t fileSize_ = 0, statedSize_ = 0, pos_ = 0, inOffset_ = 0;
  struct Z;
  std::unique_ptr<Z> z_;
  std::vector<unsigned char> in_, out_;
  std::size_t inHead_ = 0, inEnd_ = 0, outHead_ = 0, outEnd_ = 0;
  bool inEof_ = false, done_ = false, memberOpen_ = false;
};

/**
 * Lines of a plain or gzip text file, streamed, each at most @p max_line bytes:
 * a longer line is an error naming the file and line (so a one-line 300 MB
 * file costs at most max_line bytes, not the file). A UTF-8 byte-order mark at
 * the start is skipped; "\r\n" line ends are accepted. A first line with zero
 * bytes or a UTF-16 byte-order mark (UTF-16/32 text, or binary) or with a
 * carriage return inside (old Mac line breaks: the whole file one line) is an
 * error at line 1.
 */
class LineReader {
 public:
  static constexpr std::size_t kDefaultMaxLine = std::size_t(1) << 20;  // 1 MiB
  explicit LineReader(const std::string& path, std::size_t max_line = kDefaultMaxLine);
  /// Next line without its end; false at the end of the file.
  bool next(std::string_view& line);
  /// 1-based number of the line last returned.
  std::size_t lineNo() const { return lineNo_; }
  const std::string& path() const { return in_.path(); }
  GzInput& input() { return in_; }

 private:
  GzInput in_;
  std::size_t maxLine_;
  std::string line_;
  std::vector<char> buf_;
  std::size_t head_ = 0, end_ = 0;
  std::size_t lineNo_ = 0;
  bool first_ = true;
};

/// The compression or archive format (not gzip, which is read directly) whose
/// magic number starts @p head, with the command that unpacks it:
/// "bzip2-compressed (bunzip2 -k FILE)"; "" for anything else.
std::string packedFormat(std::string_view head);
/// "the file is bzip2-compressed: navimpact reads plain text or gzip; unpack it
/// first (bunzip2 -k FILE)" for a packedFormat() text.
std::string packedError(const std::string& packed);

}  // namespace navimpact
