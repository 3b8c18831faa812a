# navimpact import: the committed Katwijk rover run (manifest in datasets/), the
# reference as a pose observation that rawlog-edit reads with its travelled
# distance, and bad manifests / streams (one line naming file, line and key;
# nothing written).
set(_idir ${CMAKE_CURRENT_BINARY_DIR}/import_cli)
file(MAKE_DIRECTORY ${_idir})
set(_kat ${CMAKE_SOURCE_DIR}/datasets/katwijk_rover)

add_test(NAME cli_import_katwijk
  COMMAND ${NI} import --manifest ${_kat}/manifest.yaml --out ${_idir}/katwijk.rawlog --overwrite)
set_tests_properties(cli_import_katwijk PROPERTIES FIXTURES_SETUP import_katwijk
  PASS_REGULAR_EXPRESSION "IMU 37501 samples, 300.000 s at 125 Hz.*GNSS 101 fixes \\(position only, with sigma\\).*reference 101 samples \\(position only\\).*after Unix 1448546402")

# rawlog-edit (mrpt-apps): the reference poses give the rover's path (48.6 m in README.json)
navimpact_cli_check(cli_import_rawlog_edit_distance CHECK rawlog_edit_gt_distance
  DEFINES RAWLOG=${_idir}/katwijk.rawlog ROWS=101 MIN_M=45 MAX_M=70)
set_tests_properties(cli_import_rawlog_edit_distance PROPERTIES FIXTURES_REQUIRED import_katwijk)

# RawLogViewer opens the imported real run
navimpact_cli_check(cli_import_rawlog_viewer CHECK rawlog_viewer DEFINES RAWLOG=${_idir}/katwijk.rawlog EXPECT=loaded)
set_tests_properties(cli_import_rawlog_viewer PROPERTIES FIXTURES_REQUIRED import_katwijk)

# navimpact's own readers take the imported rawlog (IMU at its real rate)
add_test(NAME cli_import_wv_reads_it
  COMMAND ${NI} wv --input ${_idir}/katwijk.rawlog --label IMU --out ${_idir}/wv --overwrite)
set_tests_properties(cli_import_wv_reads_it PROPERTIES FIXTURES_REQUIRED import_katwijk
  PASS_REGULAR_EXPRESSION "125")

# Bad input: a copy of the manifest with one defect at a time.
file(READ ${_kat}/manifest.yaml _m)
string(REPLACE "file: imu.csv.gz" "file: ${_kat}/imu.csv.gz" _m "${_m}")
string(REPLACE "file: gnss.csv" "file: ${_kat}/gnss.csv" _m "${_m}")
string(REPLACE "file: reference.csv" "file: ${_kat}/reference.csv" _m "${_m}")
# a gzip-compressed manifest imports like the plain one (as every configuration; it was read raw)
file(WRITE ${_idir}/manifest_gz/manifest.yaml "${_m}")
file(ARCHIVE_CREATE OUTPUT ${_idir}/manifest.yaml.gz PATHS ${_idir}/manifest_gz/manifest.yaml FORMAT raw COMPRESSION GZip)
add_test(NAME cli_import_gzip_manifest
  COMMAND ${NI} import --manifest ${_idir}/manifest.yaml.gz --out ${_idir}/katwijk_gz.rawlog --overwrite)
set_tests_properties(cli_import_gzip_manifest PROPERTIES PASS_REGULAR_EXPRESSION "IMU 37501 samples, 300.000 s at 125 Hz")
# TEST|FROM|TO|REGEX: the manifest (in TEST.yaml) with FROM replaced by TO
foreach(_case "bad_unit|unit: rad/s|unit: rpm|bad_unit.yaml: key 'imu.gyro.unit'.*rpm"
              "unknown_key|max_gap_s: 3.5|max_gapp_s: 3.5|unknown_key.yaml: key 'gnss.max_gapp_s': unknown key"
              "mirror_axes|axes: [-x, y, -z]|axes: [-x, y, z]|key 'imu.axes': is a mirror")
  navimpact_cli_case("${_case}" _n _from _to _re)
  string(REPLACE "${_from}" "${_to}" _bad "${_m}")
  file(WRITE ${_idir}/${_n}.yaml "${_bad}")
  navimpact_cli_fail(cli_import_${_n}
    ARGS import --manifest ${_idir}/${_n}.yaml --out ${_idir}/bad.rawlog REGEX "${_re}" NOOUT ${_idir}/bad.rawlog)
