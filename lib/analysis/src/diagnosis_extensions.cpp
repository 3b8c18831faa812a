// The extensions of a model that navimpact diagnose fits to a channel's
// wavelet variance (see diagnosis_internal.hpp): one process family added or
// one term retuned, sets of them backfitted jointly, and the GMWM refit of
// the chosen extension.
#include <algorithm>
#include <cmath>
#include <limits>


#include "diagnosis_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/golden_section.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/process_kind.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::analysis::detail {

double wvDeviance(const std::vector<double>& nu_hat, const std::vector<double>& nu,
                  const std::vector<double>& eta) {
  // Gamma deviance: nu_hat ~ nu chi2_eta / eta  =>  -2 log-likelihood ratio
  // against the saturated fit = sum eta (r - log r - 1), r = nu_hat / nu.
  double d = 0;
  for (std::size_t j = 0; j < nu_hat.size(); ++j) {
    const double m = std::max(nu[j], 1e-300);
    const double r = nu_hat[j] / m;
    if (!(r > 0)) continue;
    d += eta[j] * (r - std::log(r) - 1.0);
  }
  return d;
}

Cause causeOf(ProcessKind k) {
  switch (k) {
    case ProcessKind::WN: return Cause::WhiteNoise;
    case ProcessKind::QN: return Cause::QuantizationNoise;
    case ProcessKind::RW: return Cause::RandomWalk;
    case ProcessKind::DR: return Cause::Drift;
    case ProcessKind::GM: return Cause::GaussMarkov;
    case ProcessKind::SIN: return Cause::Sinusoid;
  }
  return Cause::WhiteNoise;
}

double& mainParam(Process& p) { return p.*(stochastic::kindInfo(p.kind).params.front().field); }

Process unitProcess(ProcessKind k, double shape) {
  Process p;
  p.kind = k;
  const auto& params = stochastic::kindInfo(k).params;
  for (std::size_t i = 0; i < params.size(); ++i) p.*(params[i].field) = i == 0 ? 1.0 : shape;
  return p;
}

std::vector<double> wvOf(const Process& p, double rate, const std::vector<double>& tau) {
  std::vector<double> v(tau.size());
  for (std::size_t j = 0; j < tau.size(); ++j) v[j] = stochastic::haarWv(p, rate, tau[j]);
  return v;
}

std::vector<double> wvOf(const Model& m, const std::vector<double>& tau) {
  std::vector<double> v(tau.size(), 0.0);
  for (const auto& p : m.terms) {
    const auto w = wvOf(p, m.rate_hz, tau);
    for (std::size_t j = 0; j < tau.size(); ++j) v[j] += w[j];
  }
  return v;
}

std::vector<double> toStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

Model withoutSin(const Model& m) {
  Model o = m;
  o.terms.erase(std::remove_if(o.terms.begin(), o.terms.end(),
                               [](const Process& p) { return p.kind == ProcessKind::SIN; }),
                o.terms.end());
  return o;
}

WvTest wvTest(const WvData& d, double p_thr) {
  WvTest t;
  t.p_thr = p_thr;
  for (double eta : d.dof) {
    const double nu = std::max(eta, 1e-6);
    t.lo.push_back(chiQuantile(nu, 0.5 * p_thr) / eta);
    t.hi.push_back(chiUpperQuantile(nu, 0.5 * p_thr) / eta);
    t.ci95.push_back((chiUpperQuantile(nu, 0.025) - chiQuantile(nu, 0.025)) / eta);
  }
  return t;
}

int significantScales(const WvData& d, const WvTest& t, const std::vector<double>& nu_m) {
  int c = 0;
  for (std::size_t j = 0; j < d.nu.size(); ++j) {
    if (!(nu_m[j] > 0)) {
      ++c;
      continue;
    }
    const double r = d.nu[j] / nu_m[j];
    c += (r < t.lo[j] || r > t.hi[j]) ? 1 : 0;
  }
  return c;
}

