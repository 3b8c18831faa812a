/**
 * @file wv_report.hpp
 * @brief What `navimpact wv` writes and shows: wv.json, wv.csv, one log-log
 *        figure per sensor and the console summary, from a gmwm::RecordingWv.
 */
#pragma once

#include <string>

#include "navimpact/core/output.hpp"
#include "navimpact/gmwm/channels.hpp"

namespace navimpact::report {

/**
 * Stage wv.json, wv.csv, wv_gyroscope.png and wv_accelerometer.png (each
 * figure when its sensor is present) in @p out; the caller commits.
 * @param[in] input_json  JSON object copied under "input" (file, format, rate, units...).
 */
void writeWvOutputs(const gmwm::RecordingWv& w, const std::string& input_json, OutputSet& out);

/// Samples, rate, scales and the WV at the smallest and largest scale per channel.
std::string wvSummary(const gmwm::RecordingWv& w);

}  // namespace navimpact::report
