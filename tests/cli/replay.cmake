# navimpact replay: the default job on the committed rawlog (60 s outage after
# 200 s), an outage beyond the data, and a file that is not a rawlog.
set(_rdir ${CMAKE_CURRENT_BINARY_DIR}/replay_cli)
file(MAKE_DIRECTORY ${_rdir})

add_test(NAME cli_replay_default
  COMMAND ${NI} replay --config ${CMAKE_SOURCE_DIR}/config/replay/default.yaml --out ${_rdir}/default --overwrite)
set_tests_properties(cli_replay_default PROPERTIES PASS_REGULAR_EXPRESSION
  "52000 IMU steps at 200 Hz, 201 GNSS and 2601 baro updates.*outage 1 \\(60 s from 200 s\\): horizontal error at end")
navimpact_cli_check(cli_replay_default_outputs CHECK replay_outputs DEFINES DIR=${_rdir}/default)
set_tests_properties(cli_replay_default_outputs PROPERTIES DEPENDS cli_replay_default)
# an outage between two GNSS fixes (1 Hz) withholds none: said, not scored as a GNSS gap silently
add_test(NAME cli_replay_outage_between_fixes
  COMMAND ${NI} replay --rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog --outage 100.2:0.5
          --out ${_rdir}/between --overwrite)
set_tests_properties(cli_replay_outage_between_fixes PROPERTIES PASS_REGULAR_EXPRESSION
  "notice: outage 100.2:0.5 withheld no GNSS fix \\(none falls inside it\\)")

set(_rlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog)
navimpact_cli_fail(cli_replay_outage_outside_data
  ARGS replay --rawlog ${_rlog} --outage 230:60 --out ${_rdir}/late
  REGEX "^navimpact: --outage 230:60 ends at 290 s, after the data" NOOUT ${_rdir}/late)
navimpact_cli_fail(cli_replay_overlapping_outages_name_the_key
  ARGS replay --config ${CMAKE_SOURCE_DIR}/tests/data/bad/replay_overlapping_outages.yaml --out ${_rdir}/overlap
  REGEX "replay_overlapping_outages.yaml:[0-9:]* key 'outages.1.': outage 150:30 starts before the previous outage ends at 160 s"
  NOOUT ${_rdir}/overlap)
navimpact_cli_fail(cli_replay_bad_outage_text
  ARGS replay --rawlog ${_rlog} --outage 200-60 --out ${_rdir}/badtext
  REGEX "expected START:DURATION" NOOUT ${_rdir}/badtext)
navimpact_cli_fail(cli_replay_not_a_rawlog
  ARGS replay --rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz --out ${_rdir}/notraw
  REGEX "uav_flight_260s.csv.gz: entry 0" NOOUT ${_rdir}/notraw)

# Outages all along the committed rawlog, scored against its GT: 6 outages of
# 15 s every 40 s from the start, the summary's reference_errors and flat
# per-outage keys, the outage-end and trajectory figures; a bad pattern is refused.
navimpact_cli_check(cli_replay_outages_every CHECK run_json
  ARGS replay --rawlog ${_rlog} --outages-every 40:15 --out ${_rdir}/every --overwrite
  DEFINES OUT=${_rdir}/every JSON_FILE=summary.json
  JSON "outage_distribution/count=^6$" "outages/5/start_s=^225(\\.0*)?$" "outages/0/duration_s=^15(\\.0*)?$"
       "reference_errors/horizontal_rms_m=^0\\.[0-9]+" "outages/0/horizontal_error_m=^[0-9.]+" "outages/0/nees=^[0-9.]+"
  FILES trajectory.png outage_end_error.png errors_full.png)
navimpact_cli_fail(cli_replay_outages_every_bad
  ARGS replay --rawlog ${_rlog} --outages-every 15:40 --out ${_rdir}/everybad
  REGEX "PERIOD > DURATION" NOOUT ${_rdir}/everybad)