namespace {

/// min over a >= 0 of deviance(base + a * shape): the stationary points of the
/// deviance in log a, located on a log grid by the sign of its derivative
/// dD/da = sum eta s (nu - nu_hat) / nu^2 (no logarithms) and refined by
/// bisection, compared with each other and with a = 0.
double bestScale(const WvData& d, const std::vector<double>& base, const std::vector<double>& shape,
                 double* a_out) {
  const std::size_t J = d.nu.size();
  double amin = std::numeric_limits<double>::infinity(), amax = 0;
  for (std::size_t j = 0; j < J; ++j) {
    if (shape[j] > 0 && d.nu[j] > 0) {
      const double a = d.nu[j] / shape[j];
      amin = std::min(amin, a);
      amax = std::max(amax, a);
    }
  }
  std::vector<double> nu(J);
  auto dev = [&](double a) {
    for (std::size_t j = 0; j < J; ++j) nu[j] = base[j] + a * shape[j];
    return wvDeviance(d.nu, nu, d.dof);
  };
  const double d0 = wvDeviance(d.nu, base, d.dof);
  if (!(amax > 0)) {
    *a_out = 0;
    return d0;
  }
  auto slope = [&](double la) {  // sign of dD/d(log a) = a dD/da
    const double a = std::exp(la);
    double g = 0;
    for (std::size_t j = 0; j < J; ++j) {
      if (!(d.nu[j] > 0)) continue;  // as wvDeviance: scales without a measured WV do not count
      const double m = std::max(base[j] + a * shape[j], 1e-300);
      g += d.dof[j] * shape[j] * (m - d.nu[j]) / (m * m);
    }
    return g;
  };
  const double l0 = std::log(amin) - 12.0, l1 = std::log(amax) + 1.0;
  const int G = 64;
  double best = d0, best_a = 0;
  double prev_l = l0, prev_g = slope(l0);
  auto consider = [&](double la) {
    const double v = dev(std::exp(la));
    if (v < best) {
      best = v;
      best_a = std::exp(la);
    }
  };
  for (int i = 1; i <= G; ++i) {
    const double l = l0 + (l1 - l0) * i / G;
    const double g = slope(l);
    if (prev_g < 0 && g >= 0) {  // a minimum of D in (prev_l, l]
      double lo = prev_l, hi = l;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (slope(mid) < 0 ? lo : hi) = mid;
      }
      consider(0.5 * (lo + hi));
    }
    prev_l = l;
    prev_g = g;
  }
  if (prev_g < 0) consider(l1);  // still falling at the top of the range
  *a_out = best_a;
  return best;
}

/// 95 % profile interval of a (deviance within chi2_1(0.95) = 3.84 of its
/// minimum at a_hat), by bisection in log a on each side.
std::pair<double, double> scaleInterval(const WvData& d, const std::vector<double>& base,
                                        const std::vector<double>& shape, double a_hat) {
  if (!(a_hat > 0)) return {0.0, 0.0};
  std::vector<double> nu(d.nu.size());
  auto dev = [&](double a) {
    for (std::size_t j = 0; j < nu.size(); ++j) nu[j] = base[j] + a * shape[j];
    return wvDeviance(d.nu, nu, d.dof);
  };
  const double target = dev(a_hat) + 3.84;
  auto side = [&](double factor) {
    double in = std::log(a_hat), out = in;
    for (int i = 0; i < 60; ++i) {  // expand until outside
      out += std::log(factor);
      if (dev(std::exp(out)) > target) break;
      if (i == 59) return std::exp(out);
    }
    for (int i = 0; i < 50; ++i) {
      const double mid = 0.5 * (in + out);
      (dev(std::exp(mid)) > target ? out : in) = mid;
    }
    return std::exp(in);
  };
  return {side(0.5), side(2.0)};
}

}  // namespace

