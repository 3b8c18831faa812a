# All-or-nothing outputs: refusal of a non-empty --out, --overwrite replacing a
# folder whole, single-file outputs staged next to the file, failing commands
# leaving nothing (not even the parents they created), and --overwrite refusing
# the current folder. Scenarios in tests/cli/output/check.cmake.
foreach(_case refuse replace file fail cwd)
  add_test(NAME cli_output_${_case}
           COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DCASE=${_case} -DW=${CMAKE_CURRENT_BINARY_DIR}/output_${_case}
                   -DSRC=${CMAKE_SOURCE_DIR} -P ${CMAKE_CURRENT_SOURCE_DIR}/output/check.cmake)
endforeach()
