#include "test_support.hpp"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>

namespace fs = std::filesystem;

namespace navimpact::test {

std::string sharedDir() {
  const fs::path p(NAVIMPACT_SHARED_DIR);
  std::error_code ec;
  if (fs::is_directory(p / "data", ec) && fs::is_directory(p / "reference", ec)) return p.string();
  return {};
}

std::string sharedPath(const std::string& rel) { return (fs::path(sharedDir()) / rel).string(); }

std::string sourcePath(const std::string& rel) { return (fs::path(NAVIMPACT_SOURCE_DIR) / rel).string(); }

std::string dataPath(const std::string& rel) { return (fs::path(NAVIMPACT_SOURCE_DIR) / "tests" / "data" / rel).string(); }

fs::path tempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "_" + info->name() : "test";
  for (auto& c : name)
    if (c == '/') c = '_';
  const fs::path p = fs::path(NAVIMPACT_BINARY_DIR) / "test_tmp" / (name + "_" + std::to_string(counter++));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string gzipBytes(const std::string& text, int level) {
  std::string out(compressBound(static_cast<uLong>(text.size())) + 64, '\0');
  z_stream s{};
  deflateInit2(&s, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  s.avail_in = static_cast<uInt>(text.size());
  s.next_out = reinterpret_cast<Bytef*>(out.data());
  s.avail_out = static_cast<uInt>(out.size());
  deflate(&s, Z_FINISH);
  out.resize(s.total_out);
  deflateEnd(&s);
  return out;
}

std::uint64_t envOr(const char* name, std::uint64_t dflt) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 10) : dflt;
}

namespace {
/// P(X <= k) for X ~ Binomial(n, p), summed exactly from log pmfs.
double binomialCdf(int k, int n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  if (p <= 0.0) return 1.0;
  if (p >= 1.0) return 0.0;
  double s = 0.0;
  for (int i = 0; i <= k; ++i)
    s += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) + i * std::log(p) +
                  (n - i) * std::log1p(-p));
  return std::min(1.0, s);
}
}  // namespace

bool plausiblyAtLeast(int k, int n, double p, double level) { return binomialCdf(k, n, p) > level; }

int plausibleMaxCount(int n, double p, double level) {
  int k = 0;
  while (k < n && 1.0 - binomialCdf(k, n, p) > level) ++k;  // P(X > k) > level: k + 1 still plausible
  return k;
}

}  // namespace navimpact::test
