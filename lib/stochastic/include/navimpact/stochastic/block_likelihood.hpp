/**
 * @file block_likelihood.hpp
 * @brief Exact Gaussian likelihood of the means of consecutive blocks of a
 *        record under a model's random terms, with deterministic regressors
 *        (mean, trend, level shifts) concentrated out.
 *
 * Every random kind is, sampled at its rate, the scalar form
 *     x_k = z_k - mu z_{k-1},  z_k = phi z_{k-1} + e_k,  var(e_k) = q,  z_{-1} ~ N(0, p0)
 * (sampledArma(): WN phi = mu = 0; QN phi = 0, mu = 1, q = Q^2; GM phi =
 * exp(-dt/T), q = sigma^2 (1 - phi^2), p0 = sigma^2; RW phi = 1, q = gamma^2,
 * p0 = 0 as simulated). Over a block of b samples starting at kb, with the
 * state s_k = z_{kb-1} and G(m) = sum_{i<m} phi^i,
 *     block sum   = (phi - mu) G(b) s_k + sum_j d_j e_{kb+j},  d_j = G(b-j) - mu G(b-1-j),
 *     s_{k+1}     = phi^b s_k + sum_j phi^(b-1-j) e_{kb+j},
 * so the block means follow a linear state-space model with one state per
 * term and measurement noise correlated with the process noise (exact, no
 * approximation of the within-block dynamics). The Kalman filter in
 * one-step-predictor form (Anderson & Moore 1979, §5.5: K = (F P H' + M) S^-1)
 * gives the innovations and with them the exact log-likelihood; regressors
 * pass through the same filter and their coefficients are the GLS estimates
 * (Harvey 1989, §3.4: the likelihood maximised over beta). DR and SIN terms
 * are deterministic: pass them as regressors (a trend column, ...).
 */
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/// x_k = z_k - mu z_{k-1}, z_k = phi z_{k-1} + e_k, var(e) = q, z_{-1} ~ N(0, p0).
struct SampledArma {
  double phi = 0.0, mu = 0.0, q = 0.0, p0 = 0.0;
};

/// The sampled form of a random term at @p rate_hz; nullopt for DR (a trend) and SIN (a line).
std::optional<SampledArma> sampledArma(const Process& p, double rate_hz);

/// Means of consecutive blocks of @p block samples of x[0, n) (a tail shorter than a block is dropped).
std::vector<double> blockMeans(const double* x, std::size_t n, std::size_t block);

/// Result of blockLogLikelihood().
struct BlockLikelihood {
  double loglik = 0.0;       ///< exact log-likelihood, maximised over the regression coefficients
  Eigen::VectorXd beta;      ///< GLS coefficients of the regressors used
  Eigen::MatrixXd beta_cov;  ///< their covariance (X' Sigma^-1 X)^-1
};

/**
 * Exact Gaussian log-likelihood of block means.
 * @param[in] m        model at the data rate (rate_hz > 0); its WN, QN, GM and
 *                     RW terms enter exactly, DR and SIN terms are ignored.
 * @param[in] y        block means (blockMeans()), at least 2.
 * @param[in] block    samples per block, >= 1.
 * @param[in] X        regressors, y.size() rows (block means of deterministic
 *                     signals: 1 for the mean, a trend, a step); may be empty.
 * @param[in] columns  which columns of @p X to use (empty: all).
 * @throws navimpact::Error for a model without any random term, mismatched
 *         sizes or a singular regression.
 */
BlockLikelihood blockLogLikelihood(const Model& m, const std::vector<double>& y, std::size_t block,
                                   const Eigen::MatrixXd& X, const std::vector<int>& columns = {});

/**
 * blockLogLikelihood() maximised over the variance of every random term of
 * @p m (WN sigma^2, QN Q^2, RW gamma^2, GM sigma^2; GM correlation times and
 * DR kept), by coordinate-wise search in the log of one variance factor per
 * term (grid e^-12..e^4, then golden section; sweeps until the log-likelihood
 * gains less than 1e-4). @p m is updated to the maximiser. @p terms: the
 * indices of the terms to profile (empty: all; {-1}: none).
 */
double profileBlockLogLikelihood(Model& m, const std::vector<double>& y, std::size_t block,
                                 const Eigen::MatrixXd& X, const std::vector<int>& terms = {});

/**
 * Exact draw of @p nb block means of @p block samples under @p m: the block
 * state space of blockLogLikelihood() driven by its own noise (per term and
 * block the pair (w_k, v_k), jointly normal with variances R, Q and
 * covariance M; the state from N(0, P0): GM stationary, RW from 0), so the
 * draws have exactly the distribution the likelihood assumes, at a cost
 * independent of the block length. A DR term adds its trend (omega per
 * sample from sample 0, as simulate()); SIN terms are ignored. Term i draws
 * from its own stream deriveSeed(seed, i).
 * @throws navimpact::Error for block == 0 or a model without a rate.
 */
std::vector<double> simulateBlockMeans(const Model& m, std::size_t nb, std::size_t block, std::uint64_t seed);

}  // namespace navimpact::stochastic
