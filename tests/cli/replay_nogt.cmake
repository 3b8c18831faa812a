# navimpact replay of a rawlog WITHOUT ground truth (like a real flight's):
# `emulate --no-gt` on 60 s of the committed UAV excerpt, then a replay with a
# 20 s outage. An aligning phase (levelling by the GNSS velocity change over two
# 1 s intervals, heading from the GNSS course) comes first; at this launch the
# two intervals disagree (the attitude swings by tens of degrees) and the sigmas
# are raised to the disagreement; the filter starts at 2 s. solution.csv holds
# the estimate and sigmas with empty error/NEES columns, summary.json says there
# is no ground truth and has no RMS.
set(_ngdir ${CMAKE_CURRENT_BINARY_DIR}/replay_nogt_cli)
file(MAKE_DIRECTORY ${_ngdir})
navimpact_cli_uav_scenario(${_ngdir}/uav60.yaml 60 11 "ground_truth: {rate_hz: 10}\n")
add_test(NAME cli_emulate_nogt
  COMMAND ${NI} emulate --config ${_ngdir}/uav60.yaml --no-gt --out ${_ngdir}/uav60_nogt.rawlog --overwrite)
set_tests_properties(cli_emulate_nogt PROPERTIES FIXTURES_SETUP nogt_rawlog
  PASS_REGULAR_EXPRESSION "IMU 12000 samples at 200 Hz, GNSS 61 fixes, BARO 601, GT 0")

add_test(NAME cli_replay_nogt
  COMMAND ${NI} replay --rawlog ${_ngdir}/uav60_nogt.rawlog --outage 30:20 --out ${_ngdir}/out --overwrite)
set_tests_properties(cli_replay_nogt PROPERTIES FIXTURES_REQUIRED nogt_rawlog FIXTURES_SETUP nogt_replay
  PASS_REGULAR_EXPRESSION "no ground truth in the rawlog: aligning phase from 0 to 2 s.*levellings over two consecutive intervals disagree.*11600 IMU steps at 200 Hz, 38 GNSS and 581 baro updates.*outage 1 \\(20 s from 30 s\\): predicted horizontal 1-sigma at end")

navimpact_cli_check(cli_replay_nogt_outputs CHECK replay_nogt_outputs DEFINES DIR=${_ngdir}/out)
set_tests_properties(cli_replay_nogt_outputs PROPERTIES FIXTURES_REQUIRED nogt_replay)
