/**
 * @file build_info.hpp
 * @brief Versions of navimpact and of the libraries it was built with, for
 *        recording in outputs (study.json, fit.json, ...) and `--version`.
 *
 * The library versions are those CMake found at configure time
 * (cmake/NavimpactBuildInfo.cmake); an empty version means CMake's package did
 * not report one.
 */
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace navimpact {

/// One component and its version, e.g. {"MRPT", "2.5.8"}.
using ComponentVersion = std::pair<std::string, std::string>;

/// navimpact's own version (CMake project version, e.g. "0.1.0").
const std::string& navimpactVersion();

/**
 * Versions of navimpact, the compiler, the build type and every third-party
 * library: navimpact, compiler, build_type, MRPT, Eigen, GeographicLib, Ceres,
 * OpenCV, Boost, yaml-cpp, nlohmann_json, in this order.
 */
const std::vector<ComponentVersion>& buildVersions();

}  // namespace navimpact
