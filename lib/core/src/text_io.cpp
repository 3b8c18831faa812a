#include "navimpact/core/text_io.hpp"

#include <zlib.h>

#include <charconv>
#include <cstdio>
#include <memory>

#include "navimpact/core/error.hpp"

namespace navimpact {

std::string readFileMaybeGz(const std::string& path) {
  // gzopen reads plain files unchanged and gzip files decompressed.
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw Error(path + ": cannot open file");
  gzbuffer(f, 1 << 20);
  std::string out;
  std::size_t chunk = 1 << 22;
  for (;;) {
    const std::size_t old = out.size();
    out.resize(old + chunk);
    const int n = gzread(f, out.data() + old, static_cast<unsigned>(chunk));
    if (n < 0) {
      int err = 0;
      const char* msg = gzerror(f, &err);
      std::string m = msg ? msg : "read error";
      gzclose(f);
      throw Error(path + ": cannot read (" + m + ")");
    }
    out.resize(old + static_cast<std::size_t>(n));
    if (n == 0) break;
    if (chunk < (std::size_t(1) << 26)) chunk *= 2;
  }
  int err = 0;
  gzerror(f, &err);
  gzclose(f);
  if (err != Z_OK && err != Z_STREAM_END)
    throw Error(path + ": truncated or corrupt compressed file");
  return out;
}

std::vector<std::string_view> splitView(std::string_view s, char delim) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t p = s.find(delim, start);
    if (p == std::string_view::npos) {
      out.push_back(s.substr(start));
      break;
    }
    out.push_back(s.substr(start, p - start));
    start = p + 1;
  }
  return out;
}

std::string_view trim(std::string_view s) {
  const char* ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

bool parseDouble(std::string_view s, double& out) {
  s = trim(s);
  if (s.empty()) return false;
  if (s.front() == '+') s.remove_prefix(1);
  const auto res = std::from_chars(s.data(), s.data() + s.size(), out);
  return res.ec == std::errc() && res.ptr == s.data() + s.size();
}

}  // namespace navimpact
