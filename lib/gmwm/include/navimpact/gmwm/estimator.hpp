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

#include "navimpact/core/limits.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::gmwm {

/// How the 95 % intervals are formed (all in the transformed space, so they stay positive).
enum class IntervalMethod {
  Asymptotic,  ///< delta method (sandwich covariance), theta_hat +- 1.96 se
  Profile,     ///< objective profile with the threshold calibrated to the sandwich variance
};

/// Weight matrix Omega of the GMWM objective.
enum class Weighting {
  /// The R package's "fast" weights 1 / (CI_hi - CI_lo)^2 of the EMPIRICAL WV
  /// (default). Cheap, but scales where nu_hat happens to be low get more
  /// weight, which biases the fit towards low WV (amplitudes and short T).
  Fast,
  /// Iterated model-based weights: fit with Fast, then
  /// Omega_jj = eta_j / (2 nu_j(theta_hat)^2), the inverse chi-square variance
  /// of nu_hat_j under the fitted model (Percival & Walden 2000, eq. 313c),
  /// refit from theta_hat (first pass: also from the multi-start points under
  /// the new weights); repeated until theta is stable (at most
  /// FitOptions::weight_iterations times). Weights no longer depend on the
  /// noise of nu_hat (an iteratively reweighted GMWM). Measured on the Table 1
  /// reference models (6 h, 200 Hz, 10 seeds): no better recovery of the
  /// short-T GMs than Fast (test_fit_sim.cpp). selectModel's optimism is
  /// derived for Fast weights: rank structures with Fast.
  ModelBased,
  /// Efficient GMWM (Guerrier et al. 2013, Omega = V^-1 is optimal): fit with
  /// Fast, then Omega = the inverse of the FULL asymptotic covariance of the
  /// WV vector under the fitted model (wvCovariance; neighbouring scales are
  /// strongly correlated), refit from theta_hat, repeated until theta is
  /// stable (at most FitOptions::weight_iterations passes). Scales whose
  /// equivalent degrees of freedom eta_j fall below FitOptions::efficient_min_eta
  /// (the coarsest, where the asymptotic formula does not hold) keep a
  /// diagonal weight eta_j / (2 nu_j^2) and no correlation with the others.
  Efficient,
};

/// Fewest parametric bootstrap replicates (limits::kMinBootstrap); with 5 the
/// "95 %" interval was nearly the range of 5 values and could exclude the estimate.
inline constexpr int kMinBootstrap = limits::kMinBootstrap;

struct FitOptions {
  Weighting weighting = Weighting::Fast;  ///< see Weighting
  int weight_iterations = 3;     ///< ModelBased / Efficient: most reweighting passes (>= 1)
  /// Efficient: scales with eta_j = M_j / tau_j below this keep a diagonal
  /// weight (the asymptotic covariance needs M_j >> tau_j, the correlation length of W_j).
  double efficient_min_eta = 16.0;
  int bootstrap = 0;             ///< parametric bootstrap replicates for CIs (0 = asymptotic/profile, else >= kMinBootstrap)
  IntervalMethod intervals = IntervalMethod::Asymptotic;  ///< used when bootstrap == 0
  std::uint64_t seed = 20190101; ///< seed of the bootstrap / random starts
  int max_starts = 0;            ///< 0 = automatic multi-start count
  /// Extra starting points: fitted models of sub-structures (e.g. the same
  /// structure with one GM less) or of the same structure. Missing terms are
  /// added on a grid of placements (GM T across the scale range) and with a
  /// negligible amplitude, so the fit never ends above the warm start's objective.
  std::vector<stochastic::Model> warm_starts;
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
  double objective = 0.0;                        ///< weighted objective under the weights used (see weighting)
  double objective_fast = 0.0;                   ///< objective under R's fast weights (= objective for Fast)
  Weighting weighting = Weighting::Fast;         ///< weights the fit used
  int weight_passes = 0;                         ///< ModelBased: reweighting passes done
  std::vector<std::vector<ParamInterval>> ci;    ///< per term, per parameter
  std::string ci_method;                         ///< "asymptotic", "profile" or "bootstrap(N)"
  int starts = 0;                                ///< starting points tried
  bool converged = false;
  /// Parameter covariance in the transformed space (log sigma, log T, ...),
  /// delta method (Guerrier et al. 2013): (A'WA)^+ A'W V W A (A'WA)^+.
  Eigen::MatrixXd cov_transformed;
};

