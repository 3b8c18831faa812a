// Shared input loading for the CLI commands (see input.hpp). Not a command
// itself: named cmd_* only so that the CMake glob compiles it.
#include <cmath>
#include <filesystem>
#include <sstream>

#include "input.hpp"
#include "cli_common.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/rawlog/imu_reader.hpp"

namespace navimpact::cli {

namespace {

bool isSi(units::Quantity q, const std::string& unit) {
  return unit.empty() || units::toSiFactor(q, unit) == 1.0;
}

/// Apply a sensor -> body axes remap to both triads in place.
void remapAxes(ImuSeries& s, const std::string& spec) {
  int src[3];
  double sign[3];
  parseAxesSpec(spec, src, sign);
  for (int sensor = 0; sensor < 2; ++sensor) {
    std::vector<double> old[3];
    for (int i = 0; i < 3; ++i) old[i] = s.channels[3 * sensor + i].x;
    for (int i = 0; i < 3; ++i) {
      auto& x = s.channels[3 * sensor + i].x;
      for (std::size_t k = 0; k < x.size(); ++k) x[k] = sign[i] * old[src[i]][k];
    }
  }
}

}  // namespace

void addInputOptions(CLI::App& app, InputOpts& o) {
  app.add_option("--input", o.input,
                 "IMU recording: CSV or CSV.gz (columns gyro_x..acc_z, optional time t) or an "
                 "MRPT rawlog (CObservationIMU)")
      ->required();
  app.add_option("--rate", o.rate_hz,
                 "sampling rate [Hz]; required for CSV without a time column, checked for rawlog")
      ->check(within(limits::kImuRateHz));
  app.add_option("--gyro-unit", o.gyro_unit,
                 "CSV gyroscope unit: rad/s, deg/s, deg/h, mrad/s (default: from the header)")
      ->check(knownUnit(units::Quantity::AngularRate));
  app.add_option("--acc-unit", o.acc_unit,
                 "CSV accelerometer unit: m/s2, g, mg, ug (default: from the header)")
      ->check(knownUnit(units::Quantity::SpecificForce));
  app.add_option("--axes", o.axes,
                 "sensor-to-body FRD axes, e.g. x,-y,-z for a forward-left-up sensor");
  app.add_option("--label", o.label, "rawlog sensor label of the IMU observations")
      ->capture_default_str()
      ->each([&o](const std::string&) { o.label_given = true; });
  app.add_option("--time-column", o.time_column,
                 "CSV: name of the time column (default: t, t_s, time_s or time)");
  app.add_option("--time-unit", o.time_unit,
                 "CSV: unit of the time column: s, ms, us, ns (default: from the header, e.g. t[ns], else s)")
      ->check(CLI::IsMember(units::acceptedTimeUnits()));
  app.add_option("--start", o.start_s,
                 "use the record from this time on [s from its first sample, >= 0]");
  app.add_option("--end", o.end_s,
                 "use the record up to this time [s from its first sample, after --start, within the record]");
}

ImuSeries loadInput(const InputOpts& o, InputFormat* format) {
  if (!std::filesystem::exists(o.input)) throw Error(o.input + ": file not found");
  if (std::filesystem::is_directory(o.input)) throw Error(o.input + ": is a directory, not a file");
  if (std::filesystem::file_size(o.input) == 0) throw Error(o.input + ": empty file");
  const bool raw = rawlog::isRawlogFile(o.input);
  if (format) *format = raw ? InputFormat::Rawlog : InputFormat::Csv;
  auto window = [&o](ImuSeries s) {
    if (o.start_s || o.end_s) cutWindow(s, o.start_s.value_or(0.0), o.end_s);
    return s;
  };
  if (!raw) {
    if (o.label_given)
      throw Error(o.input + ": --label applies to rawlog input; a CSV's columns are named by its header");
    CsvImuOptions c;
    c.rate_hz = o.rate_hz;
    c.gyro_unit = o.gyro_unit;
    c.acc_unit = o.acc_unit;
    c.axes = o.axes;
    c.time_column = o.time_column;
    c.time_unit = o.time_unit;
    return window(readImuCsv(o.input, c));
  }
  if (!o.time_column.empty() || !o.time_unit.empty())
    throw Error(o.input + ": --time-column and --time-unit apply to CSV input; a rawlog's times are its observation timestamps");
  if (!isSi(units::Quantity::AngularRate, o.gyro_unit) ||
      !isSi(units::Quantity::SpecificForce, o.acc_unit))
    throw Error(o.input + ": rawlog IMU data are SI (rad/s, m/s^2); --gyro-unit/--acc-unit "
                          "other than SI do not apply");
  ImuSeries s = rawlog::readImuRawlog(o.input, o.label);
  if (o.rate_hz && std::fabs(*o.rate_hz - s.rate_hz) > 1e-3 * s.rate_hz) {
    std::ostringstream os;
    os << o.input << ": --rate " << *o.rate_hz << " Hz disagrees with the rawlog timestamps ("
       << s.rate_hz << " Hz)";
    throw Error(os.str());
  }
  if (!o.axes.empty()) {
    try {
      remapAxes(s, o.axes);
    } catch (const Error& e) {
      throw Error(o.input + ": --axes: " + e.what());
    }
  }
  return window(std::move(s));
}

nlohmann::json inputSelectionJson(const InputOpts& o, const ImuSeries& s) {
  nlohmann::json j = nlohmann::json::object();
  if (!s.time_column.empty()) j["time_column"] = s.time_column;
  if (!s.time_unit.empty()) j["time_unit"] = s.time_unit;
  if (o.start_s) j["start_s"] = *o.start_s + 0.0;  // + 0.0: --start -0 is recorded as 0
  if (o.end_s) j["end_s"] = *o.end_s + 0.0;
  return j;
}

std::string inputUnitsNote(const InputOpts& o, InputFormat f) {
  if (f == InputFormat::Rawlog)
    return "rawlog CObservationIMU '" + o.label + "' (SI: rad/s, m/s^2); all outputs SI";
  return "CSV gyro " + (o.gyro_unit.empty() ? std::string("unit from header") : o.gyro_unit) +
         ", acc " + (o.acc_unit.empty() ? std::string("unit from header") : o.acc_unit) +
         ", converted to SI (rad/s, m/s^2); all outputs SI";
}

}  // namespace navimpact::cli
