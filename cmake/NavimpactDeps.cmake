# Third-party dependencies, all from Debian bookworm (see scripts/deps.sh).
# Every external library is turned into one imported target here, once, so
# that module CMakeLists link narrowly by target name.

find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(Ceres 2 REQUIRED)
find_package(Boost 1.74 REQUIRED)   # header-only parts: boost::math distributions
find_package(CLI11 QUIET CONFIG)
if(NOT TARGET CLI11::CLI11)
  # Debian's libcli11-dev ships the headers only on some versions.
  add_library(CLI11::CLI11 INTERFACE IMPORTED)
endif()

# MRPT 2.5.8 modules: one package per module.
find_package(mrpt-obs REQUIRED)
find_package(mrpt-io REQUIRED)
find_package(mrpt-poses REQUIRED)
find_package(mrpt-random REQUIRED)
find_package(mrpt-system REQUIRED)

# OpenCV 4.6: only the modules the plot library needs (freetype from contrib).
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs freetype)

# GeographicLib ships only a Find module on Debian (no CMake package config):
# wrap its variables once as an imported target.
set(_gl_find_dirs /usr/share/cmake/geographiclib /usr/lib/cmake/GeographicLib
    /usr/local/share/cmake/GeographicLib)
foreach(_d ${_gl_find_dirs})
  if(EXISTS ${_d}/FindGeographicLib.cmake)
    list(APPEND CMAKE_MODULE_PATH ${_d})
  endif()
endforeach()
find_package(GeographicLib REQUIRED)
if(NOT TARGET GeographicLib::GeographicLib)
  add_library(GeographicLib::GeographicLib UNKNOWN IMPORTED)
  set_target_properties(GeographicLib::GeographicLib PROPERTIES
    IMPORTED_LOCATION "${GeographicLib_LIBRARIES}"
    INTERFACE_INCLUDE_DIRECTORIES "${GeographicLib_INCLUDE_DIRS}")
endif()

if(NAVIMPACT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(NAVIMPACT_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
