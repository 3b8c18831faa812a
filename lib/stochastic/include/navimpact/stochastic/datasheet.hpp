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

/// A GM whose correlation time is below this many samples is white noise at
/// every averaging time beyond a few samples: it enters the ARW / VRW.
constexpr double kWhiteGmMaxSamples = 4.0;
/// An Allan deviation minimum at an averaging time below this many samples
/// sits at the first scales: it is not the flat region of IEEE Std 952.
constexpr double kFirstScalesSamples = 10.0;
/// Default longest averaging time searched for the bias instability [s].
constexpr double kDefaultMaxAveragingS = 1e6;

/// Datasheet figures, SI inside.
struct DatasheetFigures {
  /// White-noise density N [unit*sqrt(s)] (ARW for gyros, VRW for accs) from
  /// the model's high-frequency PSD: N^2 = dt (sigma_WN^2 + sum over GMs with
  /// T < kWhiteGmMaxSamples of sigma^2 (1+phi)/(1-phi)), the AR(1)'s long-run
  /// variance per sample (its flat PSD level below 1/(2 pi T)), phi = exp(-dt/T).
  /// A GMWM fit often puts the first-scale noise of a quantised or internally
  /// filtered sensor into such a GM and drives WN to ~0: this keeps the ARW.
  std::optional<double> noise_density;
  /// Short-T GMs counted in noise_density, and their share of N^2 (0..1).
  int noise_density_gms = 0;
  double noise_density_gm_share = 0.0;
  double noise_density_gm_n2 = 0.0;  ///< their part of N^2 [unit^2 s]
  /// Bias instability per IEEE Std 952-1997: the flicker floor, the Allan
  /// deviation at its flat region (a local minimum at or beyond
  /// kFirstScalesSamples, the lowest such) divided by 0.664 = sqrt(2 ln 2/pi) [unit].
  /// The ADEV is the model's, AVAR(m) = 2 nu^2(tau = 2m), on a log grid of 50
  /// points per decade from 1 sample to the longest averaging time, refined
  /// by golden-section search. When only a minimum at the first scales exists
  /// it is reported with a warning; when the ADEV still falls at the longest
  /// averaging time (no flat region reached) the value is empty, with a warning.
  std::optional<double> bias_instability;
  std::optional<double> bias_instability_tau_s;  ///< averaging time of that minimum [s]
  /// Why the bias instability reading is not a flat-region floor (empty when it is).
  std::string bias_instability_warning;
  /// Rate random walk K = gamma / sqrt(dt) [unit/sqrt(s)].
  std::optional<double> random_walk;
  /// Quantization Q_c = Q dt [unit*s].
  std::optional<double> quantization;
  /// Drift rate omega / dt [unit/s].
  std::optional<double> drift_rate;
};

/**
 * Datasheet figures of @p m.
 * @param[in] m             model (per-sample parameters at m.rate_hz).
 * @param[in] max_averaging_s longest averaging time of the bias-instability search [s]
 *                          (a record supports about half its length); 0 = kDefaultMaxAveragingS.
 *                          The search is bounded to 1e12 samples whatever the rate.
 * @return empty figures for a model without terms or without a finite positive rate.
 */
DatasheetFigures datasheetFigures(const Model& m, double max_averaging_s = 0.0);

/**
 * Human-readable lines, e.g. "ARW 0.19 deg/sqrt(h)", "bias instability 4.2 deg/h"
 * for gyros; "VRW 0.07 m/s/sqrt(h)", "bias instability 0.05 mg" for accs.
 */
std::string formatDatasheet(const DatasheetFigures& f, units::Quantity q);

}  // namespace navimpact::stochastic
