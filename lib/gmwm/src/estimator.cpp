// GMWM estimator (Guerrier et al. 2013): minimise
//   (nu_hat - nu(theta))' Omega (nu_hat - nu(theta)),  Omega = diag(1/(CI_hi - CI_lo)^2)
// with Ceres (Levenberg-Marquardt, autodiff Jacobians) over a transformed
// parameter vector (fit_internal.hpp), from deterministic multi-start points.
//
// Starting values (gmwm_formulas.md §5 describes the R package's random
// search; this is a deterministic replacement): the model WV is LINEAR in the
// variance-like parameters (sigma^2, Q^2, gamma^2, omega^2, GM stationary
// variance, SIN amp^2) once the GM correlation times (and SIN frequencies) are
// fixed. So every placement of the GM T's on a log2 grid spanning the scale
// range (one grid point per octave, from tau_1/4 to 2 tau_J) is scored by a
// non-negative least-squares fit of the amplitudes (variable projection),
// both on R's unweighted relative criterion sum (1 - nu_j/nu_hat_j)^2 and on
// the weighted objective. The best placements of each are polished by Ceres
// (the relative ones first on the relative criterion, as R does), then
// minimised on the weighted objective; the lowest objective wins.
#include "navimpact/gmwm/estimator.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "fit_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::gmwm {

using stochastic::Model;
using stochastic::Process;
using stochastic::ProcessKind;

namespace detail {

Model toModel(const Layout& L, const Eigen::VectorXd& th, double rate_hz) {
  Model m;
  m.rate_hz = rate_hz;
  for (std::size_t i = 0; i < L.kinds.size(); ++i) {
    const double* t = th.data() + L.offset[i];
    switch (L.kinds[i]) {
      case ProcessKind::WN: m.terms.push_back(Process::wn(std::exp(t[0]))); break;
      case ProcessKind::QN: m.terms.push_back(Process::qn(std::exp(t[0]))); break;
      case ProcessKind::RW: m.terms.push_back(Process::rw(std::exp(t[0]))); break;
      case ProcessKind::DR: m.terms.push_back(Process::dr(std::exp(t[0]))); break;
      case ProcessKind::GM: m.terms.push_back(Process::gm(std::exp(t[0]), std::exp(t[1]) / rate_hz)); break;
      case ProcessKind::SIN:
        m.terms.push_back(Process::sin(std::exp(t[0]), std::exp(t[1]) * rate_hz));
        break;
    }
  }
  return m;
}

Eigen::VectorXd fromModel(const Layout& L, const Model& m) {
  Eigen::VectorXd th(L.p);
  for (std::size_t i = 0; i < L.kinds.size(); ++i) {
    const Process& q = m.terms.at(i);
    double* t = th.data() + L.offset[i];
    switch (L.kinds[i]) {
      case ProcessKind::WN: t[0] = std::log(q.sigma); break;
      case ProcessKind::QN: t[0] = std::log(q.Q); break;
      case ProcessKind::RW: t[0] = std::log(q.gamma); break;
      case ProcessKind::DR: t[0] = std::log(std::fabs(q.omega)); break;
      case ProcessKind::GM:
        t[0] = std::log(q.sigma);
        t[1] = std::log(q.T * m.rate_hz);
        break;
      case ProcessKind::SIN:
        t[0] = std::log(q.amp);
        t[1] = std::log(q.freq_hz / m.rate_hz);
        break;
    }
  }
  return th;
}

using Jet = ceres::Jet<double, kMaxParams>;

Eigen::MatrixXd jacobian(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau) {
  std::vector<Jet> x(L.p);
  for (int k = 0; k < L.p; ++k) x[k] = Jet(th[k], k);
  std::vector<Jet> nu(tau.size());
  modelWv(L, x.data(), tau, nu.data());
  Eigen::MatrixXd A(tau.size(), L.p);
  for (Eigen::Index j = 0; j < tau.size(); ++j)
    for (int k = 0; k < L.p; ++k) A(j, k) = nu[j].v[k];
  return A;
}

Eigen::VectorXd wvOf(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau) {
  Eigen::VectorXd nu(tau.size());
  modelWv(L, th.data(), tau, nu.data());
  return nu;
}

Eigen::MatrixXd pinvSym(const Eigen::MatrixXd& M) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (M + M.transpose()));
  const Eigen::VectorXd ev = es.eigenvalues();
  const double tol = 1e-12 * std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
  Eigen::VectorXd inv(ev.size());
  for (Eigen::Index i = 0; i < ev.size(); ++i) inv[i] = std::fabs(ev[i]) > tol ? 1.0 / ev[i] : 0.0;
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace detail

namespace {

using detail::Jet;
using detail::kMaxParams;
using detail::Layout;
using detail::pinvSym;

/**
 * Weights of the objective: residuals r = diag(d) (nu_hat - nu) or, when the
 * matrix m is set (Efficient weighting), r = m (nu_hat - nu) with m'm = Omega.
 */
struct Weights {
  Eigen::VectorXd d;
  Eigen::MatrixXd m;
  Weights(const Eigen::VectorXd& diag) : d(diag) {}  // NOLINT: implicit on purpose
  Weights(const Eigen::VectorXd& diag, const Eigen::MatrixXd& full) : d(diag), m(full) {}
  bool full() const { return m.size() > 0; }
  Eigen::VectorXd apply(const Eigen::VectorXd& e) const { return full() ? Eigen::VectorXd(m * e) : Eigen::VectorXd(d.cwiseProduct(e)); }
};

/// Residuals r = W (nu_hat - nu(theta)), Jacobian by forward-mode autodiff.
class WvCost final : public ceres::CostFunction {
 public:
  WvCost(const Layout& L, const Eigen::VectorXd& tau, const Eigen::VectorXd& nu_hat, const Weights& w)
      : L_(L), tau_(tau), nu_hat_(nu_hat), w_(w) {
    set_num_residuals(static_cast<int>(tau.size()));
    mutable_parameter_block_sizes()->push_back(L.p);
  }
  bool Evaluate(double const* const* params, double* res, double** jac) const override {
    const double* th = params[0];
    const Eigen::Index J = tau_.size();
    if (w_.full()) {
      // r = W e, dr/dtheta = -W dnu/dtheta.
      Eigen::VectorXd e(J);
      Eigen::MatrixXd de(J, L_.p);
      if (jac == nullptr || jac[0] == nullptr) {
        std::vector<double> nu(J);
        detail::modelWv(L_, th, tau_, nu.data());
        for (Eigen::Index j = 0; j < J; ++j) e[j] = nu_hat_[j] - nu[j];
      } else {
        std::vector<Jet> x(L_.p), nu(J);
        for (int k = 0; k < L_.p; ++k) x[k] = Jet(th[k], k);
        detail::modelWv(L_, x.data(), tau_, nu.data());
        for (Eigen::Index j = 0; j < J; ++j) {
          e[j] = nu_hat_[j] - nu[j].a;
          for (int k = 0; k < L_.p; ++k) de(j, k) = -nu[j].v[k];
        }
        const Eigen::MatrixXd dr = w_.m * de;
        for (Eigen::Index j = 0; j < J; ++j)
          for (int k = 0; k < L_.p; ++k) jac[0][j * L_.p + k] = dr(j, k);
      }
      const Eigen::VectorXd r = w_.m * e;
      for (Eigen::Index j = 0; j < J; ++j) res[j] = r[j];
    } else if (jac == nullptr || jac[0] == nullptr) {
      std::vector<double> nu(J);
      detail::modelWv(L_, th, tau_, nu.data());
      for (Eigen::Index j = 0; j < J; ++j) res[j] = w_.d[j] * (nu_hat_[j] - nu[j]);
    } else {
      std::vector<Jet> x(L_.p), nu(J);
      for (int k = 0; k < L_.p; ++k) x[k] = Jet(th[k], k);
      detail::modelWv(L_, x.data(), tau_, nu.data());
      for (Eigen::Index j = 0; j < J; ++j) {
        res[j] = w_.d[j] * (nu_hat_[j] - nu[j].a);
        for (int k = 0; k < L_.p; ++k) jac[0][j * L_.p + k] = -w_.d[j] * nu[j].v[k];
      }
    }
    for (Eigen::Index j = 0; j < J; ++j)
      if (!std::isfinite(res[j])) return false;
    return true;
  }

