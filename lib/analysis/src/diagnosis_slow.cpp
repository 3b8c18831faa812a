// The slow decision of navimpact diagnose (see diagnosis_slow.hpp).
//
// Random walk, drift and a Gauss-Markov process with T near the record
// differ only at the coarsest scales, where the wavelet variance has few
// degrees of freedom: its coarsest scales cannot bound a GM's T near
// record/5, and its joint fit of two slow terms tends to lose one. So every
// slow explanation -- one or two of RW, DR and GM (T from 4 blocks to
// record/5; one that goes to record/5 is the RW it imitates) on top of the
// fast terms -- is fitted on the exact Gaussian likelihood of ~512 block
// means. Among those with as many slow terms as the WV's choice, the lowest
// AIC wins, but the WV's choice gives way only when the exact likelihood
// rejects it (simulated from its fit, it gives the new winner such a lead
// in at most 5 % of its records). The choice is then put to the test that
// can say "no": a parametric bootstrap (Davison & Hinkley 1997, §4.2; for
// non-nested models the Cox test by simulation, Williams 1970) of
//  (i)  the best explanation with at most as many slow terms: simulated from
//       its own fit, how often does it give the winner a lead at least the
//       observed one? Above 5 %: not rejected, undecided;
//  (ii) the best explanation with more slow terms that the exact AIC
//       prefers: simulated from the winner's fit, how often does it lead by
//       as much? At or below 5 %: the data support it, undecided.
// Each simulated record is fitted by the same procedure as the record
// (maximise(), from the record's fits), so the comparison is calibrated for
// the fitting of T and of the variances.
#include "diagnosis_slow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <boost/math/tools/minima.hpp>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis::slow {

