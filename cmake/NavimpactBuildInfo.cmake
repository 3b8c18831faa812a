# Versions of navimpact and of every third-party library as found at
# configure time, compiled into navimpact::core (core/build_info.hpp) so that
# outputs (study.json, `navimpact --version`) record what produced them.
# Must be included after NavimpactDeps.cmake (it reads the find_package results).
set(NAVIMPACT_BI_MRPT "${mrpt-obs_VERSION}")
set(NAVIMPACT_BI_EIGEN "${Eigen3_VERSION}")
set(NAVIMPACT_BI_CERES "${Ceres_VERSION}")
set(NAVIMPACT_BI_OPENCV "${OpenCV_VERSION}")
set(NAVIMPACT_BI_BOOST "${Boost_VERSION_STRING}")
set(NAVIMPACT_BI_YAMLCPP "${yaml-cpp_VERSION}")
set(NAVIMPACT_BI_JSON "${nlohmann_json_VERSION}")
set(NAVIMPACT_BI_COMPILER "${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER_VERSION}")
set(NAVIMPACT_BI_BUILD_TYPE "${CMAKE_BUILD_TYPE}")
configure_file(${CMAKE_SOURCE_DIR}/lib/core/src/build_info.cpp.in
               ${CMAKE_BINARY_DIR}/generated/build_info.cpp @ONLY)