 private:
  const Layout& L_;
  const Eigen::VectorXd& tau_;
  const Eigen::VectorXd& nu_hat_;
  const Weights& w_;
};

/// Everything one fit needs about the data.
struct Data {
  Eigen::VectorXd tau, nu_hat, w_rel, w_obj, omega, eta;
  Eigen::VectorXd ci_w;  ///< width of the empirical WV's 95 % CI per scale (redundancy checks)
  /// Efficient weighting: W with W'W = Omega (empty otherwise: diagonal w_obj).
  Eigen::MatrixXd w_full;
  double rate = 0;
  double n = 0;
  double eff = 1.0;  ///< WaveletVariance::eff: Var(nu_hat_j) = 2 nu_j^2 / (eta_j eff)
  int J = 0;
};

Data makeData(const WaveletVariance& wv) {
  Data d;
  d.J = wv.scales();
  if (d.J < 1) throw Error("GMWM fit: the wavelet variance has no scales");
  if (!(wv.rate_hz > 0.0)) throw Error("GMWM fit: the wavelet variance has no sampling rate");
  if (wv.wv.size() != d.J || wv.ci_low.size() != d.J || wv.ci_high.size() != d.J)
    throw Error("GMWM fit: wavelet variance vectors of different lengths");
  for (int j = 0; j < d.J; ++j)
    if (!(wv.wv[j] > 0.0) || !std::isfinite(wv.wv[j]) || !(wv.ci_high[j] > wv.ci_low[j]))
      throw Error("GMWM fit: wavelet variance at scale " + std::to_string(j + 1) +
                  " is not positive and finite or has an empty confidence interval");
  d.tau = wv.tau;
  d.nu_hat = wv.wv;
  d.w_rel = wv.wv.cwiseInverse();
  d.ci_w = wv.ci_high - wv.ci_low;
  d.omega = wv.weights();
  d.w_obj = d.omega.cwiseSqrt();
  d.rate = wv.rate_hz;
  if (!(wv.eff > 0.0 && wv.eff <= 1.0)) throw Error("GMWM fit: the wavelet variance's efficiency is not in (0, 1]");
  d.eff = wv.eff;
  d.n = wv.n > 0 ? double(wv.n) : std::pow(2.0, d.J + 1);
  d.eta.resize(d.J);
  for (int j = 0; j < d.J; ++j)
    d.eta[j] = (wv.eta.size() == d.J && wv.eta[j] > 0) ? wv.eta[j] : std::max((d.n - d.tau[j] + 1) / d.tau[j], 1.0);
  return d;
}

/// Weights of the objective (diagonal, or the full efficient matrix when set).
Weights objW(const Data& d) { return d.w_full.size() ? Weights(d.w_obj, d.w_full) : Weights(d.w_obj); }

double criterion(const Layout& L, const Eigen::VectorXd& th, const Data& d, const Weights& w) {
  const Eigen::VectorXd nu = detail::wvOf(L, th, d.tau);
  const double s = w.apply(d.nu_hat - nu).squaredNorm();
  return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
}

// Bounds of the transformed parameters: log amplitudes within +-150 (no
// overflow of exp(2 x)); GM T between 0.05 samples (white) and 1000 records
// (indistinguishable from a random walk); SIN below Nyquist.
void setBounds(ceres::Problem& pb, double* x, const Layout& L, const Data& d) {
  for (std::size_t i = 0; i < L.kinds.size(); ++i) {
    const int o = L.offset[i];
    pb.SetParameterLowerBound(x, o, -150.0);
    pb.SetParameterUpperBound(x, o, 150.0);
    if (L.kinds[i] == ProcessKind::GM) {
      pb.SetParameterLowerBound(x, o + 1, std::log(0.05));
      pb.SetParameterUpperBound(x, o + 1, std::log(1000.0 * d.n));
    } else if (L.kinds[i] == ProcessKind::SIN) {
      pb.SetParameterLowerBound(x, o + 1, std::log(1.0 / (1000.0 * d.n)));
      pb.SetParameterUpperBound(x, o + 1, std::log(0.499));
    }
  }
}

void clampToBounds(Eigen::VectorXd& th, const Layout& L, const Data& d) {
  for (std::size_t i = 0; i < L.kinds.size(); ++i) {
    const int o = L.offset[i];
    th[o] = std::clamp(th[o], -150.0, 150.0);
    if (L.kinds[i] == ProcessKind::GM)
      th[o + 1] = std::clamp(th[o + 1], std::log(0.05), std::log(1000.0 * d.n));
    else if (L.kinds[i] == ProcessKind::SIN)
      th[o + 1] = std::clamp(th[o + 1], std::log(1.0 / (1000.0 * d.n)), std::log(0.499));
  }
}

/// Minimise sum (w_j (nu_hat_j - nu_j))^2 from @p th (in place); returns the criterion.
double solve(const Layout& L, Eigen::VectorXd& th, const Data& d, const Weights& w,
             bool* converged = nullptr, int fixed = -1,
             const std::vector<std::pair<double, double>>* bands = nullptr) {
  // Ceres reports through glog; library code prints nothing, so its messages
  // below FATAL (line-search or bound warnings) are dropped, once per process.
  static const bool quiet_glog = [] {
    FLAGS_minloglevel = google::GLOG_FATAL;
    FLAGS_stderrthreshold = google::GLOG_FATAL;
    return true;
  }();
  (void)quiet_glog;
  clampToBounds(th, L, d);
  if (bands)
    for (int k = 0; k < L.p; ++k) th[k] = std::clamp(th[k], (*bands)[k].first, (*bands)[k].second);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem pb(po);
  pb.AddResidualBlock(new WvCost(L, d.tau, d.nu_hat, w), nullptr, th.data());
  setBounds(pb, th.data(), L, d);
  if (bands)
    for (int k = 0; k < L.p; ++k)
      if (std::isfinite((*bands)[k].first)) {
        pb.SetParameterLowerBound(th.data(), k, (*bands)[k].first);
        pb.SetParameterUpperBound(th.data(), k, (*bands)[k].second);
      }
  if (fixed >= 0) {
    if (L.p == 1) return criterion(L, th, d, w);
    pb.SetManifold(th.data(), new ceres::SubsetManifold(L.p, {fixed}));
  }
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 400;
  so.function_tolerance = 1e-13;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-12;
  so.logging_type = ceres::SILENT;
  // Bound-constrained steps use a projected line search; bisection avoids
  // polynomial interpolation (and its warnings) on flat directions.
  so.line_search_interpolation_type = ceres::BISECTION;
  so.minimizer_progress_to_stdout = false;
  so.num_threads = 1;
  ceres::Solver::Summary sum;
  ceres::Solve(so, &pb, &sum);
  if (converged) *converged = sum.termination_type == ceres::CONVERGENCE;
  return criterion(L, th, d, w);
}

/// Unit-amplitude WV profile of term i at the nonlinear parameters in th (amplitude param = 0).
Eigen::VectorXd unitProfile(const Layout& L, int i, const Eigen::VectorXd& th, const Data& d) {
  double t[2] = {0.0, 0.0};
  if (detail::paramCount(L.kinds[i]) == 2) t[1] = th[L.offset[i] + 1];
  Eigen::VectorXd prof(d.J);
  for (int j = 0; j < d.J; ++j) prof[j] = detail::termWv(L.kinds[i], t, d.tau[j]);
  return prof;
}

/**
 * Non-negative least squares for the amplitudes (variances) a >= 0 of the
 * columns of P: min || diag(w) (nu_hat - P a) ||^2 (Lawson-Hanson active set).
 * Zero amplitudes become negligible ones (at most 1e-3 of nu_hat at any scale).
 * Writes log amplitudes (0.5 log a) into th; returns the criterion.
 */
double nnlsAmplitudes(const Layout& L, Eigen::VectorXd& th, const Data& d, const Weights& w) {
  const int m = static_cast<int>(L.kinds.size());
  Eigen::MatrixXd A(d.J, m);
  for (int i = 0; i < m; ++i) A.col(i) = w.apply(unitProfile(L, i, th, d));
  const Eigen::VectorXd y = w.apply(d.nu_hat);
  Eigen::VectorXd scale(m);
  for (int i = 0; i < m; ++i) {
    scale[i] = A.col(i).norm();
    if (!(scale[i] > 0) || !std::isfinite(scale[i])) scale[i] = 1.0;
    A.col(i) /= scale[i];
  }
  const Eigen::MatrixXd G = A.transpose() * A;
  const Eigen::VectorXd b = A.transpose() * y;
  const double yy = y.squaredNorm();
  // Lawson & Hanson (1974) active-set NNLS on the normal equations (m <= 10 columns).
  auto solvePassive = [&](const std::vector<bool>& P, Eigen::VectorXd& z) {
    std::vector<int> idx;
    for (int i = 0; i < m; ++i)
      if (P[i]) idx.push_back(i);
    const int s = static_cast<int>(idx.size());
    Eigen::MatrixXd Gs(s, s);
    Eigen::VectorXd bs(s);
    for (int r = 0; r < s; ++r) {
      bs[r] = b[idx[r]];
      for (int c = 0; c < s; ++c) Gs(r, c) = G(idx[r], idx[c]);
    }
    Gs.diagonal().array() += 1e-12;
    const Eigen::VectorXd zs = Gs.ldlt().solve(bs);
    z.setZero(m);
    for (int r = 0; r < s; ++r) z[idx[r]] = zs[r];
  };
  Eigen::VectorXd best = Eigen::VectorXd::Zero(m), z;
  std::vector<bool> P(m, false);
  for (int outer = 0; outer < 3 * m + 3; ++outer) {
    const Eigen::VectorXd grad = b - G * best;
    int jmax = -1;
    for (int i = 0; i < m; ++i)
      if (!P[i] && grad[i] > 1e-12 * std::sqrt(yy) && (jmax < 0 || grad[i] > grad[jmax])) jmax = i;
    if (jmax < 0) break;
    P[jmax] = true;
    for (int inner = 0; inner < 3 * m + 3; ++inner) {
      solvePassive(P, z);
      bool ok = true;
      for (int i = 0; i < m; ++i)
        if (P[i] && !(z[i] > 0.0)) ok = false;
      if (ok) {
        best = z;
        break;
      }
      double alpha = 1.0;
      for (int i = 0; i < m; ++i)
        if (P[i] && !(z[i] > 0.0)) alpha = std::min(alpha, best[i] / (best[i] - z[i]));
      best += alpha * (z - best);
      for (int i = 0; i < m; ++i)
        if (P[i] && best[i] <= 1e-300) {
          P[i] = false;
          best[i] = 0.0;
        }
    }
  }
  const double best_v = yy - 2.0 * best.dot(b) + best.dot(G * best);
  for (int i = 0; i < m; ++i) {
    double amp = best[i] / scale[i];  // variance-like amplitude
    if (!(amp > 0.0)) {
      // Negligible: at most 1e-3 of nu_hat at every scale.
      const Eigen::VectorXd prof = unitProfile(L, i, th, d);
      double mx = 0;
      for (int j = 0; j < d.J; ++j) mx = std::max(mx, prof[j] / d.nu_hat[j]);
      amp = mx > 0 ? 1e-3 / mx : 1e-30;
    }
    th[L.offset[i]] = 0.5 * std::log(amp);
  }
  return std::max(best_v, 0.0);
}

/// Log2 grid of GM correlation times [samples]: one point per octave, tau_1/4 .. 2 tau_J.
std::vector<double> gmGrid(const Data& d) {
  std::vector<double> g;
  for (int i = -1; i <= d.J + 1; ++i) g.push_back(std::log(std::ldexp(1.0, i)));
  return g;
}

/// SIN frequency grid [cycles/sample]: peak of the Haar response at tau = 1/f.
std::vector<double> sinGrid(const Data& d) {
  std::vector<double> g;
  for (int j = 0; j < d.J; ++j) g.push_back(std::log(std::min(0.45, 1.0 / d.tau[j])));
  return g;
}

struct Start {
  Eigen::VectorXd th;
  double score;
};

void keepBest(std::vector<Start>& best, Start s, std::size_t k) {
  if (!std::isfinite(s.score)) return;
  if (best.size() < k || s.score < best.back().score) {
    best.push_back(std::move(s));
    std::sort(best.begin(), best.end(), [](const Start& a, const Start& b) { return a.score < b.score; });
    if (best.size() > k) best.pop_back();
  }
}

/// Enumerate placements of the nonlinear parameters (GM T increasing along
/// the grid, SIN frequencies likewise) and call f(th) for each.
template <typename F>
void forEachPlacement(const Layout& L, const Data& d, F&& f) {
  std::vector<int> nl;  // terms with a nonlinear parameter
  for (std::size_t i = 0; i < L.kinds.size(); ++i)
    if (detail::paramCount(L.kinds[i]) == 2) nl.push_back(static_cast<int>(i));
  const std::vector<double> gg = gmGrid(d), sg = sinGrid(d);
  Eigen::VectorXd th = Eigen::VectorXd::Zero(L.p);
  // Recursive enumeration; same-kind terms take strictly increasing grid indices.
  std::function<void(std::size_t, int, int)> rec = [&](std::size_t k, int min_gm, int min_sin) {
    if (k == nl.size()) {
      f(th);
      return;
    }
    const int i = nl[k];
    const bool gm = L.kinds[i] == ProcessKind::GM;
    const std::vector<double>& g = gm ? gg : sg;
    for (int q = gm ? min_gm : min_sin; q < static_cast<int>(g.size()); ++q) {
      th[L.offset[i] + 1] = g[q];
      rec(k + 1, gm ? q + 1 : min_gm, gm ? min_sin : q + 1);
    }
  };
  rec(0, 0, 0);
}

/// GM terms sorted by T (ascending), SIN by frequency; other terms keep their place.
void sortTerms(const Layout& L, Eigen::VectorXd& th) {
  for (ProcessKind k : {ProcessKind::GM, ProcessKind::SIN}) {
    std::vector<int> idx;
    for (std::size_t i = 0; i < L.kinds.size(); ++i)
      if (L.kinds[i] == k) idx.push_back(L.offset[i]);
    std::vector<std::pair<double, double>> v;
    for (int o : idx) v.emplace_back(th[o + 1], th[o]);
    std::sort(v.begin(), v.end());
    for (std::size_t q = 0; q < idx.size(); ++q) {
      th[idx[q]] = v[q].second;
      th[idx[q] + 1] = v[q].first;
    }
  }
}

/// Starting points derived from a warm-start model (a sub-structure or the same structure).
std::vector<Eigen::VectorXd> warmStarts(const Layout& L, const Model& warm, const Data& d) {
  std::vector<Eigen::VectorXd> out;
  if (warm.rate_hz > 0 && std::fabs(warm.rate_hz - d.rate) > 1e-9 * d.rate) return out;
  Eigen::VectorXd th = Eigen::VectorXd::Zero(L.p);
  std::vector<bool> used(warm.terms.size(), false);
  std::vector<int> fresh;  // structure terms without a counterpart in warm
  for (std::size_t i = 0; i < L.kinds.size(); ++i) {
    int hit = -1;
    for (std::size_t q = 0; q < warm.terms.size(); ++q)
      if (!used[q] && warm.terms[q].kind == L.kinds[i]) {
        hit = static_cast<int>(q);
        break;
      }
    if (hit < 0) {
      fresh.push_back(static_cast<int>(i));
      continue;
    }
    used[hit] = true;
    Layout one({L.kinds[i]});
    Model mm;
    mm.rate_hz = d.rate;
    mm.terms = {warm.terms[hit]};
    const Eigen::VectorXd t = detail::fromModel(one, mm);
    th.segment(L.offset[i], t.size()) = t;
  }
  if (std::count(used.begin(), used.end(), false) > 0) return out;  // warm is not a sub-structure
  for (double v : th)
    if (!std::isfinite(v)) return out;
  // Negligible new terms (at most 1e-6 of nu_hat at any scale), GM T mid-range:
  // the objective starts at the warm start's value up to 1e-6.
  auto negligible = [&](Eigen::VectorXd& t, int i) {
    const Eigen::VectorXd prof = unitProfile(L, i, t, d);
    double mx = 0;
    for (int j = 0; j < d.J; ++j) mx = std::max(mx, prof[j] / d.nu_hat[j]);
    t[L.offset[i]] = 0.5 * std::log(mx > 0 ? 1e-6 / mx : 1e-30);
  };
  for (int i : fresh) {
    if (L.kinds[i] == ProcessKind::GM) th[L.offset[i] + 1] = std::log(std::sqrt(d.tau[0] * d.tau[d.J - 1]));
    if (L.kinds[i] == ProcessKind::SIN) th[L.offset[i] + 1] = std::log(0.25);
    negligible(th, i);
  }
  out.push_back(th);
  if (fresh.empty()) return out;
  // New terms placed in the largest residual gap: amplitudes of the new terms
  // only, by NNLS on the weighted residual, with every GM T of the new terms
  // on the grid (the warm terms keep their values).
  const Eigen::VectorXd resid = d.nu_hat - detail::wvOf(L, th, d.tau);
  std::vector<Start> best;
  const std::vector<double> gg = gmGrid(d), sg = sinGrid(d);
  std::function<void(std::size_t, Eigen::VectorXd&)> rec = [&](std::size_t k, Eigen::VectorXd& t) {
    if (k == fresh.size()) {
      const int m = static_cast<int>(fresh.size());
      Eigen::MatrixXd A(d.J, m);
      const Weights W = objW(d);
      for (int c = 0; c < m; ++c) A.col(c) = W.apply(unitProfile(L, fresh[c], t, d));
      const Eigen::VectorXd y = W.apply(resid);
      Eigen::VectorXd a = A.colPivHouseholderQr().solve(y);
      Eigen::VectorXd tt = t;
      for (int c = 0; c < m; ++c) {
        if (a[c] > 0 && std::isfinite(a[c]))
          tt[L.offset[fresh[c]]] = 0.5 * std::log(a[c]);
        else
          negligible(tt, fresh[c]);
      }
      keepBest(best, {tt, criterion(L, tt, d, objW(d))}, 3);
      return;
    }
    const int i = fresh[k];
    if (detail::paramCount(L.kinds[i]) == 1) {
      rec(k + 1, t);
      return;
    }
    const std::vector<double>& g = L.kinds[i] == ProcessKind::GM ? gg : sg;
    for (double v : g) {
      t[L.offset[i] + 1] = v;
      rec(k + 1, t);
    }
  };
  Eigen::VectorXd t = th;
  if (fresh.size() <= 2) rec(0, t);
  for (auto& s : best) out.push_back(s.th);
  return out;
}

// ---------------------------------------------------------------------------
// Two terms that are one. A local minimum of the objective can spend two
// terms on one feature of the WV: two GMs with (nearly) the same T, a GM
// below one sample that is white at the data's precision next to a WN, a GM
// far beyond the record next to a RW, two terms of one kind without a shape
// parameter. Such a point is a saddle for the search (moving the two terms
// apart does not change the objective to first order), so Levenberg-Marquardt
// stays there although the structure could describe more of the WV. The fit
// merges the pair into one term (same WV up to the merge's approximation),
// frees the other one and restarts with the freed term placed across the
// scale range (warmStarts of the reduced model): the returned solution never
// has such a pair, and its objective is at most the merged point's.
// ---------------------------------------------------------------------------

/// Rules by which two terms are one (see redundantTerms in estimator.hpp).
enum class DupRule { SameKind, GmPair, GmIsWhite, GmIsRandomWalk, SinPair };

struct Duplicate {
  int keep = -1;  ///< term that takes the merged amplitude
  int drop = -1;  ///< term that is freed
  DupRule rule = DupRule::SameKind;
};

/// WV profiles of every term (J x terms) at theta.
Eigen::MatrixXd termProfiles(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau) {
  Eigen::MatrixXd P(tau.size(), static_cast<Eigen::Index>(L.kinds.size()));
  for (std::size_t i = 0; i < L.kinds.size(); ++i)
    for (Eigen::Index j = 0; j < tau.size(); ++j)
      P(j, static_cast<Eigen::Index>(i)) = detail::termWv(L.kinds[i], th.data() + L.offset[i], tau[j]);
  return P;
}

/// True when |a_j - b_j| < fraction * ci_w_j at every scale (the data cannot tell a from b).
bool indistinguishable(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& ci_w,
                       double fraction) {
  for (Eigen::Index j = 0; j < a.size(); ++j)
    if (!(std::fabs(a[j] - b[j]) < fraction * ci_w[j])) return false;
  return true;
}

/// GM stationary variance s2 and phi = exp(-1/T) (T in samples) from transformed parameters.
void gmParams(const double* t, double& s2, double& phi) {
  s2 = std::exp(2.0 * t[0]);
  phi = std::exp(-std::exp(-t[1]));
}

/**
 * Pairs of non-negligible terms of theta that are one (rules in DupRule):
 * same kind without a shape parameter (WN, QN, RW, DR: proportional WVs);
 * two GMs with T within kDuplicateTFactor; two SINs within 1 % in frequency;
 * a GM with T below one sample whose WV is that of a white noise of its
 * long-run variance s2 (1 + phi) / (1 - phi) within @p fraction of the CI
 * width at every scale, when the structure has a WN; a GM whose WV is that
 * of a random walk with gamma^2 = 2 s2 (1 - phi) (its short-lag increments)
 * within the same margin, when the structure has a RW.
 */
std::vector<Duplicate> duplicates(const Layout& L, const Eigen::VectorXd& th, const Eigen::VectorXd& tau,
                                  const Eigen::VectorXd& ci_w, double fraction) {
  const int m = static_cast<int>(L.kinds.size());
  const Eigen::MatrixXd P = termProfiles(L, th, tau);
  std::vector<bool> neg(m, true);
  for (int i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < tau.size() && neg[i]; ++j)
      if (!(P(j, i) < fraction * ci_w[j])) neg[i] = false;
  std::vector<Duplicate> out;
  const double logf = std::log(kDuplicateTFactor);
  for (int a = 0; a < m; ++a) {
    if (neg[a]) continue;
    const ProcessKind ka = L.kinds[a];
    const double* ta = th.data() + L.offset[a];
    for (int b = a + 1; b < m; ++b) {
      if (neg[b]) continue;
      const ProcessKind kb = L.kinds[b];
      const double* tb = th.data() + L.offset[b];
      if (ka == kb) {
        if (ka == ProcessKind::GM) {
          if (std::fabs(ta[1] - tb[1]) < logf) out.push_back({a, b, DupRule::GmPair});
        } else if (ka == ProcessKind::SIN) {
          if (std::fabs(ta[1] - tb[1]) < std::log(1.01)) out.push_back({a, b, DupRule::SinPair});
        } else {
          out.push_back({a, b, DupRule::SameKind});
        }
        continue;
      }
      // GM against WN / RW: the GM is the one freed.
      int g = -1, o = -1;
      if (ka == ProcessKind::GM) g = a, o = b;
      if (kb == ProcessKind::GM) g = b, o = a;
      if (g < 0) continue;
      double s2 = 0, phi = 0;
      gmParams(th.data() + L.offset[g], s2, phi);
      Eigen::VectorXd eq(tau.size());
      if (L.kinds[o] == ProcessKind::WN && std::exp(th[L.offset[g] + 1]) < 1.0) {
        const double w2 = s2 * (1.0 + phi) / (1.0 - phi);
        for (Eigen::Index j = 0; j < tau.size(); ++j) eq[j] = w2 / tau[j];
        if (indistinguishable(P.col(g), eq, ci_w, fraction)) out.push_back({o, g, DupRule::GmIsWhite});
      } else if (L.kinds[o] == ProcessKind::RW) {
        const double g2 = 2.0 * s2 * (1.0 - phi);
        for (Eigen::Index j = 0; j < tau.size(); ++j) eq[j] = g2 * (tau[j] * tau[j] + 2.0) / (12.0 * tau[j]);
        if (indistinguishable(P.col(g), eq, ci_w, fraction)) out.push_back({o, g, DupRule::GmIsRandomWalk});
      }
    }
  }
  return out;
}

/// The model with the pair @p dp merged into dp.keep and dp.drop removed (a sub-structure of L).
Model mergeDuplicate(const Layout& L, const Eigen::VectorXd& th, double rate, const Duplicate& dp) {
  Model m = detail::toModel(L, th, rate);
  Process& k = m.terms[dp.keep];
  const Process& x = m.terms[dp.drop];
  auto rss = [](double a, double b) { return std::sqrt(a * a + b * b); };
  double s2 = 0, phi = 0;
  switch (dp.rule) {
    case DupRule::SameKind:
      k.sigma = rss(k.sigma, x.sigma);
      k.Q = rss(k.Q, x.Q);
      k.gamma = rss(k.gamma, x.gamma);
      k.omega = rss(k.omega, x.omega);
      break;
    case DupRule::GmPair: {
      const double a = k.sigma * k.sigma, b = x.sigma * x.sigma;
      k.T = std::exp((a * std::log(k.T) + b * std::log(x.T)) / (a + b));
      k.sigma = std::sqrt(a + b);
      break;
    }
    case DupRule::SinPair: {
      const double a = k.amp * k.amp, b = x.amp * x.amp;
      k.freq_hz = (a * k.freq_hz + b * x.freq_hz) / (a + b);
      k.amp = std::sqrt(a + b);
      break;
    }
    case DupRule::GmIsWhite:
      gmParams(th.data() + L.offset[dp.drop], s2, phi);
      k.sigma = std::sqrt(k.sigma * k.sigma + s2 * (1.0 + phi) / (1.0 - phi));
      break;
    case DupRule::GmIsRandomWalk:
      gmParams(th.data() + L.offset[dp.drop], s2, phi);
      k.gamma = std::sqrt(k.gamma * k.gamma + 2.0 * s2 * (1.0 - phi));
      break;
  }
  m.terms.erase(m.terms.begin() + dp.drop);
  return m;
}

/// One solved starting point.
struct Solved {
  Eigen::VectorXd th;
  double v = std::numeric_limits<double>::infinity();
  bool conv = false;
  bool dup = false;
};

/**
 * The best solution without two terms that are one, from the solved points
 * @p pts (objective under weights @p W): points with a pair that beat the best
 * clean one are merged (mergeDuplicate) and restarted from the reduced model
 * with the freed term placed across the scale range (warmStarts), for up to
 * three rounds (a restart can meet another pair). If no clean point exists at
 * all, the best point with its pairs merged and the freed terms negligible is
 * returned. @p restarts counts the extra starting points.
 */
Solved resolveDuplicates(const Layout& L, std::vector<Solved> pts, const Data& d, const Weights& W,
                         int* restarts) {
  auto mark = [&](Solved& s) {
    s.dup = !duplicates(L, s.th, d.tau, d.ci_w, kNegligibleFraction).empty();
  };
  for (auto& s : pts) mark(s);
  std::sort(pts.begin(), pts.end(), [](const Solved& a, const Solved& b) { return a.v < b.v; });
  Solved best;
  for (auto& s : pts)
    if (!s.dup) {
      best = s;
      break;
    }
  std::vector<Solved> queue;
  for (auto& s : pts)
    if (s.dup && s.v < best.v && queue.size() < 2) queue.push_back(s);
  for (int round = 0; round < 3 && !queue.empty(); ++round) {
    std::vector<Solved> next;
    for (const Solved& q : queue) {
      const auto dups = duplicates(L, q.th, d.tau, d.ci_w, kNegligibleFraction);
      if (dups.empty()) continue;
      const Model reduced = mergeDuplicate(L, q.th, d.rate, dups.front());
      for (Eigen::VectorXd t : warmStarts(L, reduced, d)) {
        Solved s;
        s.v = solve(L, t, d, W, &s.conv);
        sortTerms(L, t);
        s.th = t;
        mark(s);
        if (restarts) ++*restarts;
        if (!s.dup && s.v < best.v) best = s;
        if (s.dup && s.v < best.v && next.size() < 2) next.push_back(s);
      }
    }
    queue = next;
  }
  if (best.th.size() == 0) {
    // Every point has a pair: merge them all and leave the freed terms negligible.
    Solved s = pts.front();
    for (int it = 0; it < static_cast<int>(L.kinds.size()); ++it) {
      const auto dups = duplicates(L, s.th, d.tau, d.ci_w, kNegligibleFraction);
      if (dups.empty()) break;
      const auto w = warmStarts(L, mergeDuplicate(L, s.th, d.rate, dups.front()), d);
      if (w.empty()) break;
      s.th = w.front();
      sortTerms(L, s.th);
      s.v = criterion(L, s.th, d, W);
      s.conv = false;
    }
    mark(s);
    best = s;
  }
  return best;
}

/// Point estimate: multi-start, returns the transformed theta (GMs sorted),
/// never with two terms that are one (resolveDuplicates).
Eigen::VectorXd fitPoint(const Layout& L, const Data& d, const FitOptions& opt, int* starts,
                         bool* converged) {
  const std::size_t k = opt.max_starts > 0 ? std::max<std::size_t>(1, opt.max_starts / 2) : 4;
  std::vector<Start> best_rel, best_obj;
  forEachPlacement(L, d, [&](const Eigen::VectorXd& th0) {
    Eigen::VectorXd t = th0;
    const double vr = nnlsAmplitudes(L, t, d, d.w_rel);
    keepBest(best_rel, {t, vr}, k);
    t = th0;
    const double vo = nnlsAmplitudes(L, t, d, objW(d));
    keepBest(best_obj, {t, vo}, k);
  });
  std::vector<Eigen::VectorXd> cands;
  for (auto& s : best_rel) {
    Eigen::VectorXd t = s.th;
    solve(L, t, d, d.w_rel);  // R's "starting algorithm" on the relative criterion
    cands.push_back(t);
  }
  for (auto& s : best_obj) cands.push_back(s.th);
  for (const Model& w : opt.warm_starts)
    for (auto& t : warmStarts(L, w, d)) cands.push_back(t);
  std::vector<Solved> pts;
  for (auto& t : cands) {
    Solved s;
    s.v = solve(L, t, d, objW(d), &s.conv);
    if (!std::isfinite(s.v)) continue;
    sortTerms(L, t);
    s.th = t;
    pts.push_back(std::move(s));
  }
  if (pts.empty()) throw Error("GMWM fit of " + stochastic::formatStructure(L.kinds) +
                               ": no starting point gave a finite objective");
  int n_starts = static_cast<int>(cands.size());
  const Solved best = resolveDuplicates(L, std::move(pts), d, objW(d), &n_starts);
  if (starts) *starts = n_starts;
  if (converged) *converged = best.conv;
  return best.th;
}

/// Omega_jj = eta_j / (2 nu_j(theta)^2): inverse chi-square variance of nu_hat_j
/// under the model theta (Percival & Walden 2000, eq. 313c). Sets d.omega and d.w_obj.
void setModelWeights(const Layout& L, const Eigen::VectorXd& th, Data& d) {
  const Eigen::VectorXd nu = detail::wvOf(L, th, d.tau);
  for (int j = 0; j < d.J; ++j) {
    // Guard against a model WV of ~0 at a scale (a term pinned at a bound).
    const double v = std::max(nu[j], 1e-6 * d.nu_hat[j]);
    d.omega[j] = d.eff * d.eta[j] / (2.0 * v * v);
  }
  d.w_obj = d.omega.cwiseSqrt();
}

/**
 * Efficient weights at theta: Omega = V^-1, V the full asymptotic covariance
 * of nu_hat under the model theta (wvCovariance). Scales with eta_j < min_eta
 * get V_jj = 2 nu_j^2 / eta_j (eta3 chi-square variance) and no correlation:
 * the asymptotic formula assumes M_j >> tau_j and overstates their variance
 * by up to 1/eta_j. V = D R D (D = sqrt(diag V)); the correlation matrix R is
 * Cholesky-factored (R = C C', a ridge of 1e-12, 1e-10, ... on its diagonal
 * if it is not numerically positive definite) and W = C^-1 D^-1, so that
 * |W e|^2 = e' V^-1 e. Sets d.w_full, d.omega (diag of Omega) and d.w_obj.
 */
void setEfficientWeights(const Layout& L, const Eigen::VectorXd& th, Data& d, double min_eta) {
  const Model m = detail::toModel(L, th, d.rate);
  WaveletVariance wv;
  wv.tau = d.tau;
  wv.n = static_cast<std::size_t>(d.n);
  wv.rate_hz = d.rate;
  // A robust WV's covariance is the classical one over its efficiency (at the Gaussian).
  Eigen::MatrixXd V = wvCovariance(m, wv) / d.eff;
  const Eigen::VectorXd nu = detail::wvOf(L, th, d.tau);
  for (int j = 0; j < d.J; ++j) {
    const double v = std::max(nu[j], 1e-6 * d.nu_hat[j]);
    const double chi = 2.0 * v * v / (d.eta[j] * d.eff);
    if (d.eta[j] < min_eta || !(V(j, j) > 0.0) || !std::isfinite(V(j, j))) {
      V.row(j).setZero();
      V.col(j).setZero();
      V(j, j) = chi;
    }
  }
  const Eigen::VectorXd D = V.diagonal().cwiseSqrt();
  const Eigen::VectorXd Di = D.cwiseInverse();
  Eigen::MatrixXd R = Di.asDiagonal() * V * Di.asDiagonal();
  R = 0.5 * (R + R.transpose());
  Eigen::LLT<Eigen::MatrixXd> llt(R);
  for (double ridge = 1e-12; llt.info() != Eigen::Success && ridge < 1.0; ridge *= 100.0) {
    Eigen::MatrixXd Rr = R;
    Rr.diagonal().array() += ridge;
    llt.compute(Rr);
  }
  if (llt.info() != Eigen::Success) throw Error("GMWM efficient weights: WV covariance is not positive definite");
  const Eigen::MatrixXd Ci =
      llt.matrixL().solve(Eigen::MatrixXd::Identity(d.J, d.J));
  d.w_full = Ci * Di.asDiagonal();
  const Eigen::MatrixXd Om = d.w_full.transpose() * d.w_full;
  d.omega = Om.diagonal();
  d.w_obj = d.omega.cwiseSqrt();
}

/**
 * Iteratively reweighted GMWM: from the fast-weight estimate th, set the
 * weights of opt.weighting at th (model-based: setModelWeights; efficient:
 * setEfficientWeights with opt.efficient_min_eta), refit from th (on the first
 * pass, when @p multistart, also from the multi-start points of @p opt under
 * the new weights, keeping the lower objective: a fast fit that spent a GM on
 * the white noise, T < 1 sample, is left that way by a local refit), repeat
 * until the largest change of a transformed parameter is below 1e-3 (0.1 %)
 * or after opt.weight_iterations passes. Leaves d.omega / d.w_obj (and
 * d.w_full) at the weights of the last refit. opt.weighting must not be Fast.
 */
int reweight(const Layout& L, Eigen::VectorXd& th, Data& d, const FitOptions& opt, bool* converged,
             bool multistart) {
  int done = 0;
  for (int it = 0; it < std::max(opt.weight_iterations, 1); ++it) {
    if (opt.weighting == Weighting::Efficient)
      setEfficientWeights(L, th, d, opt.efficient_min_eta);
    else
      setModelWeights(L, th, d);
    std::vector<Solved> pts(1);
    pts[0].th = th;
    pts[0].v = solve(L, pts[0].th, d, objW(d), &pts[0].conv);
    sortTerms(L, pts[0].th);
    if (multistart && it == 0) {  // the fast basin need not be the best one under the new weights
      Solved s;
      s.th = fitPoint(L, d, opt, nullptr, &s.conv);
      s.v = criterion(L, s.th, d, objW(d));
      pts.push_back(s);
    }
    const Solved best = resolveDuplicates(L, std::move(pts), d, objW(d), nullptr);
    if (converged) *converged = best.conv;
    const Eigen::VectorXd t = best.th;
    const double change = (t - th).cwiseAbs().maxCoeff();
    th = t;
    ++done;
    if (change < 1e-3) break;
  }
  return done;
}

/// Names and back-transformed values of the parameters of term i.
void termParams(ProcessKind k, const double* t, double rate, std::vector<ParamInterval>& out,
                const double* lo, const double* hi) {
  auto add = [&](const char* n, double f, int q) {
    ParamInterval pi;
    pi.name = n;
    pi.value = std::exp(t[q]) * f;
    pi.low = std::exp(lo[q]) * f;
    pi.high = std::exp(hi[q]) * f;
    out.push_back(pi);
  };
  switch (k) {
    case ProcessKind::WN: add("sigma", 1.0, 0); break;
    case ProcessKind::QN: add("Q", 1.0, 0); break;
    case ProcessKind::RW: add("gamma", 1.0, 0); break;
    case ProcessKind::DR: add("omega", 1.0, 0); break;
    case ProcessKind::GM:
      add("sigma", 1.0, 0);
      add("T", 1.0 / rate, 1);
      break;
    case ProcessKind::SIN:
      add("amp", 1.0, 0);
      add("freq_hz", rate, 1);
      break;
  }
}

std::vector<std::vector<ParamInterval>> intervalsFromTheta(const Layout& L, const Eigen::VectorXd& th,
                                                           const Eigen::VectorXd& lo,
                                                           const Eigen::VectorXd& hi, double rate) {
  std::vector<std::vector<ParamInterval>> ci(L.kinds.size());
  for (std::size_t i = 0; i < L.kinds.size(); ++i)
    termParams(L.kinds[i], th.data() + L.offset[i], rate, ci[i], lo.data() + L.offset[i],
               hi.data() + L.offset[i]);
  return ci;
}

/**
 * Profile interval of parameter k (transformed space): the set of values
 * where the objective, minimised over the other parameters, stays within
 * c_k of the optimum. c_k = z^2 Psi_kk / (B^+)_kk calibrates the threshold
 * to the sandwich variance Psi (the objective is not a likelihood: Omega is
 * not V^-1): for a locally quadratic objective the interval equals the
 * delta-method one, but it follows the objective along the ridges where a
 * GM with a long T trades against a RW/DR or another GM (where the Wald
 * interval is far too narrow). Walks outward in steps of se_k (doubling
 * after 8 steps) up to +-30 (a factor e^30), interpolating the crossing.
 * GM terms keep their identity: each log T stays between the neighbouring
 * GMs' estimated T (no label switching).
 */
void profileInterval(const Layout& L, const Data& d, const Eigen::VectorXd& th, double obj, int k,
                     double c, double se, const std::vector<std::pair<double, double>>& bands, double& lo,
                     double& hi) {
  const double step0 = std::clamp(se, 0.02, 1.0);
  for (int dir : {-1, +1}) {
    Eigen::VectorXd t = th;
    double prev_x = th[k], prev_d = 0.0, x = th[k], step = step0;
    double edge = th[k] + dir * 30.0;
    if (std::isfinite(bands[k].first)) edge = dir < 0 ? std::max(edge, bands[k].first) : std::min(edge, bands[k].second);
    bool crossed = false;
    for (int it = 0; it < 40; ++it) {
      if (it >= 8) step *= 2.0;
      x = prev_x + dir * step;
      if ((x - edge) * dir > 0) x = edge;
      t[k] = x;
      clampToBounds(t, L, d);
      if (t[k] != x) {  // hit a parameter bound: the interval extends to it
        x = t[k];
        edge = x;
      }
      solve(L, t, d, objW(d), nullptr, k, &bands);
      const double delta = criterion(L, t, d, objW(d)) - obj;
      if (delta > c) {
        const double f = (c - prev_d) / (delta - prev_d);
        x = prev_x + std::clamp(f, 0.0, 1.0) * (x - prev_x);
        crossed = true;
        break;
      }
      prev_x = x;
      prev_d = std::max(delta, 0.0);
      if (x == edge) break;
    }
    if (!crossed) x = prev_x;
    (dir < 0 ? lo : hi) = x;
  }
}

constexpr double kZ975 = 1.959963984540054;  // standard normal 97.5 % quantile

}  // namespace

