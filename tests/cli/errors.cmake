# One error format everywhere (README, "Errors and exit codes"): every failure
# is one line `navimpact: FILE[:LINE|: entry N|: key K]: what (accepted)`, at
# most 300 characters, no raw binary (navimpact_cli_fail checks the form of
# every expected failure), with the documented exit code: 1 bad input,
# 2 command line, 3 out of memory, 4 internal error.
set(_erd ${CMAKE_CURRENT_BINARY_DIR}/errors)
file(MAKE_DIRECTORY ${_erd})
set(_bad ${CMAKE_SOURCE_DIR}/tests/data/bad)
set(_units --rate 100 --gyro-unit deg/s --acc-unit g)

# MRPT's multi-line exception texts become the cause, raw bytes escaped.
navimpact_cli_fail(cli_error_mrpt_cause_imu_reader EXIT 1
  ARGS wv --input ${_bad}/unregistered_class.rawlog --label XSENS --out ${_erd}/o1
  REGEX "unregistered_class.rawlog: entry 2: .*reading CObservationIMU: stored object has class 'mrpt::poses\\\\xC7:CPose3D' which is not registered")
navimpact_cli_fail(cli_error_mrpt_cause_replay_reader EXIT 1
  ARGS replay --rawlog ${_bad}/unregistered_class.rawlog --out ${_erd}/o2
  REGEX "unregistered_class.rawlog: entry 2: .*stored object has class 'mrpt::poses\\\\xC7:CPose3D'")
navimpact_cli_fail(cli_error_mrpt_abstract_class EXIT 1
  ARGS replay --rawlog ${_bad}/abstract_class.rawlog --out ${_erd}/o2a
  REGEX "^navimpact: [^\n]*abstract_class.rawlog: entry 0: an object of class 'mrpt::obs::CObservation', which MRPT cannot create \\(an abstract class\\): malformed entry$")

# CLI11: one line, exit 2, pointing at the command's --help.
navimpact_cli_fail(cli_error_cli_range EXIT 2 ARGS emulate --config x.yaml --out ${_erd}/x.rawlog --gzip-level 12
  REGEX "^navimpact: --gzip-level: .*1 to 9 \\(see 'navimpact emulate --help'\\)$")
navimpact_cli_fail(cli_error_cli_required EXIT 2 ARGS replay
  REGEX "^navimpact: --out is required \\(see 'navimpact replay --help'\\)$")
navimpact_cli_fail(cli_error_cli_conversion EXIT 2 ARGS wv --input x.csv --eff abc --out ${_erd}/o3
  REGEX "--eff.*abc.*see 'navimpact wv --help'")
# A flag's text that the library's parser refuses is a command-line error too
# (exit 2, found by a probe: these exited 1 without pointing at --help).
foreach(_case
    "replay_outage|replay|--outage|10:-5|DURATION"
    "replay_outages_every|replay|--outages-every|1e-300:1e-300|"
    "diagnose_outage|diagnose|--outage|abc|"
    "study_shard|study|--shard|3/2|"
    "sweep_shard|sweep|--shard|0/2|"
    "power_rate|diagnose-power|--rate|0.5:10|rates must be in"
    "power_snr|diagnose-power|--snr|5:1|LO:HI"
    "power_causes|diagnose-power|--causes|gm|unknown cause 'gm'"
    "power_snr_high|diagnose-power|--snr|5:2000|must be in \\[0, 1000\\]"
    "power_simulations_one|diagnose-power|--simulations|1|at least 2"
    "wv_gyro_unit|wv|--gyro-unit|furlong|'furlong' is not a known unit"
    "fit_weights|fit|--weights|bogus|bogus")
  navimpact_cli_case("${_case}" _n _cmd _flag _val _re)
  navimpact_cli_fail(cli_error_flag_value_${_n} EXIT 2 ARGS ${_cmd} ${_flag} ${_val} --out ${_erd}/fv_${_n}
    REGEX "^navimpact: ${_flag}[^\n]*${_re}[^\n]*\\(see 'navimpact ${_cmd} --help'\\)$")
endforeach()
navimpact_cli_fail(cli_error_cli_unknown_command EXIT 2 ARGS frobnicate
  REGEX "^navimpact: unknown command 'frobnicate' \\(commands: covariance, diagnose, .*\\)$")

