// Model selection by the wavelet information criterion (WIC):
// criterion = objective + optimism (Guerrier et al. 2013; R gmwm
// model_score / asympt_calc, gmwm_formulas.md §6), optimism asymptotic.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "fit_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::gmwm {

using stochastic::Model;
using stochastic::ProcessKind;

namespace {

std::vector<ProcessKind> kindsOf(const Model& m) {
  std::vector<ProcessKind> k;
  for (const auto& t : m.terms) k.push_back(t.kind);
  return k;
}

/// Counts per kind (multiset of a structure).
std::map<ProcessKind, int> counts(const std::vector<ProcessKind>& s) {
  std::map<ProcessKind, int> c;
  for (ProcessKind k : s) ++c[k];
  return c;
}

/// True if @p a is a sub-multiset of @p b with exactly one term less; @p extra gets that term.
bool oneLess(const std::vector<ProcessKind>& a, const std::vector<ProcessKind>& b, ProcessKind* extra) {
  if (a.size() + 1 != b.size()) return false;
  auto ca = counts(a), cb = counts(b);
  int diff = 0;
  for (auto& [k, n] : cb) {
    const int na = ca.count(k) ? ca[k] : 0;
    if (na > n) return false;
    if (n - na == 1) {
      ++diff;
      if (extra) *extra = k;
    } else if (n != na) {
      return false;
    }
  }
  for (auto& [k, n] : ca)
    if (!cb.count(k)) return false;
  return diff == 1;
}

}  // namespace

double optimism(const FitResult& f, const WaveletVariance& wv) {
  const detail::Layout L(kindsOf(f.model));
  const Eigen::VectorXd th = detail::fromModel(L, f.model);
  const Eigen::MatrixXd A = detail::jacobian(L, th, wv.tau);
  const Eigen::VectorXd nu = detail::wvOf(L, th, wv.tau);
  const Eigen::VectorXd om = wv.weights();
  const int J = wv.scales(), p = L.p;
  Eigen::VectorXd V(J);
  for (int j = 0; j < J; ++j) {
    const double eta = (wv.eta.size() == J && wv.eta[j] > 0) ? wv.eta[j] : 1.0;
    V[j] = 2.0 * nu[j] * nu[j] / (eta * wv.eff);
  }
  const Eigen::MatrixXd B = A.transpose() * om.asDiagonal() * A;
  // D_kl = sum_j d2nu_j/dth_k dth_l * Omega_jj (nu_j - nu_hat_j): second
  // derivatives by central differences of the (exact, autodiff) Jacobian.
  const Eigen::VectorXd c = om.cwiseProduct(nu - wv.wv);
  Eigen::MatrixXd D(p, p);
  const double h = 1e-4;
  for (int l = 0; l < p; ++l) {
    Eigen::VectorXd tp = th, tm = th;
    tp[l] += h;
    tm[l] -= h;
    const Eigen::MatrixXd dA = (detail::jacobian(L, tp, wv.tau) - detail::jacobian(L, tm, wv.tau)) / (2 * h);
    D.col(l) = dA.transpose() * c;
  }
  D = 0.5 * (D + D.transpose());
  // Hessian of the objective / 2 = B + D; d theta_hat / d nu_hat = (B + D)^+ A' Omega.
  const Eigen::MatrixXd dTheta = detail::pinvSym(B + D) * A.transpose() * om.asDiagonal();
  const Eigen::MatrixXd S = A * dTheta;  // d nu(theta_hat) / d nu_hat
  double tr = 0;
  for (int j = 0; j < J; ++j) tr += S(j, j) * V[j] * om[j];
  return 2.0 * tr;
}

std::vector<bool> negligibleTerms(const Model& m, const WaveletVariance& wv, double fraction) {
  if (!(fraction > 0.0 && fraction <= 1.0))
    throw Error("negligibleTerms: fraction " + formatNumber(fraction, 4) + " outside (0, 1]");
  std::vector<bool> out(m.terms.size(), true);
  for (std::size_t i = 0; i < m.terms.size(); ++i)
    for (int j = 0; j < wv.scales() && out[i]; ++j)
      if (!(stochastic::haarWv(m.terms[i], m.rate_hz, wv.tau[j]) < fraction * (wv.ci_high[j] - wv.ci_low[j])))
        out[i] = false;
  return out;
}

