# navimpact diagnose: end-to-end run on the committed ADIS16405 excerpt and
# bad-input errors (one clear line, exit 1, no output directory left behind).
set(_dg_data ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz)
set(_dg_out ${CMAKE_CURRENT_BINARY_DIR}/diagnose_out)
set(_dg_u --rate 100 --gyro-unit deg/s --acc-unit g)

# Full run with a white-noise-only model fitted to the data: the excerpt's
# slow processes make it inadequate; all outputs are written and the extended
# model file loads back.
navimpact_cli_check(cli_diagnose_excerpt_wn CHECK diagnose_excerpt DEFINES DATA=${_dg_data} OUT=${_dg_out}/wn)

# The whole ADIS16405 recording 1 (tests/data) with fit:auto: its models have
# long GMs and drifts, whose retuning the slow decision decides (it crashed
# there, reading the exact-likelihood terms of a retuned slow term it had not
# fitted). Diagnosed to the end, every output written.
add_test(NAME cli_diagnose_adis_recording_fit_auto
  COMMAND ${NI} diagnose --input ${CMAKE_SOURCE_DIR}/tests/data/adis16405_static_1.csv.gz ${_dg_u} --model fit:auto
          --out ${_dg_out}/adis1_auto --overwrite)
set_tests_properties(cli_diagnose_adis_recording_fit_auto PROPERTIES
  PASS_REGULAR_EXPRESSION "wrote .*diagnosis.json, report.md, model_extended.yaml")

# Bad input: each fails before any work with a one-line error naming the problem.
navimpact_cli_fail(cli_diagnose_missing_model EXIT 1 NOOUT ${_dg_out}/bad1
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model /nonexistent/model.yaml --out ${_dg_out}/bad1
  REGEX "^navimpact: .*nonexistent/model.yaml")
navimpact_cli_fail(cli_diagnose_bad_structure EXIT 1 NOOUT ${_dg_out}/bad2
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN+XYZ --out ${_dg_out}/bad2
  REGEX "^navimpact: .*XYZ")
navimpact_cli_fail(cli_diagnose_outage_without_trajectory EXIT 1 NOOUT ${_dg_out}/bad3
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --outage 100:30 --out ${_dg_out}/bad3
  REGEX "^navimpact: --outage needs --trajectory")
# a flag of the other mode is a command-line error (it was ignored, exit 0)
navimpact_cli_fail(cli_diagnose_run_with_static_flag EXIT 2 NOOUT ${_dg_out}/bad_mode1
  ARGS diagnose --run ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog --model ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref
       --end 50 --out ${_dg_out}/bad_mode1
  REGEX "^navimpact: --end excludes --run \\(see 'navimpact diagnose --help'\\)$")
navimpact_cli_fail(cli_diagnose_input_with_run_flag EXIT 2 NOOUT ${_dg_out}/bad_mode2
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --realisations 5 --out ${_dg_out}/bad_mode2
  REGEX "^navimpact: --realisations requires --run \\(see 'navimpact diagnose --help'\\)$")
navimpact_cli_fail(cli_diagnose_bad_outage EXIT 2 NOOUT ${_dg_out}/bad4
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --trajectory ${_dg_data} --outage abc --out ${_dg_out}/bad4
  REGEX "^navimpact: --outage: 'abc': expected START:DURATION")
navimpact_cli_fail(cli_diagnose_missing_unit EXIT 1 NOOUT ${_dg_out}/bad5
  ARGS diagnose --input ${_dg_data} --rate 100 --model fit:WN --out ${_dg_out}/bad5
  REGEX "^navimpact: .*unit")

