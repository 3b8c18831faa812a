/**
 * @file covariance_report.hpp
 * @brief What `navimpact covariance` writes: covariance.csv, summary.json and
 *        one figure per model set (the paper's Figures 5 and 6), from an
 *        analysis::CovarianceStudyResult (data only).
 */
#pragma once

#include <string>
#include <vector>

#include "navimpact/analysis/covariance_study.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/**
 * Write covariance.csv, summary.json and one PNG per model set
 * (covariance_<set>.png) into @p out (staged; the caller commits).
 */
void writeCovarianceStudy(const analysis::CovarianceStudyConfig& cfg,
                          const analysis::CovarianceStudyResult& res, OutputSet& out);

/// `covariance --print-states`: per model "# SET / MODEL: N states", its notes
/// ("# note: ..."), then the filter's state layout (StateLayout::describe()).
std::string covarianceStateLayouts(const std::vector<analysis::CovarianceModel>& models);

/// The sigmas at the end of every run, one line per model (human units: deg).
std::string covarianceSummary(const analysis::CovarianceStudyResult& res);

}  // namespace navimpact::report
