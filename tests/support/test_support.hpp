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
/// Path inside tests/data (committed reference data, see tests/data/README.md).
std::string dataPath(const std::string& rel);
/// Fresh, empty temporary directory unique to the calling test.
std::filesystem::path tempDir();

}  // namespace navimpact::test

/// Skip the current test, saying why, when the shared data (../shared next to
/// the checkout) is absent. Only full-record variants whose data is too large to
/// commit use it; @p what names the data they need.
#define NAVIMPACT_REQUIRE_SHARED(what)                                                    \
  do {                                                                                    \
    if (::navimpact::test::sharedDir().empty())                                           \
      GTEST_SKIP() << "needs " << (what) << " from the shared data folder "               \
                   << NAVIMPACT_SHARED_DIR                                                \
                   << ", absent here (too large to commit; the committed variants of "    \
                      "this check run from tests/data)";                                  \
  } while (0)
