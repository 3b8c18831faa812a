# All-or-nothing outputs: refusal of a non-empty --out, --overwrite replacing a
# folder whole, single-file outputs staged next to the file, failing commands
# leaving nothing (not even the parents they created), and --overwrite refusing
# the current folder. Scenarios: check_output in cli_helpers.cmake.
foreach(_case refuse replace file fail cwd)
  navimpact_cli_check(cli_output_${_case} CHECK output
    DEFINES CASE=${_case} W=${CMAKE_CURRENT_BINARY_DIR}/output_${_case} SRC=${CMAKE_SOURCE_DIR})
endforeach()

# Identical inputs give identical result files (wall-clock figures only in
# timing.json): replay, a small study and a diagnosis with a navigation gain.
set(_rep ${CMAKE_CURRENT_BINARY_DIR}/reproducible)
navimpact_cli_check(cli_reproducible_replay CHECK reproducible
  DEFINES W=${_rep}/replay
  ARGS replay --config ${CMAKE_SOURCE_DIR}/config/replay/default.yaml --outage 100:30 --out @OUT@)
navimpact_cli_check(cli_reproducible_study CHECK reproducible
  DEFINES W=${_rep}/study
  ARGS study --config ${CMAKE_SOURCE_DIR}/config/paper/study_navchip_uav.yaml --runs 4 --out @OUT@)
navimpact_cli_check(cli_reproducible_diagnose CHECK reproducible
  DEFINES W=${_rep}/diagnose
  ARGS diagnose --input ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz --rate 100 --gyro-unit deg/s
       --acc-unit g --model fit:WN --trajectory ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s.csv.gz
       --outage 200:60 --nav-runs 4 --out @OUT@)
# without a trajectory too (it wrote no timing.json then; its wall time is there now)
navimpact_cli_check(cli_reproducible_diagnose_no_trajectory CHECK reproducible
  DEFINES W=${_rep}/diagnose_no_trajectory
  ARGS diagnose --input ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz --rate 100 --gyro-unit deg/s
       --acc-unit g --model fit:WN --end 600 --simulations 2 --out @OUT@)
navimpact_cli_check(cli_reproducible_diagnose_run CHECK reproducible
  DEFINES W=${_rep}/diagnose_run
  ARGS diagnose --run ${CMAKE_SOURCE_DIR}/datasets/uav_flight_260s_ref.rawlog
       --model ${CMAKE_SOURCE_DIR}/config/models/navchip_table1.yaml:ref --durations 20 --reconverge 30
       --realisations 4 --folds 3 --out @OUT@)