# A record of 999 samples (written here) with a white-noise model.
set(_dg_short ${CMAKE_CURRENT_BINARY_DIR}/diagnose_short)
file(MAKE_DIRECTORY ${_dg_short})
set(_csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n")
foreach(i RANGE 1 999)
  math(EXPR a "${i} % 7")
  string(APPEND _csv "0.0${a},0.01,-0.02,0.001,0.002,1.0${a}\n")
endforeach()
file(WRITE ${_dg_short}/short.csv "${_csv}")
file(WRITE ${_dg_short}/model.yaml "rate_hz: 100\naccelerometer: \"WN(sigma=1e-2)\"\ngyroscope: \"WN(sigma=1e-3)\"\n")
set(_dg_short_args diagnose --input ${_dg_short}/short.csv ${_dg_u} --model ${_dg_short}/model.yaml)
navimpact_cli_fail(cli_diagnose_short_record EXIT 1 NOOUT ${_dg_out}/bad6
  ARGS ${_dg_short_args} --out ${_dg_out}/bad6
  REGEX "^navimpact: .*samples; diagnose needs at least 4096")

# MRPT rawlog input through the shared loader (--label): the committed UAV
# rawlog (200 Hz, 52,000 IMU samples; it moves, so the model is inadequate,
# but this test is about reading it).
set(_dg_rawlog ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog)
navimpact_cli_check(cli_diagnose_rawlog CHECK run_json
  ARGS diagnose --input ${_dg_rawlog} --label IMU --model fit:WN --simulations 2 --out ${_dg_out}/rawlog
  DEFINES OUT=${_dg_out}/rawlog JSON_FILE=diagnosis.json
  JSON "input/format=^rawlog$" "input/samples=^52000$" "input/rate_hz=^(200\\.0*|199\\.99)" "input/label=^IMU$"
  FILES report.md model_extended.yaml)
navimpact_cli_fail(cli_diagnose_rawlog_bad_label EXIT 1 NOOUT ${_dg_out}/bad7
  ARGS diagnose --input ${_dg_rawlog} --label XSENS --model fit:WN --out ${_dg_out}/bad7
  REGEX "^navimpact: .*no CObservationIMU with label 'XSENS'")

# Navigation gain along the committed UAV excerpt with the excerpt's measured
# errors as the truth: before/after per outage, NEES band, figure.
set(_dg_traj ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz)
navimpact_cli_check(cli_diagnose_navigation CHECK run_json
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --simulations 2 --trajectory ${_dg_traj}
       --outage 100:30 --outage 200:40 --nav-runs 4 --out ${_dg_out}/nav
  DEFINES OUT=${_dg_out}/nav JSON_FILE=diagnosis.json
  JSON "navigation/outages/1/start_s=^200(\\.0*)?$" "navigation/outages/1/duration_s=^40(\\.0*)?$"
       "navigation/outages/0/horizontal_error_m/before=^[0-9]" "navigation/outages/0/horizontal_error_m/after=^[0-9]"
       "navigation/outages/0/nees/band/1=^[0-9]" "navigation/runs=^4$"
  FILES navigation_error.png report.md)
navimpact_cli_fail(cli_diagnose_outage_past_trajectory EXIT 1 NOOUT ${_dg_out}/bad8
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --trajectory ${_dg_traj} --outage 250:30 --out ${_dg_out}/bad8
  REGEX "^navimpact: --outage 250:30 ends at 280 s, after the end of the trajectory")
navimpact_cli_fail(cli_diagnose_recording_shorter_than_trajectory EXIT 1 NOOUT ${_dg_out}/bad9
  ARGS ${_dg_short_args} --out ${_dg_out}/bad9 --trajectory ${_dg_traj} --outage 100:30
  REGEX "^navimpact: static recording too short for the navigation gain: 9.99 s available, 2.* s needed")

# Detection-power sweep: a tiny run writes its table and records every run;
# bad flags fail before any work.
navimpact_cli_check(cli_diagnose_power_small CHECK diagnose_power DEFINES OUT=${_dg_out}/power)
navimpact_cli_fail(cli_diagnose_power_bad_cause EXIT 2 NOOUT ${_dg_out}/bad10
  ARGS diagnose-power --out ${_dg_out}/bad10 --causes sinusoid,wobble
  REGEX "^navimpact: --causes: unknown cause 'wobble' .*\\(see 'navimpact diagnose-power --help'\\)$")
navimpact_cli_fail(cli_diagnose_power_bad_snr EXIT 2 NOOUT ${_dg_out}/bad11
  ARGS diagnose-power --out ${_dg_out}/bad11 --snr 5
  REGEX "^navimpact: --snr: '5': expected LO:HI")
# diagnose-power's counts, rates and record lengths have ranges and budgets,
# checked before any record is drawn (found by a bad-input probe: --runs 1e9
# held 11.6 GB within 30 s, --samples 1e12 ended in "out of memory" (exit 3),
# --rate 1e-300 wrote a duration of 4e303 s with exit 0)
# NAME|EXIT|ARGS|REGEX: library checks are exit 1 ("diagnose-power: ..."), flag ranges exit 2 naming the flag
foreach(_case "range_samples|1|--samples 1000000000000:1000000000000|diagnose-power: the records would need about [0-9.e+]+ simulated samples .* or pass --allow-large$"
              "range_memory|1|--samples 100000000:100000000 --runs 1 --null-runs 1|diagnose-power: the records held at once would need about .* MB .* lower --samples or --threads, or pass --allow-large$"
              "range_rate|2|--rate 1e-300:1e-300|--rate: '1e-300:1e-300': rates must be in \\[1, 10000\\] Hz \\(see 'navimpact diagnose-power --help'\\)$"
              "range_nothing|1|--runs 0 --null-runs 0|diagnose-power: --runs and --null-runs are both 0: no record to diagnose$"
              "range_twice|1|--causes random_walk,random_walk|diagnose-power: --causes: 'random_walk' is listed twice$"
              "flag_runs|2|--runs 1000000000|--runs: must be in \\[0, 1e\\+06\\], got 1000000000 \\(see 'navimpact diagnose-power --help'\\)$"
              "flag_threads|2|--threads -1|--threads: must be in \\[0, 1024\\], got -1 \\(see 'navimpact diagnose-power --help'\\)$"
              "flag_alpha|2|--alpha nan|--alpha: must be in \\[1e-10, 0.5\\), got nan \\(see 'navimpact diagnose-power --help'\\)$")
  navimpact_cli_case("${_case}" _n _exit _args _re)
  separate_arguments(_args)
  navimpact_cli_fail(cli_diagnose_power_${_n} EXIT ${_exit} NOOUT ${_dg_out}/pw_${_n}
    ARGS diagnose-power --out ${_dg_out}/pw_${_n} ${_args}
    REGEX "^navimpact: ${_re}")
endforeach()

# diagnose's --alpha below 1e-10 underflowed to a per-test level of 0 and failed
# after reading the input with "detectOutliers: alpha must be in (0, 1)", naming
# the file; --simulations 1 failed late (exit 1): both are flags out of range
navimpact_cli_fail(cli_diagnose_flag_alpha_tiny EXIT 2 NOOUT ${_dg_out}/bad_alpha
  ARGS ${_dg_short_args} --alpha 4.9e-324 --out ${_dg_out}/bad_alpha
  REGEX "^navimpact: --alpha: must be in \\[1e-10, 0.5\\), got 4.9e-324")
navimpact_cli_fail(cli_diagnose_flag_one_simulation EXIT 2 NOOUT ${_dg_out}/bad_sim1
  ARGS ${_dg_short_args} --simulations 1 --out ${_dg_out}/bad_sim1
  REGEX "^navimpact: --simulations: must be 0 or at least 2")

# --model fit:auto: each channel's structure chosen by the WIC first (on the
# first 600 s of the excerpt, --end); --robust applies to fit:SPEC only.
navimpact_cli_check(cli_diagnose_fit_auto CHECK run_json
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:auto --end 600 --simulations 2 --out ${_dg_out}/auto
  DEFINES OUT=${_dg_out}/auto JSON_FILE=diagnosis.json QUIET=1
  JSON "input/model=^fit:auto$" "input/end_s=^600(\\.0*)?$"
  FILES report.md model_extended.yaml)
navimpact_cli_fail(cli_diagnose_robust_needs_fit EXIT 1 NOOUT ${_dg_out}/bad_robust
  ARGS ${_dg_short_args} --robust --out ${_dg_out}/bad_robust
  REGEX "^navimpact: --robust applies to --model fit:SPEC")

# diagnose --run: a run with a reference (the committed emulated UAV rawlog)
# against the simulation with its own model; outputs and contract keys.
set(_dg_model ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref)
navimpact_cli_check(cli_diagnose_run CHECK run_json
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_model} --durations 20,40 --reconverge 30 --realisations 4
       --out ${_dg_out}/run
  DEFINES OUT=${_dg_out}/run JSON_FILE=run_diagnosis.json
  JSON "verdict=^(adequate|inadequate|undetermined)$" "verdict_test/resolution_factor=^[0-9]" "comparisons/0/quantity=^horizontal_position$" "comparisons/0/duration_s=^20"
       "comparisons/0/ratio_interval/1=^[0-9]" "durations/1/duration_s=^40" "simulation/realisations=^4$"
       "gain/significant=^(true|false|ON|OFF)$" "gain/outage_error_before_m=^[0-9]"
  FILES report.md predicted_vs_measured.png)
