/**
 * @file null_model.hpp
 * @brief The quantities of a stochastic model that the detectors need as
 *        their null: two-sided PSD, Haar wavelet variance, sd of the second
 *        difference.
 *
 * The PSD is stochastic::Spectrum's (the sampled processes, per kind from
 * the process registry), halved to the two-sided density the detectors use;
 * DR and SIN have no density (a trend is removed, a model line is excluded).
 */
#pragma once

#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/lines.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::detect {

/// Two-sided PSD of @p m at its rate [unit^2/Hz].
PsdFunction psdOf(const stochastic::Model& m);

/// Haar WV of @p m at scale tau [samples].
HaarWvFunction haarWvOf(const stochastic::Model& m);

/// Null sd of r_k = x_k - (x_{k-1} + x_{k+1}) / 2 under @p m (integral of the PSD).
double secondDifferenceSd(const stochastic::Model& m);

}  // namespace navimpact::detect