int parameterCount(const std::vector<ProcessKind>& structure) {
  int p = 0;
  for (ProcessKind k : structure) p += detail::paramCount(k);
  return p;
}

double objective(const Model& m, const WaveletVariance& wv) {
  const Eigen::VectorXd nu = stochastic::haarWv(m, wv.tau);
  const Eigen::VectorXd w = wv.weights();
  return ((wv.wv - nu).array().square() * w.array()).sum();
}

Eigen::VectorXd modelWeights(const Model& m, const WaveletVariance& wv) {
  const Data d = makeData(wv);
  const Eigen::VectorXd nu = stochastic::haarWv(m, wv.tau);
  Eigen::VectorXd w(d.J);
  for (int j = 0; j < d.J; ++j) w[j] = d.eta[j] / (2.0 * nu[j] * nu[j]);
  return w;
}

std::string weightingName(Weighting w) {
  switch (w) {
    case Weighting::ModelBased: return "model";
    case Weighting::Efficient: return "efficient";
    case Weighting::Fast: break;
  }
  return "fast";
}

Weighting parseWeighting(const std::string& s) {
  if (s == "fast") return Weighting::Fast;
  if (s == "model") return Weighting::ModelBased;
  if (s == "efficient") return Weighting::Efficient;
  throw Error("GMWM weights: '" + printable(s, 60) + "' is not one of fast, model, efficient");
}

