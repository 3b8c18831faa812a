/**
 * @file study_report.hpp
 * @brief What `navimpact study` writes: study.json, timeseries.csv, the
 *        figures and report.md, from analysis::StudyResults (data only).
 */
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/**
 * Write study.json, timeseries.csv, figures (fig_<set>_errors_o<k>.png,
 * fig_<set>_nees_o<k>.png, fig_<set>_outage_end.png) and report.md.
 */
void writeStudyOutputs(const analysis::StudyResults& r, OutputSet& out);

/// The metrics part of study.json (no timings): used by tests to compare runs.
std::string studyMetricsJson(const analysis::StudyResults& r);

/// What study.json and sweep.json both say of where they come from, into @p j:
/// navimpact_version, versions (library -> version), config_file, config_text, seed.
void provenanceJson(const analysis::StudyHeader& h, nlohmann::json& j);

}  // namespace navimpact::report
