# navimpact covariance: a short run writes every output; bad input gives one
# clear error naming the key and leaves no output directory behind.
set(_cdir ${CMAKE_CURRENT_BINARY_DIR}/covariance)
file(MAKE_DIRECTORY ${_cdir})
set(_models ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml)

# a 5 s study with two models per set
file(WRITE ${_cdir}/short.yaml "model_file: ${_models}
duration_s: 5
imu_rate_hz: 200
output_rate_hz: 10
summary_times_s: [1, 5]
static_state: {lat_deg: 46.52, lon_deg: 6.57, h_m: 400, roll_deg: 0, pitch_deg: 0, yaw_deg: 30}
baro: {rate_hz: 10, sigma_m: 0.001}
model_sets:
  - {name: accelerometer, models: [acc_model1, acc_ref]}
  - {name: gyroscope, models: [gyro_model1, gyro_ref]}
")
file(WRITE ${_cdir}/check_outputs.cmake [=[
file(REMOVE_RECURSE "${OUTDIR}")
execute_process(COMMAND ${NI} covariance --config ${CONFIG} --out ${OUTDIR} --print-states
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "exit ${rc}: ${err}")
endif()
foreach(f covariance.csv summary.json covariance_accelerometer.png covariance_gyroscope.png)
  if(NOT EXISTS ${OUTDIR}/${f})
    message(FATAL_ERROR "missing ${f}")
  endif()
endforeach()
if(NOT out MATCHES "acc_x.GM1\\(T=3.22s\\)")
  message(FATAL_ERROR "--print-states did not list acc_x.GM1(T=3.22s):\n${out}")
endif()
file(STRINGS ${OUTDIR}/covariance.csv rows)
list(LENGTH rows n)
# header + 4 models x 51 rows (0..5 s at 10 Hz)
if(NOT n EQUAL 205)
  message(FATAL_ERROR "covariance.csv has ${n} lines, expected 205")
endif()
file(READ ${OUTDIR}/summary.json js)
string(JSON nruns LENGTH "${js}" runs)
if(NOT nruns EQUAL 4)
  message(FATAL_ERROR "summary.json has ${nruns} runs")
endif()
]=])
add_test(NAME cli_covariance_short
         COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DCONFIG=${_cdir}/short.yaml -DOUTDIR=${_cdir}/out_short
                 -P ${_cdir}/check_outputs.cmake)

# bad inputs: (name, config body, expected stderr regex)
function(_cov_bad name body regex)
  file(WRITE ${_cdir}/${name}.yaml "${body}")
  add_test(NAME cli_covariance_bad_${name}
           COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=covariance|--config|${_cdir}/${name}.yaml|--out|${_cdir}/out_${name}"
                   "-DREGEX=${regex}" -DOUTDIR=${_cdir}/out_${name}
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_fail.cmake)
endfunction()
set(_base "duration_s: 2\nstatic_state: {lat_deg: 46.5, lon_deg: 6.5, h_m: 400}\n")
file(WRITE ${_cdir}/m_unknown.yaml "rate_hz: 200\nmodels:\n  bad:\n    accelerometer: \"WN(sigma=1e-3) + XX(sigma=1)\"\n")
file(WRITE ${_cdir}/m_negsigma.yaml "rate_hz: 200\nmodels:\n  bad:\n    gyroscope: \"GM(sigma=-1e-4, T=3)\"\n")
file(WRITE ${_cdir}/m_zeroT.yaml "rate_hz: 200\nmodels:\n  bad:\n    gyroscope: \"GM(sigma=1e-4, T=0)\"\n")
_cov_bad(unknown_process "model_file: ${_cdir}/m_unknown.yaml\n${_base}model_sets: [{name: a, models: [bad]}]\n"
         "model_sets\\[0\\]\\.models\\[0\\].*XX")
_cov_bad(negative_sigma "model_file: ${_cdir}/m_negsigma.yaml\n${_base}model_sets: [{name: a, models: [bad]}]\n"
         "model_sets\\[0\\]\\.models\\[0\\].*sigma")
_cov_bad(zero_T "model_file: ${_cdir}/m_zeroT.yaml\n${_base}model_sets: [{name: a, models: [bad]}]\n"
         "model_sets\\[0\\]\\.models\\[0\\].*T")
_cov_bad(unknown_model "model_file: ${_models}\n${_base}model_sets: [{name: a, models: [acc_model9]}]\n"
         "model_sets\\[0\\]\\.models\\[0\\].*acc_model9")
_cov_bad(wrong_unit "model_file: ${_models}\nduration_s: 2\nstatic_state: {lat_rad: 0.8, lon_deg: 6.5, h_m: 400}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "static_state\\.lat_rad.*unknown key.*lat_deg")
_cov_bad(wrong_type "model_file: ${_models}\nduration_s: sixty\nstatic_state: {lat_deg: 46.5}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "duration_s.*expected a number in s")
_cov_bad(duplicate_set_name "model_file: ${_models}\n${_base}model_sets: [{name: a, models: [acc_ref]}, {name: a, models: [gyro_ref]}]\n"
         "model_sets\\[1\\]\\.name.*'a' is used by an earlier model set")
_cov_bad(negative_baro_sigma "model_file: ${_models}\n${_base}baro: {rate_hz: 10, sigma_m: -1}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "baro\\.sigma_m.*> 0")

# covariance-only propagation along the committed UAV trajectory (5 s)
add_test(NAME cli_covariance_trajectory
         COMMAND ${NI} covariance --config ${_cdir}/short.yaml --out ${_cdir}/out_traj --overwrite
                 --trajectory ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)
set_tests_properties(cli_covariance_trajectory PROPERTIES PASS_REGULAR_EXPRESSION "gyro_ref +5\\.0")
add_test(NAME cli_covariance_bad_trajectory
         COMMAND ${CMAKE_COMMAND} -DNI=${NI}
                 "-DARGS=covariance|--config|${_cdir}/short.yaml|--out|${_cdir}/out_badtraj|--trajectory|${_cdir}/no_such.csv"
                 "-DREGEX=no_such.csv" -DOUTDIR=${_cdir}/out_badtraj
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_fail.cmake)
