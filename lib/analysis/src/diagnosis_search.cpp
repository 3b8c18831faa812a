// Step 4 of navimpact diagnose on one channel (see diagnosis.hpp): the cause
// of the broadband misfit. Every extension of the model by one term or two
// jointly fitted ones (diagnosis_extensions.cpp) is ranked by AIC on the
// cleaned record's wavelet variance; when the winner is slow (random walk,
// drift, long Gauss-Markov) the slow explanations are ranked again on the
// exact likelihood of the record's block means and the slow decision
// (diagnosis_slow.cpp) may replace the WV's choice and judges its runner-up;
// each term found is a finding with its evidence and runner-up, then
// restated as it stands in the joint fit of all of them.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>


#include "diagnosis_internal.hpp"
#include "diagnosis_slow.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis::detail {

namespace {

int countSignificant(const std::vector<ScaleCheck>& s) {
  int c = 0;
  for (const auto& x : s) c += x.significant ? 1 : 0;
  return c;
}

const char* shapeWords(ProcessKind k) {
  switch (k) {
    case ProcessKind::WN: return "falls as 1/tau, the shape of white noise";
    case ProcessKind::QN: return "falls as 1/tau^2, the shape of quantization noise";
    case ProcessKind::RW: return "grows as tau, the shape of a random walk";
    case ProcessKind::DR: return "grows as tau^2, the shape of a drift";
    case ProcessKind::GM: return "is peaked, the shape of a Gauss-Markov process";
    case ProcessKind::SIN: return "oscillates, the shape of a sinusoid";
  }
  return "";
}

std::string scaleRange(double lo, double hi) {
  if (!(hi > lo * 1.0001)) return "tau = " + formatNumber(lo, 3) + " s";
  return "tau = " + formatNumber(lo, 3) + "–" + formatNumber(hi, 3) + " s";
}

/// Largest |WV change| of a model change relative to the CI width of the
/// measured WV at that scale (a finding must reach 1 somewhere).
double wvChangeInCiWidths(const std::vector<ScaleCheck>& chk, const std::vector<double>& nu_before,
                          const std::vector<double>& nu_after) {
  double best = 0;
  for (std::size_t j = 0; j < chk.size(); ++j) {
    const double w = chk[j].ci_high - chk[j].ci_low;
    if (w > 0) best = std::max(best, std::abs(nu_after[j] - nu_before[j]) / w);
  }
  return best;
}

/// Scales where a change of model explains the misfit: outside the per-scale
/// 95 % CI before, with the log misfit reduced by more than half.
void explainedRange(const std::vector<ScaleCheck>& chk, const std::vector<double>& nu_before,
                    const std::vector<double>& nu_after, double* lo, double* hi, double* max_ratio,
                    int* count) {
  *lo = kNaN;
  *hi = kNaN;
  *max_ratio = 1;
  *count = 0;
  for (std::size_t j = 0; j < chk.size(); ++j) {
    const double mb = std::abs(std::log(chk[j].measured / std::max(nu_before[j], 1e-300)));
    const double ma = std::abs(std::log(chk[j].measured / std::max(nu_after[j], 1e-300)));
    if (!chk[j].outside95 || !(mb - ma > 0.5 * mb)) continue;
    if (std::isnan(*lo)) *lo = chk[j].tau_s;
    *hi = chk[j].tau_s;
    ++*count;
    const double r = chk[j].ratio;
    if (std::abs(std::log(r)) > std::abs(std::log(*max_ratio))) *max_ratio = r;
  }
}

/// @p jointly: @p before is the model with the other terms found (their joint
/// fit), not the model as given: the text says which it compares with.
Finding broadbandFinding(const std::string& ch, const Candidate& c, const Model& before,
                         const std::vector<ScaleCheck>& chk, const std::vector<double>& tau,
                         double rate, bool jointly = false) {
  Finding f;
  f.channel = ch;
  f.cause = causeOf(c.kind);
  const Model after = applyCandidate(before, c);
  const auto nb = wvOf(before, tau), na = wvOf(after, tau);
  double lo, hi, ratio;
  int count;
  explainedRange(chk, nb, na, &lo, &hi, &ratio, &count);
  f.range_key = "scales_s";
  f.range_lo = lo;
  f.range_hi = hi;
  const std::string unit = channelUnit(ch);
  Process p = c.proc;
  std::ostringstream ex;
  const bool above = ratio >= 1;
  f.direction = (c.retune && c.scale < 1) ? "overstated" : "missing";
  const double factor = above ? ratio : 1.0 / ratio;
  const char* against = jointly ? "the model with the other terms found" : "the model";
  if (count > 0 && !std::isfinite(factor))  // the comparison model has no WV there ("infx above" before)
    ex << "the measured WV is all excess over " << against << ", which has none at " << scaleRange(lo, hi) << " ("
       << count << " scale" << (count > 1 ? "s" : "") << " outside its 95 % CI); ";
  else if (count > 0)
    ex << "the measured WV is "
       << (factor < 1.5  // a small excess as a percentage ("1x" says nothing)
               ? formatNumber(100.0 * std::abs(ratio - 1.0), 2) + " % "
               : formatNumber(factor, 2) + "x ")
       << (above ? "above " : "below ") << against << " at " << scaleRange(lo, hi) << " ("
       << count << " scale" << (count > 1 ? "s" : "") << " outside the 95 % CI); ";
  switch (c.kind) {
    case ProcessKind::WN: f.params = {{"sigma", p.sigma}}; break;
    case ProcessKind::QN: f.params = {{"Q", p.Q}}; break;
    case ProcessKind::RW: f.params = {{"gamma", p.gamma}}; break;
    case ProcessKind::DR: f.params = {{"omega", p.omega}}; break;
    case ProcessKind::GM:
      f.params = {{"sigma", p.sigma}, {"T", p.T}};
      f.T_interval_s = std::make_pair(c.T_lo, c.T_hi);
      f.intervals.push_back({"T", {c.T_lo, c.T_hi}});
      break;
    case ProcessKind::SIN: f.params = {{"amplitude", p.amp}, {"freq_hz", p.freq_hz}}; break;
  }
  if (c.kind != ProcessKind::GM && std::isfinite(c.p_lo))
    f.intervals.push_back({f.params.front().first, {c.p_lo, c.p_hi}});
  const bool absent = c.retune && !(mainParam(p) > 0);
  if (absent) {
    Process old = before.terms[c.term];
    ex << "the model's " << stochastic::formatTerms({old}, 3)
       << " is overstated: the data show none of it (its best fit is zero)";
  } else if (c.retune) {
    Process old = before.terms[c.term];
    ex << "the model's " << stochastic::formatTerms({old}, 3) << " is "
       << (c.scale < 1 ? "overstated" : "understated") << "; the data fit "
       << stochastic::formatTerms({p}, 3);
  } else {
    ex << "the excess " << shapeWords(c.kind);
    if (c.kind == ProcessKind::GM)
      ex << " with T = " << formatNumber(p.T, 3) << " s (95 % interval " << formatNumber(c.T_lo, 3) << "–"
         << formatNumber(c.T_hi, 3) << " s), sigma = " << formatNumber(p.sigma, 3) << " " << unit;
    else
      ex << ": " << stochastic::formatTerms({p}, 3) << " (" << unit << ", per sample at "
         << formatNumber(rate, 4) << " Hz)";
  }
  ex << ".";
  f.explanation = ex.str();
  f.action = absent     ? "remove it from the model (model_extended.yaml leaves it out)"
             : c.retune ? "retune it in the model (model_extended.yaml)"
                      : "add it to the model (model_extended.yaml); the filter takes it as " +
                            std::string(c.kind == ProcessKind::WN || c.kind == ProcessKind::QN
                                            ? "measurement noise"
                                            : "error state(s)");
  return f;
}
// --------------------------------------------------------------------------
// The exact likelihood of the block means

/// Block means of the cleaned record for the exact likelihood that decides
/// between the slow explanations (random walk, drift, long Gauss-Markov),
/// which differ only at the coarsest WV scales where it has few dof.
struct BlockMeans {
  const ChannelContext& ctx;
  std::size_t blk;        ///< samples per block
  std::vector<double> y;  ///< the means