Candidate fitCandidate(bool retune, int term, ProcessKind kind, const Model& model,
                       const WvData& d, double T_hint, bool intervals) {
  Candidate c;
  c.retune = retune;
  c.term = term;
  c.kind = kind;
  const double rate = model.rate_hz;
  std::vector<double> base(d.tau.size(), 0.0);
  for (std::size_t i = 0; i < model.terms.size(); ++i) {
    if (retune && static_cast<int>(i) == term) continue;
    const auto w = wvOf(model.terms[i], rate, d.tau);
    for (std::size_t j = 0; j < base.size(); ++j) base[j] += w[j];
  }
  if (kind != ProcessKind::GM) {
    Process u = unitProcess(kind);
    const auto shape = wvOf(u, rate, d.tau);
    double a = 0;
    c.deviance = bestScale(d, base, shape, &a);
    c.proc = u;
    mainParam(c.proc) = std::sqrt(a);
    c.params = 1;
    if (intervals) {
      const auto iv = scaleInterval(d, base, shape, a);
      c.p_lo = std::sqrt(iv.first);
      c.p_hi = std::sqrt(iv.second);
    }
  } else {
    // GM: profile over T on a log grid from one sample to a fifth of the
    // record (a longer T is a random walk or a drift over this record).
    const double n_rec = d.samples > 0 ? d.samples : (d.tau.empty() ? 1 : 2 * d.tau.back());
    const double t0 = 1.0 / rate, t1 = 0.2 * n_rec / rate;
    const int G = 120;
    if (std::isfinite(T_hint) && T_hint > 0) {
      // Golden section in log T over four grid steps either side of the hint.
      const double h = std::log(t1 / t0) / G;
      double a = std::max(std::log(t0), std::log(T_hint) - 4 * h);
      double b = std::min(std::log(t1), std::log(T_hint) + 4 * h);
      if (!(b > a)) a = b = std::log(std::clamp(T_hint, t0, t1));
      double aa = 0;
      auto prof = [&](double lT) {
        const auto shape = wvOf(unitProcess(ProcessKind::GM, std::exp(lT)), rate, d.tau);
        return bestScale(d, base, shape, &aa);
      };
      const auto br = goldenSectionBracket(prof, a, b, 24);
      const double lT = 0.5 * (br.first + br.second);
      c.deviance = prof(lT);
      c.proc = Process::gm(std::sqrt(std::max(aa, 0.0)), std::exp(lT));
      c.params = 2;
      c.T_hi_open = lT >= std::log(t1) - h || lT <= std::log(t0) + h;
      c.T_bottom = lT <= std::log(t0) + h;
      if (retune) {
        Process o = model.terms[term];
        const double olda = mainParam(o);
        c.scale = olda > 0 ? c.proc.sigma * c.proc.sigma / (olda * olda) : kNaN;
      }
      return c;
    }
    std::vector<double> Ts(G + 1), devs(G + 1), as(G + 1);
    int gi = 0;
    for (int i = 0; i <= G; ++i) {
      Ts[i] = t0 * std::pow(t1 / t0, static_cast<double>(i) / G);
      const auto shape = wvOf(unitProcess(ProcessKind::GM, Ts[i]), rate, d.tau);
      devs[i] = bestScale(d, base, shape, &as[i]);
      if (devs[i] < devs[gi]) gi = i;
    }
    // Golden refinement of log T between the grid neighbours.
    double a = std::log(Ts[std::max(0, gi - 1)]), b = std::log(Ts[std::min(G, gi + 1)]);
    auto prof = [&](double lT, double* aa) {
      const auto shape = wvOf(unitProcess(ProcessKind::GM, std::exp(lT)), rate, d.tau);
      return bestScale(d, base, shape, aa);
    };
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double aa = 0;
    double x1 = b - r * (b - a), x2 = a + r * (b - a);
    double f1 = prof(x1, &aa), f2 = prof(x2, &aa);
    for (int it = 0; it < 30; ++it) {
      if (f1 < f2) {
        b = x2; x2 = x1; f2 = f1; x1 = b - r * (b - a); f1 = prof(x1, &aa);
      } else {
        a = x1; x1 = x2; f1 = f2; x2 = a + r * (b - a); f2 = prof(x2, &aa);
      }
    }
    double lT = 0.5 * (a + b);
    double best = prof(lT, &aa);
    if (devs[gi] < best) {
      lT = std::log(Ts[gi]);
      best = devs[gi];
      aa = as[gi];
    }
    c.deviance = best;
    c.proc = Process::gm(std::sqrt(std::max(aa, 0.0)), std::exp(lT));
    c.params = 2;
    // 95 % profile interval of T: deviance within chi2_1(0.95) = 3.84 of the minimum.
    double lo = std::exp(lT), hi = std::exp(lT);
    for (int i = 0; i <= G; ++i)
      if (devs[i] <= best + 3.84) {
        lo = std::min(lo, Ts[i]);
        hi = std::max(hi, Ts[i]);
      }
    // The grid resolves T to one grid step at best: never narrower than that.
    c.T_lo = std::min(lo, Ts[std::max(0, gi - 1)]);
    c.T_hi = std::max(hi, Ts[std::min(G, gi + 1)]);
    // A GM whose T the data do not bound below a fifth of the record (best
    // T at the top of the grid, or its 95 % profile interval reaching it) is
    // a random walk or a drift over this record; one at the bottom (one
    // sample) is white noise. Either is left to those candidates.
    c.T_hi_open = gi >= G - 1 || lT >= std::log(Ts[G - 1]) || devs[G] <= best + 3.84 ||
                  // T at the bottom of the grid (one sample): white noise, not a GM
                  gi <= 1 || lT <= std::log(Ts[1]);
    c.T_top_only = c.T_hi_open && !(gi >= G - 1 || lT >= std::log(Ts[G - 1]) || gi <= 1 || lT <= std::log(Ts[1]));
    c.T_bottom = gi <= 1 || lT <= std::log(Ts[1]);
    c.p_lo = c.p_hi = kNaN;
  }
  if (retune) {
    const Process& old = model.terms[term];
    Process o = old;
    const double olda = mainParam(o);
    c.scale = olda > 0 ? mainParam(c.proc) * mainParam(c.proc) / (olda * olda) : kNaN;
  }
  return c;
}

