// Internal helpers of study.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include "navimpact/analysis/study.hpp"

namespace navimpact::analysis::detail {

/// Values stored per epoch in a run record: err[9], sigma[9], nees[4].
constexpr int kEpochValues = 22;

/// The StudyHeader fields of a study's or a sweep's meta JSON, written into @p j / read from @p j
/// (json::exception for a missing or mistyped field: the caller names the file).
void headerToJson(const StudyHeader& h, nlohmann::json& j);
void headerFromJson(const nlohmann::json& j, StudyHeader& h);

nlohmann::json metaToJson(const StudyMeta& m);
StudyMeta metaFromJson(const nlohmann::json& j, const std::string& where);

/// chi2inv(p, dof) (boost::math).
double chi2Quantile(double p, double dof);

}  // namespace navimpact::analysis::detail