  BlockMeans(const ChannelContext& c, const std::vector<double>& x)
      : ctx(c), blk(std::max<std::size_t>(1, c.n / 512)), y(stochastic::blockMeans(x.data(), c.n, blk)) {}

  /// Enough blocks for the exact likelihood to judge.
  bool usable() const { return y.size() >= 16; }

  /// A slow term: a random walk, a drift, or an added GM of T >= 4 blocks.
  bool isSlow(const Candidate& c) const {
    if (c.kind == ProcessKind::RW || c.kind == ProcessKind::DR) return true;
    return c.kind == ProcessKind::GM && !c.retune && c.proc.T * ctx.rate >= 4.0 * static_cast<double>(blk);
  }

  bool hasSlow(const Extension& e) const {
    for (std::size_t i = e.terms.size() - e.added; i < e.terms.size(); ++i)
      if (isSlow(e.terms[i])) return true;
    return false;
  }

  /// The new terms of an extension that are not slow: extensions with the
  /// same such part differ only in their slow explanation.
  std::vector<std::tuple<int, int, int>> fastPart(const Extension& e) const {
    std::vector<std::tuple<int, int, int>> k;
    for (std::size_t i = e.terms.size() - e.added; i < e.terms.size(); ++i)
      if (!isSlow(e.terms[i])) k.emplace_back(e.terms[i].retune, e.terms[i].term, static_cast<int>(e.terms[i].kind));
    std::sort(k.begin(), k.end());
    return k;
  }

