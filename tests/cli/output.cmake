# All-or-nothing outputs: refusal of a non-empty --out, --overwrite replacing a
# folder whole, single-file outputs staged next to the file, failing commands
# leaving nothing (not even the parents they created), and --overwrite refusing
# the current folder. Scenarios: check_output in cli_helpers.cmake.
foreach(_case refuse replace file fail cwd)
  navimpact_cli_check(cli_output_${_case} CHECK output
    DEFINES CASE=${_case} W=${CMAKE_CURRENT_BINARY_DIR}/output_${_case} SRC=${CMAKE_SOURCE_DIR})
endforeach()
