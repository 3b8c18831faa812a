/**
 * @file step_test.hpp
 * @brief Level shift or stochastic wandering? An exact likelihood-ratio test
 *        of level shifts at candidate times under a noise model that has
 *        its own random walk / Gauss-Markov / drift explanation of the record.
 *
 * The record is reduced to the means of nb ~ @c target_blocks consecutive
 * blocks of b samples, whose exact Gaussian likelihood under the model's WN,
 * QN, GM and RW terms is stochastic::blockLogLikelihood (Kalman filter on the
 * exact block state space). A level shift at a block boundary is a regressor
 * (0 before, 1 after) next to the mean (and a trend when the model has a
 * drift). The statistic is the generalised likelihood ratio
 * LR = 2 (l_1 - l_0), each side maximised over the shift sizes (GLS) and over
 * the variance of every random term (GM correlation times kept; a random walk
 * is added when the model has none, so that a wandering level is always the
 * alternative explanation, its variance profiled from zero up). At a FIXED
 * boundary LR is asymptotically chi-square with one degree of freedom (Wilks;
 * Harvey 1989 §3.4 for the regression part), so the largest over the nb - 1
 * boundaries a detector can pick exceeds chi2_1(1 - alpha / (nb - 1)) with
 * probability at most about alpha (Bonferroni): the penalty is derived, not
 * tuned. Candidates (in the order a detector found them, at sample indices)
 * are snapped to the nearest block boundary; forward selection: all are
 * tested given the shifts accepted so far and the strongest is accepted when
 * significant, until none is (under "no shift at all" only the first round
 * can accept, at level alpha). Accepted shifts are then sized by GLS at their
 * exact sample indices.
 *
 * The noise model should be the best stochastic explanation of the record
 * WITHOUT the shifts (e.g. the user's model extended by the terms a WV fit of
 * the whole record asks for): a genuine shift then has to beat a random walk
 * that was allowed to absorb it.
 */
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::detect {

struct StepTestOptions {
  std::size_t target_blocks = 128;   ///< block means used (blocks of max(1, n / target) samples)
  /// Maximise the likelihood over the variance of every random term under
  /// each hypothesis (a generalised likelihood ratio); false: the model as given.
  bool profile_variances = true;
  /// With profiling: a model without a random walk gets one (its variance
  /// profiled like the others, from zero upwards), so that a wandering level
  /// is always an alternative to shifts.
  bool add_random_walk = true;
};

/// One tested candidate.
struct StepTest {
  std::size_t index = 0;     ///< candidate sample index (first sample after the shift)
  std::size_t boundary = 0;  ///< block boundary it was tested at [blocks]
  double lr = 0;             ///< 2 (l_1 - l_0), chi2_1 at a fixed boundary under the model
  double p_value = 1;        ///< Bonferroni over the nb - 1 boundaries
  bool accepted = false;
  /// Accepted: GLS size at the exact sample index (mean after - mean before)
  /// given the other accepted shifts, and its standard error [unit]; NaN otherwise.
  double size = std::numeric_limits<double>::quiet_NaN();
  double size_se = std::numeric_limits<double>::quiet_NaN();
};

struct StepTestResult {
  std::size_t block = 1;           ///< samples per block
  std::size_t blocks = 0;          ///< block means used
  std::vector<StepTest> tests;     ///< one per candidate, in the order given
  std::size_t accepted() const {
    std::size_t k = 0;
    for (const auto& t : tests) k += t.accepted ? 1 : 0;
    return k;
  }
  /// The noise model under the accepted shifts (variances profiled when asked).
  stochastic::Model model;
};

/**
 * Test level shifts at @p candidates (sample indices, in the order found)
 * in @p x under the random terms of @p m (DR adds a trend regressor).
 * @param[in] alpha  level of the first test (family-wise under "no shift").
 * @throws navimpact::Error for a model without random terms, fewer than 8
 *         samples or alpha outside (0, 1).
 */
StepTestResult testLevelShifts(const std::vector<double>& x, const stochastic::Model& m,
                               const std::vector<std::size_t>& candidates, double alpha,
                               const StepTestOptions& opt = {});

}  // namespace navimpact::detect