namespace detail {
/// Asymptotic covariance of theta_hat (transformed space), sandwich form.
Eigen::MatrixXd sandwich(const Layout& L, const Eigen::VectorXd& th, const WaveletVariance& wv,
                         const Eigen::VectorXd& om) {
  const Eigen::MatrixXd A = jacobian(L, th, wv.tau);
  const Eigen::VectorXd nu = wvOf(L, th, wv.tau);
  Eigen::VectorXd V(wv.scales());
  for (int j = 0; j < wv.scales(); ++j) {
    const double eta = (wv.eta.size() == wv.scales() && wv.eta[j] > 0) ? wv.eta[j] : 1.0;
    V[j] = 2.0 * nu[j] * nu[j] / (eta * wv.eff);  // chi-square variance of nu_hat_j (eta dof; robust: over eff)
  }
  const Eigen::MatrixXd B = A.transpose() * om.asDiagonal() * A;
  const Eigen::MatrixXd Bi = pinvSym(B);
  const Eigen::VectorXd ovo = om.cwiseProduct(V).cwiseProduct(om);
  const Eigen::MatrixXd M = A.transpose() * ovo.asDiagonal() * A;
  return Bi * M * Bi;
}
}  // namespace detail

FitResult fit(const std::vector<ProcessKind>& structure, const WaveletVariance& wv, const FitOptions& opt) {
  if (structure.empty()) throw Error("GMWM fit: the structure is empty (expected e.g. WN+GM)");
  const int p = parameterCount(structure);
  const std::string sname = stochastic::formatStructure(structure);
  if (p > wv.scales())
    throw Error("GMWM fit of " + sname + ": " + std::to_string(p) +
                " parameters but the wavelet variance has only " + std::to_string(wv.scales()) +
                " scales (use a longer record or a smaller structure)");
  if (p > kMaxParams)
    throw Error("GMWM fit of " + sname + ": " + std::to_string(p) + " parameters, at most " +
                std::to_string(kMaxParams) + " supported");
  Data d = makeData(wv);
  const Layout L(structure);
  FitResult r;
  Eigen::VectorXd th = fitPoint(L, d, opt, &r.starts, &r.converged);
  r.weighting = opt.weighting;
  if (opt.weighting != Weighting::Fast) r.weight_passes = reweight(L, th, d, opt, &r.converged, true);
  r.model = detail::toModel(L, th, d.rate);
  r.objective_fast = objective(r.model, wv);
  r.objective = opt.weighting == Weighting::Fast ? r.objective_fast : criterion(L, th, d, objW(d));
  if (opt.weighting == Weighting::Efficient) {
    // Omega = V^-1: the sandwich reduces to (A' Omega A)^-1 (Guerrier et al. 2013).
    const Eigen::MatrixXd WA = d.w_full * detail::jacobian(L, th, wv.tau);
    r.cov_transformed = pinvSym(WA.transpose() * WA);
  } else {
    r.cov_transformed = detail::sandwich(L, th, wv, d.omega);
  }
  Eigen::VectorXd lo(p), hi(p);
  if (opt.bootstrap > 0) {
    // Parametric bootstrap: simulate the fitted model at the data length,
    // recompute the WV, refit from theta_hat; percentile interval.
    const std::size_t n = wv.n;
    if (n < 4) throw Error("GMWM bootstrap: the wavelet variance does not record its sample count");
    if (opt.bootstrap < kMinBootstrap)
      throw Error("GMWM bootstrap: " + std::to_string(opt.bootstrap) + " replicates give no 95 % percentile interval (at least " +
                  std::to_string(kMinBootstrap) + ")");
    std::vector<Eigen::VectorXd> reps;
    for (int b = 0; b < opt.bootstrap; ++b) {
      const std::vector<double> x =
          stochastic::simulate(r.model, n, stochastic::deriveSeed(opt.seed, static_cast<std::uint64_t>(b)));
      // The same estimator as the data's WV (a robust fit bootstraps the robust WV).
      const WaveletVariance wb = wv.robust ? robustWaveletVariance(x.data(), n, wv.rate_hz, wv.eff)
                                           : waveletVariance(x.data(), n, wv.rate_hz, 0.05, wv.scales());
      Data db = makeData(wb);
      Eigen::VectorXd t = th;
      solve(L, t, db, objW(db));
      sortTerms(L, t);
      if (opt.weighting != Weighting::Fast) reweight(L, t, db, opt, nullptr, false);
      reps.push_back(t);
    }
    for (int k = 0; k < p; ++k) {
      std::vector<double> v;
      for (auto& t : reps) v.push_back(t[k]);
      std::sort(v.begin(), v.end());
      auto q = [&](double prob) {
        const double pos = prob * (v.size() - 1);
        const std::size_t i0 = static_cast<std::size_t>(std::floor(pos));
        const std::size_t i1 = std::min(i0 + 1, v.size() - 1);
        return v[i0] + (pos - i0) * (v[i1] - v[i0]);
      };
      lo[k] = q(0.025);
      hi[k] = q(0.975);
    }
    r.ci_method = "bootstrap(" + std::to_string(opt.bootstrap) + ")";
  } else {
    Eigen::MatrixXd Binv;
    if (opt.intervals == IntervalMethod::Profile) {
      const Eigen::MatrixXd A = detail::jacobian(L, th, wv.tau);
      if (d.w_full.size()) {
        const Eigen::MatrixXd WA = d.w_full * A;
        Binv = pinvSym(WA.transpose() * WA);
      } else {
        Binv = pinvSym(A.transpose() * d.omega.asDiagonal() * A);
      }
    }
    const double obj = criterion(L, th, d, objW(d));
    // Identity bands of the GM log T (th is sorted by T): between the neighbours.
    std::vector<std::pair<double, double>> bands(p, {-HUGE_VAL, HUGE_VAL});
    std::vector<int> gmT;
    for (std::size_t i = 0; i < L.kinds.size(); ++i)
      if (L.kinds[i] == ProcessKind::GM) gmT.push_back(L.offset[i] + 1);
    for (std::size_t q = 0; q < gmT.size(); ++q) {
      bands[gmT[q]].first = q == 0 ? std::log(0.05) : th[gmT[q - 1]];
      bands[gmT[q]].second = q + 1 == gmT.size() ? std::log(1000.0 * d.n) : th[gmT[q + 1]];
    }
    for (int k = 0; k < p; ++k) {
      const double se = std::sqrt(std::max(r.cov_transformed(k, k), 0.0));
      lo[k] = th[k] - kZ975 * se;
      hi[k] = th[k] + kZ975 * se;
      if (opt.intervals == IntervalMethod::Profile && Binv(k, k) > 0 && se > 0) {
        const double c = kZ975 * kZ975 * se * se / Binv(k, k);
        double plo = lo[k], phi = hi[k];
        profileInterval(L, d, th, obj, k, c, se, bands, plo, phi);
        lo[k] = std::min(plo, th[k]);
        hi[k] = std::max(phi, th[k]);
      }
    }
    r.ci_method = opt.intervals == IntervalMethod::Profile ? "profile" : "asymptotic";
  }
  r.ci = intervalsFromTheta(L, th, lo, hi, d.rate);
  return r;
}

