/**
 * @file run_diagnosis_report.hpp
 * @brief Outputs of `navimpact diagnose --run`: run_diagnosis.json, report.md
 *        timing.json (wall clock, kept apart from the results) and predicted_vs_measured.png (the simulation's 5-95 % band and median
 *        of the outage-end error against the measured outages, per duration).
 */
#pragma once

#include <string>

#include "navimpact/analysis/run_diagnosis.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// run_diagnosis.json (see README "Run diagnosis"); @p input_json: the command's inputs (a JSON object).
std::string runDiagnosisJson(const analysis::RunDiagnosis& d, const std::string& input_json);

/// report.md: the same for a person.
std::string runDiagnosisMarkdown(const analysis::RunDiagnosis& d);

/// A few lines for the terminal.
std::string runDiagnosisSummary(const analysis::RunDiagnosis& d);

/// Write run_diagnosis.json, report.md and the figure into @p out; returns the figure count.
std::size_t writeRunDiagnosisOutputs(const analysis::RunDiagnosis& d, const std::string& input_json, OutputSet& out);

}  // namespace navimpact::report