std::vector<int> scalesOutsideCi(const Model& m, const WaveletVariance& wv) {
  const Eigen::VectorXd nu = stochastic::haarWv(m, wv.tau);
  std::vector<int> out;
  for (int j = 0; j < wv.scales(); ++j)
    if (nu[j] < wv.ci_low[j] || nu[j] > wv.ci_high[j]) out.push_back(j);
  return out;
}

double outsideCiChance(int outside, int scales) {
  if (outside <= 0) return 1.0;
  if (outside > scales) return 0.0;
  // sum_{i >= outside} C(J, i) p^i (1-p)^(J-i), summed directly (no 1 - x cancellation), terms in logs.
  const double p = 0.05;
  double tail = 0.0;
  for (int i = scales; i >= outside; --i)
    tail += std::exp(std::lgamma(scales + 1.0) - std::lgamma(i + 1.0) - std::lgamma(scales - i + 1.0) +
                     i * std::log(p) + (scales - i) * std::log1p(-p));
  return std::min(1.0, tail);
}

std::vector<std::vector<ProcessKind>> defaultCandidates(int max_gm) {
  std::vector<std::vector<ProcessKind>> out;
  for (int g = 0; g <= max_gm; ++g)
    for (int mask = 0; mask < 8; ++mask) {
      std::vector<ProcessKind> s{ProcessKind::WN};
      if (mask & 1) s.push_back(ProcessKind::QN);
      for (int i = 0; i < g; ++i) s.push_back(ProcessKind::GM);
      if (mask & 2) s.push_back(ProcessKind::RW);
      if (mask & 4) s.push_back(ProcessKind::DR);
      out.push_back(s);
    }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return parameterCount(a) < parameterCount(b);
  });
  return out;
}

