// Helpers shared by all test suites.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace navimpact::test {

/// The shared data folder (../shared next to the checkout), or "" if absent.
std::string sharedDir();
/// Path inside the shared folder.
std::string sharedPath(const std::string& rel);
/// Path inside the source tree (committed small data, configs).
std::string sourcePath(const std::string& rel);
/// Fresh, empty temporary directory unique to the calling test.
std::filesystem::path tempDir();

}  // namespace navimpact::test

/// Skip the current test with a message when the shared reference data is absent.
#define NAVIMPACT_REQUIRE_SHARED()                                                        \
  do {                                                                                    \
    if (::navimpact::test::sharedDir().empty())                                           \
      GTEST_SKIP() << "shared reference data not found at " NAVIMPACT_SHARED_DIR          \
                      " (reference tests run only next to ../shared)";                    \
  } while (0)