# the flags have the configuration's ranges (durations [0.1 ms, 7 days]): a
# period of 1e-300 s made windows that never advanced (8 GB in 14 s)
navimpact_cli_fail(cli_replay_outages_every_tiny EXIT 2
  ARGS replay --rawlog ${_rlog} --outages-every 1e-300:1e-301 --out ${_rdir}/everytiny
  REGEX "^navimpact: --outages-every: outages every '1e-300:1e-301': PERIOD and DURATION must be in \\[0.0001, 604800\\] s, PERIOD > DURATION" NOOUT ${_rdir}/everytiny)
navimpact_cli_fail(cli_replay_outage_tiny EXIT 2
  ARGS replay --rawlog ${_rlog} --outage 25:0.00001 --out ${_rdir}/outagetiny
  REGEX "^navimpact: --outage: '25:0.00001': START must be in \\[0, 1e\\+10\\] s and DURATION in \\[0.0001, 604800\\] s \\(see 'navimpact replay --help'\\)$" NOOUT ${_rdir}/outagetiny)
# a period whose windows exceed the most outages of one run (1e6) is refused
# when the count passes it, naming the rawlog (1.3e6 windows over 260 s)
navimpact_cli_fail(cli_replay_outages_every_too_many
  ARGS replay --rawlog ${_rlog} --outages-every 0.0002:0.0001 --out ${_rdir}/everymany
  REGEX "uav_flight_260s_ref.rawlog: outages every 0.0002:0.0001 s make more than 1e\\+06 outages over the run" NOOUT ${_rdir}/everymany)

# A gate below the chi-square median would reject most innovations of a
# consistent filter: refused at load, naming the key.
file(WRITE ${_rdir}/gate_tiny.yaml "rawlog: ${_rlog}\nfilter: {gate_probability: 1e-308}\n")
navimpact_cli_fail(cli_replay_gate_below_median
  ARGS replay --config ${_rdir}/gate_tiny.yaml --out ${_rdir}/gate_tiny
  REGEX "gate_tiny.yaml: key 'filter.gate_probability': must be 0 \\(gate off\\) or in .0.5, 1." NOOUT ${_rdir}/gate_tiny)

# A positive value below its realistic lower bound is refused at load, naming
# the key (a sigma of 1e-300 squared to 0 and failed at t = 0 naming no file or
# key; an outage of 1e-300 s was reported as 'outage 100:0').
foreach(_case "noise_tiny|noise: {sigma_pos_h_m: 1e-300}|key 'noise.sigma_pos_h_m': must be in .0.0001, 10000. m, got 1e-300"
              "outage_tiny|outages: [{start_s: 100, duration_s: 1e-300}]|key 'outages.0..duration_s': must be in .0.0001, 604800. s, got 1e-300"
              "prior_tiny|filter: {extra_states: {time_offset: {sigma_s: 1e-9}}}|key 'filter.extra_states.time_offset.sigma_s': must be in .1e-07, 0.1. s, got 1e-09")
  string(REPLACE "|" ";" _p "${_case}")
  list(GET _p 0 _n)
  list(GET _p 1 _body)
  list(GET _p 2 _re)
  file(WRITE ${_rdir}/${_n}.yaml "rawlog: ${_rlog}\n${_body}\n")
  navimpact_cli_fail(cli_replay_range_${_n} ARGS replay --config ${_rdir}/${_n}.yaml --out ${_rdir}/${_n}
    REGEX "${_n}.yaml: ${_re}$" NOOUT ${_rdir}/${_n})
endforeach()

# A configuration without rawlog: names the configuration and the key (it said
# only 'replay: no rawlog given').
file(WRITE ${_rdir}/no_rawlog.yaml "outages: [{start_s: 100, duration_s: 10}]\n")
navimpact_cli_fail(cli_replay_config_without_rawlog ARGS replay --config ${_rdir}/no_rawlog.yaml --out ${_rdir}/no_rawlog
  REGEX "no_rawlog.yaml: key 'rawlog': missing \\(the rawlog to replay, or --rawlog\\)$" NOOUT ${_rdir}/no_rawlog)
