#include "test_support.hpp"

#include <atomic>

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

}  // namespace navimpact::test
