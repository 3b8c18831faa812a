// Internal declarations shared by the diagnosis sources (not installed).
//
// diagnosis.cpp runs the pipeline of diagnosis.hpp on every channel, one
// function per step, each reading the channel's ChannelContext; it holds the
// WV test of step 4 (checkWv), the extension (5) and the held-out gain (6):
//  - diagnosis_detect.cpp: steps 1-3, the detectors (outliers, lines, level
//    shifts), each taking what it finds out of the record;
//  - diagnosis_search.cpp: step 4, the search for the cause of the broadband
//    misfit on the cleaned record's WV, with the slow decision
//    (diagnosis_slow.hpp);
//  - diagnosis_extensions.cpp: the extensions of a model fitted to a measured
//    wavelet variance (WV) -- one process family added or one term retuned
//    (Candidate), sets of them backfitted jointly (Extension), chosen by AIC
//    on the chi-square (gamma) deviance -- and the GMWM refit of an extension.
// The steps write their findings and notes into the channel's
// ChannelDiagnosis and return what the later steps need.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/detect/lines.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/process.hpp"

namespace navimpact::analysis::detail {

using stochastic::Model;
using stochastic::Process;
using stochastic::ProcessKind;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Chi-square(nu) quantiles (lower at @p p; upper at @p q, P[X > x] = q) and
/// the lower and upper tail probabilities at @p x. Where boost's incomplete
/// gamma overflows (extreme dof or statistic) they fall back to the
/// Wilson-Hilferty cube-root normal approximation, accurate at the large dof
/// where that happens.
double chiQuantile(double nu, double p);
double chiUpperQuantile(double nu, double q);
std::pair<double, double> chiTails(double nu, double x);

// --------------------------------------------------------------------------
// Wavelet variances of models

/**
 * Chi-square (gamma) deviance of measured WV @p nu_hat against model WV @p nu
 * with dof @p eta: sum eta_j (nu_hat/nu - log(nu_hat/nu) - 1).
 */
double wvDeviance(const std::vector<double>& nu_hat, const std::vector<double>& nu,
                  const std::vector<double>& eta);

/// The cause a process kind stands for.
Cause causeOf(ProcessKind k);

/// The parameter of a process whose square scales its WV: the first
/// parameter of its kind in the registry (WN sigma, QN Q, RW gamma, DR omega,
/// GM sigma, SIN amp).
double& mainParam(Process& p);

/// A process of kind @p k with unit scale and, where the kind has a second
/// (shape) parameter, that parameter set to @p shape (GM T [s], SIN freq [Hz]).
Process unitProcess(ProcessKind k, double shape = 1.0);

/// Haar WV of a process at @p rate [Hz], or of a model, at scales @p tau [samples].
std::vector<double> wvOf(const Process& p, double rate, const std::vector<double>& tau);
std::vector<double> wvOf(const Model& m, const std::vector<double>& tau);

std::vector<double> toStd(const Eigen::VectorXd& v);

/// Model without its SIN terms (the null of the detectors; lines are excluded by frequency).
Model withoutSin(const Model& m);

/// A measured WV: scales, values and the chi-square dof they are judged with.
struct WvData {
  std::vector<double> tau;   ///< samples
  std::vector<double> nu;    ///< measured
  std::vector<double> dof;
  double samples = 0;        ///< record length [samples] (0: from the scales)
};

/// The WV test of a model on WvData: per-scale bounds on measured / model
/// outside which a scale is significant (two-sided, chi-square with the
/// data's dof, at @p p_thr), and the width of the 95 % CI per unit model WV.
struct WvTest {
  std::vector<double> lo, hi, ci95;
  double p_thr = 0;
};

WvTest wvTest(const WvData& d, double p_thr);

/// Scales of @p d significant under the model WV @p nu_m.
int significantScales(const WvData& d, const WvTest& t, const std::vector<double>& nu_m);

// --------------------------------------------------------------------------
// Candidate extensions: the WV of the current model plus (or with one term
// replaced by) one process family, its variance-like parameter a (sigma^2,
// Q^2, gamma^2, omega^2, GM sigma^2) and, for GM, T fitted by minimising the
// gamma deviance. Everything else in the model is kept as it is.

struct Candidate {
  bool retune = false;       ///< replace term `term` instead of adding
  int term = -1;
  ProcessKind kind = ProcessKind::WN;
  Process proc;              ///< fitted process (added or replacing)
  double deviance = kNaN;
  int params = 1;
  double T_lo = kNaN, T_hi = kNaN;  ///< GM: profile interval of T
  bool T_hi_open = false;            ///< GM: interval reaches the top of the T grid
  bool T_top_only = false;           ///< GM: only the interval reaches it (best T inside)
  bool T_bottom = false;             ///< GM: best T at one sample (white noise)
  double scale = 1;          ///< retune: new / old variance parameter
  double p_lo = kNaN, p_hi = kNaN;   ///< 95 % profile interval of the main parameter
};

/// Fit @p kind added to @p model (or, @p retune, replacing its term @p term)
/// on @p d. @p T_hint (GM only, finite): search T only near it (a refinement
/// step of a joint fit; no profile interval), else over the whole grid.
/// Without @p intervals the 95 % interval of the main parameter is left out.
Candidate fitCandidate(bool retune, int term, ProcessKind kind, const Model& model,
                       const WvData& d, double T_hint = kNaN, bool intervals = true);

/// Apply a candidate to a model: add (merging WN/QN/RW/DR into an existing
/// term of the same kind, their variances add) or replace the tuned term.
Model applyCandidate(const Model& m, const Candidate& c);

/// A candidate's term in words ("retuned " first when it replaces one).
std::string candidateText(const Candidate& c);

// --------------------------------------------------------------------------
// Joint extensions: a set of terms added to (or retuning terms of) the user's
// model, every term refitted with the others held (backfitting: each term's
// least-deviance fit given the rest, sweeps until the deviance settles). Two
// effects on one channel are told apart only when both are fitted together:
// a term fitted alone absorbs what the other explains (a random walk into a
// longer GM, white noise into a short GM's T, leaving a residue of the
// wrong shape for the next term).

/// @p base with @p cs applied, every added term kept as its own term (the WV
/// is additive; merging is for the model file). @p skip: leave that one out.
Model assemble(const Model& base, const std::vector<Candidate>& cs, int skip = -1);

/// Index of cs[i]'s term in assemble(base, cs).
int assembledIndex(const Model& base, const std::vector<Candidate>& cs, std::size_t i);

/// The same set as in the model file: retunes, then additions merged into a
/// term of the same kind (applyCandidate); vanishing additions are left out,
/// and so is a term retuned to zero unless @p keep_places (then it stays, at
/// zero, so that retune indices still refer to base's terms; such a model is
/// for its WV only: simulate() refuses a zero parameter).
Model merged(const Model& base, const std::vector<Candidate>& cs, bool keep_places = false);

/// AIC penalty of a set (from its term @p from on): 2 per parameter; retuning
/// a term of the user's model discards what they had and is charged as two
/// more parameters.
double penalty(const std::vector<Candidate>& cs, std::size_t from = 0);

/// Refit every term of @p cs given the others on @p d (warm start: their
/// current values); the last pass profiles each GM over the whole T grid
/// (its interval and whether the data bound T). Returns the deviance of
/// assemble(base, cs).
double backfit(const Model& base, std::vector<Candidate>& cs, const WvData& d);

/// One extension of the committed set: its terms (the committed ones,
/// refitted, then `added` new ones at the end), deviance and AIC.
struct Extension {
  Extension() = default;
  /// The committed set @p committed, to which the caller adds @p added new terms.
  Extension(std::vector<Candidate> committed, int added) : terms(std::move(committed)), added(added) {}
  std::vector<Candidate> terms;
  int added = 0;
  double deviance = kNaN, crit = kNaN;
  bool valid = false;
  int significant = 0;  ///< scales still significant under it
  bool needed = true;   ///< a pair: each term needed (nested likelihood-ratio test on the WV)
  bool open_top = false;  ///< invalid only by a GM whose WV profile interval of T reaches record/5
  std::string why_not;  ///< why it is not valid
};

/// The new terms of an extension in words ('+' between them).
std::string newTermsText(const Extension& e);

/// Every extension of the committed set @p S (already backfitted on @p d)
/// by one new term (each family added, or one of the user's terms retuned)
/// or, when @p max_new >= 2, by two new terms fitted jointly. Each set is
/// backfitted. Valid: no vanishing term and no GM whose T the data do not
/// bound inside (1 sample, record/5); a pair only when each of its terms
/// alone (with S) still leaves scales significant, and each changes the WV
/// by at least its 95 % CI width at some scale (both are needed).
std::vector<Extension> extensions(const Model& base, const std::vector<Candidate>& S, const WvData& d,
                                  const WvTest& wt, int max_new);

/// Best stochastic extension of @p m on the WV @p d: terms added (one or two
/// at a time, jointly fitted) while AIC improves, up to @p max_terms, as the
/// cause search; used as the alternative explanation of candidate level
/// shifts. *params: parameters added.
Model greedyExtension(const Model& m, const WvData& d, int max_terms, double p_thr, int* params);

/// GMWM refit of @p start's structure (SIN terms kept as they are) on @p wv,
/// warm-started at @p start; returns the refit when its gamma deviance on @p d
/// is not above the start's, else @p start. @p how says which was kept.
Model gmwmRefit(const Model& start, const gmwm::WaveletVariance& wv, const WvData& d,
                std::string* how);

// --------------------------------------------------------------------------
// One channel's diagnosis

/// Family-wise level of each test family, per channel.
struct Budget {
  double wv = 0, spec = 0, steps = 0, spikes = 0;
};

/// What every step of one channel's diagnosis reads.
struct ChannelContext {
  std::string name;             ///< e.g. "gyro_z"
  std::string unit;             ///< its SI unit (channelUnit)
  int index = 0;                ///< channel index (seeds its random streams)
  double rate = 0;              ///< sampling rate [Hz]
  std::size_t n = 0;            ///< samples
  double record = 0;            ///< record length [s]
  double t0 = 0;                ///< time of the first sample [s]
  Model m0;                     ///< the user's model at the data rate
  Model m0n;                    ///< the same without SIN terms (the detectors' null)
  Budget B;                     ///< this channel's share of alpha per test family
  double channels = 1;          ///< channels diagnosed (Bonferroni of WV p-values)
  int max_terms = 3;            ///< DiagnoseOptions::max_terms
  int simulations = 0;          ///< DiagnoseOptions::simulations
  std::uint64_t seed = 0;       ///< DiagnoseOptions::seed
};

/// 1. Outlier events (spikes, bursts such as a knock) of @p x, interpolated
/// out: one finding for all, each event in cd.outlier_events. Returns false
/// (with a note) for a channel quantised below its quantum, where the
/// Gaussian event tests of step 3 do not hold.
bool removeOutliers(const ChannelContext& ctx, std::vector<double>& x, ChannelDiagnosis& cd);

/// 2. Spectral lines of @p x against the model's PSD, subtracted from @p x:
/// the spectrum and line frequencies in @p cd, one finding per line (its
/// harmonics and a line wandering within 10 bins of it with it). Returns
/// every line found.
std::vector<detect::SpectralLine> removeLines(const ChannelContext& ctx, std::vector<double>& x,
                                              ChannelDiagnosis& cd);

/// 3. Level shifts, detected under the model and accepted only when each is
/// significant against the best stochastic explanation of the record
/// without shifts, fitted to @p wv_pre (the WV of @p x as steps 1-2 left it;
/// a random walk, a long Gauss-Markov or a drift also make large window
/// contrasts): exact likelihood-ratio test of block means, Bonferroni over
/// the block boundaries (detect/step_test.hpp); accepted shifts are removed
/// from @p x. Transients of at most 1 s (knocks), tested at their own scale,
/// are outlier events, interpolated out. Returns whether @p x changed.
///
/// When no shift beats that explanation, the candidates are left in
/// @p left for shiftsTheSearchLeft (after the cause search).
struct ShiftsLeft {
  std::vector<std::size_t> index;  ///< candidate sample indices
  std::vector<double> lr_ext0;     ///< their likelihood ratios against the explanation without shifts
  std::string ext0, how;           ///< that explanation and its test, in words
  double lr_thr = 0;               ///< the test's threshold (chi2_1, Bonferroni over the block boundaries)
};
bool removeLevelShifts(const ChannelContext& ctx, const gmwm::WaveletVariance& wv_pre, std::vector<double>& x,
                       ChannelDiagnosis& cd, ShiftsLeft& left);

/// The candidate shifts of step 3 that a random walk took up, tested again
/// once the cause search is done: against the user's model with the terms
/// it found, @p found_model (variances profiled, no random walk added; the
/// same level and threshold). A shift significant there is something
/// neither the model nor the terms found explain, which the explanation
/// without shifts took up as a random walk: an undecided level-shift
/// finding, that random walk its runner-up. Without terms found, the test
/// is step 3's under the user's model alone, at its level.
std::vector<Finding> shiftsTheSearchLeft(const ChannelContext& ctx, const std::vector<double>& x,
                                         const ShiftsLeft& left, const Model& found_model);


/// Per-scale comparison of a measured WV with a model WV @p nu_m under
/// chi-square(@p dof), significant below @p p_thr; the simulation envelope
/// @p env_lo / @p env_hi may be empty (NaN in the result).
std::vector<ScaleCheck> checkScales(const gmwm::WaveletVariance& wv, const std::vector<double>& nu_m,
                                    const std::vector<double>& dof, double p_thr,
                                    const std::vector<double>& env_lo,
                                    const std::vector<double>& env_hi);

/// The WV of the raw and of the cleaned record against the user's model
/// (diagnosis.cpp, the start of step 4).
struct WvCheck {
  gmwm::WaveletVariance raw;      ///< WV of the raw record (its mean removed)
  gmwm::WaveletVariance cleaned;  ///< WV of the record steps 1-3 cleaned
  std::vector<double> tau;        ///< scales [samples]
  /// Chi-square dof per scale: the WV's, lowered to those seen in the model's
  /// own simulations where those are fewer.
  std::vector<double> dof;
  double p_thr = 0;               ///< per-scale p-value threshold (Bonferroni over scales)
  WvData full;                    ///< the cleaned WV with those dof, on the whole record
  std::vector<ScaleCheck> cleaned_vs_model;  ///< the cleaned WV against the model without its lines
};

/// 4. The cause of the broadband misfit of the cleaned record @p x: while
/// scales stay significant, the extension of the terms found so far (one
/// term, or two fitted jointly) chosen by AIC on the cleaned WV, the slow
/// explanations ranked again on the exact likelihood of the block means and
/// put to the slow decision (diagnosis_slow.hpp); a finding per new term
/// with its evidence and runner-up, restated as it stands in the joint fit
/// of all. Returns the terms found (backfitted on the whole record).
std::vector<Candidate> searchCauses(const ChannelContext& ctx, const std::vector<double>& x, const WvCheck& w,
                                    ChannelDiagnosis& cd);

}  // namespace navimpact::analysis::detail
