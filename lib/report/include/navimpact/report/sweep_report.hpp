/**
 * @file sweep_report.hpp
 * @brief What `navimpact sweep` / `sweep-merge` write: sweep.json, report.md
 *        and one heat map per column (map_<k>.png), from analysis::SweepResults.
 *        No timings: identical inputs give byte-identical files (the cost
 *        figures go to timing.json, writeSweepTiming / writeSweepShardTiming).
 */
#pragma once

#include <string>

#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// The white-noise threshold as a person reads it: "12 s", "> 60 s" (never
/// departs within the scanned outage) or "n/a".
std::string thresholdText(const analysis::WnThreshold& t);
/// Its 95 % bootstrap interval: "[8, 15] s", "[8, > 60] s" or "n/a".
std::string intervalText(const analysis::WnThreshold& t);

/// sweep.json text (see README "Model-sufficiency sweep").
std::string sweepJson(const analysis::SweepResults& r);

/// Write sweep.json, report.md and map_<k>.png (k = column number from 1).
void writeSweepOutputs(const analysis::SweepResults& r, OutputSet& out);

/// timing.json of a sweep or sweep-merge: @p wall_s of the command, the filter steps and their cost.
void writeSweepTiming(double wall_s, const analysis::SweepResults& r, OutputSet& out);

/// timing.json of a shard: its filter steps and filter wall time (sweep-merge adds them up).
void writeSweepShardTiming(const analysis::SweepRuns& r, OutputSet& out);

}  // namespace navimpact::report
