/**
 * @file model_file.hpp
 * @brief IMU error model files (YAML): six per-axis composite models.
 *
 * A file holds either one model:
 * @code
 *   rate_hz: 200                       # rate of the per-sample parameters [Hz]
 *   accelerometer: "WN(sigma=5.521e-3) + GM(sigma=4.811e-4, T=3.22)"   # m/s^2
 *   gyroscope: "WN(sigma=9.788e-4)"    # rad/s
 *   gyro_z: "WN(sigma=1.2e-3)"         # per-axis keys override the sensor key
 * @endcode
 * or several named models under `models:` (each with the keys above; a model
 * may override `rate_hz`). A sensor left out of a model has no error ("none").
 * Commands select a model as `FILE:NAME`; `FILE` alone is valid when the file
 * holds a single model (or exactly one named model).
 */
#pragma once

#include <array>
#include <string>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/// Error models of the six IMU axes, in kChannelNames order (gyro_x..acc_z).
struct ImuModel {
  std::string source;           ///< "FILE:NAME" as loaded, for reports
  std::string name;             ///< model name ("" for a single-model file)
  double rate_hz = 0.0;         ///< rate of the per-sample parameters [Hz]
  std::array<Model, 6> axis;    ///< each with rate_hz set

  const Model& forChannel(const std::string& channel) const;
  Model& forChannel(const std::string& channel);
};

/**
 * Load `FILE` or `FILE:NAME`.
 * @throws navimpact::Error naming the file and the key for unknown keys,
 *         missing rate_hz, unparsable model strings, unknown model names
 *         (listing the available ones) and invalid parameters.
 */
ImuModel loadImuModel(const std::string& spec);

/**
 * The model @p name ("" = the only one) of a model file's YAML @p text, e.g. the
 * model a rawlog's scenario records; @p source names it in messages and
 * becomes ImuModel::source. Same keys and errors as loadImuModel().
 */
ImuModel parseImuModel(const std::string& text, const std::string& source, const std::string& name = "");

/// Names of the models in a file (empty for a single-model file).
std::vector<std::string> listModels(const std::string& file);

/// YAML text of a single-model file that loadImuModel() reads back exactly.
std::string toYaml(const ImuModel& m, const std::string& comment = "");

/// Every axis converted exactly to @p new_rate_hz (see convertRate(Model)).
ImuModel convertRate(const ImuModel& m, double new_rate_hz);

/**
 * @p m at @p rate_hz: itself when it is at that rate (to 1e-9 relative), else
 * converted exactly (convertRate) with one line appended to @p notes, the one
 * wording of a rate conversion: "model SOURCE given at X Hz, converted exactly
 * to Y Hz (the same continuous-time processes)".
 */
ImuModel atRate(const ImuModel& m, double rate_hz, std::vector<std::string>* notes = nullptr);

}  // namespace navimpact::stochastic