navimpact_cli_fail(cli_diagnose_run_fit_model EXIT 1 NOOUT ${_dg_out}/bad11
  ARGS diagnose --run ${_dg_rawlog} --model fit:WN --out ${_dg_out}/bad11
  REGEX "^navimpact: --run needs --model FILE")
navimpact_cli_fail(cli_diagnose_run_too_long EXIT 1 NOOUT ${_dg_out}/bad12
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_model} --durations 400 --out ${_dg_out}/bad12
  REGEX "^navimpact: .*no outage of 400 s")
navimpact_cli_fail(cli_diagnose_neither_input_nor_run EXIT 1 NOOUT ${_dg_out}/bad13
  ARGS diagnose --model ${_dg_model} --out ${_dg_out}/bad13
  REGEX "^navimpact: diagnose needs --input")
# identical inputs, identical power.md / power.json (the cost only in timing.json)
navimpact_cli_check(cli_reproducible_diagnose_power CHECK reproducible
  DEFINES W=${_dg_out}/power_twice
  ARGS diagnose-power --out @OUT@ --runs 2 --null-runs 1 --snr 5:5 --samples 8192:16384
       --causes sinusoid,level_shift,outliers --threads 2)

# Counts that size work and memory (found by the bad-input battery: '--nav-runs
# 2000000000' held 17.7 GB within a minute, '--simulations 2000000000' and
# 'diagnose --run --realisations 100000000' ran without end): a range, then
# the estimated work against the documented budget, before any long work;
# nothing is written. '--folds' above the run's outages is one fold per outage
# with a notice (the fold count no longer sizes memory).
set(_dg_nav --trajectory ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz --outage 200:60)
set(_dg_ref ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref)
navimpact_cli_fail(cli_diagnose_nav_runs_range EXIT 2 NOOUT ${_dg_out}/bud1
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model ${_dg_ref} ${_dg_nav} --nav-runs 2000000000 --out ${_dg_out}/bud1
  REGEX "^navimpact: --nav-runs: must be in \\[2, 1e\\+06\\], got 2000000000 \\(see 'navimpact diagnose --help'\\)$")
