// The slow decision of navimpact diagnose (step 4 of the cause search,
// internal): which slow explanation -- random walk, drift, a Gauss-Markov
// process with T near the record, or two of them -- a channel's excess at
// the coarsest scales is, decided on the exact likelihood of the record's
// block means (stochastic/block_likelihood.hpp) and calibrated by a
// parametric bootstrap, whatever the wavelet variance made of it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::analysis::slow {

/// Level and simulated records of the bootstraps: with 39 records the
/// Monte Carlo test is exact at 5 % (Barnard 1963; Besag & Clifford 1989):
/// rejected when at most 1 of them reaches the observed margin.
constexpr double kLevel = 0.05;
constexpr int kDraws = 39;

/// What the cause search hands over: the explanation its WV stage chose.
struct Problem {
  /// The model without lines: the user's terms, the terms found before and
  /// the chosen explanation's fast new terms (none of its slow ones). They
  /// stay as the WV fitted them: at the block length they add a white
  /// variance that the short scales fix far better than the block means.
  stochastic::Model base;
  double fast_pen = 0;                    ///< the fast new terms' AIC penalty
  std::vector<std::string> fast_causes;   ///< their causes
  /// The WV stage's explanation: its model (start of its own fit), its slow
  /// random terms (indices in wv_start), its penalty and slow causes.
  stochastic::Model wv_start;
  std::vector<int> wv_own;
  double wv_pen = 0;
  std::vector<Cause> wv_slow;
  /// Its slow new terms (drift included) in wv_start, in the order they
  /// were added; empty when one of them retunes a term of the model (then
  /// only a swap reports exact-likelihood parameters).
  std::vector<int> wv_idx;
  std::string wv_text;                    ///< its new terms in words
  const std::vector<double>* y = nullptr; ///< block means of the cleaned record
  std::size_t block = 1;                  ///< samples per block
  double rate_hz = 0, record_s = 0;
  std::uint64_t seed = 0;
};

/// A slow term of the chosen explanation as fitted on the exact likelihood.
struct Term {
  stochastic::Process proc;               ///< RW gamma, DR omega (signed), GM sigma and T
  double lo = 0, hi = 0;                  ///< 95 % profile interval: gamma, omega, or T (GM)
  bool open_top = false;                  ///< GM: the interval of T reaches record/5
};

struct Choice {
  bool decided_here = false;              ///< false: too few blocks or nothing fitted; the caller keeps its own
  bool swapped = false;                   ///< the chosen slow terms differ from the WV stage's
  std::vector<Term> terms;                ///< the chosen slow terms as fitted on the exact likelihood (to replace the WV's)
  std::string causes;                     ///< chosen causes ('+'-joined, sorted), fast ones included
  std::string evidence;                   ///< one clause: what the exact likelihood said
  // The runner-up that leaves the choice most open (empty: none compared).
  std::string runner_up, runner_up_detail;
  double aic_margin = 0;                  ///< runner-up AIC minus the winner's (exact likelihood)
  double p = 1;                           ///< bootstrap p-value of the comparison
  int draws = 0;                          ///< simulated records behind it
  bool larger = false;                    ///< the runner-up has more slow terms (p: its lead under the winner)
  bool decided = true;                    ///< no rival survives at the level
};

/// Decide (see the file comment). Deterministic for a given seed.
Choice decide(const Problem& p);

}  // namespace navimpact::analysis::slow
