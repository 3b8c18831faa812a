# navimpact study / study-merge: a short study writes every output; shards
# merged give the same metrics as one unsharded study; bad input is one clear
# error before any run, with no output folder left behind.
set(_sdir ${CMAKE_CURRENT_BINARY_DIR}/study)
file(MAKE_DIRECTORY ${_sdir})
set(_sm ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml)
set(_straj ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)

function(_study_cfg name outage_start outage_dur gyro_model)
  file(WRITE ${_sdir}/${name}.yaml "trajectory: {file: ${_straj}, end_s: 40}
imu: {rate_hz: 100}
truth: {errors: model, model: ${_sm}:ref}
candidates:
  - {label: Gyro 1, gyroscope: ${_sm}:${gyro_model}}
  - {label: Ref both, model: ${_sm}:ref}
outages: [{start_s: ${outage_start}, duration_s: ${outage_dur}}]
monte_carlo: {runs: 3, seed: 5}
")
endfunction()
_study_cfg(short 20 15 gyro_model1)
_study_cfg(outage_late 30 15 gyro_model1)
_study_cfg(bad_model 20 15 gyro_model9)

file(WRITE ${_sdir}/check_study.cmake [=[
file(REMOVE_RECURSE "${D}")
foreach(a full s1 s2 merged)
  file(REMOVE_RECURSE "${D}/${a}")
endforeach()
function(run)
  execute_process(COMMAND ${NI} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "navimpact ${ARGN}: exit ${rc}: ${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(study --config ${CONFIG} --out ${D}/full --threads 2)
if(NOT out MATCHES "report: .*/full/report.md")
  message(FATAL_ERROR "study did not print where the report is:\n${out}")
endif()
foreach(f study.json timeseries.csv report.md fig_all_errors_o1.png fig_all_nees_o1.png fig_all_outage_end.png)
  if(NOT EXISTS ${D}/full/${f})
    message(FATAL_ERROR "missing ${f}")
  endif()
endforeach()
run(study --config ${CONFIG} --out ${D}/s1 --shard 1/2 --threads 1)
run(study --config ${CONFIG} --out ${D}/s2 --shard 2/2 --threads 2)
run(study-merge ${D}/s2 ${D}/s1 --out ${D}/merged)
file(READ ${D}/full/study.json a)
file(READ ${D}/merged/study.json b)
foreach(key models sets anees_band_95)
  string(JSON ja GET "${a}" ${key})
  string(JSON jb GET "${b}" ${key})
  if(NOT ja STREQUAL jb)
    message(FATAL_ERROR "study.json '${key}' differs between the unsharded study and the merged shards")
  endif()
endforeach()
string(JSON runs GET "${b}" study runs)
if(NOT runs EQUAL 3)
  message(FATAL_ERROR "merged study has ${runs} runs, expected 3")
endif()
# The outputs record what produced them: seed and library versions.
string(JSON seed GET "${b}" study seed)
string(JSON mrpt GET "${b}" study versions MRPT)
string(JSON eigen GET "${b}" study versions Eigen)
string(JSON gl GET "${b}" study versions GeographicLib)
if(NOT seed EQUAL 5 OR NOT mrpt MATCHES "^[0-9]+\\.[0-9]+" OR NOT eigen MATCHES "^3\\." OR NOT gl MATCHES "^[0-9]+\\.")
  message(FATAL_ERROR "study.json lacks the seed or library versions: seed=${seed} MRPT=${mrpt} Eigen=${eigen} GeographicLib=${gl}")
endif()
]=])
add_test(NAME cli_study_short_and_shards
         COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DCONFIG=${_sdir}/short.yaml -DD=${_sdir}/out
                 -P ${_sdir}/check_study.cmake)

function(_study_bad name args regex)
  add_test(NAME cli_study_bad_${name}
           COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=${args}" "-DREGEX=${regex}"
                   -DOUTDIR=${_sdir}/out_${name} -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_fail.cmake)
endfunction()
_study_bad(outage_outside "study|--config|${_sdir}/outage_late.yaml|--out|${_sdir}/out_outage_outside"
           "outage .* ends after the trajectory")
_study_bad(zero_runs "study|--config|${_sdir}/short.yaml|--out|${_sdir}/out_zero_runs|--runs|0"
           "--runs must be >= 1")
_study_bad(missing_model "study|--config|${_sdir}/bad_model.yaml|--out|${_sdir}/out_missing_model"
           "candidate 'Gyro 1'.*gyro_model9")
_study_bad(unreadable "study|--config|${_sdir}/no_such_file.yaml|--out|${_sdir}/out_unreadable"
           "no_such_file.yaml")
_study_bad(bad_shard "study|--config|${_sdir}/short.yaml|--out|${_sdir}/out_bad_shard|--shard|3/2"
           "--shard '3/2'")
_study_bad(merge_missing "study-merge|${_sdir}/no_such_shard|--out|${_sdir}/out_merge_missing"
           "no_such_shard/shard.json")
