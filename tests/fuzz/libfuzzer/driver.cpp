// libFuzzer driver for the readers of untrusted input (tests/fuzz/fuzz_targets.hpp).
// One executable; the target is chosen by the name it is called by
// (build-fuzz/bin/fuzz_<target>, links made by CMake) or by the environment
// variable NAVIMPACT_FUZZ_TARGET. Each input is written to a file in a private
// temporary folder that mirrors the source layout (root/config/case/input.EXT,
// with root/config/models, root/datasets and root/tests linked to the source tree), so that
// relative paths in configurations resolve as they do in config/, and read
// with fuzz::runOne: read, or refused with one navimpact::Error line. Anything
// else (another exception, an error message of more than one line, a single
// allocation above 1 GiB) aborts, which libFuzzer reports as a crash and keeps
// as an artifact. Built with -fsanitize=fuzzer,address,undefined (scripts/fuzz.sh).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "../fuzz_targets.hpp"

namespace fs = std::filesystem;

namespace {

const navimpact::fuzz::Target* g_target = nullptr;
std::string g_input;
fs::path g_dir;

void removeDir() {
  std::error_code ec;
  if (!g_dir.empty()) fs::remove_all(g_dir, ec);
}

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "navimpact fuzz: %s\n", what.c_str());
  std::exit(1);
}

const navimpact::fuzz::Target* findTarget(const std::string& name) {
  for (const auto& t : navimpact::fuzz::targets())
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  std::string name;
  if (const char* e = std::getenv("NAVIMPACT_FUZZ_TARGET"); e && *e) {
    name = e;
  } else {
    const std::string self = fs::path((*argv)[0]).filename().string();
    if (self.rfind("fuzz_", 0) == 0) name = self.substr(5);
  }
  g_target = findTarget(name);
  if (!g_target) {
    std::string known;
    for (const auto& t : navimpact::fuzz::targets()) known += std::string(known.empty() ? "" : ", ") + t.name;
    die("unknown target '" + name + "': call the driver as fuzz_<target> or set NAVIMPACT_FUZZ_TARGET (targets: " +
        known + ")");
  }
  // /dev/shm keeps the per-input file write off the disk where it exists.
  const char* tmp = std::getenv("TMPDIR");
  const fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::path(tmp && *tmp ? tmp : "/tmp");
  std::string templ = (base / "navimpact-fuzz-XXXXXX").string();
  if (!mkdtemp(templ.data())) die("cannot create a temporary folder under " + base.string());
  g_dir = templ;
  std::atexit(removeDir);
  const fs::path case_dir = navimpact::fuzz::mirrorSourceLayout(g_dir, NAVIMPACT_SOURCE_DIR);
  g_input = (case_dir / (std::string("input") + g_target->extension)).string();
  // scripts/fuzz.sh keeps this file when it has to kill a run that hangs
  // (libFuzzer writes no artifact then): it holds the input being read.
  std::fprintf(stderr, "navimpact fuzz: each input is written to %s\n", g_input.c_str());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(g_input.c_str(), "wb");
  if (!f) die("cannot write " + g_input);
  if (size && std::fwrite(data, 1, size, f) != size) die("cannot write " + g_input);
  std::fclose(f);
  try {
    (void)navimpact::fuzz::runOne(*g_target, g_input);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "navimpact fuzz %s: %s\n", g_target->name, e.what());
    std::abort();  // a finding: libFuzzer keeps the input as crash-<sha1>
  }
  return 0;
}
