# navimpact fit on the committed ADIS16405 excerpt (100 Hz, deg/s and g).
set(_fdata ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz)
set(_fdir ${CMAKE_CURRENT_BINARY_DIR}/fit_cli)
file(MAKE_DIRECTORY ${_fdir})



add_test(NAME cli_fit_wn_gm
  COMMAND ${NI} fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GM
          --seed 7 --out ${_fdir}/wn_gm --overwrite)
set_tests_properties(cli_fit_wn_gm PROPERTIES
  PASS_REGULAR_EXPRESSION "gyro_x: WN\\(sigma=[0-9.e-]+\\) \\+ GM\\(sigma=[0-9.e-]+, T=[0-9.e+-]+\\).*objective.*ARW.*acc_z: WN"
  FIXTURES_SETUP fit_wn_gm)

# the written model file loads back through the model file reader
add_test(NAME cli_fit_model_loads COMMAND ${NI} model show ${_fdir}/wn_gm/model.yaml)
set_tests_properties(cli_fit_model_loads PROPERTIES
  PASS_REGULAR_EXPRESSION "per sample at 100 Hz.*gyro_x[^\n]*WN\\(sigma=.*GM\\(sigma=.*acc_z[^\n]*WN\\(sigma=.*GM\\("
  FIXTURES_REQUIRED fit_wn_gm)

# fit.json has the six channels, each with terms, intervals and the WV; both figures exist.
navimpact_cli_check(cli_fit_json CHECK fit_json DEFINES DIR=${_fdir}/wn_gm)
set_tests_properties(cli_fit_json PROPERTIES FIXTURES_REQUIRED fit_wn_gm)

# automatic selection on two channels prints the reason and ranks the candidates
add_test(NAME cli_fit_auto
  COMMAND ${NI} fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure auto
          --max-gm 2 --channels gyro_x,acc_z --out ${_fdir}/auto --overwrite)
set_tests_properties(cli_fit_auto PROPERTIES
  PASS_REGULAR_EXPRESSION "gyro_x: .*picked [A-Z+]+: criterion .*acc_z: .*picked [A-Z+]+: criterion")

# a bad structure string: error naming the position, no output left behind
navimpact_cli_fail(cli_fit_bad_structure
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GX+DR --out ${_fdir}/bad
  REGEX "^navimpact: .*structure.*position 4.*'GX'" NOOUT ${_fdir}/bad)

# more parameters (WN + 9 GM = 19) than the 18 scales of 2^18 samples: clear error
navimpact_cli_fail(cli_fit_too_many_parameters
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+9GM --out ${_fdir}/big
  REGEX "^navimpact: .*channel gyro_x: .*19 parameters but the wavelet variance has only 18 scales"
  NOOUT ${_fdir}/big)

# an unknown channel name is rejected
navimpact_cli_fail(cli_fit_bad_channel
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels gyro_q --out ${_fdir}/badch
  REGEX "^navimpact: --channels: unknown channel 'gyro_q'" NOOUT ${_fdir}/badch)

# --weights: default r (the R package's objective) is recorded; efficient is
# recorded with the R objective of the same model next to it; every term
# carries its negligible flag and the rule is stated (check fit_weights).

navimpact_cli_check(cli_fit_weights_default_r CHECK fit_weights DEFINES DIR=${_fdir}/wn_gm WEIGHTS=r)
set_tests_properties(cli_fit_weights_default_r PROPERTIES FIXTURES_REQUIRED fit_wn_gm)

add_test(NAME cli_fit_weights_efficient
  COMMAND ${NI} fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GM+DR
          --channels gyro_x,acc_z --weights efficient --out ${_fdir}/eff --overwrite)
set_tests_properties(cli_fit_weights_efficient PROPERTIES
  PASS_REGULAR_EXPRESSION "gyro_x: WN.*objective [0-9.e+-]+ \\(efficient weights, R objective [0-9.e+-]+\\).*acc_z: WN"
  FIXTURES_SETUP fit_eff)