endforeach()
# TEST|FROM|TO|REGEX: a stream with a defect (the GNSS file copied to gnss_TEST.csv
# with FROM replaced by TO, named by the manifest TEST.yaml): a NaN, a repeated time
file(READ ${_kat}/gnss.csv _g)
foreach(_case "nan|0.700,3.000,1448546405.617,52.2141820426667|0.700,3.000,1448546405.617,nan|gnss_nan.csv:3: column 'lat_deg' \\(key gnss.position.lat\\): value is nan"
              "repeated_time|0.700,3.000|-2.300,3.000|gnss_repeated_time.csv:3: column 't_s' \\(key gnss.time.column\\): time repeats")
  navimpact_cli_case("${_case}" _n _from _to _re)
  string(REPLACE "${_from}" "${_to}" _bad "${_g}")
  file(WRITE ${_idir}/gnss_${_n}.csv "${_bad}")
  string(REPLACE "${_kat}/gnss.csv" "${_idir}/gnss_${_n}.csv" _bad "${_m}")
  file(WRITE ${_idir}/${_n}.yaml "${_bad}")
  navimpact_cli_fail(cli_import_${_n}
    ARGS import --manifest ${_idir}/${_n}.yaml --out ${_idir}/bad.rawlog REGEX "${_re}" NOOUT ${_idir}/bad.rawlog)
endforeach()
navimpact_cli_fail(cli_import_missing_manifest
  ARGS import --manifest ${_idir}/none.yaml --out ${_idir}/bad.rawlog
  REGEX "none.yaml: cannot open \\(No such file or directory\\)" NOOUT ${_idir}/bad.rawlog)

# The same path for emulated and measured runs: the bundled emulated UAV rawlog
# exported as CSV + manifest (datasets/uav_flight_260s_emulated/), imported and
# replayed, gives the outage of the original rawlog's replay (to 2 micrometres).
add_test(NAME cli_export_uav
  COMMAND ${NI} export --rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog --out ${_idir}/uav_export --overwrite)
set_tests_properties(cli_export_uav PROPERTIES
  PASS_REGULAR_EXPRESSION "exported IMU 52000, GNSS 261, BARO 2601, reference 2601 records")
navimpact_cli_fail(cli_export_not_a_rawlog
  ARGS export --rawlog ${_kat}/gnss.csv --out ${_idir}/bad_export
  REGEX "gnss.csv: entry 0" NOOUT ${_idir}/bad_export)
add_test(NAME cli_import_uav_emulated
  COMMAND ${NI} import --manifest ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_emulated/manifest.yaml
          --out ${_idir}/uav.rawlog --overwrite)
set_tests_properties(cli_import_uav_emulated PROPERTIES FIXTURES_SETUP import_uav
  PASS_REGULAR_EXPRESSION "IMU 52000 samples, 259.995 s at 200 Hz.*GNSS 261 fixes \\(with velocity, with sigma\\).*BARO 2601.*reference 2601 samples \\(with attitude\\)")
add_test(NAME cli_import_uav_replay
  COMMAND ${NI} replay --rawlog ${_idir}/uav.rawlog --model ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref
          --outage 200:60 --out ${_idir}/uav_replay --overwrite)
set_tests_properties(cli_import_uav_replay PROPERTIES FIXTURES_REQUIRED import_uav FIXTURES_SETUP import_uav_replay)
add_test(NAME cli_import_uav_replay_original
  COMMAND ${NI} replay --rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog --outage 200:60
          --out ${_idir}/uav_replay_original --overwrite)
set_tests_properties(cli_import_uav_replay_original PROPERTIES FIXTURES_SETUP import_uav_replay)
navimpact_cli_check(cli_import_uav_same_outage CHECK same_outage
  DEFINES A=${_idir}/uav_replay/summary.json B=${_idir}/uav_replay_original/summary.json)
set_tests_properties(cli_import_uav_same_outage PROPERTIES FIXTURES_REQUIRED import_uav_replay)

# A rawlog navimpact did not write (an Xsens driver's IMU label): a label that is
# not there is named with the labels found.
navimpact_cli_fail(cli_replay_missing_imu_label
  ARGS replay --rawlog ${CMAKE_SOURCE_DIR}/tests/data/imu_label_xsens.rawlog --imu-label NOPE --out ${_idir}/nolabel
  REGEX "imu_label_xsens.rawlog: no IMU entries with label 'NOPE' \\(labels found: XSENS \\(64\\)\\)" NOOUT ${_idir}/nolabel)
# the same label from the replay configuration (imu_label), and an empty one refused by key
file(WRITE ${_idir}/label_nope.yaml "imu_label: NOPE\n")
navimpact_cli_fail(cli_replay_config_imu_label
  ARGS replay --config ${_idir}/label_nope.yaml --rawlog ${CMAKE_SOURCE_DIR}/tests/data/imu_label_xsens.rawlog --out ${_idir}/nolabel2
  REGEX "imu_label_xsens.rawlog: no IMU entries with label 'NOPE' \\(labels found: XSENS \\(64\\)\\)" NOOUT ${_idir}/nolabel2)
file(WRITE ${_idir}/label_empty.yaml "gnss_label: ''\n")
navimpact_cli_fail(cli_replay_config_empty_label
  ARGS replay --config ${_idir}/label_empty.yaml --rawlog ${CMAKE_SOURCE_DIR}/tests/data/imu_label_xsens.rawlog --out ${_idir}/nolabel3
  REGEX "label_empty.yaml: key 'gnss_label'" NOOUT ${_idir}/nolabel3)