std::vector<RedundantPair> redundantTerms(const Model& m, const WaveletVariance& wv, double fraction) {
  if (!(fraction > 0.0 && fraction <= 1.0))
    throw Error("redundantTerms: fraction " + formatNumber(fraction) + " outside (0, 1]");
  if (wv.ci_high.size() != wv.tau.size() || wv.ci_low.size() != wv.tau.size())
    throw Error("redundantTerms: the wavelet variance has no confidence interval");
  std::vector<ProcessKind> kinds;
  for (const auto& t : m.terms) kinds.push_back(t.kind);
  const Layout L(kinds);
  const double rate = m.rate_hz > 0 ? m.rate_hz : wv.rate_hz;
  Model mm = m;
  mm.rate_hz = rate;
  const Eigen::VectorXd th = detail::fromModel(L, mm);
  const Eigen::VectorXd ci_w = wv.ci_high - wv.ci_low;
  std::vector<RedundantPair> out;
  auto num = [](double v) {
    std::ostringstream os;
    os.precision(3);
    os << v;
    return os.str();
  };
  auto label = [&](int i) {
    int k = 0;
    for (int q = 0; q <= i; ++q)
      if (kinds[q] == kinds[i]) ++k;
    return std::string(stochastic::kindName(kinds[i])) + " " + std::to_string(k);
  };
  for (const Duplicate& dp : duplicates(L, th, wv.tau, ci_w, fraction)) {
    RedundantPair r;
    r.keep = dp.keep;
    r.drop = dp.drop;
    const Process& a = m.terms[dp.keep];
    const Process& b = m.terms[dp.drop];
    switch (dp.rule) {
      case DupRule::SameKind:
        r.why = label(dp.keep) + " and " + label(dp.drop) + " are the same process (proportional WVs)";
        break;
      case DupRule::GmPair:
        r.why = label(dp.keep) + " and " + label(dp.drop) + " have T within a factor " + num(kDuplicateTFactor) +
                " (" + num(a.T) + " s, " + num(b.T) + " s)";
        break;
      case DupRule::SinPair:
        r.why = label(dp.keep) + " and " + label(dp.drop) + " have the same frequency (" + num(a.freq_hz) +
                " Hz, " + num(b.freq_hz) + " Hz)";
        break;
      case DupRule::GmIsWhite:
        r.why = label(dp.drop) + " (T = " + num(b.T) + " s, below one sample) is white noise at the data's "
                "precision, next to " + label(dp.keep);
        break;
      case DupRule::GmIsRandomWalk:
        r.why = label(dp.drop) + " (T = " + num(b.T) + " s) is a random walk at the data's precision, next to " +
                label(dp.keep);
        break;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace navimpact::gmwm
