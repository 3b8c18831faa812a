# navimpact wv: positive run on the committed ADIS16405 excerpt, and bad input
# (each: non-zero exit, a one-line error naming the file, no output directory).
set(_wv_dir ${CMAKE_CURRENT_BINARY_DIR}/wv_cli)
set(_wv_data ${CMAKE_SOURCE_DIR}/datasets/adis16405_static_excerpt.csv.gz)
file(MAKE_DIRECTORY ${_wv_dir})

add_test(NAME cli_wv_excerpt
  COMMAND ${NI} wv --input ${_wv_data} --rate 100 --gyro-unit deg/s --acc-unit g --allan
          --out ${_wv_dir}/excerpt --overwrite)
set_tests_properties(cli_wv_excerpt PROPERTIES
  PASS_REGULAR_EXPRESSION "262144 samples at 100 Hz, 18 scales")
# Excerpt: 262144 samples -> 18 scales, six channels; outputs present.
navimpact_cli_check(cli_wv_excerpt_outputs CHECK wv_json DEFINES DIR=${_wv_dir}/excerpt)
set_tests_properties(cli_wv_excerpt_outputs PROPERTIES DEPENDS cli_wv_excerpt)

# A time window (--start 0 crashed: the selection's JSON was iterated after its end of life).
add_test(NAME cli_wv_window
  COMMAND ${NI} wv --input ${_wv_data} --rate 100 --gyro-unit deg/s --acc-unit g --start 0 --end 1000
          --out ${_wv_dir}/window --overwrite)
set_tests_properties(cli_wv_window PROPERTIES PASS_REGULAR_EXPRESSION "100000 samples at 100 Hz")

# Rawlog input (committed, 64 samples, label XSENS): reads with the right label.
add_test(NAME cli_wv_rawlog
  COMMAND ${NI} wv --input ${CMAKE_SOURCE_DIR}/tests/data/imu_label_xsens.rawlog --label XSENS
          --out ${_wv_dir}/rawlog --overwrite)
set_tests_properties(cli_wv_rawlog PROPERTIES
  PASS_REGULAR_EXPRESSION "64 samples at 100 Hz, 6 scales")

# Bad inputs, written here at configure time.
set(_hdr "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z")
file(WRITE ${_wv_dir}/empty.csv "")
file(WRITE ${_wv_dir}/missing_column.csv "${_hdr}\n1,2,3,4,5,6\n1,2,3,4,5\n")
file(WRITE ${_wv_dir}/nan.csv "${_hdr}\n1,2,3,4,5,6\n1,nan,3,4,5,6\n1,2,3,4,5,7\n2,2,3,4,5,6\n")
set(_rows "")
foreach(i RANGE 63)
  string(APPEND _rows "0.5,0.5,0.5,0,0,-1\n")
endforeach()
file(WRITE ${_wv_dir}/constant.csv "${_hdr}\n${_rows}")
file(WRITE ${_wv_dir}/three.csv "${_hdr}\n1,2,3,4,5,6\n2,3,4,5,6,7\n0,1,2,3,4,5\n")

# wv_expect_fail(NAME REGEX ARG...): navimpact wv ARG... --out DIR must fail
# with stderr matching REGEX and leave no DIR.
function(wv_expect_fail name regex)
  navimpact_cli_fail(cli_wv_bad_${name} ARGS wv ${ARGN} --out ${_wv_dir}/out_${name}
                     REGEX "${regex}" NOOUT ${_wv_dir}/out_${name})
endfunction()
set(_u --rate 100 --gyro-unit deg/s --acc-unit g)
wv_expect_fail(empty "empty\\.csv: empty file" --input ${_wv_dir}/empty.csv ${_u})
wv_expect_fail(missing_column "missing_column\\.csv:3" --input ${_wv_dir}/missing_column.csv ${_u})
wv_expect_fail(nan "nan\\.csv:3" --input ${_wv_dir}/nan.csv ${_u})
wv_expect_fail(constant "constant\\.csv: channel gyro_x: .*constant"
               --input ${_wv_dir}/constant.csv ${_u})
wv_expect_fail(too_short "three\\.csv: channel gyro_x: .*at least 4 samples"
               --input ${_wv_dir}/three.csv ${_u})
# samples of 1e-300 (not constant): their squares underflow, the wavelet variance
# is 0 at every scale; named with file and channel (it was a plot error naming none)
string(REPEAT "1e-300,2e-300,1e-300,2e-300,1e-300,2e-300\n2e-300,1e-300,2e-300,1e-300,2e-300,1e-300\n" 64 _tiny_rows)
file(WRITE ${_wv_dir}/tiny.csv "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n${_tiny_rows}")
wv_expect_fail(underflow "^navimpact: .*tiny\\.csv: channel gyro_x: wavelet variance is 0 at every scale \\(the samples reach only .x. = 2e-300: their squares underflow; is the unit right\\?\\)$"
               --input ${_wv_dir}/tiny.csv --rate 100 --gyro-unit rad/s --acc-unit m/s2)
wv_expect_fail(unknown_unit
               "^navimpact: --acc-unit: 'furlong' is not a known unit \\(accepted: m/s2, .*\\) \\(see 'navimpact wv --help'\\)$"
               --input ${_wv_data} --rate 100 --gyro-unit deg/s --acc-unit furlong)
# flags that do not apply, or no time: one line naming the input
wv_expect_fail(csv_label "^navimpact: .*adis16405_static_excerpt\\.csv\\.gz: --label applies to rawlog input; a CSV's columns are named by its header$"
               --input ${_wv_data} --rate 100 --gyro-unit deg/s --acc-unit g --label XSENS)
wv_expect_fail(end_inf "^navimpact: .*adis16405_static_excerpt\\.csv\\.gz: --end inf s must be a finite time \\(the record has"
               --input ${_wv_data} --rate 100 --gyro-unit deg/s --acc-unit g --end inf)
wv_expect_fail(rawlog_label
               "imu_label_xsens\\.rawlog: no CObservationIMU with label 'IMU' \\(labels found: 'XSENS'"
               --input ${CMAKE_SOURCE_DIR}/tests/data/imu_label_xsens.rawlog)
# --eff is checked against what the biweight reaches before the file is read
# (0.9999999 passed a (0, 1) check and failed late, blaming the file), and needs --robust
wv_expect_fail(eff_unreachable "^navimpact: --eff: robust wavelet variance: efficiency 0\\.9999999 is outside what the biweight reaches \\(0\\.05 \\.\\. 0\\.999985, .*\\) \\(see 'navimpact wv --help'\\)$"
               --input ${_wv_data} ${_u} --robust --eff 0.9999999)
wv_expect_fail(eff_without_robust "^navimpact: --eff requires --robust \\(see 'navimpact wv --help'\\)$"
               --input ${_wv_data} ${_u} --eff 0.9)