/// Number of parameters of a structure (GM and SIN count 2, the others 1).
int parameterCount(const std::vector<stochastic::ProcessKind>& structure);

/// The GMWM objective of @p m against @p wv (weights = wv.weights()).
double objective(const stochastic::Model& m, const WaveletVariance& wv);

/// Model-based weights eta_j / (2 nu_j(m)^2) of @p m at the scales of @p wv [1/unit^4].
Eigen::VectorXd modelWeights(const stochastic::Model& m, const WaveletVariance& wv);

/// "fast", "model" or "efficient".
std::string weightingName(Weighting w);
/// Parse "fast" / "model" / "efficient". @throws navimpact::Error naming the expected values.
Weighting parseWeighting(const std::string& s);

/**
 * Asymptotic covariance of the empirical Haar WV vector of @p wv's scales
 * under the Gaussian model @p m (Percival 1995; Percival & Walden 2000 §8.3):
 * Cov(nu_hat_j, nu_hat_k) = 2 / max(M_j, M_k) int |H_j(f)|^2 |H_k(f)|^2 S(f)^2 df,
 * H_j the Haar MODWT wavelet filter of level j, S the spectral density per
 * sample of the random terms (WN, QN, RW pseudo-spectrum, GM). DR and SIN are
 * deterministic and add no variance (their cross terms with the noise are neglected).
 * Valid for M_j >> tau_j (eta_j >> 1); it overstates the variance of the coarsest scales.
 * @param[in] m   model (per-sample parameters at m.rate_hz, which must equal the data rate).
 * @param[in] wv  scales tau_j [samples] and coefficient counts M_j (n_coef, or n - tau_j + 1).
 * @return J x J covariance [unit^4].
 */
Eigen::MatrixXd wvCovariance(const stochastic::Model& m, const WaveletVariance& wv);

/// Haar WV of @p m at scale @p tau [samples] by integrating |H(f)|^2 S(f) (check of wvCovariance's quadrature) [unit^2].
double spectralWv(const stochastic::Model& m, double tau);

/**
 * Fit a structure (e.g. WN+GM+GM+DR) to @p wv.
 * @throws navimpact::Error if the structure is empty or has more parameters than scales.
 */
FitResult fit(const std::vector<stochastic::ProcessKind>& structure, const WaveletVariance& wv,
              const FitOptions& opt = {});

/**
 * Asymptotic optimism of a fit, 2 tr(A dTheta V Omega) with
 * dTheta = (B + D)^+ A' Omega the sensitivity of theta_hat to nu_hat,
 * B = A' Omega A, D_kl = sum_j d2nu_j/dtheta_k dtheta_l Omega_jj (nu_j(theta_hat) - nu_hat_j),
 * V = diag(2 nu_j(theta_hat)^2 / eta_j) (chi-square variance of each WV estimate).
 * (Guerrier et al. 2013 / R gmwm model_score, gmwm_formulas.md §6.)
 */
double optimism(const FitResult& f, const WaveletVariance& wv);

/**
 * Default candidates of the automatic selection: WN + optional QN, RW, DR +
 * 0..max_gm GM (WN always present: every MEMS channel shows it at the first scales).
 */
std::vector<std::vector<stochastic::ProcessKind>> defaultCandidates(int max_gm = 3);

/// Default fraction of the empirical WV's 95 % CI width below which a term is negligible.
constexpr double kNegligibleFraction = 0.1;

