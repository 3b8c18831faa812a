# navimpact emulate: a 30 s scenario from the committed UAV excerpt, rawlog-edit
# --info on its output (when MRPT's apps are installed), and bad input.
set(_edir ${CMAKE_CURRENT_BINARY_DIR}/emulate_cli)
file(MAKE_DIRECTORY ${_edir})
navimpact_cli_uav_scenario(${_edir}/uav30.yaml 30 5 "ground_truth: {rate_hz: 10}\n")
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
navimpact_cli_check(cli_emulate_rawlog_edit_info CHECK rawlog_edit_info DEFINES RAWLOG=${_edir}/uav30.rawlog)
set_tests_properties(cli_emulate_rawlog_edit_info PROPERTIES FIXTURES_REQUIRED emu_rawlog)

# RawLogViewer opens it (on a virtual display); a file of random bytes it cannot
# read shows its "Zero entries loaded" box instead, so the check can say no.
navimpact_cli_check(cli_emulate_rawlog_viewer CHECK rawlog_viewer DEFINES RAWLOG=${_edir}/uav30.rawlog EXPECT=loaded)
set_tests_properties(cli_emulate_rawlog_viewer PROPERTIES FIXTURES_REQUIRED emu_rawlog)
string(RANDOM LENGTH 4000 RANDOM_SEED 20261125 _garbage)
file(WRITE ${_edir}/garbage.rawlog "${_garbage}")
navimpact_cli_check(cli_rawlog_viewer_refuses_garbage CHECK rawlog_viewer DEFINES RAWLOG=${_edir}/garbage.rawlog EXPECT=zero)


# Bad input: one-line error, nothing written.
navimpact_cli_fail(cli_emulate_bad_key
  ARGS emulate --config ${_edir}/bad_key.yaml --out ${_edir}/bad.rawlog
  REGEX "bad_key.yaml.*imu.sede.*unknown key" NOOUT ${_edir}/bad.rawlog)
navimpact_cli_fail(cli_emulate_static_rate_mismatch
  ARGS emulate --config ${_edir}/static_rate.yaml --out ${_edir}/static.rawlog
  REGEX "static recording is at 100 Hz, emulation at 200 Hz" NOOUT ${_edir}/static.rawlog)

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

# Values beyond their documented physical range are refused at load, naming the key.
foreach(_case "baro_sigma|imu: {errors: none}\nbaro: {sigma_m: 1e308}|key 'baro.sigma_m': must be in .0.0001, 10000. m, got 1e.308"
              "baro_sigma_tiny|imu: {errors: none}\nbaro: {sigma_m: 1e-300}|key 'baro.sigma_m': must be in .0.0001, 10000. m, got 1e-300"
              "lever_arm|imu: {errors: none}\ngnss: {lever_arm_B_m: [0, 1e308, 0]}|key 'gnss.lever_arm_B_m.1.': must be in .-100, 100. m"
              "imu_rate|imu: {rate_hz: 1e7, errors: none}|key 'imu.rate_hz': must be in .1, 10000. Hz, got 1e.07"
              "knot_step_range|imu: {errors: none}\nsmoothing: {knot_step_s: 1e-308}|key 'smoothing.knot_step_s': must be in .0.0001, 604800. s, got 1e-308"
              "cutoff_range|imu: {errors: none}\nsmoothing: {position_cutoff_hz: 1e-308}|key 'smoothing.position_cutoff_hz': must be in .0.001, 10000. Hz, got 1e-308"
              "knot_step_tiny|imu: {errors: none}\nsmoothing: {knot_step_s: 0.0001}|key 'smoothing.knot_step_s': cutoff 1 Hz times knot step 0.0001 s is 0.0001, below 0.0002"
              "cutoff_tiny|imu: {errors: none}\nsmoothing: {position_cutoff_hz: 0.001}|key 'smoothing.position_cutoff_hz': cutoff 0.001 Hz"
              "knots_finer_than_samples|imu: {errors: none}\nsmoothing: {knot_step_s: 0.0001, position_cutoff_hz: 2, attitude_cutoff_hz: 2}|uav_flight_260s.csv.gz: smoothing spline: knot step 0.0001 s gives 300000 knot intervals for 3001 samples .at most 64 per sample")
  navimpact_cli_case("${_case}" _n _body _re)
  file(WRITE ${_edir}/range_${_n}.yaml
       "trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz, end_s: 30}\n${_body}\n")
  navimpact_cli_fail(cli_emulate_range_${_n}
    ARGS emulate --config ${_edir}/range_${_n}.yaml --out ${_edir}/range_${_n}.rawlog
    REGEX "${_re}" NOOUT ${_edir}/range_${_n}.rawlog)
