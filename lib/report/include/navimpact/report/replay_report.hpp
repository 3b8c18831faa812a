/**
 * @file replay_report.hpp
 * @brief What `navimpact replay` writes: solution.csv, summary.json and the
 *        figures in the style of Khaghani et al. (2019) Figures 8 and 9
 *        (error and +-1 sigma envelope, outage shaded), from an
 *        analysis::ReplayResult (data only).
 */
#pragma once

#include <string>

#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// solution.csv text (one row per recorded epoch; units in the header).
std::string solutionCsv(const analysis::ReplayResult& r);

/// summary.json text.
std::string summaryJson(const analysis::ReplayResult& r);

/// Notices, what was replayed, and per outage the error (or predicted sigma) at its end.
std::string replaySummary(const analysis::ReplayResult& r);

/// Stage solution.csv, summary.json, errors_full.png, errors_outage_K.png (the first 12
/// outages), trajectory.png and, when scored, outage_end_error.png in @p out; the caller commits.
void writeReplayOutputs(const analysis::ReplayResult& r, OutputSet& out);

}  // namespace navimpact::report