Model applyCandidate(const Model& m, const Candidate& c) {
  Model out = m;
  if (c.retune) {
    out.terms[c.term] = c.proc;
    return out;
  }
  if (c.kind != ProcessKind::GM) {
    for (auto& t : out.terms) {
      if (t.kind == c.kind) {
        double& a = mainParam(t);
        Process p = c.proc;
        a = std::sqrt(a * a + mainParam(p) * mainParam(p));
        return out;
      }
    }
  }
  if (mainParam(const_cast<Process&>(c.proc)) > 0) out.terms.push_back(c.proc);
  return out;
}

std::string candidateText(const Candidate& c) {
  Process p = c.proc;
  std::string s = c.retune ? "retuned " : "";
  s += stochastic::formatTerms({p}, 3);
  return s;
}

Model assemble(const Model& base, const std::vector<Candidate>& cs, int skip) {
  Model m = base;
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (static_cast<int>(i) != skip && cs[i].retune) m.terms[cs[i].term] = cs[i].proc;
  for (std::size_t i = 0; i < cs.size(); ++i)
    if (static_cast<int>(i) != skip && !cs[i].retune) m.terms.push_back(cs[i].proc);
  return m;
}

int assembledIndex(const Model& base, const std::vector<Candidate>& cs, std::size_t i) {
  if (cs[i].retune) return cs[i].term;
  int k = static_cast<int>(base.terms.size());
  for (std::size_t q = 0; q < i; ++q) k += cs[q].retune ? 0 : 1;
  return k;
}