endforeach()

# Work budget: a run above 10^8 IMU samples (here 12,000 s at 10 kHz) is refused before
# it starts, naming the key and the flag that lifts it; nothing is written.
file(WRITE ${_edir}/long_traj.csv "time_s,x_N_m,x_E_m,x_D_m,roll_rad,pitch_rad,yaw_rad\n0,0,0,0,0,0,0\n1500,0,0,0,0,0,0\n3000,0,0,0,0,0,0\n4500,0,0,0,0,0,0\n6000,0,0,0,0,0,0\n7500,0,0,0,0,0,0\n9000,0,0,0,0,0,0\n10500,0,0,0,0,0,0\n12000,0,0,0,0,0,0\n")
file(WRITE ${_edir}/long.yaml "
trajectory: {file: long_traj.csv, system: ned, origin: {lat_deg: 46.5, lon_deg: 6.5, height_m: 400}, max_gap_s: 20000}
imu: {rate_hz: 10000, errors: none}
")
navimpact_cli_fail(cli_emulate_budget
  ARGS emulate --config ${_edir}/long.yaml --out ${_edir}/long.rawlog
  REGEX "long.yaml: key 'imu.rate_hz': the run would need about 1.2e.08 IMU samples .12000 s at 10000 Hz; about 8.04 GB of rawlog.*above the budget of 1e.08 IMU samples: .*, or pass --allow-large"
  NOOUT ${_edir}/long.rawlog)

# Sensor effects in an emulation (effects: ...): a 240 s run whose gyros read
# 1 % too much (a scale factor 5x the detection limit of README "Run diagnosis"),
# then diagnose --run with the model the sensor was emulated with names
# scale_factor with a significant held-out gain and writes the extension.
navimpact_cli_uav_scenario(${_edir}/gyro_scale.yaml 240 41601 "effects: {gyro_scale: [0.01, -0.01, 0.01], seed: 41604}\n")
add_test(NAME cli_emulate_effects
  COMMAND ${NI} emulate --config ${_edir}/gyro_scale.yaml --out ${_edir}/gyro_scale.rawlog --overwrite)
set_tests_properties(cli_emulate_effects PROPERTIES FIXTURES_SETUP emu_effects
  PASS_REGULAR_EXPRESSION "IMU 48000 samples at 200 Hz")
navimpact_cli_check(cli_emulate_effects_diagnose_run CHECK run_json
  ARGS diagnose --run ${_edir}/gyro_scale.rawlog --model ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref
       --durations 10 --reconverge 10 --realisations 8 --folds 3 --alpha 0.05 --seed 41605
       --out ${_edir}/gyro_scale_diagnosis
  DEFINES OUT=${_edir}/gyro_scale_diagnosis JSON_FILE=run_diagnosis.json
  JSON "verdict=^inadequate$" "findings/0/cause=^scale_factor$" "findings/0/channel=^gyro_x$"
       "findings/0/params/scale=^0[.]0(09|1)" "gain/cause=^scale_factor$" "gain/significant=^(true|ON)$"
  FILES report.md model_extended.yaml filter_extended.yaml)
set_tests_properties(cli_emulate_effects_diagnose_run PROPERTIES FIXTURES_REQUIRED emu_effects)
# the extension it writes is a replay configuration that loads (its prior sigmas
# are written within the ranges the replay reads them with) and runs
add_test(NAME cli_emulate_effects_extension_replays
  COMMAND ${NI} replay --config ${_edir}/gyro_scale_diagnosis/filter_extended.yaml --rawlog ${_edir}/gyro_scale.rawlog
          --outage 100:10 --out ${_edir}/gyro_scale_extension --overwrite)
set_tests_properties(cli_emulate_effects_extension_replays PROPERTIES FIXTURES_REQUIRED emu_effects
  DEPENDS cli_emulate_effects_diagnose_run PASS_REGULAR_EXPRESSION "outage 1 \\(10 s from 100 s\\): horizontal error at end")
# an effect out of its documented range is refused, naming the key
navimpact_cli_fail(cli_emulate_effects_bad_range
  ARGS emulate --config ${_edir}/gyro_scale_bad.yaml --out ${_edir}/gyro_scale_bad.rawlog
  REGEX "gyro_scale_bad.yaml.*effects.time_offset_s.*must be in .-0.1, 0.1. s" NOOUT ${_edir}/gyro_scale_bad.rawlog)
file(WRITE ${_edir}/gyro_scale_bad.yaml "
trajectory: {file: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz, end_s: 30}
imu: {errors: none}
effects: {time_offset_s: 0.5}
")
