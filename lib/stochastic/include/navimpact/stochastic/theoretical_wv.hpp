/**
 * @file theoretical_wv.hpp
 * @brief Closed-form Haar wavelet variance of each process and of a sum.
 *
 * Scales are in samples, tau = 2^j (j >= 1), as in the R package gmwm
 * (Guerrier et al. 2013; formulas in shared/reference/gmwm_formulas.md §3).
 * AR1/GM is evaluated in a numerically stable form valid for phi -> 1.
 */
#pragma once

#include <Eigen/Core>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/**
 * Haar WV of one process at scale @p tau (in samples, even, >= 2).
 * @param[in] p        the process (parameters per convention at @p rate_hz).
 * @param[in] rate_hz  sampling rate [Hz] (fixes phi = exp(-1/(rate T))).
 */
double haarWv(const Process& p, double rate_hz, double tau);

/// AR1 WV in the R package's parametrisation (phi, innovation variance), stable for phi -> 1.
double haarWvAr1(double phi, double sigma2_innov, double tau);

/// Sum model WV at the scales tau_j (samples).
Eigen::VectorXd haarWv(const Model& m, const Eigen::VectorXd& tau);

/// Per-term WVs: column i is term i (for plots with dashed components).
Eigen::MatrixXd haarWvTerms(const Model& m, const Eigen::VectorXd& tau);

/// Dyadic scales 2^1 .. 2^J in samples.
Eigen::VectorXd dyadicScales(int J);

}  // namespace navimpact::stochastic