navimpact_cli_check(cli_fit_weights_efficient_json CHECK fit_weights DEFINES DIR=${_fdir}/eff WEIGHTS=efficient)
set_tests_properties(cli_fit_weights_efficient_json PROPERTIES FIXTURES_REQUIRED fit_eff)

# an unknown weighting is a one-line error before any output
navimpact_cli_fail(cli_fit_bad_weights EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --weights optimal --out ${_fdir}/badw
  REGEX "^navimpact: --weights: optimal not in {r,model,efficient} \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/badw)

# A term pushed to its lower bound is reported, not hidden: on gyro_x of the
# excerpt, WN+GM+RW+DR puts the white noise into a GM with T < 1 sample and
# leaves WN at ~1e-66; the console says so and fit.json flags it.
add_test(NAME cli_fit_negligible_term
  COMMAND ${NI} fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GM+RW+DR
          --channels gyro_x --out ${_fdir}/neg --overwrite)
set_tests_properties(cli_fit_negligible_term PROPERTIES
  PASS_REGULAR_EXPRESSION "negligible: term 1 WN\\(sigma=[0-9.e-]+\\) \\(its WV is below 0.1 of the WV's 95 % CI width at every scale[^\n]*kept: the requested structure has it\\)"
  FIXTURES_SETUP fit_neg)
navimpact_cli_check(cli_fit_negligible_json CHECK fit_negligible DEFINES DIR=${_fdir}/neg)
set_tests_properties(cli_fit_negligible_json PROPERTIES FIXTURES_REQUIRED fit_neg)

# Real-record input: a time window of the record (--start/--end, seconds from
# its first sample), a named time column, the robust GMWM.
navimpact_cli_check(cli_fit_window CHECK run_json
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GM --channels gyro_x
       --start 100 --end 1100 --out ${_fdir}/window
  DEFINES OUT=${_fdir}/window JSON_FILE=fit.json QUIET=1
  JSON "input/samples=^100000$" "input/start_s=^100(\\.0*)?$" "input/end_s=^1100(\\.0*)?$" "estimator/wv=^classical"
  FILES model.yaml)
# --start -0 is the record's start, recorded as 0 (it was -0.0)
navimpact_cli_check(cli_fit_window_minus_zero CHECK run_json
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels gyro_x
       --start -0 --end 100 --out ${_fdir}/window0
  DEFINES OUT=${_fdir}/window0 JSON_FILE=fit.json QUIET=1
  JSON "input/samples=^10000$" "input/start_s=^0(\\.0*)?$")
navimpact_cli_fail(cli_fit_start_beyond_record EXIT 1 NOOUT ${_fdir}/bad_start
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --start 3000 --out ${_fdir}/bad_start
  REGEX "^navimpact: .*adis16405_static_excerpt.csv.gz: --start 3000 s is not before the end of the record \\(the record has 262144 samples, 0 to 2621.44 s at 100 Hz\\)")
navimpact_cli_fail(cli_fit_end_beyond_record EXIT 1 NOOUT ${_fdir}/bad_end
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --end 2700 --out ${_fdir}/bad_end
  REGEX "^navimpact: .*: --end 2700 s is beyond the end of the record \\(the record has 262144 samples")
navimpact_cli_fail(cli_fit_end_before_start EXIT 1 NOOUT ${_fdir}/bad_order
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --start 10 --end 5 --out ${_fdir}/bad_order
  REGEX "^navimpact: .*: --end 5 s must be after --start 10")
navimpact_cli_fail(cli_fit_time_column_missing EXIT 1 NOOUT ${_fdir}/bad_tcol
  ARGS fit --input ${_fdata} --gyro-unit deg/s --acc-unit g --structure WN --time-column stamp --out ${_fdir}/bad_tcol
  REGEX "^navimpact: .*adis16405_static_excerpt.csv.gz:1: no time column 'stamp' \\(--time-column\\) in header 'gyro_x,")

# A 200 Hz record whose time column is 'stamp' (and whose 't' column is not a time).
set(_tcsv "t,stamp,gyro_x[rad/s],acc_z[m/s2]\n")
foreach(i RANGE 0 4199)
  math(EXPR a "(${i} * 7919) % 97")
  math(EXPR b "(${i} * 104729) % 89")
  math(EXPR ms "${i} * 5")
  math(EXPR sec "${ms} / 1000")
  math(EXPR frac "${ms} % 1000")
  string(LENGTH "${frac}" _fl)
  if(_fl EQUAL 1)
    set(frac "00${frac}")
  elseif(_fl EQUAL 2)
    set(frac "0${frac}")
  endif()
  string(APPEND _tcsv "${a},${sec}.${frac},0.0${a},9.8${b}\n")
  string(APPEND _tcsv_ms "${a},${ms},0.0${a},9.8${b}\n")
endforeach()
file(WRITE ${_fdir}/stamp.csv "${_tcsv}")
# the same stamps in milliseconds: read at 200 Hz with --time-unit ms (they were seconds, a 0.2 Hz record)
file(WRITE ${_fdir}/stamp_ms.csv "t,stamp,gyro_x[rad/s],acc_z[m/s2]\n${_tcsv_ms}")
navimpact_cli_check(cli_fit_time_unit CHECK run_json
  ARGS fit --input ${_fdir}/stamp_ms.csv --time-column stamp --time-unit ms --structure WN --out ${_fdir}/tunit
  DEFINES OUT=${_fdir}/tunit JSON_FILE=fit.json
  JSON "input/rate_hz=^200(\\.0*)?$" "input/samples=^4200$" "input/time_column=^stamp$" "input/time_unit=^ms$")
navimpact_cli_check(cli_fit_time_column CHECK run_json
  ARGS fit --input ${_fdir}/stamp.csv --time-column stamp --structure WN --out ${_fdir}/tcol
  DEFINES OUT=${_fdir}/tcol JSON_FILE=fit.json
  JSON "input/rate_hz=^200(\\.0*)?$" "input/samples=^4200$" "input/time_column=^stamp$"
       "unfitted_channels/0=^gyro_y$" "unfitted_channels/3=^acc_y$"
  FILES model.yaml)
# the default time column is recorded too (it was left out without --time-column)
string(REPLACE "t,stamp,gyro_x" "n,time_s,gyro_x" _tcsv_default "${_tcsv}")
file(WRITE ${_fdir}/time_s.csv "${_tcsv_default}")
navimpact_cli_check(cli_fit_time_column_default CHECK run_json
  ARGS fit --input ${_fdir}/time_s.csv --structure WN --out ${_fdir}/tcol_default
  DEFINES OUT=${_fdir}/tcol_default JSON_FILE=fit.json
  JSON "input/rate_hz=^200(\\.0*)?$" "input/time_column=^time_s$" "input/time_unit=^s$")

# Robust GMWM: the estimator is recorded; --eff needs --robust.
navimpact_cli_check(cli_fit_robust CHECK run_json
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+GM --channels gyro_x,acc_z
       --robust --eff 0.8 --end 1000 --out ${_fdir}/robust
  DEFINES OUT=${_fdir}/robust JSON_FILE=fit.json QUIET=1
  JSON "estimator/wv=^robust" "estimator/eff=^0.8" "channels/0/name=^gyro_x$"
  FILES model.yaml)
navimpact_cli_fail(cli_fit_eff_without_robust EXIT 2 NOOUT ${_fdir}/bad_eff
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --eff 0.8 --out ${_fdir}/bad_eff
  REGEX "^navimpact: .*--eff requires --robust")

# The automatic selection (about 40 GMWM fits per channel through Ceres) on the
# whole excerpt writes nothing to stderr: no solver or logging lines.
navimpact_cli_check(cli_fit_auto_quiet CHECK run_json
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure auto --out ${_fdir}/auto_quiet
  DEFINES OUT=${_fdir}/auto_quiet JSON_FILE=fit.json QUIET=1
  JSON "structure=^auto"
  FILES model.yaml)

# --bootstrap has a range (1e9 replicates ran without end) and a channel is fitted once
navimpact_cli_fail(cli_fit_bootstrap_range EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --bootstrap 1000000000 --out ${_fdir}/boot
  REGEX "^navimpact: --bootstrap: must be in \\[0, 10000\\], got 1000000000 \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/boot)
# a "95 %" percentile interval from 5 replicates was nearly their range and
# could exclude the estimate: 0 or at least 39 ((N + 1) * 0.025 >= 1)
navimpact_cli_fail(cli_fit_bootstrap_too_few EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --bootstrap 5 --out ${_fdir}/boot5
  REGEX "^navimpact: --bootstrap: must be 0 or at least 39 \\(a 95 % percentile interval needs \\(N \\+ 1\\) \\* 0.025 >= 1\\), got 5 \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/boot5)
navimpact_cli_fail(cli_fit_channel_twice
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels gyro_x,gyro_x --out ${_fdir}/twice
  REGEX "^navimpact: --channels: 'gyro_x' is listed twice$" NOOUT ${_fdir}/twice)
# flags that were ignored without a word: an empty channel entry (fitted every
# channel), --intervals beside a bootstrap (its percentile intervals were
# written), an unknown --intervals (exit 1 after reading), an --eff the biweight
# does not reach (failed after reading, blaming the file)
navimpact_cli_fail(cli_fit_channels_empty_entry EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels , --out ${_fdir}/empty_ch
  REGEX "^navimpact: --channels: ',' has an empty entry \\(expected channel names separated by commas, e.g. gyro_x,acc_z\\) \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/empty_ch)
navimpact_cli_fail(cli_fit_intervals_with_bootstrap EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --intervals asymptotic --bootstrap 40 --out ${_fdir}/int_boot
  REGEX "^navimpact: --intervals: applies without --bootstrap .* \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/int_boot)
navimpact_cli_fail(cli_fit_intervals_unknown EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --intervals foo --out ${_fdir}/int_foo
  REGEX "^navimpact: --intervals: foo not in {profile,asymptotic} \\(see 'navimpact fit --help'\\)$" NOOUT ${_fdir}/int_foo)
# flags that meant nothing: --max-gm beside a fixed structure, --channels naming none ("" or blank: it fitted all)
navimpact_cli_fail(cli_fit_max_gm_fixed_structure EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN+RW --max-gm 2 --out ${_fdir}/maxgm
  REGEX "^navimpact: --max-gm: applies to --structure auto \\(the structure WN\\+RW fixes its GM terms\\)" NOOUT ${_fdir}/maxgm)
navimpact_cli_fail(cli_fit_channels_empty EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels " " --out ${_fdir}/chempty
  REGEX "^navimpact: --channels: names no channel \\(leave the flag out to fit all\\)" NOOUT ${_fdir}/chempty)
navimpact_cli_fail(cli_fit_eff_unreachable EXIT 2
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --robust --eff 0.001 --out ${_fdir}/eff_low
  REGEX "^navimpact: --eff: robust wavelet variance: efficiency 0\\.001 is outside what the biweight reaches" NOOUT ${_fdir}/eff_low)
# --bootstrap 0 with --intervals is the asymptotic path, not a conflict
add_test(NAME cli_fit_intervals_bootstrap_zero
  COMMAND ${NI} fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --channels gyro_x
          --bootstrap 0 --intervals asymptotic --out ${_fdir}/int_b0 --overwrite)
set_tests_properties(cli_fit_intervals_bootstrap_zero PROPERTIES PASS_REGULAR_EXPRESSION "gyro_x: WN\\(sigma=")
