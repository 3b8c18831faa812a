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
navimpact_cli_check(cli_covariance_short CHECK covariance_outputs
  DEFINES CONFIG=${_cdir}/short.yaml OUTDIR=${_cdir}/out_short)

# bad inputs: (name, config body, expected stderr regex)
function(_cov_bad name body regex)
  file(WRITE ${_cdir}/${name}.yaml "${body}")
  navimpact_cli_fail(cli_covariance_bad_${name}
    ARGS covariance --config ${_cdir}/${name}.yaml --out ${_cdir}/out_${name}
    REGEX "${regex}" NOOUT ${_cdir}/out_${name})
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
         "key 'duration_s': must be a number in .* s, got 'sixty'")
_cov_bad(duplicate_set_name "model_file: ${_models}\n${_base}model_sets: [{name: a, models: [acc_ref]}, {name: a, models: [gyro_ref]}]\n"
         "model_sets\\[1\\]\\.name.*'a' is used by an earlier model set")
_cov_bad(negative_baro_sigma "model_file: ${_models}\n${_base}baro: {rate_hz: 10, sigma_m: -1}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "baro\\.sigma_m.*must be in .0.0001, 10000. m, got -1")
# rows every k-th IMU step (k whole) and summary times on those rows, in order: 3 Hz at 200 Hz
# gave rows every 0.335 s and summary "5 s" at 4.69 s; a model twice in a set, its rows twice
_cov_bad(output_rate_not_dividing "model_file: ${_models}\n${_base}imu_rate_hz: 200\noutput_rate_hz: 3\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'output_rate_hz': must divide imu_rate_hz = 200 Hz \\(a row every k-th IMU step, k whole\\), got 3 Hz$")
_cov_bad(baro_rate_not_dividing "model_file: ${_models}\n${_base}imu_rate_hz: 200\nbaro: {rate_hz: 3, sigma_m: 0.01}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'baro.rate_hz': must divide imu_rate_hz = 200 Hz")
_cov_bad(summary_unordered "model_file: ${_models}\n${_base}summary_times_s: [2, 1]\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'summary_times_s': must increase strictly, got 1 s after 2 s$")
_cov_bad(summary_off_rows "model_file: ${_models}\n${_base}output_rate_hz: 10\nsummary_times_s: [1.03]\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'summary_times_s': 1.03 s is not a time of the results \\(every 0.1 s from 0, or duration_s\\)$")
_cov_bad(model_twice "model_file: ${_models}\n${_base}model_sets: [{name: a, models: [acc_ref, acc_ref]}]\n"
         "model_sets\\[0\\]\\.models\\[1\\].*'acc_ref' is listed twice in this model set")
# one value cannot make a run spin or exhaust memory: ranges at load, work budget before the run
_cov_bad(huge_rate "model_file: ${_models}\n${_base}imu_rate_hz: 1e12\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'imu_rate_hz': must be in \\[1, 10000\\] Hz, got 1e\\+12")
_cov_bad(over_budget "model_file: ${_models}\nduration_s: 604800\nimu_rate_hz: 10000\nstatic_state: {lat_deg: 46.5}\nmodel_sets: [{name: a, models: [acc_ref]}]\n"
         "key 'duration_s': the run would need about .* operations .6.05e\\+09 IMU steps., above the budget of 1e\\+13 operations: shorten it .or lower imu_rate_hz or the models' states., or pass --allow-large$")

# covariance-only propagation along the committed UAV trajectory (5 s)
add_test(NAME cli_covariance_trajectory
         COMMAND ${NI} covariance --config ${_cdir}/short.yaml --out ${_cdir}/out_traj --overwrite
                 --trajectory ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)
set_tests_properties(cli_covariance_trajectory PROPERTIES PASS_REGULAR_EXPRESSION "gyro_ref +5\\.0")
navimpact_cli_fail(cli_covariance_bad_trajectory
  ARGS covariance --config ${_cdir}/short.yaml --out ${_cdir}/out_badtraj --trajectory ${_cdir}/no_such.csv
  REGEX "no_such.csv" NOOUT ${_cdir}/out_badtraj)
