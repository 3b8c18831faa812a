// Steps 1-3 of navimpact diagnose on one channel (see diagnosis.hpp): the
// detectors of lib/detect, each calibrated under the user's model, find what
// is not noise -- outlier events and knocks, spectral lines, level shifts --
// name it, and take it out of the record before its wavelet variance is
// explained (step 4).
#include <algorithm>
#include <cmath>
#include <sstream>

#include <boost/math/distributions/normal.hpp>

#include "diagnosis_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/detect/outliers.hpp"
#include "navimpact/detect/step_test.hpp"
#include "navimpact/stochastic/model_text.hpp"

namespace navimpact::analysis::detail {

namespace {

/// Transients (level excursions of up to 1 s) replaced by the local level and noise.
void cleanTransients(std::vector<double>& x, const std::vector<detect::Transient>& ts) {
  std::vector<detect::OutlierEvent> evs;
  for (const auto& tr : ts) {
    detect::OutlierEvent e;
    e.first = tr.first;
    e.last = tr.last > tr.first ? tr.last - 1 : tr.first;
    e.peak = tr.first;
    e.peak_value = tr.peak;
    e.peak_z = tr.z;
    evs.push_back(e);
  }
  detect::OutlierOptions o;
  o.local_fill = true;
  detect::cleanOutliers(x, evs, o);
}

/// Candidate level shifts and transients of @p x under the user's model
/// (the search runs on a copy); transients that last longer than 1 s or
/// touch an end of the record are dropped.
detect::ChangePointResult shiftCandidates(const ChannelContext& ctx, const std::vector<double>& x,
                                          const detect::ChangePointOptions& cpo) {
  const double rate = ctx.rate;
  const std::size_t n = ctx.n;
  std::vector<double> xs = x;
  auto cpr = detect::detectChangePoints(xs, detect::haarWvOf(ctx.m0n), ctx.B.steps, cpo);
  // Transients (a knock, a bump) last at most 1 s.
  cpr.transients.erase(std::remove_if(cpr.transients.begin(), cpr.transients.end(),
                                      [&](const detect::Transient& tr) {
                                        return static_cast<double>(tr.last - tr.first) / rate > 1.0 ||
                                               tr.first == 0 || tr.last >= n;
                                      }),
                       cpr.transients.end());
  return cpr;
}

/// The best stochastic explanation of the record without shifts (the
/// runner-up of every shift and transient), fitted to the WV of the record
/// with the transient candidates interpolated out: fitted with them, a
/// short GM (and QN) takes up a knock's energy and the knock no longer
/// stands out against it. The user's model when there is nothing to judge.
/// *params: the parameters it adds to the model.
Model shiftFreeExplanation(const ChannelContext& ctx, const std::vector<double>& x,
                           const gmwm::WaveletVariance& wv_pre, const detect::ChangePointResult& cpr,
                           int* params) {
  const std::size_t n = ctx.n;
  if (cpr.transients.empty() && cpr.changes.empty()) return ctx.m0n;  // only needed to judge those
  const std::vector<double> tau = toStd(wv_pre.tau);
  WvData d0{tau, toStd(wv_pre.wv), toStd(wv_pre.eta), static_cast<double>(n)};
  if (!cpr.transients.empty()) {
    std::vector<double> xt = x;
    cleanTransients(xt, cpr.transients);
    const auto wv_t = gmwm::waveletVariance(xt.data(), n, ctx.rate);
    d0 = WvData{tau, toStd(wv_t.wv), toStd(wv_t.eta), static_cast<double>(n)};
  }
  return greedyExtension(ctx.m0n, d0, ctx.max_terms, ctx.B.wv / static_cast<double>(wv_pre.scales()), params);
}

/// Each transient judged at its own scale (the edge contrasts with the
/// window matched to its duration, detect::testTransient) against the
/// explanation @p ext0; a candidate first seen in a long window (a knock
/// leaves the search with long-window corrections of its sizes) counts by
/// its own excursion, one that noise of that explanation makes is left alone.
std::vector<detect::Transient> significantTransients(const ChannelContext& ctx, const std::vector<double>& x,
                                                     const std::vector<detect::Transient>& candidates,
                                                     const Model& ext0, const detect::ChangePointOptions& cpo) {
  const auto wv_ext0 = detect::haarWvOf(ext0);
  std::vector<detect::Transient> kept;
  for (auto tr : candidates) {
    const auto tt = detect::testTransient(x, tr.first, tr.last, wv_ext0, ctx.B.steps, cpo);
    if (!tt.significant()) continue;
    tr.peak = tt.level;
    tr.z = tt.z;
    tr.threshold = tt.threshold;
    tr.p_value = tt.p_value;
    tr.half_width = tt.half_width;
    kept.push_back(tr);
  }
  return kept;
}

/// Transients: outlier events, interpolated out of @p x. One within 10
/// samples of a spike event (the part of a burst the second difference did
/// not flag) is that event, its span extended (its time stays the spike
/// peak's): one event however many samples it spans. The channel's outlier
/// finding counts them (made here when step 1 found none).
void removeTransients(const ChannelContext& ctx, const std::vector<detect::Transient>& transients,
                      std::vector<double>& x, ChannelDiagnosis& cd) {
  const double rate = ctx.rate, t0 = ctx.t0;
  std::vector<double> new_times;
  const double gap = 10.0 / rate;
  for (const auto& tr : transients) {
    const double a = t0 + static_cast<double>(tr.first) / rate, len = static_cast<double>(tr.last - tr.first) / rate;
    bool merged_into = false;
    for (auto& e : cd.outlier_events) {
      if (a > e.t_s + e.duration_s + gap || a + len < e.t_s - gap) continue;
      const double end = std::max(e.t_s + e.duration_s, a + len), start = std::min(e.t_s, a);
      e.t_s = start;
      e.duration_s = end - start;
      if (std::abs(tr.peak) > std::abs(e.size)) e.size = tr.peak;
      merged_into = true;
      break;
    }
    if (!merged_into) {
      cd.outlier_events.push_back({a, len, tr.peak});
      new_times.push_back(a);
    }
  }
  cleanTransients(x, transients);
  Finding* of = nullptr;
  for (auto& f : cd.findings)
    if (f.cause == Cause::Outliers) of = &f;
  if (!of) {
    Finding f;
    f.channel = cd.name;
    f.cause = Cause::Outliers;
    f.params = {{"count", 0.0}};
    f.range_key = "t_s";
    f.statistic = transients.front().z;
    f.threshold = transients.front().threshold;
    f.p_value = transients.front().p_value;
    f.evidence = "level changes that undo each other within 1 s, significant at their own scale against the best stochastic explanation of the record without them: a transient (a knock), not level shifts";
    f.action = "remove them before estimating (they were interpolated here); not a filter state";
    cd.findings.push_back(f);
    of = &cd.findings.back();
  }
  of->times_s.insert(of->times_s.end(), new_times.begin(), new_times.end());
  std::sort(of->times_s.begin(), of->times_s.end());
  of->params = {{"count", static_cast<double>(of->times_s.size())}};
  of->range_lo = of->times_s.front();
  of->range_hi = of->times_s.back();
  of->explanation = std::to_string(of->times_s.size()) +
                    " outlier event(s): spikes, bursts or transients (a knock) that return to the local level; "
                    "each counts once however many samples it spans.";
}

/// Shift or wandering: exact likelihood ratio of each candidate shift
/// (forward selection, each given those accepted before it) under the best
/// stochastic explanation of the record without shifts, @p ext0_model
/// (adding @p p_ext0 parameters to the user's model); chi2_1 at a fixed
/// time, Bonferroni over the block boundaries a detector can pick
/// (detect/step_test.hpp): the level holds whatever wanders. The accepted
/// shifts are findings, removed from @p x; the others a note. Returns
/// whether a shift was accepted.
bool removeShifts(const ChannelContext& ctx, const std::vector<detect::ChangePoint>& changes,
                  const Model& ext0_model, int p_ext0, std::vector<double>& x, ChannelDiagnosis& cd,
                  ShiftsLeft& left) {
  const double rate = ctx.rate, t0 = ctx.t0;
  const std::size_t n = ctx.n;
  const Budget& B = ctx.B;
  const std::string& unit = ctx.unit;
  std::vector<std::size_t> idx;
  for (const auto& c : changes) idx.push_back(c.index);
  const int K = static_cast<int>(changes.size());
  const std::string ext0 =
      p_ext0 > 0 ? stochastic::formatTerms(ext0_model.terms, 3) : std::string("the model as given");
  detect::StepTestResult st;
  std::string failed;
  try {
    st = detect::testLevelShifts(x, ext0_model, idx, B.steps);
  } catch (const Error& e) {
    failed = e.what();
  }
  const int best_k = static_cast<int>(st.accepted());
  const double boundaries = static_cast<double>(st.blocks > 1 ? st.blocks - 1 : 1);
  const double lr_thr = chiUpperQuantile(1.0, B.steps / boundaries);
  const std::string how = "generalised likelihood ratio, every variance profiled and a random walk allowed; exact Gaussian likelihood of " +
                          std::to_string(st.blocks) + " block means of " + std::to_string(st.block) +
                          " sample(s); chi2_1 at a fixed time, Bonferroni over the " +
                          formatNumber(boundaries, 6) + " block boundaries: threshold " + formatNumber(lr_thr, 4);
  if (best_k > 0) {
    double lr_rest = 0;  // strongest candidate left out
    for (std::size_t q = 0; q < st.tests.size(); ++q) {
      const auto& c = changes[q];
      const auto& t = st.tests[q];
      if (!t.accepted) {
        lr_rest = std::max(lr_rest, t.lr);
        continue;
      }
      const double size = t.size, se = t.size_se;
      for (std::size_t k = c.index; k < n; ++k) x[k] -= size;
      Finding f;
      f.channel = cd.name;
      f.cause = Cause::LevelShift;
      const double tt = t0 + static_cast<double>(c.index) / rate;
      f.params = {{"size", size}, {"t_s", tt}};
      f.intervals.push_back({"size", {size - 1.96 * se, size + 1.96 * se}});
      f.range_key = "t_s";
      f.range_lo = f.range_hi = tt;
      f.statistic = t.lr;
      f.threshold = lr_thr;
      f.p_value = t.p_value;
      f.explanation = "a level shift of " + formatNumber(size, 3) + " " + unit + " at t = " + formatNumber(tt, 6) +
                      " s (" + formatNumber(std::abs(size) / std::max(se, 1e-300), 3) + " standard errors; found by the model's " +
                      formatNumber(c.half_width / rate, 3) + " s window contrast at " + formatNumber(c.z, 3) + " sd).";
      f.evidence = "likelihood ratio " + formatNumber(t.lr, 4) + " for a shift here against the best stochastic explanation without shifts, " +
                   ext0 + " (" + how + "; p = " + formatNumber(t.p_value, 3) + ")";
      // Decided by the test (it rejected the best explanation without
      // shifts at the Bonferroni level); the AIC margin for the record.
      f.runner_up = causeName(Cause::RandomWalk);
      f.runner_up_detail = "the best stochastic explanation without shifts, " + ext0 + ", a random walk allowed";
      f.aic_margin = t.lr - 4.0;  // the shift's size and time
      f.decided = true;
      f.action = "segment the record at t = " + formatNumber(tt, 6) +
                 " s (estimate the model on each part) or remove the step; a stationary filter state cannot represent a one-off jump";
      cd.findings.push_back(f);
    }
    if (best_k < K)
      cd.notes.push_back(std::to_string(K - best_k) + " weaker candidate level shift(s) are not significant given the " +
                         std::to_string(best_k) + " found (likelihood ratio up to " + formatNumber(lr_rest, 4) +
                         " below " + formatNumber(lr_thr, 4) + "): left to the wavelet-variance analysis");
    return true;
  }
  if (!failed.empty()) {
    cd.notes.push_back(std::to_string(K) + " candidate level shift(s) not tested (" + failed +
                       "): left to the wavelet-variance analysis");
  } else {
    left.index = idx;
    left.lr_ext0.clear();
    for (const auto& t : st.tests) left.lr_ext0.push_back(t.lr);
    left.ext0 = ext0;
    left.how = how;
    left.lr_thr = lr_thr;
    cd.notes.push_back(std::to_string(K) + " candidate level shift(s) are explained as well by " + ext0 +
                       " (likelihood ratio up to " + formatNumber([&] {
                         double v = 0;
                         for (const auto& t : st.tests) v = std::max(v, t.lr);
                         return v;
                       }(), 4) + ", " + how +
                       "): left to the wavelet-variance analysis");
  }
  return false;
}

}  // namespace

bool removeOutliers(const ChannelContext& ctx, std::vector<double>& x, ChannelDiagnosis& cd) {
  const double rate = ctx.rate, t0 = ctx.t0;
  const std::size_t n = ctx.n;
  const std::string& unit = ctx.unit;
  const auto orr = detect::detectOutliers(x, detect::secondDifferenceSd(ctx.m0n), ctx.B.spikes);
  detect::cleanOutliers(x, orr.events);
  if (orr.sub_quantum)
    cd.notes.push_back("quantised below its quantum (" + formatNumber(orr.quantum, 3) + " " + unit +
                       "): most samples sit on their neighbours' level, so each change of one quantum would be a "
                       "many-sigma event for Gaussian noise; outliers are judged against the quantum, and level "
                       "shifts and knocks are not tested");
  const bool gaussian = !orr.sub_quantum;
  if (orr.events.empty()) return gaussian;
  Finding f;
  f.channel = cd.name;
  f.cause = Cause::Outliers;
  double maxz = 0, maxa = 0, longest = 0;
  for (const auto& e : orr.events) {
    f.times_s.push_back(t0 + static_cast<double>(e.peak) / rate);
    maxz = std::max(maxz, e.peak_z);
    maxa = std::max(maxa, std::abs(e.peak_value));
    longest = std::max(longest, static_cast<double>(e.last - e.first + 1) / rate);
    cd.outlier_events.push_back({t0 + static_cast<double>(e.first) / rate,
                                 static_cast<double>(e.last - e.first + 1) / rate, e.peak_value});
  }
  f.params = {{"count", static_cast<double>(orr.events.size())}};
  f.range_key = "t_s";
  f.range_lo = f.times_s.front();
  f.range_hi = f.times_s.back();
  f.statistic = maxz;
  f.threshold = orr.threshold;
  f.p_value = std::min(1.0, 2.0 * static_cast<double>(n) *
                                boost::math::cdf(boost::math::complement(boost::math::normal(), maxz)));
  const bool heavy = orr.events.size() > std::max<std::size_t>(20, n / 5000);
  std::ostringstream ex;
  ex << orr.events.size() << " outlier event(s)" << (longest > 1.5 / rate ? " (bursts up to " + formatNumber(longest, 2) + " s count once)" : "")
     << ", up to " << formatNumber(maxa, 3) << " " << unit << " from the local level, " << formatNumber(maxz, 3)
     << " sd of the second difference (threshold " << formatNumber(orr.threshold, 3) << ").";
  f.explanation = ex.str();
  f.evidence = heavy ? "so many events throughout the record point to heavy-tailed noise rather than isolated outliers"
                     : "Gaussian noise of the model exceeds this threshold anywhere in the record with probability below the outlier share of alpha; a step would leave the level changed, these return to it";
  f.action = heavy ? "estimate the model robustly (`navimpact wv --robust`); heavy-tailed noise is not a filter state"
                   : "remove them before estimating (they were interpolated here); not a filter state";
  cd.findings.push_back(f);
  return gaussian;
}

std::vector<detect::SpectralLine> removeLines(const ChannelContext& ctx, std::vector<double>& x,
                                              ChannelDiagnosis& cd) {
  const std::string& unit = ctx.unit;
  detect::LineTestOptions lo;
  for (const auto& p : ctx.m0.terms)
    if (p.kind == ProcessKind::SIN) lo.exclude_hz.push_back(p.freq_hz);
  const auto lt = detect::detectLines(x, ctx.rate, detect::psdOf(ctx.m0n), ctx.B.spec, lo);
  const std::vector<detect::SpectralLine>& lines = lt.lines;
  cd.spectrum.freq_hz = lt.plot_freq_hz;
  cd.spectrum.psd = lt.plot_psd;
  cd.spectrum.background = lt.plot_background;
  cd.spectrum.threshold_ratio = lt.threshold;
  cd.spectrum.bins_tested = lt.bins_tested;
  cd.spectrum.bin_hz = lt.bin_hz;
  cd.spectrum.f_min_hz = lt.f_min_hz;
  cd.spectrum.f_max_hz = lt.f_max_hz;
  // A line within 10 bins of a stronger one is the same line wandering in
  // frequency (what a real vibration does): one finding, both subtracted.
  std::vector<int> near_of(lines.size(), -1);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].harmonic_of >= 0) continue;
    for (std::size_t j = 0; j < i; ++j)
      if (lines[j].harmonic_of < 0 && near_of[j] < 0 &&
          std::abs(lines[i].freq_hz - lines[j].freq_hz) <= 10.0 * lt.bin_hz) {
        near_of[i] = static_cast<int>(j);
        break;
      }
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto& L = lines[i];
    cd.line_freqs_hz.push_back(L.freq_hz);
    if (L.harmonic_of >= 0 || near_of[i] >= 0) continue;
    Finding f;
    f.channel = cd.name;
    f.cause = Cause::Sinusoid;
    f.params = {{"amplitude", L.amplitude}, {"freq_hz", L.freq_hz}};
    const double fse = std::max(L.freq_se_hz, 0.0);
    f.intervals.push_back({"freq_hz", {L.freq_hz - 1.96 * fse, L.freq_hz + 1.96 * fse}});
    f.intervals.push_back({"amplitude", {std::max(0.0, L.amplitude - 1.96 * L.amp_se), L.amplitude + 1.96 * L.amp_se}});
    for (const auto& H : lines)
      if (H.harmonic_of == static_cast<int>(i)) f.harmonics_hz.push_back(H.freq_hz);
    std::sort(f.harmonics_hz.begin(), f.harmonics_hz.end());
    f.range_key = "freq_hz";
    f.range_lo = L.freq_hz - lt.bin_hz;
    f.range_hi = L.freq_hz + lt.bin_hz;
    f.statistic = L.ratio;
    f.threshold = lt.threshold;
    f.p_value = L.p_value;
    std::ostringstream ex;
    ex << "a spectral line at " << formatNumber(L.freq_hz, 6) << " Hz, amplitude " << formatNumber(L.amplitude, 3) << " " << unit
       << " (" << formatNumber(L.ratio, 3) << "x the background; threshold " << formatNumber(lt.threshold, 3) << "x)";
    if (!f.harmonics_hz.empty()) {
      ex << ", with harmonic(s) at";
      for (double h : f.harmonics_hz) ex << " " << formatNumber(h, 5);
      ex << " Hz";
    }
    {
      std::string nearby;
      for (std::size_t q = 0; q < lines.size(); ++q)
        if (near_of[q] == static_cast<int>(i)) nearby += " " + formatNumber(lines[q].freq_hz, 6);
      if (!nearby.empty()) ex << "; its frequency wanders (also at" << nearby << " Hz)";
    }
    ex << ".";
    f.explanation = ex.str();
    std::ostringstream ev;
    ev << "peak " << formatNumber(L.local_ratio, 3) << "x its own spectral neighbourhood: a Gauss-Markov process has a smooth spectrum and cannot make it; amplitude "
       << formatNumber(L.amp_half[0], 3) << " / " << formatNumber(L.amp_half[1], 3) << " " << unit << " in the two halves";
    f.evidence = ev.str();
    f.action = "add SIN(amp, freq) per line (a two-state oscillator in the filter), or notch it out if it is a vibration of the test set-up";
    cd.findings.push_back(f);
  }
  return lines;
}

