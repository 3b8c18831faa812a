// Mutation fuzzing of every reader of untrusted input. Seeds are real files
// (datasets/, config/, tests/data and a short emulated rawlog); each iteration
// applies 1-6 random mutations (bit flips, interesting bytes, insertions,
// deletions, duplicated ranges and lines, truncation, extreme numbers, splices
// of two seeds; rawlogs mutated inside the gzip stream and re-compressed, or
// in the compressed bytes). Every input must be read or refused with one
// navimpact::Error line, printing nothing: any other exception, output on
// stderr (from the readers or the libraries they call), a crash or a single allocation
// above 1 GiB fails the test, and the input is kept under
// build/test_tmp/fuzz_findings/ to become a regression (tests/fuzz/regressions/).
// Seed and iterations are logged; NAVIMPACT_FUZZ_SEED and NAVIMPACT_FUZZ_ITERS
// override them (scripts/fuzz_long.sh).
#include <gtest/gtest.h>
#include <zlib.h>

#include <cctype>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "fuzz_targets.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void spit(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

std::string gunzip(const std::string& path) { return readFileMaybeGz(path); }

std::string gzip(const std::string& text) { return test::gzipBytes(text, 1); }

std::string headLines(const std::string& text, int n) {
  std::size_t p = 0;
  for (int i = 0; i < n && p != std::string::npos; ++i) p = text.find('\n', p + 1);
  return p == std::string::npos ? text : text.substr(0, p + 1);
}

using test::envOr;

/// Seeds per target (decompressed bytes for rawlogs: the harness compresses).
std::map<std::string, std::vector<std::string>> seeds(const fs::path& dir) {
  std::map<std::string, std::vector<std::string>> s;
  auto src = [](const std::string& rel) { return test::sourcePath(rel); };
  s["imu_csv"] = {headLines(gunzip(src("datasets/adis16405_static_excerpt.csv.gz")), 150)};
  s["trajectory_csv"] = {headLines(gunzip(src("datasets/uav_flight_260s.csv.gz")), 150)};
  s["model_text"] = {"WN(sigma=9.788e-4) + GM(sigma=4.805e-5, T=59.22) + GM(sigma=2.209e-5, T=1.457)",
                     "WN(sigma=5.521e-3) + GM(sigma=4.811e-4, T=3.22) + DR(omega=9.302e-10)",
                     "QN(Q=1e-5) + RW(gamma=2e-7) + SIN(amp=1e-3, freq=12.5)",
                     "AR1(phi=0.999, sigma2=1e-6) + WN(sigma=1e-3)",
                     "WN+3GM+DR",
                     "none"};
  s["model_file"] = {slurp(src("config/models/navchip_table1.yaml")), slurp(src("config/models/adis16405_fitted.yaml"))};
  s["covariance_config"] = {slurp(src("config/paper/covariance_static.yaml"))};
  s["replay_config"] = {slurp(src("config/replay/default.yaml")),
                        slurp(src("config/replay/uav_flight_600s_ref_emulation.yaml"))};
  s["emulation_config"] = {slurp(src("config/emulation/uav_flight_260s_ref.yaml")),
                           slurp(src("config/emulation/lemniscate_600s.yaml"))};
  s["study_config"] = {slurp(src("config/paper/study_navchip_uav.yaml")),
                       slurp(src("config/paper/study_adis_measured.yaml"))};
  // A short emulated rawlog with every label (IMU, GNSS, BARO, GT, comment).
  emulation::EmulationConfig c;
  c.trajectory.file = src("datasets/uav_flight_260s.csv.gz");
  c.trajectory.end_s = 2.0;
  c.imu_rate_hz = 50.0;
  c.imu_errors = "model";
  c.model_spec = src("config/models/navchip_table1.yaml:ref");
  const auto emu = (dir / "seed_emulated.rawlog").string();
  rawlog::writeRawlog(emu, emulation::runEmulation(c, "fuzz"));
  const std::vector<std::string> rl = {gunzip(emu), gunzip(test::dataPath("imu_label_xsens.rawlog"))};
  s["imu_rawlog"] = rl;
  s["rawlog"] = rl;
  s["sweep_config"] = {slurp(src("config/sweep/navchip_uav_sweep.yaml")), slurp(src("tests/data/sweep_small.yaml"))};
  s["import_manifest"] = {slurp(src("tests/fuzz/import_run/manifest.yaml"))};
  s["import_csv"] = {headLines(gunzip(src("tests/fuzz/import_run/imu.csv.gz")), 150),
                     slurp(src("tests/fuzz/import_run/gnss.csv"))};
  return s;
}