  /// Regressors of the block means: the mean, a trend when the model has a
  /// drift, and optionally a level shift at block boundary @p step.
  Eigen::MatrixXd regressors(bool trend, std::size_t step) const {
    Eigen::MatrixXd X(static_cast<Eigen::Index>(y.size()), 1 + (trend ? 1 : 0) + (step > 0 ? 1 : 0));
    for (std::size_t k = 0; k < y.size(); ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      X(r, 0) = 1.0;
      if (trend) X(r, 1) = (static_cast<double>(k) + 0.5) / static_cast<double>(y.size()) - 0.5;
      if (step > 0) X(r, X.cols() - 1) = k >= step ? 1.0 : 0.0;
    }
    return X;
  }

  /// AIC on the exact likelihood of the block means of an extension: only its
  /// new terms profiled (a drift's slope is the GLS trend), their parameters
  /// counted. NaN when the likelihood cannot be evaluated.
  double exactAic(const Extension& e, double* loglik) const {
    Model mc = withoutSin(assemble(ctx.m0n, e.terms));
    const Eigen::MatrixXd X = regressors(mc.count(ProcessKind::DR) > 0, 0);
    std::vector<int> own;
    for (std::size_t q = e.terms.size() - e.added; q < e.terms.size(); ++q)
      if (e.terms[q].kind != ProcessKind::DR) own.push_back(assembledIndex(ctx.m0n, e.terms, q));
    if (own.empty()) own.push_back(-1);
    try {
      const double l = stochastic::profileBlockLogLikelihood(mc, y, blk, X, own);
      *loglik = l;
      return -2.0 * l + penalty(e.terms, e.terms.size() - e.added);
    } catch (const Error&) {
      return kNaN;
    }
  }