Model merged(const Model& base, const std::vector<Candidate>& cs, bool keep_places) {
  Model m = base;
  // Retunes first, a retune to zero included: the model's term is not in the
  // data (it used to be skipped, which kept the overstated term: an RW of the
  // model retuned to 0 on the first half stayed at its old gamma there, and
  // the held-out gain compared the model with itself).
  std::vector<int> vanished;
  for (const auto& c : cs) {
    if (!c.retune) continue;
    Process p = c.proc;
    m = applyCandidate(m, c);
    if (!(mainParam(p) > 0)) vanished.push_back(c.term);
  }
  if (!keep_places) {
    std::sort(vanished.rbegin(), vanished.rend());
    vanished.erase(std::unique(vanished.begin(), vanished.end()), vanished.end());
    for (int t : vanished) m.terms.erase(m.terms.begin() + t);
  }
  for (const auto& c : cs) {
    Process p = c.proc;
    if (!c.retune && mainParam(p) > 0) m = applyCandidate(m, c);
  }
  return m;
}

double penalty(const std::vector<Candidate>& cs, std::size_t from) {
  double p = 0;
  for (std::size_t i = from; i < cs.size(); ++i) p += 2.0 * cs[i].params + (cs[i].retune ? 4.0 : 0.0);
  return p;
}

double backfit(const Model& base, std::vector<Candidate>& cs, const WvData& d) {
  if (cs.empty()) return wvDeviance(d.nu, wvOf(base, d.tau), d.dof);
  if (cs.size() > 1) {
    double prev = std::numeric_limits<double>::infinity();
    for (int sweep = 0; sweep < 10; ++sweep) {
      double now = prev;
      for (std::size_t i = 0; i < cs.size(); ++i) {
        const double hint = cs[i].kind == ProcessKind::GM ? cs[i].proc.T : kNaN;
        cs[i] = fitCandidate(cs[i].retune, cs[i].term, cs[i].kind, assemble(base, cs, static_cast<int>(i)), d, hint, false);
        now = cs[i].deviance;
      }
      if (!(prev - now > 1e-6 * (1.0 + std::abs(now)))) break;
      prev = now;
    }
  }
  for (std::size_t i = 0; i < cs.size(); ++i)
    cs[i] = fitCandidate(cs[i].retune, cs[i].term, cs[i].kind, assemble(base, cs, static_cast<int>(i)), d);
  return cs.back().deviance;
}

std::string newTermsText(const Extension& e) {
  std::string s;
  for (std::size_t i = e.terms.size() - e.added; i < e.terms.size(); ++i)
    s += (s.empty() ? "" : " + ") + candidateText(e.terms[i]);
  return s;
}

