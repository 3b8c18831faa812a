# Small helpers shared by the module, test and bench CMakeLists.

set(NAVIMPACT_WARNINGS -Wall -Wextra -Wpedantic -Wno-unused-parameter)

# navimpact_add_module(NAME core SOURCES ... PUBLIC_LINK ... PRIVATE_LINK ...)
# Defines static library navimpact_<NAME> and alias navimpact::<NAME>, with
# public headers under lib/<NAME>/include/navimpact/<NAME>/.
function(navimpact_add_module)
  cmake_parse_arguments(M "" "NAME" "SOURCES;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(navimpact_${M_NAME} STATIC ${M_SOURCES})
  add_library(navimpact::${M_NAME} ALIAS navimpact_${M_NAME})
  target_include_directories(navimpact_${M_NAME} PUBLIC
    ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_compile_options(navimpact_${M_NAME} PRIVATE ${NAVIMPACT_WARNINGS})
  target_link_libraries(navimpact_${M_NAME} PUBLIC ${M_PUBLIC_LINK}
                        PRIVATE ${M_PRIVATE_LINK})
endfunction()

# navimpact_add_gtest(NAME test_core SOURCES ... LINK ...)
# One GoogleTest executable, registered test by test with CTest.
function(navimpact_add_gtest)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;LINK;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LINK} GTest::gtest GTest::gtest_main
                        navimpact_testsupport)
  target_compile_options(${T_NAME} PRIVATE ${NAVIMPACT_WARNINGS})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  gtest_discover_tests(${T_NAME}
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR}
    PROPERTIES TIMEOUT ${T_TIMEOUT} LABELS "${T_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()