# A value of the wrong type: the file and the dotted key, what is accepted and what came.
file(READ ${CMAKE_SOURCE_DIR}/config/replay/default.yaml _rc)
string(REPLACE "rawlog: ../../" "rawlog: ${CMAKE_SOURCE_DIR}/" _rc "${_rc}")
string(REPLACE "use_gnss_velocity: true " "use_gnss_velocity: perhaps" _rc "${_rc}")
file(WRITE ${_erd}/perhaps.yaml "${_rc}")
navimpact_cli_fail(cli_error_yaml_bad_conversion EXIT 1 ARGS replay --config ${_erd}/perhaps.yaml --out ${_erd}/o4
  REGEX "^navimpact: [^ ]*perhaps.yaml: key 'filter.use_gnss_velocity': must be true or false, got 'perhaps'$")
file(WRITE ${_erd}/complex_key.yaml "rawlog: x.rawlog\n? [a, b]\n: 1\n")
navimpact_cli_fail(cli_error_yaml_complex_key EXIT 1 ARGS replay --config ${_erd}/complex_key.yaml --out ${_erd}/o5
  REGEX "complex_key.yaml:2:[0-9]+: ")

# Raw input echoed escaped and cut: control bytes, a 5000-byte field, a long model text.
string(ASCII 1 _soh)
file(WRITE ${_erd}/binary_field.csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,4,5,x${_soh}y\n")
navimpact_cli_fail(cli_error_csv_binary_field EXIT 1 ARGS wv --input ${_erd}/binary_field.csv ${_units} --out ${_erd}/o6
  REGEX "binary_field.csv:2: column 6 \\('acc_z'\\): 'x\\\\x01y' is not a number$")
string(REPEAT "z" 5000 _long)
file(WRITE ${_erd}/long_field.csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,4,5,${_long}\n")
navimpact_cli_fail(cli_error_csv_long_field EXIT 1 ARGS wv --input ${_erd}/long_field.csv ${_units} --out ${_erd}/o7
  REGEX "long_field.csv:2: column 6 \\('acc_z'\\): 'z+\\.\\.\\.\\(5000 bytes\\)' is not a number$")
string(REPEAT "GM(sigma=1, T=2) + " 30 _longmodel)
file(WRITE ${_erd}/long_model.yaml "rate_hz: 100\ngyroscope: \"${_longmodel}XX(a=1)\"\n")
navimpact_cli_fail(cli_error_model_text_long EXIT 1 ARGS model show ${_erd}/long_model.yaml
  REGEX "long_model.yaml: key 'gyroscope': model '.*\\.\\.\\.\\([0-9]+ bytes\\)': at position 571: expected a process name")

# A file named by a configuration key that cannot be read (missing, a folder)
# is named with the configuration and the key as well as the path, in every
# command that reads such keys (ConfigNode::inputFile / modelRef), before any
# work and with no output left behind.
set(_fk ${_erd}/filekeys)
file(MAKE_DIRECTORY ${_fk}/folder)
set(_m ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml)
set(_traj ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)
file(WRITE ${_fk}/replay_rawlog.yaml "rawlog: no_such.rawlog\n")
file(WRITE ${_fk}/replay_model.yaml "rawlog: ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog\nmodel: folder:ref\n")
file(READ ${CMAKE_SOURCE_DIR}/datasets/katwijk_rover/manifest.yaml _man)
string(REPLACE "file: imu.csv.gz" "file: no_such_imu.csv" _man "${_man}")
string(REPLACE "file: gnss.csv" "file: ${CMAKE_SOURCE_DIR}/datasets/katwijk_rover/gnss.csv" _man "${_man}")
string(REPLACE "file: reference.csv" "file: ${CMAKE_SOURCE_DIR}/datasets/katwijk_rover/reference.csv" _man "${_man}")
file(WRITE ${_fk}/manifest.yaml "${_man}")
file(WRITE ${_fk}/emulate_traj.yaml "trajectory: {file: folder}\nimu: {errors: none}\n")
file(WRITE ${_fk}/emulate_model.yaml "trajectory: {file: ${_traj}}\nimu: {errors: model, model: no_such.yaml:ref}\n")
file(WRITE ${_fk}/emulate_static.yaml
  "trajectory: {file: ${_traj}}\nimu: {errors: static, static: {file: no_such.csv, gyro_unit: deg/s, acc_unit: g}}\n")
file(WRITE ${_fk}/study.yaml "trajectory: {file: ${_traj}}
truth: {errors: model, model: ${_m}:ref}
candidates:
  - {label: A, model: ${_m}:ref}
  - {label: B, accelerometer: ${_m}:acc_ref, gyroscope: no_such.yaml:gyro_ref}
")
file(WRITE ${_fk}/covariance.yaml "model_file: no_such.yaml\nmodel_sets: [{name: a, models: [ref]}]\n")
# _file_key(NAME CONFIG KEY PATH REASON COMMAND...): COMMAND fails naming CONFIG, KEY, PATH and REASON.
function(_file_key name config key path reason)
  navimpact_cli_fail(cli_error_file_key_${name} EXIT 1 ARGS ${ARGN} NOOUT ${_fk}/out_${name}
    REGEX "^navimpact: [^ ]*/${config}: key '${key}': cannot open '[^']*/filekeys/${path}' \\(${reason}\\)$")
endfunction()
set(_none "No such file or directory")
_file_key(replay_rawlog replay_rawlog.yaml rawlog no_such.rawlog "${_none}"
  replay --config ${_fk}/replay_rawlog.yaml --out ${_fk}/out_replay_rawlog)
_file_key(replay_model replay_model.yaml model folder "Is a directory"
  replay --config ${_fk}/replay_model.yaml --out ${_fk}/out_replay_model)
_file_key(import manifest.yaml imu.file no_such_imu.csv "${_none}"
  import --manifest ${_fk}/manifest.yaml --out ${_fk}/out_import)
_file_key(emulate_trajectory emulate_traj.yaml trajectory.file folder "Is a directory"
  emulate --config ${_fk}/emulate_traj.yaml --out ${_fk}/out_emulate_trajectory)
_file_key(emulate_model emulate_model.yaml imu.model no_such.yaml "${_none}"
  emulate --config ${_fk}/emulate_model.yaml --out ${_fk}/out_emulate_model)
_file_key(emulate_static emulate_static.yaml imu.static.file no_such.csv "${_none}"
  emulate --config ${_fk}/emulate_static.yaml --out ${_fk}/out_emulate_static)
_file_key(study study.yaml "candidates\\[1\\].gyroscope" no_such.yaml "${_none}"
  study --config ${_fk}/study.yaml --out ${_fk}/out_study)
_file_key(covariance covariance.yaml model_file no_such.yaml "${_none}"
  covariance --config ${_fk}/covariance.yaml --out ${_fk}/out_covariance)
# A flag that replaces the key leaves its file unchecked (the file is not read).
add_test(NAME cli_error_file_key_replaced_by_flag
  COMMAND ${NI} replay --config ${_fk}/replay_rawlog.yaml --rawlog ${CMAKE_BINARY_DIR}/tests/cli/emulate_cli/uav30.rawlog
          --outage 15:10 --out ${_fk}/o9 --overwrite)
set_tests_properties(cli_error_file_key_replaced_by_flag PROPERTIES FIXTURES_REQUIRED emu_rawlog
  PASS_REGULAR_EXPRESSION "6000 IMU steps at 200 Hz")

# Found by the bad-input battery (README, "Errors and exit codes"): flags checked
# against their documented ranges at the command line, NaN and sentinels
# included ('--rate nan' said "rate must be a positive number of Hz" naming no
# flag, '--rate 1e308' ran, '--seed -1' silently meant the configuration's seed,
# '--durations 1e-308' ended in "outage (30, 30] is empty"); values of a file
# beyond what navimpact reads back.
set(_x ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz)
set(_r ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog)
set(_study ${CMAKE_SOURCE_DIR}/config/paper/study_navchip_uav.yaml)
foreach(_case
    "rate_nan|wv|--input|${_x}|--rate|nan|^navimpact: --rate: must be in \\[1, 10000\\] Hz, got nan \\(see 'navimpact wv --help'\\)$"
    "rate_huge|fit|--input|${_x}|--structure|WN|--rate|1e308|--rate: must be in \\[1, 10000\\] Hz, got 1e308"
    "convert_rate|model|convert|${_m}:ref|--rate|1e308|--rate: must be in \\[1, 10000\\] Hz"
    "eff|wv|--input|${_x}|--rate|100|--robust|--eff|1|--eff: robust wavelet variance: efficiency 1 is outside what the biweight reaches"
    "seed_negative|study|--config|${_study}|--seed|-1|--seed: must be an integer seed in 0..18446744073709551615, got '-1'"
    "runs_negative|study|--config|${_study}|--runs|-1|--runs: .*not in range 1 to 1000000"
    "propagate_zero|replay|--rawlog|${_r}|--propagate-every|0|--propagate-every: .*not in range 1 to 1000"
    "gap_nan|replay|--rawlog|${_r}|--max-imu-gap|nan|--max-imu-gap: must be in \\[0, 2\\] s, got nan"
    "durations_tiny|diagnose|--run|${_r}|--model|${_m}:ref|--durations|10,1e-308|--durations: must be in \\[0.0001, 604800\\] s, got 1e-308")
  string(REPLACE "|" ";" _p "${_case}")
  list(GET _p 0 _n)
  list(GET _p -1 _re)
  list(SUBLIST _p 1 -1 _args)
  list(REMOVE_AT _args -1)
  navimpact_cli_fail(cli_error_flag_${_n} EXIT 2 ARGS ${_args} --out ${_erd}/flag_${_n} REGEX "${_re}" NOOUT ${_erd}/flag_${_n})
endforeach()
# robust WV efficiency outside what the biweight reaches: the range, not the solver's
# exception (exit 4 before), as a flag error before the file is read (exit 1 after it before)
navimpact_cli_fail(cli_error_eff_unreachable EXIT 2 ARGS wv --input ${_x} --rate 100 --gyro-unit deg/s --acc-unit g --robust --eff 1e-308 --out ${_erd}/eff
  REGEX "efficiency 1e-308 is outside what the biweight reaches \\(0.05 .. 0.999985" NOOUT ${_erd}/eff)
# a model amplitude beyond any IMU (model show printed an ARW of inf), and an
# emulation whose samples no reader would take back (replay refused its rawlog)
file(WRITE ${_erd}/huge_model.yaml "rate_hz: 100\ngyroscope: \"WN(sigma=1e308)\"\n")
navimpact_cli_fail(cli_error_model_amplitude EXIT 1 ARGS model show ${_erd}/huge_model.yaml
  REGEX "huge_model.yaml: key 'gyro_x': .*sigma = 1e\\+308 is beyond any IMU")
file(WRITE ${_erd}/big_model.yaml "rate_hz: 100\ngyroscope: \"WN(sigma=1e4)\"\n")
file(WRITE ${_erd}/big_emulation.yaml "trajectory: {file: ${_traj}, end_s: 20}\nimu: {rate_hz: 100, errors: model, model: big_model.yaml}\n")
navimpact_cli_fail(cli_error_emulated_sample_beyond_readers EXIT 1
  ARGS emulate --config ${_erd}/big_emulation.yaml --out ${_erd}/big.rawlog
  REGEX "big_emulation.yaml: key 'imu.model': the emulated IMU sample gyro_. = .* rad/s at t = .* is beyond any IMU .*<= 1000 rad/s; no reader would take the rawlog"
  NOOUT ${_erd}/big.rawlog)
# a UTC start time read partly ('0' was the year 0) and a sensor label a navimpact rawlog ignores
file(WRITE ${_erd}/utc.yaml "trajectory: {file: ${_traj}, end_s: 20}\nimu: {errors: none}\noutput: {start_utc: '2026-02-30T00:00:00Z'}\n")
navimpact_cli_fail(cli_error_start_utc EXIT 1 ARGS emulate --config ${_erd}/utc.yaml --out ${_erd}/utc.rawlog
  REGEX "utc.yaml: key 'output.start_utc': must be a UTC time YYYY-MM-DDTHH:MM:SSZ from 1970 to 2286, got '2026-02-30T00:00:00Z'$"
  NOOUT ${_erd}/utc.rawlog)
navimpact_cli_fail(cli_error_label_on_own_rawlog EXIT 1 ARGS replay --rawlog ${_r} --imu-label XSENS --out ${_erd}/label
  REGEX "uav_flight_260s_ref.rawlog: a rawlog navimpact wrote: its IMU entries are labelled 'IMU', not 'XSENS'" NOOUT ${_erd}/label)
