// The readers of untrusted input, each as one call on a file (shared by the
// mutation CTest and by libFuzzer-style drivers).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace navimpact::fuzz {

struct Target {
  const char* name;       ///< e.g. "imu_csv"
  const char* extension;  ///< file name ending given to the input, e.g. ".csv"
  void (*read)(const std::string& path);
};

/// Every reader: IMU CSV, trajectory CSV, model text (structure and model
/// strings, which must round-trip), model file, covariance / replay /
/// emulation / study / sweep configurations, IMU rawlog and full rawlog
/// readers, the import manifest and the CSV column reader of its streams.
const std::vector<Target>& targets();

/**
 * Lay out @p dir as the source tree @p src is seen from a configuration:
 * dir/root/config/case (where an input is written), with root/config/models,
 * root/datasets and root/tests linked to @p src, so that relative paths in an
 * input resolve as they do from config/.
 * @return the folder inputs go to, dir/root/config/case.
 */
std::filesystem::path mirrorSourceLayout(const std::filesystem::path& dir, const std::filesystem::path& src);

/**
 * Run @p t on @p path under a 1 GiB single-allocation cap.
 * @return "" when the input was read, else the navimpact::Error message.
 * @throws std::runtime_error describing any other outcome (another exception
 *         type, a refused allocation, an error message of more than one line).
 */
std::string runOne(const Target& t, const std::string& path);

}  // namespace navimpact::fuzz