bool removeLevelShifts(const ChannelContext& ctx, const gmwm::WaveletVariance& wv_pre, std::vector<double>& x,
                       ChannelDiagnosis& cd, ShiftsLeft& left) {
  detect::ChangePointOptions cpo;
  cpo.max_transient = static_cast<std::size_t>(std::floor(ctx.rate));  // transients last at most 1 s
  auto cpr = shiftCandidates(ctx, x, cpo);
  int p_ext0 = 0;
  const Model ext0 = shiftFreeExplanation(ctx, x, wv_pre, cpr, &p_ext0);
  cpr.transients = significantTransients(ctx, x, cpr.transients, ext0, cpo);
  bool changed = false;
  if (!cpr.transients.empty()) {
    removeTransients(ctx, cpr.transients, x, cd);
    changed = true;
  }
  if (!cpr.changes.empty() && removeShifts(ctx, cpr.changes, ext0, p_ext0, x, cd, left)) changed = true;
  return changed;
}

std::vector<Finding> shiftsTheSearchLeft(const ChannelContext& ctx, const std::vector<double>& x,
                                         const ShiftsLeft& left, const Model& found_model) {
  if (left.index.empty()) return {};
  detect::StepTestOptions o;
  o.add_random_walk = false;
  detect::StepTestResult sm;
  try {
    sm = detect::testLevelShifts(x, found_model, left.index, ctx.B.steps, o);
  } catch (const Error&) {
    return {};
  }
  const bool extended = found_model.terms.size() != ctx.m0n.terms.size();
  const std::string against =
      extended ? "the model with the terms found, " + stochastic::formatTerms(found_model.terms, 3) : std::string("the model as given");
  std::vector<Finding> out;
  for (std::size_t q = 0; q < sm.tests.size(); ++q) {
    const auto& t = sm.tests[q];
    if (!t.accepted) continue;
    const double tt = ctx.t0 + static_cast<double>(left.index[q]) / ctx.rate;
    const double lr_ext0 = q < left.lr_ext0.size() ? left.lr_ext0[q] : std::numeric_limits<double>::quiet_NaN();
    Finding f;
    f.channel = ctx.name;
    f.cause = Cause::LevelShift;
    f.params = {{"size", t.size}, {"t_s", tt}};
    f.intervals.push_back({"size", {t.size - 1.96 * t.size_se, t.size + 1.96 * t.size_se}});
    f.range_key = "t_s";
    f.range_lo = f.range_hi = tt;
    f.statistic = t.lr;
    f.threshold = left.lr_thr;
    f.p_value = t.p_value;
    f.explanation = "a level shift of " + formatNumber(t.size, 3) + " " + ctx.unit + " at t = " + formatNumber(tt, 6) +
                    " s (" + formatNumber(std::abs(t.size) / std::max(t.size_se, 1e-300), 3) +
                    " standard errors), or a wandering level neither the model nor the terms found have.";
    f.evidence = "likelihood ratio " + formatNumber(t.lr, 4) + " for a shift here against " + against +
                 " (the same test without a random walk; p = " + formatNumber(t.p_value, 3) + "); against " + left.ext0 +
                 ", the best explanation without shifts, a random walk allowed, only " + formatNumber(lr_ext0, 4) + " (" +
                 left.how + ")";
    f.runner_up = causeName(Cause::RandomWalk);
    f.runner_up_detail = left.ext0 + " with a random walk, the best stochastic explanation without shifts (likelihood ratio of the shift " +
                         formatNumber(lr_ext0, 4) + " below " + formatNumber(left.lr_thr, 4) + ")";
    f.aic_margin = lr_ext0 - 4.0;  // the shift's size and time, as for an accepted shift
    f.decided = false;
    f.action = "look at the record around t = " + formatNumber(tt, 6) +
               " s: segment it there if the level jumped (a stationary filter state cannot represent a one-off "
               "jump), else add a random walk to the model";
    out.push_back(f);
  }
  return out;
}

}  // namespace navimpact::analysis::detail