navimpact_cli_fail(cli_diagnose_nav_runs_budget EXIT 1 NOOUT ${_dg_out}/bud2
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model ${_dg_ref} ${_dg_nav} --nav-runs 100000 --out ${_dg_out}/bud2
  REGEX "^navimpact: navigation gain: --nav-runs 100000: the runs would need about 7.8e\\+09 IMU steps .* above the budget of 2e\\+09 IMU steps: lower --nav-runs, or pass --allow-large$")
navimpact_cli_fail(cli_diagnose_simulations_range EXIT 2 NOOUT ${_dg_out}/bud3
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model ${_dg_ref} --simulations 2000000000 --out ${_dg_out}/bud3
  REGEX "^navimpact: --simulations: must be in \\[0, 1e\\+06\\], got 2000000000 \\(see 'navimpact diagnose --help'\\)$")
navimpact_cli_fail(cli_diagnose_simulations_budget EXIT 1 NOOUT ${_dg_out}/bud4
  ARGS diagnose --input ${_dg_data} ${_dg_u} --model fit:WN --simulations 100000 --out ${_dg_out}/bud4
  REGEX "^navimpact: diagnose: --simulations 100000: the model's simulations would need about 1.57e\\+11 simulated samples .*above the budget of 2e\\+10 simulated samples: lower --simulations, or pass --allow-large$")
