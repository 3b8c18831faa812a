// Shared CLI input handling: load an IMU recording (CSV/CSV.gz or MRPT rawlog)
// from the common options --input --rate --gyro-unit --acc-unit --axes --label.
// Used by wv, fit, diagnose (implementation in cmd_input_common.cpp, which the
// cmd_* glob of apps/navimpact/CMakeLists.txt picks up).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "navimpact/core/imu_series.hpp"

namespace navimpact::cli {

struct InputOpts {
  std::string input;              ///< file path (CSV, CSV.gz or rawlog)
  std::optional<double> rate_hz;  ///< CSV: required without time column; rawlog: checked
  std::string gyro_unit;          ///< CSV gyroscope unit ("" = from the header)
  std::string acc_unit;           ///< CSV accelerometer unit ("" = from the header)
  std::string axes;               ///< sensor -> body FRD remap, e.g. "x,-y,-z"
  std::string label = "IMU";      ///< rawlog sensor label
  bool label_given = false;       ///< --label on the command line (it applies to a rawlog only)
  std::string time_column;        ///< CSV time column name ("" = t, t_s, time_s or time)
  std::string time_unit;          ///< CSV time column unit s/ms/us/ns ("" = the header's, else s)
  std::optional<double> start_s;  ///< window start [s from the record's first sample]
  std::optional<double> end_s;    ///< window end (exclusive) [s from the record's first sample]
};

/// Declare --input (required), --rate, --gyro-unit, --acc-unit, --axes, --label,
/// --time-column, --start, --end on @p app.
void addInputOptions(CLI::App& app, InputOpts& o);

/// What loadInput read.
enum class InputFormat { Csv, Rawlog };

/**
 * Load the recording named by @p o into SI body-FRD channels.
 * Dispatch: a rawlog (".rawlog" name or binary content) goes to
 * rawlog::readImuRawlog, anything else to readImuCsv (gzip transparent).
 * @throws navimpact::Error whose message starts with the file name.
 */
ImuSeries loadInput(const InputOpts& o, InputFormat* format = nullptr);

/// Short human description of the units the input was read with (for reports).
std::string inputUnitsNote(const InputOpts& o, InputFormat f);

/// The input options that select data (time column, window) as JSON members
/// for the commands' "input" records: time_column (the one read, the default
/// t/time_s/time included: it was left out unless --time-column was given),
/// start_s, end_s when given.
nlohmann::json inputSelectionJson(const InputOpts& o, const ImuSeries& s);

}  // namespace navimpact::cli