std::vector<RankedModel> selectModel(const std::vector<std::vector<ProcessKind>>& candidates,
                                     const WaveletVariance& wv, const FitOptions& opt, std::string* why) {
  if (candidates.empty()) throw Error("model selection: no candidate structures");
  // Fit the smaller structures first; each candidate is warm-started from the
  // fitted candidates with one term less, so a larger nested model never ends
  // with a higher objective than its sub-model.
  std::vector<std::size_t> order(candidates.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return candidates[a].size() < candidates[b].size();
  });
  std::vector<RankedModel> out;
  std::vector<std::vector<ProcessKind>> fitted_kinds;
  for (std::size_t i : order) {
    const auto& s = candidates[i];
    if (parameterCount(s) > wv.scales()) continue;  // not identifiable at this length
    FitOptions o = opt;
    o.bootstrap = 0;  // intervals of the pick only (below)
    for (std::size_t q = 0; q < out.size(); ++q)
      if (oneLess(fitted_kinds[q], s, nullptr)) o.warm_starts.push_back(out[q].fit.model);
    RankedModel rm;
    rm.fit = fit(s, wv, o);
    rm.optimism = optimism(rm.fit, wv);
    rm.criterion = rm.fit.objective + rm.optimism;
    out.push_back(rm);
    fitted_kinds.push_back(s);
  }
  if (out.empty())
    throw Error("model selection: every candidate has more parameters than the " +
                std::to_string(wv.scales()) + " scales of the wavelet variance");
  // Rank by criterion; criteria equal to 1e-9 (relative to the smallest) are
  // ties, broken by fewer parameters: a negligible extra term (e.g. a DR that
  // stayed at 1e-3 of the WV) adds neither objective nor optimism.
  double cmin = out.front().criterion;
  for (const auto& r : out) cmin = std::min(cmin, r.criterion);
  const double tol = 1e-9 * std::max(std::fabs(cmin), 1e-300);
  auto key = [&](const RankedModel& r) { return std::floor((r.criterion - cmin) / tol + 0.5); };
  std::stable_sort(out.begin(), out.end(), [&](const RankedModel& a, const RankedModel& b) {
    const double ka = key(a), kb = key(b);
    if (ka != kb) return ka < kb;
    return parameterCount(kindsOf(a.fit.model)) < parameterCount(kindsOf(b.fit.model));
  });
  // A pick with a term the data cannot see yields to the structure without it.
  std::string dropped;
  for (int pass = 0; pass < 8; ++pass) {
    const Model& bm = out.front().fit.model;
    const std::vector<bool> neg = negligibleTerms(bm, wv);
    const auto bk = kindsOf(bm);
    std::size_t swap_to = 0;
    ProcessKind gone{};
    for (std::size_t q = 1; q < out.size() && swap_to == 0; ++q) {
      ProcessKind extra{};
      if (!oneLess(kindsOf(out[q].fit.model), bk, &extra)) continue;
      for (std::size_t i = 0; i < bm.terms.size(); ++i)
        if (neg[i] && bm.terms[i].kind == extra) {
          swap_to = q;
          gone = extra;
          break;
        }
    }
    if (swap_to == 0) break;
    dropped += std::string(dropped.empty() ? "" : ", ") + stochastic::formatStructure(bk) + " -> " +
               stochastic::formatStructure(kindsOf(out[swap_to].fit.model)) + " (its " +
               stochastic::kindName(gone) + " is negligible)";
    RankedModel r = out[swap_to];
    out.erase(out.begin() + static_cast<std::ptrdiff_t>(swap_to));
    out.insert(out.begin(), r);
  }
  if (opt.bootstrap > 0) {
    // Bootstrap intervals for the selected model only.
    FitOptions o = opt;
    o.warm_starts = {out.front().fit.model};
    const double crit = out.front().criterion, opt0 = out.front().optimism;
    out.front().fit = fit(kindsOf(out.front().fit.model), wv, o);
    out.front().optimism = opt0;
    out.front().criterion = crit;
  }
  if (why) {
    const RankedModel& b = out.front();
    const auto bk = kindsOf(b.fit.model);
    std::ostringstream os;
    os << "picked " << stochastic::formatStructure(bk) << ": criterion " << formatNumber(b.criterion, 4)
       << " (objective " << formatNumber(b.fit.objective, 4) << " + optimism " << formatNumber(b.optimism, 4) << ")";
    if (!dropped.empty())
      os << " [preferred over a lower criterion with a term below " << formatNumber(kNegligibleFraction, 4)
         << " of the WV's 95 % CI width at every scale: " << dropped << "]";
    // Best simpler neighbour (one term less) and best richer one (one term more).
    for (const auto& r : out) {
      ProcessKind extra{};
      const auto rk = kindsOf(r.fit.model);
      if (oneLess(rk, bk, &extra)) {
        os << "; without " << stochastic::kindName(extra) << " (" << stochastic::formatStructure(rk)
           << ") the criterion is " << formatNumber(r.criterion, 4) << ": the objective rises by "
           << formatNumber(r.fit.objective - b.fit.objective, 4) << " while the optimism falls only by "
           << formatNumber(b.optimism - r.optimism, 4);
        break;
      }
    }
    // Richer neighbour: the one-term-larger structure that lowers the objective most.
    const RankedModel* rich = nullptr;
    ProcessKind rich_extra{};
    for (const auto& r : out) {
      ProcessKind extra{};
      if (oneLess(bk, kindsOf(r.fit.model), &extra) &&
          (!rich || r.fit.objective < rich->fit.objective)) {
        rich = &r;
        rich_extra = extra;
      }
    }
    if (rich && b.fit.objective - rich->fit.objective > 1e-9 * b.fit.objective)
      os << "; adding " << stochastic::kindName(rich_extra) << " ("
         << stochastic::formatStructure(kindsOf(rich->fit.model)) << ") lowers the objective by "
         << formatNumber(b.fit.objective - rich->fit.objective, 4) << " but costs " << formatNumber(rich->optimism - b.optimism, 4)
         << " in optimism (criterion " << formatNumber(rich->criterion, 4) << ")";
    else if (rich)
      os << "; no added term lowers the objective";
    // Runner-up: the best candidate with a different criterion value.
    for (std::size_t q = 1; q < out.size(); ++q)
      if (key(out[q]) != key(b)) {
        os << "; runner-up " << stochastic::formatStructure(kindsOf(out[q].fit.model)) << " at "
           << formatNumber(out[q].criterion, 4);
        break;
      }
    *why = os.str();
  }
  return out;
}

}  // namespace navimpact::gmwm
