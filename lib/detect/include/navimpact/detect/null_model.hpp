/**
 * @file null_model.hpp
 * @brief The quantities of a stochastic model that the detectors need as
 *        their null: two-sided PSD, Haar wavelet variance, sd of the second
 *        difference.
 *
 * PSD of the sampled processes (two-sided, [unit^2/Hz], w = 2 pi f / fs):
 * WN sigma^2/fs; QN (differenced white noise of variance Q^2)
 * 4 Q^2 sin^2(w/2)/fs; RW (pseudo-spectrum) gamma^2 / (4 sin^2(w/2) fs);
 * GM (AR(1), phi = e^{-1/(fs T)}) sigma^2 (1 - phi^2) / ((1 - 2 phi cos w + phi^2) fs);
 * DR and SIN are deterministic (a trend is removed, a model line is excluded).
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
