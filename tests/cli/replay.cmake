# navimpact replay: the default job on the committed rawlog (60 s outage after
# 200 s), an outage beyond the data, and a file that is not a rawlog.
set(_rdir ${CMAKE_CURRENT_BINARY_DIR}/replay_cli)
file(MAKE_DIRECTORY ${_rdir})

add_test(NAME cli_replay_default
  COMMAND ${NI} replay --config ${CMAKE_SOURCE_DIR}/config/replay/default.yaml --out ${_rdir}/default --overwrite)
set_tests_properties(cli_replay_default PROPERTIES PASS_REGULAR_EXPRESSION
  "52000 IMU steps at 200 Hz, 201 GNSS and 2601 baro updates.*outage 1 \\(60 s from 200 s\\): horizontal error at end")
file(WRITE ${_rdir}/check_outputs.cmake [=[
foreach(f solution.csv summary.json errors_full.png errors_outage_1.png)
  if(NOT EXISTS ${DIR}/${f})
    message(FATAL_ERROR "${DIR}/${f} missing")
  endif()
endforeach()
file(READ ${DIR}/summary.json js)
string(JSON n LENGTH "${js}" outages)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "summary.json: expected 1 outage, got ${n}")
endif()
string(JSON hs GET "${js}" outages 0 position horizontal_sigma_end_m)
string(JSON he GET "${js}" outages 0 position horizontal_error_end_m)
if(NOT hs GREATER 0.5 OR NOT he GREATER 0)
  message(FATAL_ERROR "summary.json: implausible outage drift (error ${he} m, sigma ${hs} m)")
endif()
file(STRINGS ${DIR}/solution.csv rows)
list(LENGTH rows nrows)
if(NOT nrows EQUAL 2602)  # header + 2601 GT epochs (10 Hz over 260 s)
  message(FATAL_ERROR "solution.csv: expected 2602 lines, got ${nrows}")
endif()
]=])
add_test(NAME cli_replay_default_outputs
  COMMAND ${CMAKE_COMMAND} -DDIR=${_rdir}/default -P ${_rdir}/check_outputs.cmake)
set_tests_properties(cli_replay_default_outputs PROPERTIES DEPENDS cli_replay_default)

file(WRITE ${_rdir}/expect_fail_nodir.cmake [=[
string(REPLACE "|" ";" _args "${ARGS}")
file(REMOVE_RECURSE ${OUTDIR})
execute_process(COMMAND ${NI} ${_args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0; output: ${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${REGEX}")
  message(FATAL_ERROR "output does not match '${REGEX}': ${out}${err}")
endif()
if(EXISTS ${OUTDIR})
  message(FATAL_ERROR "${OUTDIR} was created although the command failed")
endif()
]=])
add_test(NAME cli_replay_outage_outside_data
  COMMAND ${CMAKE_COMMAND} -DNI=${NI}
          "-DARGS=replay|--rawlog|${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog|--outage|230:60|--out|${_rdir}/late"
          -DOUTDIR=${_rdir}/late "-DREGEX=outage 230:60 ends at 290 s, after the data" -P ${_rdir}/expect_fail_nodir.cmake)
add_test(NAME cli_replay_bad_outage_text
  COMMAND ${CMAKE_COMMAND} -DNI=${NI}
          "-DARGS=replay|--rawlog|${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog|--outage|200-60|--out|${_rdir}/badtext"
          -DOUTDIR=${_rdir}/badtext "-DREGEX=expected START:DURATION" -P ${_rdir}/expect_fail_nodir.cmake)
add_test(NAME cli_replay_not_a_rawlog
  COMMAND ${CMAKE_COMMAND} -DNI=${NI}
          "-DARGS=replay|--rawlog|${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz|--out|${_rdir}/notraw"
          -DOUTDIR=${_rdir}/notraw "-DREGEX=uav_flight_260s.csv.gz: entry 0" -P ${_rdir}/expect_fail_nodir.cmake)
