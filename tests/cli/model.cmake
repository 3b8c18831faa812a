# navimpact model {show,list,convert} on the committed Table 1 model file.
set(_models ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml)
set(_mdir ${CMAKE_CURRENT_BINARY_DIR}/model_cli)
file(MAKE_DIRECTORY ${_mdir})


add_test(NAME cli_model_show_gyro_ref
  COMMAND ${NI} model show ${_models}:gyro_ref)
set_tests_properties(cli_model_show_gyro_ref PROPERTIES PASS_REGULAR_EXPRESSION
  "gyro_x, gyro_y, gyro_z: WN\\(sigma=0.0009788\\) \\+ GM\\(sigma=4.805e-05, T=59.22\\) \\+ GM\\(sigma=2.209e-05, T=1.457\\) \\+ GM\\(sigma=7.555e-05, T=2008\\)[^\n]*\n +ARW +0.2379 deg/sqrt\\(h\\)")

add_test(NAME cli_model_list COMMAND ${NI} model list ${_models})
set_tests_properties(cli_model_list PROPERTIES PASS_REGULAR_EXPRESSION
  "acc_ref +gyro: none +acc: WN\\+GM\\+GM\\+GM\\+DR.*gyro_ref +gyro: WN\\+GM\\+GM\\+GM")

# convert to 100 Hz, then show the written file: WN sigma scales by sqrt(1/2).
add_test(NAME cli_model_convert
  COMMAND ${NI} model convert ${_models}:ref --rate 100 --out ${_mdir}/ref_100hz.yaml --overwrite)
set_tests_properties(cli_model_convert PROPERTIES
  PASS_REGULAR_EXPRESSION "converted from 200 Hz to 100 Hz"
  FIXTURES_SETUP model_100hz)
add_test(NAME cli_model_show_converted COMMAND ${NI} model show ${_mdir}/ref_100hz.yaml)
set_tests_properties(cli_model_show_converted PROPERTIES
  PASS_REGULAR_EXPRESSION "per sample at 100 Hz.*WN\\(sigma=0.0006921\\).*ARW +0.2379 deg/sqrt\\(h\\)"
  FIXTURES_REQUIRED model_100hz)

# convert without --out prints the YAML with the note as a comment
add_test(NAME cli_model_convert_stdout COMMAND ${NI} model convert ${_models}:gyro_model1 --rate 400)
set_tests_properties(cli_model_convert_stdout PROPERTIES PASS_REGULAR_EXPRESSION
  "# navimpact model convert: .*converted from 200 Hz to 400 Hz.*rate_hz: 400")

# an unparsable model string: non-zero exit, message names the file's key and position
file(WRITE ${_mdir}/bad_model.yaml
  "rate_hz: 200\nmodels:\n  broken:\n    gyroscope: \"WN(sigma=1e-3) + GM(sigma=2e-5 T=3)\"\n")
navimpact_cli_fail(cli_model_bad_string ARGS model show ${_mdir}/bad_model.yaml:broken
  REGEX "^navimpact: .*bad_model.yaml: key 'models.broken.gyroscope': model .*at position 32: expected ',' or '\\)'")

# unknown model name: non-zero exit, lists the available names
navimpact_cli_fail(cli_model_unknown_name ARGS model show ${_models}:gyro_model9
  REGEX "no model named 'gyro_model9' \\(available: acc_model1, acc_model2, acc_model3, acc_ref, gyro_model1, gyro_model2, gyro_model3, gyro_ref, ref\\)")

# rate_hz 1e308: the datasheet's Allan-deviation search is bounded (it used to
# loop forever when 1e6 s * rate overflowed); the command ends, printing the
# figures, or refuses the rate with a message naming it.
file(WRITE ${_mdir}/huge_rate.yaml
  "rate_hz: 1e308\ngyroscope: \"WN(sigma=1e-3) + GM(sigma=1e-4, T=10) + RW(gamma=1e-7)\"\naccelerometer: \"WN(sigma=1e-3)\"\n")
add_test(NAME cli_model_show_huge_rate COMMAND ${NI} model show ${_mdir}/huge_rate.yaml)
set_tests_properties(cli_model_show_huge_rate PROPERTIES TIMEOUT 60
  PASS_REGULAR_EXPRESSION "ARW +[0-9.e+-]+ deg/sqrt\\(h\\)|rate_hz")

# model convert writes only what loads again: a WN sigma of 9e4 at 1 Hz is 9e6 at
# 10 kHz, beyond any IMU (it was written with exit 0 and refused by model show)
file(WRITE ${_mdir}/big_at_1hz.yaml "rate_hz: 1\ngyroscope: \"WN(sigma=9e4)\"\naccelerometer: \"WN(sigma=1e-3)\"\n")
navimpact_cli_fail(cli_model_convert_beyond_any_imu
  ARGS model convert ${_mdir}/big_at_1hz.yaml --rate 10000 --out ${_mdir}/big_at_10khz.yaml
  REGEX "^navimpact: .*big_at_1hz.yaml: converted from 1 Hz to 10000 Hz, axis gyro_x: .*sigma = 9e\\+06 is beyond any IMU"
  NOOUT ${_mdir}/big_at_10khz.yaml)