namespace {

using stochastic::Model;
using stochastic::Process;
using stochastic::ProcessKind;

constexpr double kInf = std::numeric_limits<double>::infinity();


/// Regressors of block means: the mean, and a trend (centred, in records) when @p trend.
Eigen::MatrixXd meanTrend(std::size_t nb, bool trend) {
  Eigen::MatrixXd X(static_cast<Eigen::Index>(nb), trend ? 2 : 1);
  for (std::size_t k = 0; k < nb; ++k) {
    X(static_cast<Eigen::Index>(k), 0) = 1.0;
    if (trend) X(static_cast<Eigen::Index>(k), 1) = (static_cast<double>(k) + 0.5) / static_cast<double>(nb) - 0.5;
  }
  return X;
}

/// The amplitude whose square is the term's variance parameter.
double& amplitude(Process& p) {
  switch (p.kind) {
    case ProcessKind::QN: return p.Q;
    case ProcessKind::RW: return p.gamma;
    default: return p.sigma;  // WN, GM
  }
}

struct Fit {
  Model model;
  double loglik = -kInf;
  Eigen::VectorXd beta;      ///< GLS mean[, trend]
  Eigen::MatrixXd beta_cov;
};

/// The exact log-likelihood of @p y under @p m maximised by coordinate
/// ascent over the variance of every term in @p own (log factor within
/// e^-1.5..e^1.5 of the current value per sweep) and the T of every GM among
/// them but @p fixed_T (log T within a factor 4 per sweep at a fixed
/// innovation variance, kept in [T_lo, T_hi]), from @p m, until a sweep
/// gains less than 1e-3; the mean and a drift's slope by GLS.
/// @p m becomes the maximiser. -inf when it cannot be evaluated.
double maximise(Model& m, const std::vector<int>& own, const std::vector<double>& y, std::size_t blk, double T_lo,
                double T_hi, int fixed_T = -1, Fit* out = nullptr) {
  const Eigen::MatrixXd X = meanTrend(y.size(), m.count(ProcessKind::DR) > 0);
  auto ll = [&](const Model& mm) {
    try {
      return stochastic::blockLogLikelihood(mm, y, blk, X).loglik;
    } catch (const Error&) {
      return -kInf;
    }
  };
  double best = ll(m);
  for (int sweep = 0; sweep < 8 && std::isfinite(best); ++sweep) {
    const double before = best;
    for (int i : own) {
      Process& p = m.terms[static_cast<std::size_t>(i)];
      // One coordinate in log space on [lo, hi], the new value kept only
      // when it gains.
      auto line = [&](auto set, double lo, double hi) {
        const Process p0 = p;
        auto f = [&](double v) {
          p = p0;
          set(v);
          return -ll(m);
        };
        // Brent's method (golden section with parabolic steps; Brent 1973,
        // ch. 5) to about 1e-3 of the bracket.
        std::uintmax_t it = 30;
        const auto r = boost::math::tools::brent_find_minima(f, lo, hi, 10, it);
        p = p0;
        set(r.first);
        const double v = -r.second;
        if (v > best) best = v;
        else p = p0;
      };
      const double a0 = amplitude(p);
      line([&](double lf) { amplitude(p) = a0 * std::exp(0.5 * lf); }, -1.5, 1.5);
      if (p.kind == ProcessKind::GM && i != fixed_T) {
        // T at a fixed innovation variance sigma^2 (1 - phi^2): the
        // coordinates (log q, log T) are nearly independent where a long GM
        // imitates a random walk of gamma^2 = q, (log sigma^2, log T) are not.
        const double lT = std::log(p.T), a = std::max(std::log(T_lo), lT - std::log(4.0)),
                     b = std::min(std::log(T_hi), lT + std::log(4.0));
        const double dt = 1.0 / m.rate_hz, s0 = p.sigma, w0 = -std::expm1(-2.0 * dt / p.T);
        if (b > a)
          line(
              [&](double v) {
                p.T = std::exp(v);
                p.sigma = s0 * std::sqrt(w0 / -std::expm1(-2.0 * dt / p.T));
              },
              a, b);
      }
    }
    if (!(best - before > 1e-3)) break;
  }
  if (out) {
    out->model = m;
    out->loglik = best;
    try {
      const auto r = stochastic::blockLogLikelihood(m, y, blk, X);
      out->beta = r.beta;
      out->beta_cov = r.beta_cov;
    } catch (const Error&) {
      out->beta = Eigen::VectorXd::Zero(X.cols());
      out->beta_cov = Eigen::MatrixXd::Zero(X.cols(), X.cols());
    }
  }
  return best;
}

/// One slow explanation: its slow causes, start, fitted terms and fit.
struct Set {
  std::vector<Cause> slow;          ///< sorted
  Model start;
  std::vector<int> own;             ///< its fitted (slow random) terms in start and fit.model
  /// Every start its fit was tried from (model, its fitted terms), the one
  /// its fit came from first: a GM's likelihood may have several maxima in T.
  std::vector<std::pair<Model, std::vector<int>>> starts;
  std::vector<int> slow_idx;        ///< its slow terms in the model (DR included)
  double pen = 0, aic = kInf;
  Fit fit;
  bool from_wv = false;
  /// Largest T of its GMs: record/5, or below it for a rival whose GM went
  /// there (rival_only: the random walk it imitates cannot win as a GM).
  double T_cap = 0;
  bool rival_only = false;
  std::string causes, text;
};

std::string joinCauses(std::vector<std::string> cs) {
  std::sort(cs.begin(), cs.end());
  cs.erase(std::unique(cs.begin(), cs.end()), cs.end());
  std::string j;
  for (const auto& c : cs) j += (j.empty() ? "" : "+") + c;
  return j;
}


/// A set fitted to the block means @p ys as to the record: from the
/// record's fit (Davison & Hinkley 1997, §4.2) and, when it has a GM (whose
/// likelihood may have several maxima in T; that of the random walk's and
/// the drift's parameters has one), also from the start its record fit came
/// from; the better.
double refit(const Set& s, const std::vector<double>& ys, std::size_t blk, double T_lo, double T_hi) {
  if (s.T_cap > 0) T_hi = s.T_cap;
  Model m = s.fit.model;
  double best = maximise(m, s.own, ys, blk, T_lo, T_hi);
  if (std::find(s.slow.begin(), s.slow.end(), Cause::GaussMarkov) != s.slow.end() && !s.starts.empty()) {
    Model q = s.starts.front().first;
    best = std::max(best, maximise(q, s.starts.front().second, ys, blk, T_lo, T_hi));
  }
  return best;
}

/// How often the explanation @p alt, simulated from its fit (exact block
/// means of its random terms plus its GLS mean and trend), gives a margin
/// AIC(alt) - AIC(win) at least @p observed, each simulated record fitted by
/// refit(): (1 + exceedances) / (1 + draws) over kDraws (seeded by @p seed),
/// *used of them. It stops early only once the p-value must exceed @p level
/// (then p = exceedances / draws, Besag & Clifford 1991): the margins are
/// skewed (a random walk fitted as a mean-reverting process, Dickey & Fuller
/// 1979), so a normal approximation of their tail would decide too often.
double bootstrapP(const Set& win, const Set& alt, double observed, const std::vector<double>& y, std::size_t blk,
                  double T_lo, double T_hi, double level, std::uint64_t seed, int* used) {
  Model noise = alt.fit.model;
  noise.terms.erase(std::remove_if(noise.terms.begin(), noise.terms.end(),
                                   [](const Process& p) { return p.kind == ProcessKind::DR || p.kind == ProcessKind::SIN; }),
                    noise.terms.end());
  const std::size_t nb = y.size();
  const Eigen::MatrixXd X = meanTrend(nb, alt.fit.beta.size() > 1);
  const Eigen::VectorXd mean = X * alt.fit.beta;
  int exceed = 0, done = 0;
  for (int b = 0; b < kDraws; ++b) {
    std::vector<double> ys = stochastic::simulateBlockMeans(noise, nb, blk, stochastic::deriveSeed(seed, static_cast<std::uint64_t>(b)));
    for (std::size_t k = 0; k < nb; ++k) ys[k] += mean(static_cast<Eigen::Index>(k));
    const double lw = refit(win, ys, blk, T_lo, T_hi), la = refit(alt, ys, blk, T_lo, T_hi);
    ++done;
    // A simulated record that cannot be fitted counts against the decision.
    const double margin = std::isfinite(lw) && std::isfinite(la) ? (-2.0 * la + alt.pen) - (-2.0 * lw + win.pen) : kInf;
    if (margin >= observed) ++exceed;
    // Sequential test (Besag & Clifford 1991): once the p-value must
    // exceed the level, stop with p = exceedances / draws.
    if ((1.0 + exceed) / (1.0 + kDraws) > level) {
      *used = done;
      return static_cast<double>(exceed) / done;
    }
  }
  *used = done;
  return (1.0 + exceed) / (1.0 + kDraws);
}

/// 95 % profile interval of one coordinate of a fitted set: where the
/// log-likelihood, maximised over the other coordinates, falls 1.92 (chi2_1
/// 95 % / 2) below its maximum; @p set_coord puts a value (log scale) into
/// the model; [lo, hi] in log scale bounds the search (*open_* when the
/// bound is reached inside the interval).
template <class SetCoord>
std::pair<double, double> profileInterval(const Set& s, int term, SetCoord set_coord, double v_hat, double lo, double hi,
                                          bool variance, const std::vector<double>& y, std::size_t blk, double T_lo,
                                          double T_hi, bool* open_lo, bool* open_hi) {
  std::vector<int> others;
  for (int i : s.own)
    if (!(variance && i == term)) others.push_back(i);
  const double top = s.fit.loglik;
  auto drop = [&](double v) {
    Model m = s.fit.model;
    set_coord(m.terms[static_cast<std::size_t>(term)], v);
    return top - maximise(m, others, y, blk, T_lo, T_hi, variance ? -1 : term);
  };
  auto side = [&](double dir, double bound, bool* open) {
    double inside = v_hat, step = 0.25, out = v_hat;
    for (;;) {
      out = std::clamp(inside + dir * step, std::min(lo, hi), std::max(lo, hi));
      if (drop(out) >= 1.92) break;
      inside = out;
      if (out == bound) {
        *open = true;
        return bound;
      }
      step *= 2;
    }
    for (int it = 0; it < 10; ++it) {
      const double mid = 0.5 * (inside + out);
      (drop(mid) >= 1.92 ? out : inside) = mid;
    }
    return 0.5 * (inside + out);
  };
  *open_lo = *open_hi = false;
  const double a = side(-1.0, lo, open_lo), b = side(1.0, hi, open_hi);
  return {a, b};
}

}  // namespace

