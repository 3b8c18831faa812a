/**
 * @file datasheet.hpp
 * @brief Continuous-time figures an engineer reads off a datasheet, from a model.
 */
#pragma once

#include <optional>
#include <string>

#include "navimpact/core/units.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/// Datasheet figures, SI inside; the *_human members are for printing only.
struct DatasheetFigures {
  /// White-noise density N = sigma sqrt(dt) [unit*sqrt(s)] (ARW for gyros, VRW for accs).
  std::optional<double> noise_density;
  /// Bias instability, IEEE 952 flicker-floor reading from the model's Allan
  /// deviation minimum divided by 0.664 [unit]. Empty if no minimum in range.
  /// The ADEV is the model's, AVAR(m) = 2 nu^2(tau = 2m), on a log grid of 50
  /// points per decade from 1 sample to 1e6 s; the FIRST interior local minimum
  /// is reported (the floor after the white-noise slope).
  std::optional<double> bias_instability;
  std::optional<double> bias_instability_tau_s;  ///< tau where the minimum occurs [s]
  /// Rate random walk K = gamma / sqrt(dt) [unit/sqrt(s)].
  std::optional<double> random_walk;
  /// Quantization Q_c = Q dt [unit*s].
  std::optional<double> quantization;
  /// Drift rate omega / dt [unit/s].
  std::optional<double> drift_rate;
};

DatasheetFigures datasheetFigures(const Model& m);

/**
 * Human-readable lines, e.g. "ARW 0.19 deg/sqrt(h)", "bias instability 4.2 deg/h"
 * for gyros; "VRW 0.07 m/s/sqrt(h)", "bias instability 0.05 mg" for accs.
 */
std::string formatDatasheet(const DatasheetFigures& f, units::Quantity q);

}  // namespace navimpact::stochastic