std::vector<Extension> extensions(const Model& base, const std::vector<Candidate>& S, const WvData& d,
                                  const WvTest& wt, int max_new) {
  struct Family {
    bool retune;
    int term;
    ProcessKind kind;
  };
  std::vector<Family> fams;
  // A WN, QN, RW or DR already found (added or retuned) is refitted with
  // the set, not offered again; GMs may be several.
  auto kindFound = [&](ProcessKind k) {
    if (k == ProcessKind::GM) return false;
    for (const auto& c : S)
      if (c.kind == k) return true;
    return false;
  };
  for (ProcessKind k : {ProcessKind::WN, ProcessKind::QN, ProcessKind::RW, ProcessKind::DR, ProcessKind::GM})
    if (!kindFound(k)) fams.push_back({false, -1, k});
  for (std::size_t i = 0; i < base.terms.size(); ++i) {
    if (base.terms[i].kind == ProcessKind::SIN || kindFound(base.terms[i].kind)) continue;
    bool taken = false;
    for (const auto& c : S) taken = taken || (c.retune && c.term == static_cast<int>(i));
    if (!taken) fams.push_back({true, static_cast<int>(i), base.terms[i].kind});
  }
  const Model cur = assemble(base, S);
  auto finish = [&](Extension& e) {
    e.crit = e.deviance + penalty(e.terms);
    e.valid = true;
    // Terms found before were judged when they were found (a long GM may
    // have been bounded by the exact likelihood only).
    bool open_top = false;
    for (std::size_t i = 0; i < e.terms.size(); ++i) {
      const Candidate& c = e.terms[i];
      Process p = c.proc;
      // an added term must be there; a model's term retuned to zero is a finding
      // (the data show none of it: an overstated RW on white noise was named
      // quantization noise + white noise when this was refused)
      if (!(mainParam(p) > 0) && !c.retune) e.why_not = "a vanishing term";
      else if (c.kind == ProcessKind::GM && c.T_bottom) e.why_not = "a GM at one sample (white noise)";
      else if (i >= S.size() && c.kind == ProcessKind::GM && c.T_hi_open) {
        if (c.T_top_only) open_top = true;
        else e.why_not = "a GM whose T the data do not bound";
      }
    }
    e.open_top = open_top && e.why_not.empty();
    if (open_top && e.why_not.empty()) e.why_not = "a GM whose T the WV does not bound below record/5";
    e.valid = e.why_not.empty();
    if (e.valid) e.significant = significantScales(d, wt, wvOf(assemble(base, e.terms), d.tau));
  };
  std::vector<Extension> out;
  for (const auto& f : fams) {
    Extension e(S, 1);
    e.terms.push_back(fitCandidate(f.retune, f.term, f.kind, cur, d));
    e.deviance = S.empty() ? e.terms.back().deviance : backfit(base, e.terms, d);
    finish(e);
    out.push_back(std::move(e));
  }
  if (max_new < 2) return out;
  const std::size_t singles = out.size();
  auto nonGmKind = [](const Family& f) { return f.kind != ProcessKind::GM; };
  for (std::size_t a = 0; a < singles; ++a)
    for (std::size_t b = a; b < singles; ++b) {
      const Family &fa = fams[a], &fb = fams[b];
      if (a == b && (fa.retune || fa.kind != ProcessKind::GM)) continue;  // only two GMs may share a family
      if (fa.kind == fb.kind && nonGmKind(fa)) continue;                   // WN + WN is one WN
      const Extension& ea = out[a];
      Extension e(S, 2);
      e.terms.push_back(ea.terms.back());
      e.terms.push_back(fitCandidate(fb.retune, fb.term, fb.kind, assemble(base, e.terms), d));
      e.deviance = backfit(base, e.terms, d);
      finish(e);
      // Both needed: the pair's deviance lies below every valid one-term
      // explanation (those it contains, and any other) by more than the 99 %
      // quantile of chi-square with the parameters it has in excess (a
      // likelihood-ratio test on the WV, nested for the terms it contains).
      // A pair that fails is still kept for the exact likelihood of the slow
      // explanations, which may need both (see the cause search).
      for (std::size_t q1 = 0; q1 < singles; ++q1) {
        const Extension& sub = out[q1];
        if (!sub.valid) continue;
        const double dp = (penalty(e.terms) - penalty(sub.terms)) / 2.0;
        const double q = chiUpperQuantile(std::max(dp, 1.0), 0.01);
        if (!(sub.deviance - e.deviance > q)) e.needed = false;
      }
      if (e.valid) {
        const auto full = wvOf(assemble(base, e.terms), d.tau);
        for (std::size_t q = e.terms.size() - 2; q < e.terms.size() && e.valid; ++q) {
          const auto without = wvOf(assemble(base, e.terms, static_cast<int>(q)), d.tau);
          double widths = 0;
          for (std::size_t j = 0; j < full.size(); ++j)
            if (without[j] > 0) widths = std::max(widths, std::abs(full[j] - without[j]) / (without[j] * wt.ci95[j]));
          if (widths < 1.0) {
            e.valid = false;
            e.why_not = "a term that changes the WV by less than its CI width";
          }
        }
      }
      out.push_back(std::move(e));
    }
  return out;
}