# The imported Katwijk run replayed (config/replay/katwijk.yaml): no GNSS fix at
# the first IMU sample and a position-only reference (the RTK antenna track):
# static levelling over the first 19 s at rest, heading from the GNSS chord,
# then 6 outages of 20 s scored against the reference at its antenna point.
navimpact_cli_check(cli_replay_katwijk_outages CHECK run_json
  ARGS replay --config ${CMAKE_SOURCE_DIR}/config/replay/katwijk.yaml --rawlog ${_idir}/katwijk.rawlog
       --outages-every 40:20 --out ${_idir}/katwijk_replay --overwrite
  DEFINES OUT=${_idir}/katwijk_replay JSON_FILE=summary.json
  JSON "alignment/levelling=^static$" "alignment/heading=^gnss_chord_course$" "outage_distribution/count=^6$"
       "reference_errors/horizontal_rms_m=^0\\.0[0-9]+" "outages/0/horizontal_error_m=^[0-9.]+"
  FILES trajectory.png outage_end_error.png)
set_tests_properties(cli_replay_katwijk_outages PROPERTIES FIXTURES_REQUIRED import_katwijk)
# The reference has a fix every 3 s: an outage whose last reference epoch lies
# before its end says where it was scored (outage 1 at 19 s of its 20 s).
add_test(NAME cli_replay_katwijk_scored_epoch
  COMMAND ${NI} replay --config ${CMAKE_SOURCE_DIR}/config/replay/katwijk.yaml --rawlog ${_idir}/katwijk.rawlog
          --outages-every 40:20 --out ${_idir}/katwijk_replay_epoch --overwrite)
set_tests_properties(cli_replay_katwijk_scored_epoch PROPERTIES FIXTURES_REQUIRED import_katwijk
  PASS_REGULAR_EXPRESSION "outage 1 \\(20 s from 41\\.712 s\\)[^\n]*\\(at 19 s of it: the last reference epoch inside\\)")
# The same with the NIS gate at 0.999: the fixes from 30.7 s on fail the gate;
# without re-admission every later fix is rejected and the run diverges (to
# kilometres); with it the filter takes the fourth fix with P inflated and
# follows the RTK track again (aided horizontal RMS below a metre).
file(READ ${CMAKE_SOURCE_DIR}/config/replay/katwijk.yaml _kcfg)
string(REPLACE "../models/" "${CMAKE_SOURCE_DIR}/config/models/" _kcfg "${_kcfg}")
file(WRITE ${_idir}/katwijk_gate.yaml "${_kcfg}filter: {gate_probability: 0.999}\n")
file(WRITE ${_idir}/katwijk_gate_locked.yaml "${_kcfg}filter: {gate_probability: 0.999, gate_readmit_after: 0}\n")
navimpact_cli_check(cli_replay_katwijk_gate_readmits CHECK run_json
  ARGS replay --config ${_idir}/katwijk_gate.yaml --rawlog ${_idir}/katwijk.rawlog
       --outages-every 40:20 --out ${_idir}/katwijk_gate --overwrite
  DEFINES OUT=${_idir}/katwijk_gate JSON_FILE=summary.json
  JSON "readmitted_updates=^[1-9][0-9]*$" "readmitted/0/kind=^gnss_position$"
       "reference_errors/horizontal_rms_m=^0\\.[0-9]+")
set_tests_properties(cli_replay_katwijk_gate_readmits PROPERTIES FIXTURES_REQUIRED import_katwijk)
# the lock-out itself, so that the test above can fail for the right reason
navimpact_cli_check(cli_replay_katwijk_gate_locks_out CHECK run_json
  ARGS replay --config ${_idir}/katwijk_gate_locked.yaml --rawlog ${_idir}/katwijk.rawlog
       --outages-every 40:20 --out ${_idir}/katwijk_gate_locked --overwrite
  DEFINES OUT=${_idir}/katwijk_gate_locked JSON_FILE=summary.json
  JSON "readmitted_updates=^0$" "reference_errors/horizontal_rms_m=^[1-9][0-9][0-9]+\\.")
set_tests_properties(cli_replay_katwijk_gate_locks_out PROPERTIES FIXTURES_REQUIRED import_katwijk)

# --overwrite never replaces an input of the run: import --out onto its own
# manifest replaced it with the rawlog (found by a probe); a copy of the run
file(COPY ${_kat}/ DESTINATION ${_idir}/own_input)
navimpact_cli_fail(cli_import_out_onto_its_manifest EXIT 1
  ARGS import --manifest ${_idir}/own_input/manifest.yaml --out ${_idir}/own_input/manifest.yaml --overwrite
  REGEX "^navimpact: [^ ]*own_input/manifest.yaml: --overwrite: it is an input of this run \\(write the output elsewhere\\)$")
