// The readers of untrusted input, each as one call on a file (shared by the
// mutation CTest and by libFuzzer-style drivers).
#pragma once

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
/// emulation / study configurations, IMU rawlog and full rawlog readers.
const std::vector<Target>& targets();

/**
 * Run @p t on @p path under a 1 GiB single-allocation cap.
 * @return "" when the input was read, else the navimpact::Error message.
 * @throws std::runtime_error describing any other outcome (another exception
 *         type, a refused allocation, an error message of more than one line).
 */
std::string runOne(const Target& t, const std::string& path);

}  // namespace navimpact::fuzz