navimpact_cli_fail(cli_diagnose_run_realisations_range EXIT 2 NOOUT ${_dg_out}/bud5
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_ref} --realisations 100000000 --out ${_dg_out}/bud5
  REGEX "^navimpact: --realisations: must be in \\[2, 1e\\+06\\], got 100000000 \\(see 'navimpact diagnose --help'\\)$")
# The run's memory, estimated before its replays: the run and 1000 workers of
# 1000 realisations (52,000 samples x (120 + 180 x 1000) bytes, 9.4 GB)
navimpact_cli_fail(cli_diagnose_run_memory_budget EXIT 1 NOOUT ${_dg_out}/bud6
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_ref} --realisations 1000 --threads 1000 --out ${_dg_out}/bud6
  REGEX "^navimpact: [^ ]*uav_flight_260s_ref.rawlog: diagnose --run would need about [0-9.e+]+ MB \\([0-9.e+]+ samples x \\(120 \\+ 180 x 1000 workers\\) bytes\\), above the budget of 2e\\+03 MB: lower --threads or diagnose an excerpt of the run, or pass --allow-large$")
# --durations: a handful, each once, each in [0.1 ms, 7 days] (2000 durations held 1.3 GB and ran on)
navimpact_cli_fail(cli_diagnose_run_durations_twice EXIT 1 NOOUT ${_dg_out}/dur1
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_ref} --durations 30,30 --out ${_dg_out}/dur1
  REGEX "^navimpact: diagnose --run: --durations: 30 s is listed twice$")
navimpact_cli_fail(cli_diagnose_run_durations_many EXIT 1 NOOUT ${_dg_out}/dur2
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_ref} --durations 1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17 --out ${_dg_out}/dur2
  REGEX "^navimpact: diagnose --run: --durations: at most 16 outage durations, got 17$")
navimpact_cli_fail(cli_diagnose_run_realisations_budget EXIT 1 NOOUT ${_dg_out}/bud6
  ARGS diagnose --run ${_dg_rawlog} --model ${_dg_ref} --durations 10 --realisations 1000000 --out ${_dg_out}/bud6
  REGEX "^navimpact: diagnose --run: --realisations 1000000: the simulation would need about .* IMU steps .* above the budget of 2e\\+09 IMU steps: lower --realisations or --durations, or pass --allow-large$")
add_test(NAME cli_diagnose_run_folds_above_outages
  COMMAND ${NI} diagnose --run ${_dg_rawlog} --model ${_dg_ref} --durations 10 --realisations 2 --folds 1000
          --out ${_dg_out}/folds --overwrite)
set_tests_properties(cli_diagnose_run_folds_above_outages PROPERTIES
  PASS_REGULAR_EXPRESSION "notice: --folds 1000 is more than the run's 6 outages: 6 folds")
