#include "navimpact/core/text_io.hpp"

#include <sys/stat.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <cstdio>
#include <memory>

#include "navimpact/core/error.hpp"
#include "navimpact/core/gz_input.hpp"

namespace navimpact {

std::string readFileMaybeGz(const std::string& path, std::size_t max_bytes) {
  GzInput in(path);  // plain or gzip, strict (corrupt, truncated, trailing garbage)
  std::string out;
  std::size_t chunk = std::size_t(1) << 16;
  for (;;) {
    const std::size_t old = out.size();
    if (old > max_bytes)
      throw Error(path + ": larger than " + std::to_string(max_bytes) + " bytes, more than this kind of file can be");
    out.resize(old + chunk);
    const std::size_t n = in.read(out.data() + old, chunk);
    out.resize(old + n);
    if (n == 0) break;
    if (chunk < (std::size_t(1) << 24)) chunk *= 2;
  }
  return out;
}

std::string unreadableReason(const std::string& path) {
  if (path.empty()) return std::strerror(ENOENT);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::strerror(errno);
  if (S_ISDIR(st.st_mode)) return std::strerror(EISDIR);
  if (!S_ISREG(st.st_mode)) return "not a regular file";
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return std::strerror(errno);
  std::fclose(f);
  return "";
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
  if (res.ptr != s.data() + s.size()) return false;
  if (res.ec == std::errc::result_out_of_range) {
    // from_chars refuses both ends; a value below the smallest double (1e-400)
    // is that close to 0 and is read as strtod rounds it, one beyond the
    // largest (1e400) stays no number (the program keeps the "C" locale)
    const double v = std::strtod(std::string(s).c_str(), nullptr);
    if (!(std::abs(v) < 1.0)) return false;
    out = v;
    return true;
  }
  return res.ec == std::errc();
}

}  // namespace navimpact
