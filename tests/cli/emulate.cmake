# navimpact emulate: a 30 s scenario from the committed UAV excerpt, rawlog-edit
# --info on its output (when MRPT's apps are installed), and bad input.
set(_edir ${CMAKE_CURRENT_BINARY_DIR}/emulate_cli)
file(MAKE_DIRECTORY ${_edir})
file(WRITE ${_edir}/uav30.yaml "
trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz, system: geodetic, end_s: 30}
imu: {rate_hz: 200, errors: model, model: ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref, seed: 5}
gnss: {seed: 6}
baro: {seed: 7}
ground_truth: {rate_hz: 10}
")
file(WRITE ${_edir}/bad_key.yaml "
trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz}
imu: {rate_hz: 200, errors: none, sede: 5}
")
file(WRITE ${_edir}/static_rate.yaml "
trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz, end_s: 30}
imu:
  rate_hz: 200
  errors: static
  static: {file: ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz, gyro_unit: deg/s, acc_unit: g, rate_hz: 100, offset_s: 10}
")

add_test(NAME cli_emulate_uav30
  COMMAND ${NI} emulate --config ${_edir}/uav30.yaml --out ${_edir}/uav30.rawlog --overwrite)
set_tests_properties(cli_emulate_uav30 PROPERTIES FIXTURES_SETUP emu_rawlog
  PASS_REGULAR_EXPRESSION "IMU 6000 samples at 200 Hz, GNSS 31 fixes, BARO 301, GT 301")

# rawlog-edit (package mrpt-apps) must see the labels at their rates.
file(WRITE ${_edir}/rawlog_edit_info.cmake [=[
find_program(RAWLOG_EDIT rawlog-edit)
if(NOT RAWLOG_EDIT)
  message("rawlog-edit not installed (apt-get install mrpt-apps): check skipped")
  return()
endif()
execute_process(COMMAND ${RAWLOG_EDIT} --info -i ${RAWLOG} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "rawlog-edit --info failed (${rc}): ${out}${err}")
endif()
foreach(re "All sensor labels *: *, BARO, GNSS, GT, IMU"
           "IMU / +6000 /200\\.000"
           "GNSS / +31 /1\\.000"
           "BARO / +301 /10\\.000"
           "GT / +301 /10\\.000"
           "Observations format *: Yes")
  if(NOT "${out}" MATCHES "${re}")
    message(FATAL_ERROR "rawlog-edit --info output does not match '${re}':\n${out}")
  endif()
endforeach()
message("rawlog-edit --info: labels and rates as expected")
]=])
add_test(NAME cli_emulate_rawlog_edit_info
  COMMAND ${CMAKE_COMMAND} -DRAWLOG=${_edir}/uav30.rawlog -P ${_edir}/rawlog_edit_info.cmake)
set_tests_properties(cli_emulate_rawlog_edit_info PROPERTIES FIXTURES_REQUIRED emu_rawlog)

# Bad input: one-line error, nothing written.
file(WRITE ${_edir}/expect_fail_nofile.cmake [=[
string(REPLACE "|" ";" _args "${ARGS}")
file(REMOVE ${OUTFILE})
execute_process(COMMAND ${NI} ${_args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0; output: ${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "output does not match '${REGEX}': ${out}${err}")
endif()
if(EXISTS ${OUTFILE})
  message(FATAL_ERROR "${OUTFILE} was written although the command failed")
endif()
]=])
add_test(NAME cli_emulate_bad_key
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=emulate|--config|${_edir}/bad_key.yaml|--out|${_edir}/bad.rawlog"
          -DOUTFILE=${_edir}/bad.rawlog "-DREGEX=bad_key.yaml.*imu.sede.*unknown key" -P ${_edir}/expect_fail_nofile.cmake)
add_test(NAME cli_emulate_static_rate_mismatch
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=emulate|--config|${_edir}/static_rate.yaml|--out|${_edir}/static.rawlog"
          -DOUTFILE=${_edir}/static.rawlog "-DREGEX=static recording is at 100 Hz, emulation at 200 Hz"
          -P ${_edir}/expect_fail_nofile.cmake)

# --gzip-level: the fast default and the smallest level both round-trip through
# the reader (replay of the level-9 file runs); an out-of-range level is refused.
add_test(NAME cli_emulate_gzip9
  COMMAND ${NI} emulate --config ${_edir}/uav30.yaml --out ${_edir}/uav30_l9.rawlog --gzip-level 9 --overwrite)
set_tests_properties(cli_emulate_gzip9 PROPERTIES FIXTURES_SETUP emu_rawlog_l9
  PASS_REGULAR_EXPRESSION "IMU 6000 samples at 200 Hz")
add_test(NAME cli_emulate_gzip9_replays
  COMMAND ${NI} replay --rawlog ${_edir}/uav30_l9.rawlog --outage 10:5 --out ${_edir}/replay_l9 --overwrite)
set_tests_properties(cli_emulate_gzip9_replays PROPERTIES FIXTURES_REQUIRED emu_rawlog_l9
  PASS_REGULAR_EXPRESSION "wrote .*solution.csv")
add_test(NAME cli_emulate_bad_gzip_level
  COMMAND ${NI} emulate --config ${_edir}/uav30.yaml --out ${_edir}/bad_level.rawlog --gzip-level 12)
set_tests_properties(cli_emulate_bad_gzip_level PROPERTIES WILL_FAIL TRUE)
