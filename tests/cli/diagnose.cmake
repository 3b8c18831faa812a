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
