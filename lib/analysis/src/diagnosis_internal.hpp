// Internal helpers shared by the diagnosis sources (not installed).
#pragma once

#include <string>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"

namespace navimpact::analysis {

/**
 * Chi-square (gamma) deviance of measured WV @p nu_hat against model WV @p nu
 * with dof @p eta: sum eta_j (nu_hat/nu - log(nu_hat/nu) - 1).
 */
double wvDeviance(const std::vector<double>& nu_hat, const std::vector<double>& nu,
                  const std::vector<double>& eta);

}  // namespace navimpact::analysis
