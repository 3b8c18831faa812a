// What the benchmarks share: where the committed and the shared data are
// (NAVIMPACT_SOURCE_DIR and NAVIMPACT_SHARED_DIR, set by bench/CMakeLists.txt).
#pragma once

#include <string>

namespace navimpact::bench {

/// A file of the source tree (datasets/, config/).
inline std::string sourcePath(const std::string& relative) { return std::string(NAVIMPACT_SOURCE_DIR) + "/" + relative; }

/// A file of the shared data folder (real recordings, full trajectories); may be absent.
inline std::string sharedPath(const std::string& relative) { return std::string(NAVIMPACT_SHARED_DIR) + "/" + relative; }

}  // namespace navimpact::bench
