/**
 * @file power_report.hpp
 * @brief What `navimpact diagnose-power` writes: the power table and power.json,
 *        from an analysis::power::PowerResult (data only).
 */
#pragma once

#include <string>

#include "navimpact/analysis/diagnose_power.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// Markdown table: power (detected) and right cause/parameter per SNR bin and cause.
std::string powerTable(const analysis::power::PowerResult& r);

/// power.json text.
std::string powerJson(const analysis::power::PowerResult& r);
/// timing.json (report/timing.hpp): the CPU and wall time, kept apart from the results (identical runs, identical power.json).
void writePowerTiming(const analysis::power::PowerResult& r, OutputSet& out);

}  // namespace navimpact::report
