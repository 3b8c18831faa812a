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

# A run killed by SIGTERM removes its staging folder before it dies (it stayed
# until the next run in that folder): once the staging folder exists, TERM; the
# exit status must say the signal ended it (128 + 15) and no staging folder remains.
set(_sig ${CMAKE_CURRENT_BINARY_DIR}/output_signal)
add_test(NAME cli_output_killed_run_removes_its_staging
  COMMAND bash -c "rm -rf '${_sig}'; mkdir -p '${_sig}' || exit 1; \
'$<TARGET_FILE:navimpact>' fit --input '${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz' --rate 100 \
--gyro-unit deg/s --acc-unit g --structure WN+GM+GM+DR --bootstrap 2000 --allow-large --out '${_sig}/o' >/dev/null 2>&1 & \
pid=$!; for i in $(seq 1 600); do ls -A '${_sig}' | grep -q navimpact-staging && break; sleep 0.05; done; \
ls -A '${_sig}' | grep -q navimpact-staging || { echo 'no staging folder appeared'; exit 1; }; \
kill -TERM $pid; wait $pid; rc=$?; [ $rc -eq 143 ] || { echo \"exit status $rc, not 143\"; exit 1; }; \
left=$(ls -A '${_sig}'); [ -z \"$left\" ] || { echo \"left behind: $left\"; exit 1; }")
