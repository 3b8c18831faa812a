/**
 * @file fit_report.hpp
 * @brief What `navimpact fit` writes and shows: model.yaml, fit.json, the WV
 *        figures in the style of the paper's Figures 1-4, and the console
 *        summary, from a gmwm::RecordingFit (data only).
 */
#pragma once

#include <string>

#include "navimpact/core/output.hpp"
#include "navimpact/gmwm/channels.hpp"

namespace navimpact::report {

/**
 * Stage model.yaml (stochastic::loadImuModel reads it back), fit.json
 * (estimates, intervals, WV and model WV per channel) and one WV figure per
 * sensor (fit_gyroscope.png, fit_accelerometer.png) in @p out; the caller commits.
 * @param[in] input_json  JSON object copied under "input" (file, format, units...).
 * @param[in] version     navimpact version, for the model file's comment.
 */
void writeFitOutputs(const gmwm::RecordingFit& f, const std::string& input_json,
                     const std::string& version, OutputSet& out);

/// Per channel: the model, its objective, negligible terms, the selection's reason and the datasheet figures.
std::string fitSummary(const gmwm::RecordingFit& f);

}  // namespace navimpact::report
