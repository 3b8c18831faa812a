/**
 * @file diagnosis_report.hpp
 * @brief What `navimpact diagnose` writes: diagnosis.json, report.md and the
 *        figures, from an analysis::Diagnosis (which holds data only).
 */
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// diagnosis.json text (see README "diagnose"); @p input_json is copied under "input".
std::string diagnosisJson(const analysis::Diagnosis& d, const std::string& input_json);

/// report.md text; @p figures are the PNG names to link.
std::string diagnosisReport(const analysis::Diagnosis& d, const std::vector<std::string>& figures);

/**
 * Render the figures (PNG): an overview of the measured WV vs the simulated
 * envelope of every channel with the misfit scales marked; per channel with
 * findings the extended model's fit and, where a line was found, the spectrum.
 * @param[in] path_for  maps a file name ("wv_envelope.png") to the path to write
 *                      (e.g. OutputSet::stage).
 * @return the file names written.
 */
std::vector<std::string> diagnosisFigures(
    const analysis::Diagnosis& d, const std::function<std::string(const std::string&)>& path_for);

/**
 * Stage the figures, diagnosis.json, report.md and model_extended.yaml (the
 * extended model, @p model_comment as its header) in @p out; the caller commits.
 * @return the number of figures.
 */
std::size_t writeDiagnosisOutputs(const analysis::Diagnosis& d, const std::string& input_json,
                                  const std::string& model_comment, OutputSet& out);

/// The verdict, one line per channel (causes, scales outside the CI, gain) and the navigation gain.
std::string diagnosisSummary(const analysis::Diagnosis& d);

}  // namespace navimpact::report