  /// The best single level shift on top of @p terms (block boundaries in the
  /// middle 90 %, every 4th then refined): exact AIC with the shift's size and
  /// time as its two parameters; *t_s, *size where it sits.
  double bestShiftAic(const std::vector<Candidate>& terms, double* t_s, double* size) const {
    const Model mb = withoutSin(assemble(ctx.m0n, terms));
    const bool trend = mb.count(ProcessKind::DR) > 0;
    const std::size_t nb = y.size(), k0 = std::max<std::size_t>(1, nb / 20), k1 = nb - k0;
    double best_l = -std::numeric_limits<double>::infinity();
    std::size_t best_k = 0;
    double best_size = kNaN;
    auto at = [&](std::size_t k) {
      try {
        const auto r = stochastic::blockLogLikelihood(mb, y, blk, regressors(trend, k));
        if (r.loglik > best_l) {
          best_l = r.loglik;
          best_k = k;
          best_size = r.beta(r.beta.size() - 1);
        }
      } catch (const Error&) {
      }
    };
    for (std::size_t k = k0; k <= k1; k += 4) at(k);
    const std::size_t c = best_k;
    for (std::size_t k = c > k0 + 3 ? c - 3 : k0; k <= std::min(k1, c + 3); ++k)
      if (k != c) at(k);
    if (best_k == 0) return kNaN;
    *t_s = ctx.t0 + static_cast<double>(best_k * blk) / ctx.rate;
    *size = best_size;
    return -2.0 * best_l + 4.0;
  }
};

/// The causes of an extension's new terms ('+'-joined, sorted, each once).
std::string causesOf(const Extension& e) {
  std::vector<std::string> c;
  for (std::size_t q = e.terms.size() - e.added; q < e.terms.size(); ++q) c.push_back(causeName(causeOf(e.terms[q].kind)));
  std::sort(c.begin(), c.end());
  c.erase(std::unique(c.begin(), c.end()), c.end());
  std::string j;
  for (const auto& x : c) j += (j.empty() ? "" : "+") + x;
  return j;
}

/// @p t is one of the new terms of @p e (same kind, same retuned term).
bool hasNewTerm(const Extension& e, const Candidate& t) {
  for (std::size_t k = e.terms.size() - e.added; k < e.terms.size(); ++k)
    if (e.terms[k].kind == t.kind && e.terms[k].retune == t.retune && e.terms[k].term == t.term) return true;
  return false;
}

/// Every new term of @p small is one of @p big's.
bool containsNewTerms(const Extension& big, const Extension& small) {
  for (std::size_t q = small.terms.size() - small.added; q < small.terms.size(); ++q)
    if (!hasNewTerm(big, small.terms[q])) return false;
  return true;
}

// --------------------------------------------------------------------------
// One round of the search: the extensions of the terms found so far ranked,
// the winner and its runner-up

/// The WV's ranking of the extensions: the valid ones whose terms the WV
/// needs, by AIC (`order`), and those that may still compete on the exact
/// likelihood of the slow explanations (`others`, in index order: valid but
/// not needed, or invalid only by a GM whose T the WV leaves open at the top).
struct WvRanking {
  std::vector<int> order, others;
};

WvRanking rankByWv(const std::vector<Extension>& ext) {
  WvRanking r;
  for (std::size_t i = 0; i < ext.size(); ++i)
    if (ext[i].valid) (ext[i].needed ? r.order : r.others).push_back(static_cast<int>(i));
    else if (ext[i].open_top) r.others.push_back(static_cast<int>(i));
  std::stable_sort(r.order.begin(), r.order.end(), [&](int a, int b) { return ext[a].crit < ext[b].crit; });
  return r;
}

/// The reference is the best explanation with the fewest terms whose GMs
/// the WV bounds (a GM whose WV profile interval of T reaches record/5
/// competes by AIC). One with more terms that the WV did not need stays in
/// @p ranked only when it contains the reference's terms and its exact
/// likelihood ratio against the reference rejects at 1 % (nested:
/// chi-square with the added parameters as dof).
std::vector<std::pair<double, int>> nestedOnly(const std::vector<Extension>& ext, const std::vector<double>& loglik,
                                               const std::vector<std::pair<double, int>>& ranked) {
  int simple = -1;
  for (const auto& r : ranked)
    if (!ext[r.second].open_top && (simple < 0 || ext[r.second].added < ext[simple].added)) simple = r.second;
  if (simple < 0) return ranked;
  std::vector<std::pair<double, int>> kept;
  for (const auto& r : ranked) {
    const Extension& e = ext[r.second];
    if (e.added > ext[simple].added && !e.needed) {
      if (!containsNewTerms(e, ext[simple])) continue;
      const double dof_lr = std::max(1.0, (penalty(e.terms, e.terms.size() - e.added) -
                                           penalty(ext[simple].terms, ext[simple].terms.size() - ext[simple].added)) / 2.0);
      const double lr = 2.0 * (loglik[r.second] - loglik[simple]);
      if (!(lr > chiUpperQuantile(dof_lr, 0.01))) continue;
    }
    kept.push_back(r);
  }
  return kept;
}

/// The slow explanations ranked on the exact likelihood of the block means.
struct ExactRanking {
  std::vector<std::pair<double, int>> ranked;  ///< (exact AIC, extension), best first
  std::string evidence;                        ///< a clause for the finding ("" with fewer than two)
};

/// Slow explanations compared by the exact Gaussian likelihood of the block
/// means (the new terms' variances profiled, a drift's slope by GLS), AIC:
/// every extension ranked by the WV that differs from the WV's winner
/// @p wv_best only in its slow terms.
ExactRanking rankSlowExactly(const BlockMeans& bm, const std::vector<Extension>& ext, const WvRanking& wv,
                             int wv_best) {
  ExactRanking out;
  const auto key = bm.fastPart(ext[wv_best]);
  std::vector<std::pair<double, int>> ranked;
  std::vector<double> loglik(ext.size(), kNaN);
  std::vector<int> pool = wv.order;
  pool.insert(pool.end(), wv.others.begin(), wv.others.end());
  for (int i : pool) {
    const Extension& e = ext[i];
    if (!bm.hasSlow(e) || bm.fastPart(e) != key) continue;
    double l = kNaN;
    const double aic = bm.exactAic(e, &l);
    if (!std::isfinite(aic)) continue;
    loglik[i] = l;
    ranked.push_back({aic, i});
  }
  std::stable_sort(ranked.begin(), ranked.end());
  out.ranked = nestedOnly(ext, loglik, ranked);
  if (out.ranked.size() >= 2) {
    const int best = out.ranked[0].second, second = out.ranked[1].second;
    out.evidence = "; among the slow explanations the exact likelihood of " + std::to_string(bm.y.size()) +
                   " block means (variances profiled) gives AIC " + formatNumber(out.ranked[0].first, 7) + " against " +
                   formatNumber(out.ranked[1].first, 7) + " for " + newTermsText(ext[second]) +
                   (best != wv_best ? " (the WV alone preferred " + newTermsText(ext[wv_best]) + ")" : std::string());
  }
  return out;
}

/// A slow term as the slow decision fitted it, with its profile interval.
Candidate exactCandidate(const slow::Term& t) {
  Candidate c;
  c.kind = t.proc.kind;
  c.proc = t.proc;
  c.params = c.kind == ProcessKind::GM ? 2 : 1;
  if (c.kind == ProcessKind::GM) {
    c.T_lo = t.lo;
    c.T_hi = t.hi;
    c.T_hi_open = c.T_top_only = t.open_top;
  } else {
    c.p_lo = t.lo;
    c.p_hi = t.hi;
  }
  return c;
}

/// The slow decision on the exact likelihood of the block means
/// (diagnosis_slow.hpp) for @p chosen, an extension of the terms found
/// @p S: it may replace the WV's slow terms by the slow explanation the
/// block means prefer (@p chosen then becomes that explanation, its WV
/// deviance on @p full), and it judges the runner-up. Not decided here
/// unless @p chosen has a slow term and the record enough blocks.
slow::Choice decideSlow(const BlockMeans& bm, const std::vector<Candidate>& S, const WvData& full,
                        Extension& chosen) {
  const ChannelContext& ctx = bm.ctx;
  const Model& m0n = ctx.m0n;
  slow::Choice sc;
  if (!(bm.hasSlow(chosen) && bm.usable())) return sc;
  slow::Problem sp;
  std::vector<Candidate> fast_terms(chosen.terms.begin(), chosen.terms.end() - chosen.added);
  for (std::size_t q = chosen.terms.size() - chosen.added; q < chosen.terms.size(); ++q) {
    const Candidate& c = chosen.terms[q];
    if (bm.isSlow(c)) {
      sp.wv_slow.push_back(causeOf(c.kind));
    } else {
      fast_terms.push_back(c);
      sp.fast_causes.push_back(causeName(causeOf(c.kind)));
    }
  }
  sp.base = withoutSin(assemble(m0n, fast_terms));
  sp.fast_pen = penalty(fast_terms, S.size());
  sp.wv_start = withoutSin(assemble(m0n, chosen.terms));
  bool retunes = false;
  for (std::size_t q = chosen.terms.size() - chosen.added; q < chosen.terms.size(); ++q)
    if (bm.isSlow(chosen.terms[q])) {
      const int k = assembledIndex(m0n, chosen.terms, q);
      if (chosen.terms[q].kind != ProcessKind::DR) sp.wv_own.push_back(k);
      sp.wv_idx.push_back(k);
      retunes = retunes || chosen.terms[q].retune;
    }
  if (retunes) sp.wv_idx.clear();
  sp.wv_pen = penalty(chosen.terms, chosen.terms.size() - chosen.added);
  sp.wv_text = newTermsText(chosen);
  sp.y = &bm.y;
  sp.block = bm.blk;
  sp.rate_hz = ctx.rate;
  sp.record_s = ctx.record;
  sp.seed = stochastic::deriveSeed(ctx.seed, 7000000u + 1000u * static_cast<unsigned>(ctx.index) + static_cast<unsigned>(S.size()));
  sc = slow::decide(sp);
  if (sc.decided_here && sc.swapped) {
    Extension e;
    e.terms = fast_terms;
    for (const auto& t : sc.terms) e.terms.push_back(exactCandidate(t));
    e.added = static_cast<int>(e.terms.size() - S.size());
    e.deviance = wvDeviance(full.nu, wvOf(assemble(m0n, e.terms), full.tau), full.dof);
    e.crit = e.deviance + penalty(e.terms);
    e.valid = true;
    chosen = e;
  } else if (sc.decided_here && !sc.terms.empty() && sc.terms.size() == sp.wv_idx.size()) {
    // The WV's choice kept: its random walks as the exact likelihood fits
    // them, with the profile interval (the WV's own interval treats its
    // scales as independent and is too narrow for a random walk, whose
    // coarse scales are strongly correlated). A drift keeps its WV fit,
    // a GM its WV fit of T (the block means blur a T near the block length).
    std::size_t k = 0;
    for (std::size_t q = chosen.terms.size() - chosen.added; q < chosen.terms.size(); ++q) {
      Candidate& c = chosen.terms[q];
      if (!bm.isSlow(c) || k >= sc.terms.size()) continue;
      const slow::Term& t = sc.terms[k++];
      if (c.kind == ProcessKind::RW && t.proc.kind == ProcessKind::RW) c = exactCandidate(t);
    }
    chosen.deviance = wvDeviance(full.nu, wvOf(assemble(m0n, chosen.terms), full.tau), full.dof);
    chosen.crit = chosen.deviance + penalty(chosen.terms);
    // The decision's words name the kept explanation as it now stands.
    const std::string now = newTermsText(chosen);
    for (std::string* t : {&sc.evidence, &sc.runner_up_detail})
      for (std::size_t at = t->find(sp.wv_text); !sp.wv_text.empty() && at != std::string::npos;
           at = t->find(sp.wv_text, at + now.size()))
        t->replace(at, sp.wv_text.size(), now);
  }
  return sc;
}

/// Why @p win: its AIC against the runner-up @p second's (-1: none), for a
/// pair the best single term it beat, then what the exact likelihood said
/// (the slow decision's clause, else @p exact_evidence).
std::string winnerEvidence(const std::vector<Extension>& ext, const WvRanking& wv, const Extension& win, int second,
                           const slow::Choice& sc, const std::string& exact_evidence) {
  std::string evidence = "AIC " + formatNumber(win.crit, 5) +
                         (second >= 0 ? " against " + formatNumber(ext[second].crit, 5) + " for the runner-up, " + newTermsText(ext[second])
                                      : std::string(" (no other family fits)"));
  if (win.added == 2) {
    // Name the best one-term explanation the pair beat.
    int single = -1;
    for (int i : wv.order)
      if (ext[i].added == 1) {
        single = i;
        break;
      }
    evidence += "; fitted jointly: " + newTermsText(win) +
                (single >= 0 ? " against the best single term " + newTermsText(ext[single]) + " (AIC " +
                                   formatNumber(ext[single].crit, 5) + ", " + std::to_string(ext[single].significant) +
                                   " scale(s) still significant)"
                             : std::string()) +
                (win.needed ? ", below every single term by more than the 1 % chi-square margin"
                            : ", both needed by the exact likelihood (nested likelihood ratio at 1 %)");
  }
  if (sc.decided_here) evidence = (sc.swapped ? "the WV's coarsest scales leave the slow explanations open" : evidence) + sc.evidence;
  else evidence += exact_evidence;
  return evidence;
}

/// The runner-up of a finding: the explanation naming other causes, on the
/// criterion that chose.
struct RunnerUp {
  std::string causes, detail;   ///< "" when none was compared
  double margin = kNaN;         ///< its AIC minus the winner's
  double p = kNaN;              ///< bootstrap p-value of the slow decision (NaN: not simulated)
  int draws = 0;                ///< simulated records behind p
  bool larger = false;          ///< it contains the winner (p: its lead under the winner)

