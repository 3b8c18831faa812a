// Internal helpers shared by the diagnosis sources (not installed).
#pragma once

#include <string>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"

namespace navimpact::analysis {

/// Refine a line's frequency on the whole record (zoomed DFT), fit its
/// amplitude by least squares and subtract it from @p x (spectrum.cpp).
LineResult refineAndRemoveLine(std::vector<double>& x, double rate_hz, int segment_length,
                               const LineResult& coarse);

/// Short number formatting for reports ("3.1e-05", "45.2").
std::string fmtNum(double v, int digits = 3);

/// Unit name of a channel's SI unit ("rad/s" or "m/s^2").
std::string channelUnit(const std::string& channel);

}  // namespace navimpact::analysis
