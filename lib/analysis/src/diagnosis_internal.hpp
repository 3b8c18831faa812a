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

}  // namespace navimpact::analysis