/**
 * Flags the terms of @p m that the data cannot see: a term is negligible when
 * its Haar WV is below @p fraction times the width of the empirical WV's 95 %
 * CI (ci_high_j - ci_low_j) at EVERY scale of @p wv, i.e. removing it moves
 * the model WV by less than a tenth of the data's own uncertainty anywhere
 * (typically a term pushed to its lower bound, e.g. WN(sigma=7e-66)).
 * @param[in] m         fitted model (per-sample parameters at m.rate_hz).
 * @param[in] wv        the empirical WV the model was fitted to.
 * @param[in] fraction  in (0, 1], default kNegligibleFraction.
 * @return one flag per term of @p m.
 */
std::vector<bool> negligibleTerms(const stochastic::Model& m, const WaveletVariance& wv,
                                  double fraction = kNegligibleFraction);

/**
 * Scales where the model's Haar WV lies outside the empirical WV's confidence
 * interval (ci_low, ci_high), i.e. what the model does not describe. With
 * marginal 95 % intervals about 5 % of the scales fall outside by chance.
 * @return indices into @p wv's scales, ascending.
 */
std::vector<int> scalesOutsideCi(const stochastic::Model& m, const WaveletVariance& wv);

/**
 * Chance that at least @p outside of @p scales marginal 95 % intervals miss a
 * correct model: the binomial tail P(X >= outside), X ~ Binomial(scales, 0.05)
 * (scales treated as independent; neighbouring Haar scales are nearly so).
 * Below 0.05 the misses are more than chance gives: the model does not
 * describe the data there.
 */
double outsideCiChance(int outside, int scales);

/// Two GMs whose correlation times are within this factor are one term
/// (their WV peaks are less than an octave apart, one Haar scale step).
constexpr double kDuplicateTFactor = 2.0;

/// Two terms of a model that are one (redundantTerms).
struct RedundantPair {
  int keep = -1;    ///< index of the term that would take the merged amplitude
  int drop = -1;    ///< index of the term that is wasted
  std::string why;  ///< plain-language reason, e.g. "GM 1 and GM 2 have T within a factor 2 (0.006 s, 0.006 s)"
};

/**
 * Pairs of terms of @p m that are one, among the terms that are not
 * negligible (negligibleTerms with @p fraction): two terms of one kind
 * without a shape parameter (WN, QN, RW, DR: proportional WVs); two GMs with
 * T within kDuplicateTFactor; two SINs within 1 % in frequency; a GM with T
 * below one sample whose WV equals that of a white noise of its long-run
 * variance sigma^2 (1+phi)/(1-phi) within @p fraction of the CI width at every
 * scale, next to a WN; a GM whose WV equals that of a random walk with
 * gamma^2 = 2 sigma^2 (1-phi) within the same margin, next to a RW.
 * gmwm::fit never returns such a pair: it merges the two, frees one term and
 * restarts the search with the freed term placed across the scale range.
 * A GM below one sample that is measurably NOT white (lag-1 correlation the
 * WV resolves) next to a vanishing WN is not a pair: it is the better model
 * of the high-frequency noise (see stochastic::datasheetFigures for its ARW).
 * @param[in] m         model (per-sample parameters at m.rate_hz = wv.rate_hz).
 * @param[in] wv        empirical WV (its CI widths set the margins).
 * @param[in] fraction  in (0, 1], default kNegligibleFraction.
 */
std::vector<RedundantPair> redundantTerms(const stochastic::Model& m, const WaveletVariance& wv,
                                          double fraction = kNegligibleFraction);

/// One candidate of an automatic model selection.
struct RankedModel {
  FitResult fit;
  double criterion = 0.0;   ///< objective + optimism (wavelet information criterion)
  double optimism = 0.0;
};

/**
 * Rank candidate structures by the wavelet information criterion (objective +
 * estimated optimism); best first. If the best candidate has a negligible term
 * (negligibleTerms) and the candidate without that term was fitted, the
 * latter is moved to the front (the data cannot tell the two apart; the
 * simpler one is preferred), repeatedly. @p why receives a plain-language reason.
 */
std::vector<RankedModel> selectModel(const std::vector<std::vector<stochastic::ProcessKind>>& candidates,
                                     const WaveletVariance& wv, const FitOptions& opt,
                                     std::string* why = nullptr);

}  // namespace navimpact::gmwm
