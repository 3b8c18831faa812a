# navimpact study / study-merge: a short study writes every output; shards
# merged give the same metrics as one unsharded study; bad input is one clear
# error before any run, with no output folder left behind.
set(_sdir ${CMAKE_CURRENT_BINARY_DIR}/study)
file(MAKE_DIRECTORY ${_sdir})
set(_sm ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml)
set(_straj ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)

function(_study_cfg name outage_start outage_dur gyro_model)
  file(WRITE ${_sdir}/${name}.yaml "trajectory: {file: ${_straj}, end_s: 40}
imu: {rate_hz: 100}
truth: {errors: model, model: ${_sm}:ref}
candidates:
  - {label: Gyro 1, gyroscope: ${_sm}:${gyro_model}}
  - {label: Ref both, model: ${_sm}:ref}
outages: [{start_s: ${outage_start}, duration_s: ${outage_dur}}]
monte_carlo: {runs: 3, seed: 5}
")
endfunction()
_study_cfg(short 20 15 gyro_model1)
_study_cfg(outage_late 30 15 gyro_model1)
_study_cfg(bad_model 20 15 gyro_model9)

navimpact_cli_check(cli_study_short_and_shards CHECK study_shards
  DEFINES CONFIG=${_sdir}/short.yaml D=${_sdir}/out)

function(_study_bad name args regex)
  string(REPLACE "|" ";" args "${args}")
  navimpact_cli_fail(cli_study_bad_${name} ARGS ${args} REGEX "${regex}" NOOUT ${_sdir}/out_${name})
endfunction()
_study_bad(outage_outside "study|--config|${_sdir}/outage_late.yaml|--out|${_sdir}/out_outage_outside"
           "outage_late.yaml: key 'outages': outage .* ends at .* s, after the end of the trajectory")
_study_bad(zero_runs "study|--config|${_sdir}/short.yaml|--out|${_sdir}/out_zero_runs|--runs|0"
           "--runs: Value 0 not in range 1 to 1000000")
_study_bad(missing_model "study|--config|${_sdir}/bad_model.yaml|--out|${_sdir}/out_missing_model"
           "candidate 'Gyro 1'.*gyro_model9")
_study_bad(unreadable "study|--config|${_sdir}/no_such_file.yaml|--out|${_sdir}/out_unreadable"
           "no_such_file.yaml")
_study_bad(bad_shard "study|--config|${_sdir}/short.yaml|--out|${_sdir}/out_bad_shard|--shard|3/2"
           "--shard: '3/2': expected K/N")
_study_bad(merge_missing "study-merge|${_sdir}/no_such_shard|--out|${_sdir}/out_merge_missing"
           "no_such_shard/shard.json")
# work and memory are estimated before the first run (found by a bad-input
# probe: --runs 1000000 ran for weeks of CPU; 8 workers at 10 kHz held 2.5 GB
# within 30 s): refused naming the runs, unless --allow-large
_study_bad(runs_budget "study|--config|${_sdir}/short.yaml|--out|${_sdir}/out_runs_budget|--runs|1000000"
           "^navimpact: study: 1e\\+06 runs: the runs would need about 1.2e\\+10 IMU steps .4e\\+03 samples x 3 .emulation and filters. per run., above the budget of 2e\\+09 IMU steps: lower --runs .monte_carlo.runs. or run shards .--shard K/N., or pass --allow-large$")
file(READ ${_sdir}/short.yaml _s10k)
string(REPLACE "end_s: 40}" "end_s: 130}" _s10k "${_s10k}")
string(REPLACE "rate_hz: 100}" "rate_hz: 10000}" _s10k "${_s10k}")
file(WRITE ${_sdir}/fast_imu.yaml "${_s10k}")
_study_bad(memory_budget "study|--config|${_sdir}/fast_imu.yaml|--out|${_sdir}/out_memory_budget|--runs|16|--threads|16"
           "^navimpact: study: 16 runs: the workers would need about 2.63e\\+03 MB .16 workers x 1.3e\\+06 samples., above the budget of 2e\\+03 MB: lower --threads or imu.rate_hz, or pass --allow-large$")