Model greedyExtension(const Model& m, const WvData& d, int max_terms, double p_thr, int* params) {
  const WvTest wt = wvTest(d, p_thr);
  std::vector<Candidate> S;
  double cur = wvDeviance(d.nu, wvOf(m, d.tau), d.dof);
  while (static_cast<int>(S.size()) < max_terms) {
    const auto ext = extensions(m, S, d, wt, max_terms - static_cast<int>(S.size()));
    int best = -1;
    for (std::size_t i = 0; i < ext.size(); ++i)
      if (ext[i].valid && ext[i].needed && ext[i].crit < cur && (best < 0 || ext[i].crit < ext[best].crit)) best = static_cast<int>(i);
    if (best < 0) break;
    S = ext[best].terms;
    cur = ext[best].crit;
  }
  *params = 0;
  for (const auto& c : S) *params += c.params;
  return merged(m, S);
}

Model gmwmRefit(const Model& start, const gmwm::WaveletVariance& wv, const WvData& d,
                std::string* how) {
  Model core = start, sins = start;
  core.terms.clear();
  sins.terms.clear();
  for (const auto& p : start.terms) (p.kind == ProcessKind::SIN ? sins : core).terms.push_back(p);
  std::vector<ProcessKind> structure;
  for (const auto& p : core.terms) structure.push_back(p.kind);
  if (structure.empty() || gmwm::parameterCount(structure) > wv.scales()) {
    *how = "none (structure too large for the scales)";
    return start;
  }
  Model refit;
  try {
    gmwm::FitOptions fo;
    fo.warm_starts = {core};
    fo.max_starts = 2;
    refit = gmwm::fit(structure, wv, fo).model;
  } catch (const Error& e) {
    *how = std::string("start kept (GMWM refit failed: ") + e.what() + ")";
    return start;
  }
  refit.rate_hz = start.rate_hz;
  // "Keeping the parts that were right": a refit that collapses a term of the
  // start (its variance-like parameter below 1e-3 of the start's) or moves a GM
  // below one sample of correlation time (practically white, what GMWM does on
  // quantised data) trades a term for another rather than refining it.
  {
    auto params = [](const Model& m, ProcessKind k) {
      std::vector<double> v;
      for (Process p : m.terms)
        if (p.kind == k) v.push_back(mainParam(p));
      std::sort(v.rbegin(), v.rend());
      return v;
    };
    auto subSample = [&](const Model& m) {
      int c = 0;
      for (const auto& p : m.terms) c += (p.kind == ProcessKind::GM && p.T < 1.0 / start.rate_hz) ? 1 : 0;
      return c;
    };
    for (ProcessKind k : {ProcessKind::WN, ProcessKind::QN, ProcessKind::RW, ProcessKind::DR,
                          ProcessKind::GM}) {
      const auto pa = params(core, k), pb = params(refit, k);
      for (std::size_t i = 0; i < pa.size() && i < pb.size(); ++i)
        if (pa[i] > 0 && pb[i] < 1e-3 * pa[i]) {
          *how = "start kept (the GMWM refit " + stochastic::formatTerms(refit.terms, 3) +
                 " collapsed a term of " + stochastic::formatTerms(core.terms, 3) + ")";
          return start;
        }
    }
    if (subSample(refit) > subSample(core)) {
      *how = "start kept (the GMWM refit " + stochastic::formatTerms(refit.terms, 3) +
             " has a GM below one sample of correlation time)";
      return start;
    }
  }
  for (const auto& p : sins.terms) refit.terms.push_back(p);
  const double dev0 = wvDeviance(d.nu, wvOf(core, d.tau), d.dof);
  Model rc = refit;
  rc.terms.erase(std::remove_if(rc.terms.begin(), rc.terms.end(),
                                [](const Process& p) { return p.kind == ProcessKind::SIN; }),
                 rc.terms.end());
  const double dev1 = wvDeviance(d.nu, wvOf(rc, d.tau), d.dof);
  if (dev1 <= dev0 + 1e-9 * std::abs(dev0)) {
    *how = "gmwm (deviance " + formatNumber(dev0, 4) + " -> " + formatNumber(dev1, 4) + ")";
    return refit;
  }
  *how = "start kept (GMWM refit raised the deviance " + formatNumber(dev0, 4) + " -> " + formatNumber(dev1, 4) + ")";
  return start;
}

}  // namespace navimpact::analysis::detail