Choice decide(const Problem& pr) {
  Choice ch;
  const std::vector<double>& y = *pr.y;
  const std::size_t blk = pr.block, nb = y.size();
  if (nb < 16) return ch;
  const double T_lo = 4.0 * static_cast<double>(blk) / pr.rate_hz, T_hi = pr.record_s / 5.0;
  const double n_used = static_cast<double>(nb * blk);
  double mean_y = 0, sd = 0;
  for (double v : y) mean_y += v / static_cast<double>(nb);
  for (double v : y) sd += (v - mean_y) * (v - mean_y) / static_cast<double>(nb);
  sd = std::sqrt(sd);

  auto fitSet = [&](Set& s) {
    Model m = s.start;
    maximise(m, s.own, y, blk, T_lo, T_hi, -1, &s.fit);
    s.aic = std::isfinite(s.fit.loglik) ? -2.0 * s.fit.loglik + s.pen : kInf;
    s.starts = {{s.start, s.own}};
  };
  std::vector<std::string> fast_names = pr.fast_causes;
  // Two fits of one explanation: the better one, with the starts of both
  // (the better fit's first).
  auto keepBetter = [](Set& into, Set other) {
    if (other.aic < into.aic) std::swap(into, other);
    into.starts.insert(into.starts.end(), other.starts.begin(), other.starts.end());
  };

  // The WV stage's explanation, from its own fit.
  Set wv;
  wv.slow = pr.wv_slow;
  std::sort(wv.slow.begin(), wv.slow.end());
  wv.start = pr.wv_start;
  wv.own = pr.wv_own;
  wv.pen = pr.wv_pen;
  wv.slow_idx = pr.wv_idx;
  wv.from_wv = true;
  fitSet(wv);

  // Every explanation by one or two of RW, DR, GM on top of the fast terms.
  const std::vector<Cause> kinds = {Cause::RandomWalk, Cause::Drift, Cause::GaussMarkov};
  // A random walk may be added on top of one the model has (their variances
  // add, as in the WV stage); a drift it has is already the GLS trend of
  // every explanation.
  auto present = [&](Cause c) { return c == Cause::Drift && pr.base.count(ProcessKind::DR) > 0; };
  std::vector<Set> sets;
  for (std::size_t a = 0; a < kinds.size(); ++a)
    for (std::size_t b = a; b <= kinds.size(); ++b) {
      std::vector<Cause> slow = {kinds[a]};
      if (b < kinds.size()) {
        if (b == a) continue;
        slow.push_back(kinds[b]);
      }
      std::sort(slow.begin(), slow.end());
      if (slow == wv.slow) {
        if (std::isfinite(wv.aic)) sets.push_back(wv);
        if (std::count(slow.begin(), slow.end(), Cause::GaussMarkov) == 0) continue;  // the WV start is its start
      }
      bool ok = sd > 0;
      for (Cause c : slow) ok = ok && !present(c) && !(c == Cause::GaussMarkov && !(T_hi > T_lo));
      if (!ok) continue;
      Set best;
      const int starts = std::count(slow.begin(), slow.end(), Cause::GaussMarkov) > 0 ? 3 : 1;
      for (int st = 0; st < starts; ++st) {
        Set s;
        s.slow = slow;
        s.start = pr.base;
        s.pen = pr.fast_pen;
        for (Cause c : slow) {
          Process p;
          if (c == Cause::RandomWalk) {
            p = Process::rw(0.3 * sd / std::sqrt(n_used));
            s.pen += 2;
          } else if (c == Cause::Drift) {
            p = Process::dr(0.0);  // its slope is the GLS trend
            s.pen += 2;
          } else {
            p = Process::gm(0.5 * sd, std::clamp((st == 0 ? 0.02 : st == 1 ? 0.07 : 0.18) * pr.record_s, T_lo, T_hi));
            s.pen += 4;
          }
          s.slow_idx.push_back(static_cast<int>(s.start.terms.size()));
          if (p.kind != ProcessKind::DR) s.own.push_back(static_cast<int>(s.start.terms.size()));
          s.start.terms.push_back(p);
        }
        fitSet(s);
        keepBetter(best, std::move(s));
      }
      if (!std::isfinite(best.aic)) continue;
      if (slow == wv.slow) {
        // The same explanation from two starts: keep the better fit.
        best.from_wv = true;  // the same causes: no swap, only a better fit
        best.text = pr.wv_text;
        for (auto& s : sets)
          if (s.from_wv) keepBetter(s, best);
        continue;
      }
      sets.push_back(std::move(best));
    }
  // A GM whose T goes to record/5 is no explanation of its own: the data do
  // not bound its T, and over this record it is the random walk (or drift)
  // it imitates (the rule: no GM with T beyond a fifth of the
  // record). Such a set cannot win; it competes as the nearest GM that is
  // not a random walk, refitted with T at most record/5 e^-0.5 (record/8).
  const double T_cap = T_hi * std::exp(-0.5);
  auto capT = [&](Model& m, const std::vector<int>& idx) {
    for (int i : idx) {
      Process& p = m.terms[static_cast<std::size_t>(i)];
      if (p.kind != ProcessKind::GM || p.T <= T_cap) continue;
      const double dt = 1.0 / pr.rate_hz, w0 = -std::expm1(-2.0 * dt / p.T);
      p.T = T_cap;
      p.sigma *= std::sqrt(w0 / -std::expm1(-2.0 * dt / p.T));  // the same innovation variance
    }
  };
  for (auto& s : sets) {
    bool top = false;
    for (int i : s.slow_idx) {
      const Process& p = s.fit.model.terms[static_cast<std::size_t>(i)];
      top = top || (p.kind == ProcessKind::GM && p.T >= T_hi * std::exp(-0.05));
    }
    if (!top) continue;
    s.rival_only = true;
    s.T_cap = T_cap;
    Model m = s.fit.model;
    capT(m, s.own);
    maximise(m, s.own, y, blk, T_lo, T_cap, -1, &s.fit);
    s.aic = std::isfinite(s.fit.loglik) ? -2.0 * s.fit.loglik + s.pen : kInf;
    for (auto& st : s.starts) capT(st.first, st.second);
  }
  if (sets.empty()) return ch;
  for (auto& s : sets) {
    std::vector<std::string> cs = fast_names;
    for (Cause c : s.slow) cs.push_back(causeName(c));
    s.causes = joinCauses(cs);
    if (s.from_wv) {
      s.text = pr.wv_text;
      continue;
    }
    for (int i : s.slow_idx) {
      Process p = s.fit.model.terms[static_cast<std::size_t>(i)];
      if (p.kind == ProcessKind::DR) p.omega = s.fit.beta.size() > 1 ? s.fit.beta(1) / n_used : 0.0;
      s.text += (s.text.empty() ? "" : " + ") + stochastic::formatTerms({p}, 3);
    }
  }

  // The choice: the explanation with the lowest AIC among those with as
  // many slow terms as the WV's (the WV's dof decide how many terms the
  // record needs; a larger set competes as a runner-up, below).
  const std::string blocks = std::to_string(nb) + " block means";
  const std::size_t count = std::max<std::size_t>(1, wv.slow.size());
  int wi = -1;
  for (std::size_t i = 0; i < sets.size(); ++i)
    if (!sets[i].rival_only && sets[i].slow.size() == count &&
        (wi < 0 || sets[i].aic < sets[static_cast<std::size_t>(wi)].aic))
      wi = static_cast<int>(i);
  if (wi < 0) return ch;
  // The WV's explanation gives way only when the exact likelihood rejects
  // it: simulated from its fit, it rarely (at most 5 %) gives the new
  // winner such a lead.
  std::string kept_evidence;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const Set& v = sets[i];
    if (!v.from_wv || v.rival_only || static_cast<int>(i) == wi) continue;
    const Set& x = sets[static_cast<std::size_t>(wi)];
    int used = 0;
    const double p = bootstrapP(x, v, v.aic - x.aic, y, blk, T_lo, T_hi, kLevel, stochastic::deriveSeed(pr.seed, 4), &used);
    if (p > kLevel) {
      kept_evidence = "; the WV's choice is kept: " + x.text + " leads it by " + formatNumber(v.aic - x.aic, 3) +
                      " in AIC, a lead " + std::to_string(used) + " records simulated from it gave in " +
                      formatNumber(100.0 * p, 2) + " %";
      wi = static_cast<int>(i);
    }
  }
  const Set& w = sets[static_cast<std::size_t>(wi)];
  ch.decided_here = true;
  ch.causes = w.causes;
  ch.swapped = !w.from_wv;

  // The winner's slow terms with their 95 % profile intervals, also when
  // they are the WV's (the caller takes a kept random walk's from here).
  if (w.slow_idx.size() == w.slow.size()) {
    for (int i : w.slow_idx) {
      Term t;
      t.proc = w.fit.model.terms[static_cast<std::size_t>(i)];
      bool olo = false, ohi = false;
      if (t.proc.kind == ProcessKind::DR) {
        const double se = w.fit.beta_cov.rows() > 1 ? std::sqrt(std::max(0.0, w.fit.beta_cov(1, 1))) : 0.0;
        t.proc.omega = w.fit.beta(1) / n_used;
        t.lo = (w.fit.beta(1) - 1.96 * se) / n_used;
        t.hi = (w.fit.beta(1) + 1.96 * se) / n_used;
      } else if (t.proc.kind == ProcessKind::RW) {
        const double g = t.proc.gamma;
        const auto iv = profileInterval(
            w, i, [&](Process& p, double lf) { p.gamma = g * std::exp(0.5 * lf); }, 0.0, -12.0, 6.0, true, y, blk, T_lo,
            T_hi, &olo, &ohi);
        t.lo = olo ? 0.0 : g * std::exp(0.5 * iv.first);
        t.hi = g * std::exp(0.5 * iv.second);
      } else {
        const double lT = std::log(t.proc.T);
        const auto iv = profileInterval(
            w, i, [&](Process& p, double v) { p.T = std::exp(v); }, lT, std::log(T_lo), std::log(T_hi), false, y, blk,
            T_lo, T_hi, &olo, &ohi);
        t.lo = std::exp(iv.first);
        t.hi = std::exp(iv.second);
        t.open_top = ohi;
      }
      ch.terms.push_back(t);
    }
  }

  // The rivals, each put to its bootstrap; the one that leaves the choice
  // most open is the runner-up.
  double worst = -1;
  auto consider = [&](const Set& r, double p, int used, bool larger, const std::string& detail) {
    const bool open = larger ? p <= kLevel : p > kLevel;
    // An open rival before any other; then the one nearer to opening it.
    const double how_open = (open ? 2.0 : 0.0) + (larger ? 1.0 - p : p);
    if (how_open > worst) {
      worst = how_open;
      ch.runner_up = r.causes;
      ch.runner_up_detail = detail;
      ch.aic_margin = r.aic - w.aic;
      ch.p = p;
      ch.draws = used;
      ch.larger = larger;
      ch.decided = !open;
    }
  };
  // (i) The best explanation with at most as many slow terms: would it,
  // simulated, give the winner this lead? (ii) The best one with more that
  // the exact AIC prefers: would the winner, simulated, give it its lead?
  int oi = -1, li = -1;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    if (static_cast<int>(i) == wi || sets[i].causes == w.causes) continue;
    const bool more = sets[i].slow.size() > w.slow.size();
    if (!more && (oi < 0 || sets[i].aic < sets[static_cast<std::size_t>(oi)].aic)) oi = static_cast<int>(i);
    if (more && sets[i].aic < w.aic && (li < 0 || sets[i].aic < sets[static_cast<std::size_t>(li)].aic))
      li = static_cast<int>(i);
  }
  // A rival judged under the explanation simulated: itself (i), or the
  // winner (ii: larger).
  auto judge = [&](const Set& r, bool larger, std::uint64_t index) {
    const Set &sim = larger ? w : r, &other = larger ? r : w;
    int used = 0;
    const double p = bootstrapP(other, sim, sim.aic - other.aic, y, blk, T_lo, T_hi, kLevel,
                                stochastic::deriveSeed(pr.seed, index), &used);
    consider(r, p, used, larger,
             r.text + " (exact likelihood of " + blocks + ": AIC " + formatNumber(std::abs(r.aic - w.aic), 3) +
                 (r.aic < w.aic ? " below" : " above") + " the winner's; " + std::to_string(used) + " records simulated from " +
                 (larger ? "the winner" : "it") + " gave such a lead in " + formatNumber(100.0 * p, 2) + " %)");
  };
  if (oi >= 0) judge(sets[static_cast<std::size_t>(oi)], false, 1);
  if (li >= 0) judge(sets[static_cast<std::size_t>(li)], true, 2);
  ch.evidence = "; among the slow explanations (random walk, drift, Gauss-Markov with T up to record/5, one or two, "
                "fitted on the exact likelihood of " + blocks + ") " + w.text +
                (kept_evidence.empty() ? " has the lowest AIC" : " is kept") +
                (ch.swapped ? " (the WV alone preferred " + pr.wv_text + ")" : std::string()) + kept_evidence;
  if (!ch.runner_up.empty())
    ch.evidence += "; parametric bootstrap of the runner-up, " + ch.runner_up_detail + ": " +
                   (ch.decided ? "decided at 5 %" : "undecided at 5 %");
  return ch;
}

}  // namespace navimpact::analysis::slow
