// Internal helpers of study.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include "navimpact/analysis/study.hpp"

namespace navimpact::analysis::detail {

/// Values stored per epoch in a run record: err[9], sigma[9], nees[4].
constexpr int kEpochValues = 22;

nlohmann::json metaToJson(const StudyMeta& m);
StudyMeta metaFromJson(const nlohmann::json& j, const std::string& where);

/// chi2inv(p, dof) (boost::math).
double chi2Quantile(double p, double dof);

}  // namespace navimpact::analysis::detail
