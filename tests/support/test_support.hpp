// Helpers shared by all test suites.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "navimpact/core/error.hpp"

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

/// The message of the navimpact::Error that @p f throws, or "(no error)" when
/// it returns (any other exception passes through and fails the test).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const navimpact::Error& e) {
    return e.what();
  }
  return "(no error)";
}

/// @p text as one gzip member at zlib @p level (0 = stored .. 9).
std::string gzipBytes(const std::string& text, int level = 6);

/// The unsigned integer in the environment variable @p name, or @p dflt when
/// it is unset or empty (seeds and run counts a user may override).
std::uint64_t envOr(const char* name, std::uint64_t dflt);

// Monte Carlo rate claims, checked with exact one-sided binomial tests at
// @p level (a claim fails only where its draws are that unlikely under it;
// "rate >= 0.9" asserted on the point estimate fails half the time when the
// rate is exactly 0.9, and mean + 3 sd of a rare count is far from 3 sigma:
// P(X >= 2 | 24 draws, 1 %) = 2.4 %).
/// Whether @p k successes in @p n draws are plausible for a success rate of at least @p p.
bool plausiblyAtLeast(int k, int n, double p, double level = 1e-3);
/// The largest count of @p n draws still plausible for an event rate of at most @p p.
int plausibleMaxCount(int n, double p, double level = 1e-3);

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
