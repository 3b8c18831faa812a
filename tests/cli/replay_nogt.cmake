# navimpact replay of a rawlog WITHOUT ground truth (like a real flight's):
# `emulate --no-gt` on 60 s of the committed UAV excerpt, then a replay with a
# 20 s outage. The filter starts from the first GNSS fix, levelling and the GNSS
# course; solution.csv holds the estimate and sigmas with empty error/NEES
# columns, summary.json says there is no ground truth and has no RMS.
set(_ngdir ${CMAKE_CURRENT_BINARY_DIR}/replay_nogt_cli)
file(MAKE_DIRECTORY ${_ngdir})
file(WRITE ${_ngdir}/uav60.yaml "
trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz, system: geodetic, end_s: 60}
imu: {rate_hz: 200, errors: model, model: ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref, seed: 11}
gnss: {seed: 12}
baro: {seed: 13}
ground_truth: {rate_hz: 10}
")
add_test(NAME cli_emulate_nogt
  COMMAND ${NI} emulate --config ${_ngdir}/uav60.yaml --no-gt --out ${_ngdir}/uav60_nogt.rawlog --overwrite)
set_tests_properties(cli_emulate_nogt PROPERTIES FIXTURES_SETUP nogt_rawlog
  PASS_REGULAR_EXPRESSION "IMU 12000 samples at 200 Hz, GNSS 61 fixes, BARO 601, GT 0")

add_test(NAME cli_replay_nogt
  COMMAND ${NI} replay --rawlog ${_ngdir}/uav60_nogt.rawlog --outage 30:20 --out ${_ngdir}/out --overwrite)
set_tests_properties(cli_replay_nogt PROPERTIES FIXTURES_REQUIRED nogt_rawlog FIXTURES_SETUP nogt_replay
  PASS_REGULAR_EXPRESSION "no ground truth in the rawlog.*12000 IMU steps at 200 Hz, 41 GNSS and 601 baro updates.*outage 1 \\(20 s from 30 s\\): predicted horizontal 1-sigma at end")

file(WRITE ${_ngdir}/check_nogt.cmake [=[
cmake_policy(SET CMP0007 NEW)  # keep the empty cells of a CSV row
foreach(f solution.csv summary.json errors_full.png errors_outage_1.png)
  if(NOT EXISTS ${DIR}/${f})
    message(FATAL_ERROR "${DIR}/${f} missing")
  endif()
endforeach()
file(READ ${DIR}/summary.json js)
string(JSON gt GET "${js}" ground_truth)
if(gt)
  message(FATAL_ERROR "summary.json: ground_truth should be false, got ${gt}")
endif()
string(JSON rms ERROR_VARIABLE rms_err GET "${js}" overall_rms)
if(NOT rms_err)
  message(FATAL_ERROR "summary.json: overall_rms must be absent without ground truth")
endif()
string(JSON hs GET "${js}" outages 0 position horizontal_sigma_end_m)
if(NOT hs GREATER 1.0)
  message(FATAL_ERROR "summary.json: predicted horizontal sigma after a 20 s outage only ${hs} m")
endif()
file(STRINGS ${DIR}/solution.csv rows)
list(LENGTH rows nrows)
if(NOT nrows EQUAL 602)  # header + 601 epochs (every 0.1 s over 60 s)
  message(FATAL_ERROR "solution.csv: expected 602 lines, got ${nrows}")
endif()
list(GET rows 300 row)
string(REPLACE "," ";" cells "${row}")
list(LENGTH cells ncells)
if(NOT ncells EQUAL 33)
  message(FATAL_ERROR "solution.csv: expected 33 cells in '${row}', got ${ncells}")
endif()
list(GET cells 19 err_pN)
list(GET cells 31 nees_all)
list(GET cells 1 lat)
if(NOT err_pN STREQUAL "" OR NOT nees_all STREQUAL "")
  message(FATAL_ERROR "solution.csv: error and NEES cells must be empty without ground truth: '${row}'")
endif()
if(lat LESS 46.0 OR lat GREATER 47.0)
  message(FATAL_ERROR "solution.csv: implausible latitude ${lat} deg in '${row}'")
endif()
]=])
add_test(NAME cli_replay_nogt_outputs
  COMMAND ${CMAKE_COMMAND} -DDIR=${_ngdir}/out -P ${_ngdir}/check_nogt.cmake)
set_tests_properties(cli_replay_nogt_outputs PROPERTIES FIXTURES_REQUIRED nogt_replay)