  /// Decided: by the bootstrap where simulated, else by an AIC margin of at
  /// least 2 (below 2 both have substantial support; Burnham & Anderson
  /// 2002, §2.6).
  bool decided() const {
    return causes.empty() || (std::isfinite(p) ? (larger ? p > slow::kLevel : p <= slow::kLevel)
                                               : !(margin < 2.0));
  }
};

/// The runner-up naming other causes, on the criterion that chose (the
/// exact likelihood among the slow explanations, else the WV AIC), and a
/// single level shift on top of the terms found @p S against a slow winner
/// (a shift near its detection limit that the shift test could not accept
/// looks like a random walk). @p best: the winner's index in @p ext.
RunnerUp runnerUp(const BlockMeans& bm, const std::vector<Extension>& ext, const WvRanking& wv, int best,
                  const Extension& win, const slow::Choice& sc, const ExactRanking& exact,
                  const std::vector<Candidate>& S) {
  RunnerUp ru;
  const std::string mine = causesOf(win);
  if (sc.decided_here) {
    // The slow decision (diagnosis_slow.hpp): its runner-up and bootstrap.
    ru.causes = sc.runner_up;
    ru.detail = sc.runner_up_detail;
    ru.margin = sc.runner_up.empty() ? kNaN : sc.aic_margin;
    ru.p = sc.runner_up.empty() ? kNaN : sc.p;
    ru.draws = sc.draws;
    ru.larger = sc.larger;
  } else {
    for (int i : wv.order)
      if (i != best && causesOf(ext[i]) != mine) {
        ru.causes = causesOf(ext[i]);
        ru.detail = newTermsText(ext[i]) + " (WV deviance)";
        ru.margin = ext[i].crit - win.crit;
        break;
      }
  }
  if (bm.hasSlow(win) && bm.usable()) {
    double l_slow = kNaN, t_shift = kNaN, size_shift = kNaN;
    double aic_slow = kNaN;
    // The winner's exact AIC as ranked, unless the slow decision replaced
    // its slow terms (then the replacement's own).
    if (!sc.swapped)
      for (const auto& r : exact.ranked)
        if (r.second == best) aic_slow = r.first;
    if (!std::isfinite(aic_slow)) aic_slow = bm.exactAic(win, &l_slow);
    const double aic_shift = bm.bestShiftAic(S, &t_shift, &size_shift);
    // The shift is the runner-up when it is closer than the slow one (by
    // AIC, or, when the slow one was simulated and rejected, whenever it
    // is within the AIC margin of 2 that decides against a shift).
    const double shift_margin = aic_shift - aic_slow;
    const bool slow_open = std::isfinite(ru.p) && (ru.larger ? ru.p <= slow::kLevel : ru.p > slow::kLevel);
    const bool closer = std::isfinite(ru.p) ? !slow_open && shift_margin < 2.0
                                            : (!std::isfinite(ru.margin) || shift_margin < ru.margin);
    if (std::isfinite(aic_slow) && std::isfinite(aic_shift) && closer) {
      ru.p = kNaN;
      ru.draws = 0;
      ru.larger = false;
      ru.causes = causeName(Cause::LevelShift);
      ru.detail = "a level shift of " + formatNumber(size_shift, 3) + " " + bm.ctx.unit + " at t = " + formatNumber(t_shift, 6) +
                  " s (exact likelihood of " + std::to_string(bm.y.size()) + " block means: AIC " +
                  formatNumber(aic_shift, 7) + " against " + formatNumber(aic_slow, 7) + ")";
      ru.margin = aic_shift - aic_slow;
    }
  }
  return ru;
}

/// The runner-up of one fast term @p q of a winner that also has slow terms:
/// the slow decision and the level shift contest only the slow terms (the
/// block means see nothing of a white noise or a short GM, which every slow
/// explanation keeps), so this term's rival is the best extension the WV
/// ranks that does without it, by the WV AIC.
RunnerUp fastTermRunnerUp(const std::vector<Extension>& ext, const WvRanking& wv, int best, const Extension& win,
                          std::size_t q) {
  RunnerUp ru;
  for (int i : wv.order) {
    const Extension& e = ext[static_cast<std::size_t>(i)];
    if (i == best || hasNewTerm(e, win.terms[q])) continue;
    ru.causes = causesOf(e);
    ru.detail = newTermsText(e) + " (WV deviance)";
    ru.margin = e.crit - win.crit;
    break;
  }
  return ru;
}

/// Each term found as it stands in the joint fit of @p S: its parameters,
/// intervals and the misfit it explains given the other terms found, in
/// place of its finding at cd.findings[found_at[i]] (which keeps the test,
/// evidence and runner-up it was found with).
void restateInJointFit(const ChannelContext& ctx, const WvCheck& w, const std::vector<Candidate>& S,
                       const std::vector<std::size_t>& found_at, ChannelDiagnosis& cd) {
  for (std::size_t i = 0; i < S.size(); ++i) {
    std::vector<Candidate> others;
    for (std::size_t q = 0; q < S.size(); ++q)
      if (q != i) others.push_back(S[q]);
    // The other terms as the model file has them, in m0n's places (retune
    // indices refer to m0n's terms; one retuned to zero stays there at zero).
    const Model before = merged(ctx.m0n, others, true);
    const auto chk_i = checkScales(w.cleaned, wvOf(before, w.tau), w.dof, w.p_thr, {}, {});
    Finding nf = broadbandFinding(cd.name, S[i], before, chk_i, w.tau, ctx.rate, S.size() > 1);
    Finding& f = cd.findings[found_at[i]];
    nf.statistic = f.statistic;
    nf.threshold = f.threshold;
    nf.p_value = f.p_value;
    nf.evidence = f.evidence;
    nf.runner_up = f.runner_up;
    nf.runner_up_detail = f.runner_up_detail;
    nf.aic_margin = f.aic_margin;
    nf.runner_up_p = f.runner_up_p;
    nf.runner_up_draws = f.runner_up_draws;
    nf.decided = f.decided;
    f = nf;
  }
}

}  // namespace

