# Run with: cmake -DNI=<navimpact> "-DARGS=a|b|c" -DREGEX=<regex> [-DOUTDIR=<dir>] -P expect_fail.cmake
# Requires a non-zero exit, stderr matching REGEX, and (if given) no OUTDIR left
# behind. ARGS are '|'-separated (';' would be split by add_test).
# This file is also include()d by tests/cli/CMakeLists.txt's *.cmake glob at
# configure time: do nothing then.
if(NOT CMAKE_SCRIPT_MODE_FILE)
  return()
endif()
string(REPLACE "|" ";" _args "${ARGS}")
if(DEFINED OUTDIR)
  file(REMOVE_RECURSE "${OUTDIR}")
endif()
execute_process(COMMAND ${NI} ${_args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0\nstdout: ${out}\nstderr: ${err}")
endif()
if(NOT "${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "stderr does not match '${REGEX}'\nstderr: ${err}")
endif()
if(DEFINED OUTDIR AND EXISTS "${OUTDIR}")
  message(FATAL_ERROR "a failing command left ${OUTDIR} behind")
endif()
message(STATUS "ok (exit ${rc}): ${err}")