const char* const kNumbers[] = {"1e308", "-1e308", "nan", "inf", "-0", "0", "1e-320", "4294967295", "-1",
                                "99999999999999999999", "1e7", "2000", "0.5", "1e12", "-2147483648"};

std::string mutate(std::string s, const std::vector<std::string>& pool, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n ? static_cast<std::size_t>(rng() % n) : 0; };
  const int ops = 1 + static_cast<int>(rng() % 6);
  for (int k = 0; k < ops; ++k) {
    switch (rng() % 10) {
      case 0:
        if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << (rng() % 8));
        break;
      case 1: {
        static const char bytes[] = {'\0', '\xff', '\x7f', '\x80', '\n', ',', ':', '[', '{', '-', '9', '.', 'e', '"'};
        if (!s.empty()) s[pick(s.size())] = bytes[pick(sizeof bytes)];
        break;
      }
      case 2: {
        std::string ins(1 + pick(16), ' ');
        for (auto& ch : ins) ch = static_cast<char>(rng());
        s.insert(pick(s.size() + 1), ins);
        break;
      }
      case 3:
        if (!s.empty()) {
          const std::size_t a = pick(s.size());
          s.erase(a, 1 + pick(std::min<std::size_t>(64, s.size() - a)));
        }
        break;
      case 4:
        if (!s.empty()) {
          const std::size_t a = pick(s.size()), n = 1 + pick(std::min<std::size_t>(256, s.size() - a));
          s.insert(pick(s.size() + 1), s.substr(a, n));
        }
        break;
      case 5:
        s.resize(pick(s.size() + 1));
        break;
      case 6: {  // an extreme number in place of a number
        std::size_t a = pick(s.size() + 1);
        while (a < s.size() && !std::isdigit(static_cast<unsigned char>(s[a]))) ++a;
        std::size_t b = a;
        while (b < s.size() && (std::isdigit(static_cast<unsigned char>(s[b])) || s[b] == '.' || s[b] == 'e' || s[b] == '-'))
          ++b;
        s.replace(a, b - a, kNumbers[pick(std::size(kNumbers))]);
        break;
      }
      case 7: {  // a line duplicated (duplicate keys, rows, entries)
        const std::size_t a = s.rfind('\n', pick(s.size() + 1));
        const std::size_t from = a == std::string::npos ? 0 : a + 1;
        const std::size_t e = s.find('\n', from);
        const std::string line = s.substr(from, e == std::string::npos ? std::string::npos : e - from + 1);
        s.insert(pick(s.size() + 1), line);
        break;
      }
      case 8: {  // splice with another seed
        const std::string& o = pool[pick(pool.size())];
        s = s.substr(0, pick(s.size() + 1)) + o.substr(pick(o.size() + 1));
        break;
      }
      default: {  // a 4-byte field set to an extreme length
        if (s.size() >= 4) {
          static const std::uint32_t v[] = {0xffffffffu, 0x7fffffffu, 0x80000000u, 0x10000000u, 0u};
          const std::uint32_t x = v[pick(std::size(v))];
          std::memcpy(&s[pick(s.size() - 3)], &x, 4);
        }
        break;
      }
    }
  }
  return s;
}

/// A fresh temporary folder mirroring the source layout (root/config/case for
/// the input, root/config/models, root/datasets and root/tests linked) so that relative
/// paths in configurations resolve as in config/.
fs::path mirror() {
  const fs::path dir = test::tempDir();
  fuzz::mirrorSourceLayout(dir, test::sourcePath(""));
  return dir;
}

struct Outcome {
  std::size_t read = 0, refused = 0;
};

