/**
 * @file csv_reader.hpp
 * @brief Read IMU recordings from CSV (plain or gzip) into SI, FRD body axes.
 *
 * Format: one header line naming the columns, comma separated. Recognised
 * columns are the canonical channels `gyro_x gyro_y gyro_z acc_x acc_y acc_z`
 * and an optional time column: `t`, `t_s`, `time_s` or `time`, or the one named by
 * CsvImuOptions::time_column, in seconds unless its header bracket or
 * CsvImuOptions::time_unit says ms, us or ns (stamps are read exactly enough
 * for Unix nanoseconds, on a file's time axis of at most 1e10 s); other
 * columns are ignored, except a channel's name written otherwise (`Gyro_X`)
 * and, with no time column read, a column that looks like time stamps
 * (`T`, `time...`, `t_...`, `...stamp...`): both are errors naming the column.
 * A column name may carry its unit in brackets, e.g. `gyro_x[deg/s]`,
 * which overrides the option. Without a time column, the rate must be given.
 */
#pragma once

#include <optional>
#include <string>

#include "navimpact/core/imu_series.hpp"

namespace navimpact {

struct CsvImuOptions {
  /// Sampling rate [Hz] (> 0). Required when the file has no time column; when
  /// both exist they must agree to 0.1 %.
  std::optional<double> rate_hz;
  /// Unit of the gyroscope columns in the file (see units::toSiFactor). Empty:
  /// the header must say it, else reading fails naming the column.
  std::string gyro_unit;
  /// Unit of the accelerometer columns in the file. Empty: as for gyro_unit.
  std::string acc_unit;
  /**
   * Axis remapping from the file's sensor axes to body FRD, applied to both
   * sensors, e.g. "x,-y,-z" (body x = file x, body y = -file y, ...) for a
   * sensor mounted forward-left-up. Empty: identity.
   */
  std::string axes;
  /// Name of the time column (its header name without a [unit] part).
  /// Empty: `t`, `t_s`, `time_s` or `time` when present. Set: that column must exist
  /// and the default names are ordinary (ignored) columns.
  std::string time_column;
  /// Unit of the time column: s, ms, us or ns (units::secondsPer). Empty: the
  /// header's bracket (e.g. `t[ns]`), else s. Both given: they must agree.
  std::string time_unit;
  /// Largest accepted relative deviation of a time step from the median step.
  double max_dt_deviation = 0.01;
};

/**
 * Read a CSV IMU recording.
 * @param[in] path  file path; gzip is detected from the content.
 * @param[in] opt   see CsvImuOptions.
 * @throws navimpact::Error naming file, line and column for: empty file, no
 *         recognised column, a row with a missing or extra field, a value
 *         that is not a number, NaN or Inf, times that are not increasing or
 *         leave a gap, an unknown unit, a malformed axes spec.
 */
ImuSeries readImuCsv(const std::string& path, const CsvImuOptions& opt);

/**
 * Parse an axes remapping spec ("x,-y,-z", "y,x,-z", ...).
 * @param[out] src   body axis i takes file axis src[i] (0..2).
 * @param[out] sign  and multiplies it by sign[i] (+1 or -1).
 * @throws navimpact::Error when the spec is not a signed permutation of x,y,z.
 */
void parseAxesSpec(const std::string& spec, int src[3], double sign[3]);

}  // namespace navimpact
