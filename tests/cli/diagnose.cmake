# navimpact diagnose: end-to-end run on the committed ADIS16405 excerpt and
# bad-input errors (one clear line, exit 1, no output directory left behind).
set(_dg_data ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz)
set(_dg_dir ${CMAKE_CURRENT_SOURCE_DIR}/diagnose)
set(_dg_out ${CMAKE_CURRENT_BINARY_DIR}/diagnose_out)

# Full run with a white-noise-only model fitted to the data: the excerpt's
# slow processes make it inadequate; all outputs are written and the extended
# model file loads back.
add_test(NAME cli_diagnose_excerpt_wn
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DDATA=${_dg_data} -DOUT=${_dg_out}/wn
          -P ${_dg_dir}/run_and_check.cmake)

# Bad input: each fails before any work with a one-line error naming the problem.
add_test(NAME cli_diagnose_missing_model
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad1
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;/nonexistent/model.yaml;--out;${_dg_out}/bad1"
          "-DEXPECT=error: .*nonexistent/model.yaml" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_bad_structure
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad2
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;fit:WN+XYZ;--out;${_dg_out}/bad2"
          "-DEXPECT=error: .*XYZ" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_outage_without_trajectory
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad3
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;fit:WN;--outage;100:30;--out;${_dg_out}/bad3"
          "-DEXPECT=error: --outage needs --trajectory" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_bad_outage
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad4
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;fit:WN;--trajectory;${_dg_data};--outage;abc;--out;${_dg_out}/bad4"
          "-DEXPECT=error: --outage 'abc': expected START:DURATION" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_missing_unit
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad5
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--model;fit:WN;--out;${_dg_out}/bad5"
          "-DEXPECT=error: .*unit" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_short_record
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad6 -DSHORT=1
          "-DEXPECT=error: .*samples; diagnose needs at least 4096" -P ${_dg_dir}/expect_error.cmake)

# MRPT rawlog input through the shared loader (--label): the committed UAV
# rawlog (200 Hz, 52,000 IMU samples; it moves, so the model is inadequate,
# but this test is about reading it).
set(_dg_rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog)
add_test(NAME cli_diagnose_rawlog
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/rawlog
          "-DARGS=diagnose;--input;${_dg_rawlog};--label;IMU;--model;fit:WN;--simulations;2;--out;${_dg_out}/rawlog"
          "-DCHECKS=input/format=^rawlog$;input/samples=^52000$;input/rate_hz=^(200\\.0*|199\\.99);input/label=^IMU$"
          "-DFILES=report.md;model_extended.yaml" -P ${_dg_dir}/run_json.cmake)
add_test(NAME cli_diagnose_rawlog_bad_label
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad7
          "-DARGS=diagnose;--input;${_dg_rawlog};--label;XSENS;--model;fit:WN;--out;${_dg_out}/bad7"
          "-DEXPECT=error: .*no CObservationIMU with label 'XSENS'" -P ${_dg_dir}/expect_error.cmake)

# Navigation gain along the committed UAV excerpt with the excerpt's measured
# errors as the truth: before/after per outage, NEES band, figure.
set(_dg_traj ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)
add_test(NAME cli_diagnose_navigation
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/nav
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;fit:WN;--simulations;2;--trajectory;${_dg_traj};--outage;100:30;--outage;200:40;--nav-runs;4;--out;${_dg_out}/nav"
          "-DCHECKS=navigation/outages/1/start_s=^200(\\.0*)?$;navigation/outages/1/duration_s=^40(\\.0*)?$;navigation/outages/0/horizontal_error_m/before=^[0-9];navigation/outages/0/horizontal_error_m/after=^[0-9];navigation/outages/0/nees/band/1=^[0-9];navigation/runs=^4$"
          "-DFILES=navigation_error.png;report.md" -P ${_dg_dir}/run_json.cmake)
add_test(NAME cli_diagnose_outage_past_trajectory
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad8
          "-DARGS=diagnose;--input;${_dg_data};--rate;100;--gyro-unit;deg/s;--acc-unit;g;--model;fit:WN;--trajectory;${_dg_traj};--outage;250:30;--out;${_dg_out}/bad8"
          "-DEXPECT=error: --outage 250:30 ends at 280 s, after the end of the trajectory" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_recording_shorter_than_trajectory
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad9 -DSHORT=1
          "-DEXTRA=--trajectory;${_dg_traj};--outage;100:30"
          "-DEXPECT=error: static recording too short for the navigation gain: 9.99 s available, 2.* s needed"
          -P ${_dg_dir}/expect_error.cmake)

# Detection-power sweep: a tiny run writes its table and records every run;
# bad flags fail before any work.
add_test(NAME cli_diagnose_power_small
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/power -P ${_dg_dir}/run_power.cmake)
add_test(NAME cli_diagnose_power_bad_cause
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad10
          "-DARGS=diagnose-power;--out;${_dg_out}/bad10;--causes;sinusoid,wobble"
          "-DEXPECT=error: --causes: unknown cause 'wobble'" -P ${_dg_dir}/expect_error.cmake)
add_test(NAME cli_diagnose_power_bad_snr
  COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DOUT=${_dg_out}/bad11
          "-DARGS=diagnose-power;--out;${_dg_out}/bad11;--snr;5"
          "-DEXPECT=error: --snr '5': expected LO:HI" -P ${_dg_dir}/expect_error.cmake)
