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
navimpact_cli_fail(cli_fit_bad_weights
  ARGS fit --input ${_fdata} --rate 100 --gyro-unit deg/s --acc-unit g --structure WN --weights optimal --out ${_fdir}/badw
  REGEX "^navimpact: --weights: expected 'r', 'model' or 'efficient', got 'optimal'" NOOUT ${_fdir}/badw)

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