void fuzzTarget(const std::string& name) {
  const fuzz::Target* t = nullptr;
  for (const auto& x : fuzz::targets())
    if (name == x.name) t = &x;
  ASSERT_NE(t, nullptr);
  const fs::path dir = mirror();
  const auto pool = seeds(dir).at(name);
  const std::uint64_t seed = envOr("NAVIMPACT_FUZZ_SEED", 20261124) + std::hash<std::string>{}(name) % 1000;
  const std::uint64_t iters = envOr("NAVIMPACT_FUZZ_ITERS", 400);
  std::printf("fuzz %s: seed %llu, %llu iterations, %zu seeds\n", name.c_str(), static_cast<unsigned long long>(seed),
              static_cast<unsigned long long>(iters), pool.size());
  std::mt19937_64 rng(seed);
  const bool rawlog = std::string(t->extension) == ".rawlog";
  const std::string input = (dir / "root/config/case" / (std::string("input") + t->extension)).string();
  const fs::path findings = fs::path(NAVIMPACT_BINARY_DIR) / "test_tmp/fuzz_findings";
  Outcome out;
  std::size_t failures = 0;
  for (std::uint64_t i = 0; i < iters; ++i) {
    std::string bytes = mutate(pool[rng() % pool.size()], pool, rng);
    if (rawlog) {
      const auto how = rng() % 4;
      if (how < 2) bytes = gzip(bytes);                                        // mutated inside the stream
      else if (how == 2) bytes = mutate(gzip(pool[rng() % pool.size()]), pool, rng);  // mutated compressed bytes
    } else if (rng() % 8 == 0) {
      bytes = gzip(bytes);  // text readers accept gzip too
    }
    spit(input, bytes);  // stays on disk if the reader crashes: the reproducer
    std::string failure;
    testing::internal::CaptureStderr();  // library code (and what it calls: MRPT, yaml-cpp) prints nothing
    try {
      const std::string m = fuzz::runOne(*t, input);
      ++(m.empty() ? out.read : out.refused);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    if (const std::string printed = testing::internal::GetCapturedStderr(); !printed.empty() && failure.empty())
      failure = "the reader printed to stderr: " + printed.substr(0, 300);
    if (!failure.empty()) {
      fs::create_directories(findings);
      const auto keep = findings / (name + "_" + std::to_string(seed) + "_" + std::to_string(i) + t->extension);
      spit(keep.string(), bytes);
      ADD_FAILURE() << name << " iteration " << i << " (seed " << seed << "): " << failure << "; input kept as "
                    << keep.string();
      if (++failures >= 5) break;
    }
  }
  std::printf("fuzz %s: %zu read, %zu refused with one error line, %zu failures\n", name.c_str(), out.read,
              out.refused, failures);
}

}  // namespace

TEST(FuzzReaders, ImuCsv) { fuzzTarget("imu_csv"); }
TEST(FuzzReaders, TrajectoryCsv) { fuzzTarget("trajectory_csv"); }
TEST(FuzzReaders, ModelText) { fuzzTarget("model_text"); }
TEST(FuzzReaders, ModelFile) { fuzzTarget("model_file"); }
TEST(FuzzReaders, CovarianceConfig) { fuzzTarget("covariance_config"); }
TEST(FuzzReaders, ReplayConfig) { fuzzTarget("replay_config"); }
TEST(FuzzReaders, EmulationConfig) { fuzzTarget("emulation_config"); }
TEST(FuzzReaders, StudyConfig) { fuzzTarget("study_config"); }
TEST(FuzzReaders, SweepConfig) { fuzzTarget("sweep_config"); }
TEST(FuzzReaders, ImuRawlog) { fuzzTarget("imu_rawlog"); }
TEST(FuzzReaders, Rawlog) { fuzzTarget("rawlog"); }
TEST(FuzzReaders, ImportManifest) { fuzzTarget("import_manifest"); }
TEST(FuzzReaders, ImportCsv) { fuzzTarget("import_csv"); }

// Every input a fuzzing run found (tests/fuzz/regressions/<target>/...) is read
// or refused with one error line.
TEST(FuzzReaders, Regressions) {
  const fs::path root = test::sourcePath("tests/fuzz/regressions");
  const fs::path dir = mirror();
  std::size_t n = 0;
  for (const auto& t : fuzz::targets()) {
    const fs::path d = root / t.name;
    if (!fs::is_directory(d)) continue;
    for (const auto& f : fs::directory_iterator(d)) {
      ++n;
      // read from the mirrored layout, as when it was found (relative paths resolve)
      const auto input = (dir / "root/config/case" / (std::string("input") + t.extension)).string();
      fs::copy_file(f.path(), input, fs::copy_options::overwrite_existing);
      testing::internal::CaptureStderr();
      std::string m, failure;
      try {
        m = fuzz::runOne(t, input);
      } catch (const std::exception& e) {
        failure = e.what();
      }
      const std::string printed = testing::internal::GetCapturedStderr();
      if (!failure.empty()) ADD_FAILURE() << f.path() << ": " << failure;
      else if (!printed.empty()) ADD_FAILURE() << f.path() << ": the reader printed to stderr: " << printed;
      else std::printf("%s: %s\n", f.path().filename().c_str(), m.empty() ? "read" : m.c_str());
    }
  }
  std::printf("%zu regression inputs\n", n);
}
