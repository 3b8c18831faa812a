// Level shifts against a stochastic explanation by an exact likelihood ratio
// (see step_test.hpp).
#include "navimpact/detect/step_test.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Core>
#include <boost/math/distributions/chi_squared.hpp>

#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"

namespace navimpact::detect {

namespace {

/// Block means of the regressors: the mean, a trend (when the model drifts)
/// and one column per shift, 0 before and 1 after sample @p at (a fraction
/// in the block that contains it).
Eigen::MatrixXd regressors(std::size_t nb, std::size_t b, std::size_t n, bool trend,
                           const std::vector<std::size_t>& shifts_at) {
  const int p = 1 + (trend ? 1 : 0) + static_cast<int>(shifts_at.size());
  Eigen::MatrixXd X(static_cast<Eigen::Index>(nb), p);
  const double bd = static_cast<double>(b), nd = static_cast<double>(n);
  for (std::size_t k = 0; k < nb; ++k) {
    const auto r = static_cast<Eigen::Index>(k);
    int c = 0;
    X(r, c++) = 1.0;
    if (trend) X(r, c++) = (static_cast<double>(k) * bd + 0.5 * (bd - 1.0) - 0.5 * nd) / nd;
    for (std::size_t at : shifts_at) {
      const std::size_t a = k * b, e = a + b;
      X(r, c++) = at <= a ? 1.0 : (at >= e ? 0.0 : static_cast<double>(e - at) / bd);
    }
  }
  return X;
}

}  // namespace

StepTestResult testLevelShifts(const std::vector<double>& x, const stochastic::Model& m,
                               const std::vector<std::size_t>& candidates, double alpha,
                               const StepTestOptions& opt) {
  if (!(alpha > 0 && alpha < 1)) throw Error("testLevelShifts: alpha must be in (0, 1)");
  const std::size_t n = x.size();
  if (n < 8) throw Error("testLevelShifts: need at least 8 samples");
  StepTestResult res;
  res.block = std::max<std::size_t>(1, n / std::max<std::size_t>(4, opt.target_blocks));
  const std::vector<double> y = stochastic::blockMeans(x.data(), n, res.block);
  const std::size_t nb = y.size(), b = res.block, used = nb * b;
  res.blocks = nb;
  const bool trend = m.count(stochastic::ProcessKind::DR) > 0;
  const double boundaries = static_cast<double>(nb - 1);
  const boost::math::chi_squared chi1(1.0);

  std::vector<std::size_t> acc_boundary;  // accepted shifts, snapped (for the tests)
  std::vector<std::size_t> acc_index;     // and at their sample indices (for the sizes)
  stochastic::Model m0 = m;
  if (opt.add_random_walk && opt.profile_variances && nb >= 3) {
    // Start: every increment of the block means a random walk's (an upper
    // bound); the profile scales it down as far as the data ask. A random walk
    // of the model below that bound starts there too: the profile searches
    // e^-12..e^4 around its start, so a negligible one (a fit's gamma = 1e-65)
    // could never grow to what the data ask, and a slow wander would be taken
    // for shifts.
    double dm = 0, v = 0;
    for (std::size_t k = 1; k < nb; ++k) dm += y[k] - y[k - 1];
    dm /= static_cast<double>(nb - 1);  // a drift's share of the increments
    for (std::size_t k = 1; k < nb; ++k) v += (y[k] - y[k - 1] - dm) * (y[k] - y[k - 1] - dm);
    v /= static_cast<double>(nb - 1);
    const double gamma_bound = std::sqrt(v / static_cast<double>(b));
    bool has_rw = false;
    for (auto& p : m0.terms)
      if (p.kind == stochastic::ProcessKind::RW) {
        has_rw = true;
        if (v > 0 && !(p.gamma >= gamma_bound)) p.gamma = gamma_bound;
      }
    if (!has_rw && v > 0) m0.terms.push_back(stochastic::Process::rw(gamma_bound));
  }
  auto loglik = [&](stochastic::Model& mm, const Eigen::MatrixXd& X) {
    return opt.profile_variances ? stochastic::profileBlockLogLikelihood(mm, y, b, X) : stochastic::blockLogLikelihood(mm, y, b, X).loglik;
  };
  double l0 = loglik(m0, regressors(nb, b, used, trend, {}));
  stochastic::Model m_acc = m0;  // the noise model given the shifts accepted so far
  // Forward selection: every candidate not yet accepted is tested given the
  // accepted ones; the strongest is accepted when significant, until none is.
  res.tests.resize(candidates.size());
  std::vector<bool> open(candidates.size(), false);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    StepTest& t = res.tests[i];
    t.index = candidates[i];
    t.boundary = static_cast<std::size_t>(std::llround(static_cast<double>(t.index) / static_cast<double>(b)));
    open[i] = t.boundary >= 1 && t.boundary + 1 <= nb;  // not at the record's ends
  }
  std::vector<std::size_t> order;  // accepted candidates, in acceptance order
  for (;;) {
    std::vector<std::size_t> snapped_acc;
    for (std::size_t i : order) snapped_acc.push_back(res.tests[i].boundary * b);
    int best = -1;
    double best_l1 = -std::numeric_limits<double>::infinity();
    stochastic::Model best_m1;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (!open[i]) continue;
      StepTest& t = res.tests[i];
      bool dup = false;
      for (std::size_t j : order) dup = dup || res.tests[j].boundary == t.boundary;
      if (dup) {  // on an accepted shift: nothing to test
        open[i] = false;
        t.lr = 0;
        t.p_value = 1;
        continue;
      }
      std::vector<std::size_t> with = snapped_acc;
      with.push_back(t.boundary * b);
      stochastic::Model m1 = m_acc;
      double l1;
      try {
        l1 = loglik(m1, regressors(nb, b, used, trend, with));
      } catch (const Error&) {  // collinear with the trend
        open[i] = false;
        continue;
      }
      t.lr = std::max(0.0, 2.0 * (l1 - l0));
      t.p_value = std::min(1.0, boundaries * boost::math::cdf(boost::math::complement(chi1, t.lr)));
      if (l1 > best_l1) {
        best_l1 = l1;
        best = static_cast<int>(i);
        best_m1 = m1;
      }
    }
    if (best < 0) break;
    {
      // The null again, started from the alternative's variances: both sides
      // at their best, so that the statistic measures the shift and not the
      // search.
      stochastic::Model m0b = best_m1;
      const double l0b = loglik(m0b, regressors(nb, b, used, trend, snapped_acc));
      if (l0b > l0) {
        l0 = l0b;
        m_acc = m0b;
      }
      StepTest& t = res.tests[static_cast<std::size_t>(best)];
      t.lr = std::max(0.0, 2.0 * (best_l1 - l0));
      t.p_value = std::min(1.0, boundaries * boost::math::cdf(boost::math::complement(chi1, t.lr)));
    }
    StepTest& t = res.tests[static_cast<std::size_t>(best)];
    if (!(t.p_value < alpha)) break;
    t.accepted = true;
    open[static_cast<std::size_t>(best)] = false;
    order.push_back(static_cast<std::size_t>(best));
    acc_boundary.push_back(t.boundary);
    acc_index.push_back(std::min(t.index, used));
    l0 = best_l1;
    m_acc = best_m1;
  }
  if (!acc_index.empty()) {
    const int first = 1 + (trend ? 1 : 0);
    std::vector<double> sz, se;
    try {
      // Sized at their sample indices, the variances profiled again there:
      // the tests' snapped regressors leave the block that holds a shift
      // misfit, and a random walk of the null takes that up (a 142x shift
      // came out 1 % small, 18 of its inflated standard errors, and the
      // rest was named a random walk).
      const Eigen::MatrixXd X = regressors(nb, b, used, trend, acc_index);
      if (opt.profile_variances) {
        // From the tests' noise model and from the one given (the tests'
        // profile can end in a corner: white noise gone, a random walk
        // carrying every block's noise); the better.
        double best_l = stochastic::blockLogLikelihood(m_acc, y, b, X).loglik;
        for (const stochastic::Model& start : {m_acc, m}) {
          stochastic::Model mf = start;
          const double l = stochastic::profileBlockLogLikelihood(mf, y, b, X);
          if (l > best_l) {
            best_l = l;
            m_acc = mf;
          }
        }
      }
      const auto fit = stochastic::blockLogLikelihood(m_acc, y, b, X);
      for (std::size_t i = 0; i < acc_index.size(); ++i) {
        const auto j = static_cast<Eigen::Index>(first + static_cast<int>(i));
        sz.push_back(fit.beta(j));
        se.push_back(std::sqrt(std::max(0.0, fit.beta_cov(j, j))));
      }
    } catch (const Error&) {  // exact indices collinear (two shifts in one block): snapped ones
      std::vector<std::size_t> s(acc_boundary.size());
      for (std::size_t i = 0; i < s.size(); ++i) s[i] = acc_boundary[i] * b;
      const auto fit = stochastic::blockLogLikelihood(m_acc, y, b, regressors(nb, b, used, trend, s));
      for (std::size_t i = 0; i < s.size(); ++i) {
        const auto j = static_cast<Eigen::Index>(first + static_cast<int>(i));
        sz.push_back(fit.beta(j));
        se.push_back(std::sqrt(std::max(0.0, fit.beta_cov(j, j))));
      }
    }
    for (std::size_t q = 0; q < order.size(); ++q) {
      res.tests[order[q]].size = sz[q];
      res.tests[order[q]].size_se = se[q];
    }
  }
  res.model = m_acc;
  return res;
}

}  // namespace navimpact::detect
