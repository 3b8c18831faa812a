# One error format everywhere (README, "Errors and exit codes"): every failure
# is one line `navimpact: FILE[:LINE|: entry N|: key K]: what (accepted)`, at
# most 300 characters, no raw binary, with the documented exit code:
# 1 bad input, 2 command line, 3 out of memory, 4 internal error.
set(_erd ${CMAKE_CURRENT_BINARY_DIR}/errors)
file(MAKE_DIRECTORY ${_erd})
function(_one_line name exit regex)
  string(REPLACE ";" "|" _a "${ARGN}")
  add_test(NAME cli_error_${name}
           COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=${_a}" -DEXIT=${exit} "-DREGEX=${regex}"
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/errors/one_line.cmake)
endfunction()
set(_bad ${CMAKE_SOURCE_DIR}/tests/data/bad)
set(_units --rate 100 --gyro-unit deg/s --acc-unit g)

# MRPT's multi-line exception texts become the cause, raw bytes escaped.
_one_line(mrpt_cause_imu_reader 1
  "unregistered_class.rawlog: entry 2: .*reading CObservationIMU: stored object has class 'mrpt::poses\\\\xC7:CPose3D' which is not registered"
  wv --input ${_bad}/unregistered_class.rawlog --label XSENS --out ${_erd}/o1)
_one_line(mrpt_cause_replay_reader 1
  "unregistered_class.rawlog: entry 2: .*stored object has class 'mrpt::poses\\\\xC7:CPose3D'"
  replay --rawlog ${_bad}/unregistered_class.rawlog --out ${_erd}/o2)

# CLI11: one line, exit 2, pointing at the command's --help.
_one_line(cli_range 2 "^navimpact: --gzip-level: .*1 to 9 \\(see 'navimpact emulate --help'\\)$"
  emulate --config x.yaml --out ${_erd}/x.rawlog --gzip-level 12)
_one_line(cli_required 2 "^navimpact: --out is required \\(see 'navimpact replay --help'\\)$" replay)
_one_line(cli_conversion 2 "--eff.*abc.*see 'navimpact wv --help'" wv --input x.csv --eff abc --out ${_erd}/o3)
_one_line(cli_unknown_command 2 "^navimpact: unknown command 'frobnicate' \\(commands: covariance, diagnose, .*\\)$" frobnicate)

# yaml-cpp conversion errors: the file, line and column.
file(READ ${CMAKE_SOURCE_DIR}/config/replay/default.yaml _rc)
string(REPLACE "rawlog: ../../" "rawlog: ${CMAKE_SOURCE_DIR}/" _rc "${_rc}")
string(REPLACE "use_gnss_velocity: true " "use_gnss_velocity: perhaps" _rc "${_rc}")
file(WRITE ${_erd}/perhaps.yaml "${_rc}")
_one_line(yaml_bad_conversion 1 "^navimpact: [^ ]*perhaps.yaml:12:22: bad conversion"
  replay --config ${_erd}/perhaps.yaml --out ${_erd}/o4)
file(WRITE ${_erd}/complex_key.yaml "rawlog: x.rawlog\n? [a, b]\n: 1\n")
_one_line(yaml_complex_key 1 "complex_key.yaml:2:[0-9]+: " replay --config ${_erd}/complex_key.yaml --out ${_erd}/o5)

# Raw input echoed escaped and cut: control bytes, invalid UTF-8, a 5000-byte field.
string(ASCII 1 _soh)
file(WRITE ${_erd}/binary_field.csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,4,5,x${_soh}y\n")
_one_line(csv_binary_field 1 "binary_field.csv:2: column 6 \\('acc_z'\\): 'x\\\\x01y' is not a number$"
  wv --input ${_erd}/binary_field.csv ${_units} --out ${_erd}/o6)
string(REPEAT "z" 5000 _long)
file(WRITE ${_erd}/long_field.csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,4,5,${_long}\n")
_one_line(csv_long_field 1 "long_field.csv:2: column 6 \\('acc_z'\\): 'z+\\.\\.\\.\\(5000 bytes\\)' is not a number$"
  wv --input ${_erd}/long_field.csv ${_units} --out ${_erd}/o7)
string(REPEAT "GM(sigma=1, T=2) + " 200 _longmodel)
file(WRITE ${_erd}/long_model.yaml "rate_hz: 100\ngyroscope: \"${_longmodel}XX(a=1)\"\n")
_one_line(model_text_long 1 "long_model.yaml: key 'gyroscope': model '.*\\.\\.\\.\\([0-9]+ bytes\\)': at position 3801: expected a process name"
  model show ${_erd}/long_model.yaml)