std::vector<Candidate> searchCauses(const ChannelContext& ctx, const std::vector<double>& x, const WvCheck& w,
                                    ChannelDiagnosis& cd) {
  const Model& m0n = ctx.m0n;
  const WvData& full = w.full;
  const int J = w.raw.scales();
  const BlockMeans bm(ctx, x);
  const WvTest wt = wvTest(full, w.p_thr);
  std::vector<Candidate> S;          // the terms found, backfitted on the whole record
  std::vector<std::size_t> found_at;  // S[i]'s finding in cd.findings
  double cur_crit = wvDeviance(full.nu, wvOf(m0n, w.tau), full.dof);
  auto chk = w.cleaned_vs_model;
  while (static_cast<int>(S.size()) < ctx.max_terms && countSignificant(chk) > 0) {
    // Cause chosen on the whole cleaned record (all scales: the coarsest
    // ones separate random walk, drift and long Gauss-Markov), by AIC over
    // every extension by one term or two jointly fitted ones.
    const auto ext = extensions(m0n, S, full, wt, ctx.max_terms - static_cast<int>(S.size()));
    const WvRanking wv = rankByWv(ext);
    if (wv.order.empty() || !(ext[wv.order[0]].crit < cur_crit)) break;
    int best = wv.order[0];
    int second = wv.order.size() > 1 ? wv.order[1] : -1;
    ExactRanking exact;
    if (bm.hasSlow(ext[best]) && bm.usable()) {
      exact = rankSlowExactly(bm, ext, wv, best);
      if (exact.ranked.size() >= 2) {
        best = exact.ranked[0].second;
        second = exact.ranked[1].second;
      }
    }
    if (second == best) second = -1;
    if (second < 0)
      for (int i : wv.order)
        if (i != best) {
          second = i;
          break;
        }
    Extension win = ext[best];
    const slow::Choice sc = decideSlow(bm, S, full, win);
    // A finding must change the WV by at least its CI width at some scale.
    if (win.added == 1 && wvChangeInCiWidths(chk, wvOf(merged(m0n, S), w.tau), wvOf(merged(m0n, win.terms), w.tau)) < 1.0) break;
    const std::string evidence = winnerEvidence(ext, wv, win, second, sc, exact.evidence);
    const RunnerUp ru = runnerUp(bm, ext, wv, best, win, sc, exact, S);
    double pmin = 1;
    for (const auto& s : chk) pmin = std::min(pmin, s.p_value);
    // One finding per new term, restated below as it stands in the joint fit.
    for (std::size_t q = win.terms.size() - win.added; q < win.terms.size(); ++q) {
      const RunnerUp& r = bm.hasSlow(win) && !bm.isSlow(win.terms[q]) ? fastTermRunnerUp(ext, wv, best, win, q) : ru;
      Finding nf;
      nf.channel = cd.name;
      nf.statistic = pmin;
      nf.threshold = w.p_thr;
      nf.p_value = std::min(1.0, pmin * J * ctx.channels / 0.4);  // Bonferroni over scales and channels (WV share)
      nf.evidence = evidence;
      nf.runner_up = r.causes;
      nf.runner_up_detail = r.detail;
      nf.aic_margin = r.margin;
      nf.runner_up_p = r.p;
      nf.runner_up_draws = r.draws;
      nf.decided = r.decided();
      cd.findings.push_back(nf);
      found_at.push_back(cd.findings.size() - 1);
    }
    cur_crit = win.crit;
    S = std::move(win.terms);
    chk = checkScales(w.cleaned, wvOf(merged(m0n, S), w.tau), w.dof, w.p_thr, {}, {});
  }
  restateInJointFit(ctx, w, S, found_at, cd);
  return S;
}

}  // namespace navimpact::analysis::detail
