/**
 * @file estimator.hpp
 * @brief GMWM estimation of a composite model from an empirical WV
 *        (Guerrier et al. 2013), with Ceres as the optimizer.
 *
 * theta_hat = argmin (nu_hat - nu(theta))^T Omega (nu_hat - nu(theta)),
 * Omega = diag(1 / (CI_hi - CI_lo)^2) by default (the R package's "fast" V).
 * Parameters are optimised in a transformed space (log of scales, logit of
 * phi), from multiple deterministic starting points.
 */
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::gmwm {

struct FitOptions {
  int bootstrap = 0;             ///< parametric bootstrap replicates for CIs (0 = asymptotic)
  std::uint64_t seed = 20190101; ///< seed of the bootstrap / random starts
  int max_starts = 0;            ///< 0 = automatic multi-start count
};

/// 95 % interval of one parameter.
struct ParamInterval {
  std::string name;   ///< e.g. "sigma", "T", "omega"
  double value = 0;
  double low = 0;
  double high = 0;
};

struct FitResult {
  stochastic::Model model;                       ///< estimated model, per-sample SI at rate_hz
  double objective = 0.0;                        ///< value of the weighted objective
  std::vector<std::vector<ParamInterval>> ci;    ///< per term, per parameter
  std::string ci_method;                         ///< "asymptotic" or "bootstrap(N)"
  int starts = 0;                                ///< starting points tried
  bool converged = false;
};

/// The GMWM objective of @p m against @p wv (weights = wv.weights()).
double objective(const stochastic::Model& m, const WaveletVariance& wv);

/**
 * Fit a structure (e.g. WN+GM+GM+DR) to @p wv.
 * @throws navimpact::Error if the structure is empty or has more parameters than scales.
 */
FitResult fit(const std::vector<stochastic::ProcessKind>& structure, const WaveletVariance& wv,
              const FitOptions& opt = {});

/// One candidate of an automatic model selection.
struct RankedModel {
  FitResult fit;
  double criterion = 0.0;   ///< objective + optimism (wavelet information criterion)
  double optimism = 0.0;
};

/**
 * Rank candidate structures by the wavelet information criterion (objective +
 * estimated optimism); best first. @p why receives a plain-language reason.
 */
std::vector<RankedModel> selectModel(const std::vector<std::vector<stochastic::ProcessKind>>& candidates,
                                     const WaveletVariance& wv, const FitOptions& opt,
                                     std::string* why = nullptr);

}  // namespace navimpact::gmwm
