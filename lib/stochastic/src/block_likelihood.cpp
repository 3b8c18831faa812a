// Exact Gaussian likelihood of block means (see block_likelihood.hpp).
#include "navimpact/stochastic/block_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "kind.hpp"
#include "rng.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/core/error.hpp"

namespace navimpact::stochastic {

std::optional<SampledArma> sampledArma(const Process& p, double rate_hz) {
  return detail::kindDef(p.kind).sampledArma(p, rate_hz);
}

std::vector<double> blockMeans(const double* x, std::size_t n, std::size_t block) {
  if (block == 0) throw Error("blockMeans: block must be >= 1 sample");
  const std::size_t nb = n / block;
  std::vector<double> y(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    double s = 0;
    for (std::size_t i = 0; i < block; ++i) s += x[k * block + i];
    y[k] = s / static_cast<double>(block);
  }
  return y;
}

namespace {

constexpr double kLn2Pi = 1.8378770664093453;

/// One term over a block of b samples: state s_k = z_{kb-1}; block mean =
/// H s_k + w_k, s_{k+1} = F s_k + v_k; var w = R, var v = Q, cov(v, w) = M.
struct TermBlock {
  double F = 0, H = 0, Q = 0, M = 0, R = 0, P0 = 0;
};

/// The sums of blockForm() over the b samples of a block depend on phi, mu
/// and b only (q and p0 scale them afterwards).
struct BlockSums {
  std::uint64_t phi = 0, mu = 0;  ///< bit patterns of the key
  std::size_t b = 0;
  double G = 0, c = 1, sdd = 0, scc = 0, scd = 0;
};

/// Cached per thread: the variance profile and the scans over block
/// boundaries evaluate the same terms at many variances, and the loop over
/// the b samples of a block was most of the cost of a likelihood. The cached
/// values are those the loop computes (same arithmetic, same bits).
BlockSums blockSums(double phi, double mu, std::size_t b) {
  std::uint64_t kp = 0, km = 0;
  std::memcpy(&kp, &phi, sizeof kp);
  std::memcpy(&km, &mu, sizeof km);
  constexpr std::size_t kSlots = 64;
  thread_local std::vector<BlockSums> cache;
  thread_local std::size_t next = 0;
  for (const auto& e : cache)
    if (e.b == b && e.phi == kp && e.mu == km) return e;
  // Sums over j = b-1 down to 0, i.e. m = b - j = 1..b samples to the block end:
  // G(m) = 1 + phi G(m-1), d_j = G(m) - mu G(m-1), c_j = phi^(m-1).
  BlockSums e;
  e.phi = kp;
  e.mu = km;
  e.b = b;
  double G_prev = 0, c = 1, sdd = 0, scc = 0, scd = 0;
  for (std::size_t m = 1; m <= b; ++m) {
    const double G = 1.0 + phi * G_prev;
    const double d = G - mu * G_prev;
    sdd += d * d;
    scc += c * c;
    scd += c * d;
    G_prev = G;
    if (m < b) c *= phi;
  }
  e.G = G_prev;
  e.c = c;
  e.sdd = sdd;
  e.scc = scc;
  e.scd = scd;
  if (cache.size() < kSlots) cache.push_back(e);
  else cache[next++ % kSlots] = e;
  return e;
}

TermBlock blockForm(const SampledArma& a, std::size_t b) {
  const BlockSums s = blockSums(a.phi, a.mu, b);
  const double bd = static_cast<double>(b);
  TermBlock t;
  t.H = (a.phi - a.mu) * s.G / bd;  // G(b)
  t.F = s.c * a.phi;                 // phi^b
  t.R = a.q * s.sdd / (bd * bd);
  t.Q = a.q * s.scc;
  t.M = a.q * s.scd / bd;
  t.P0 = a.p0;
  return t;
}

/// Variance-like parameter of a random term, scaled by @p f (variance factor).
void scaleVariance(Process& p, double f) {
  const double r = std::sqrt(f);
  switch (p.kind) {
    case ProcessKind::WN: p.sigma *= r; break;
    case ProcessKind::QN: p.Q *= r; break;
    case ProcessKind::RW: p.gamma *= r; break;
    case ProcessKind::GM: p.sigma *= r; break;
    default: break;
  }
}

bool isRandom(const Process& p) {
  return p.kind == ProcessKind::WN || p.kind == ProcessKind::QN ||
         p.kind == ProcessKind::RW || p.kind == ProcessKind::GM;
}

}  // namespace

BlockLikelihood blockLogLikelihood(const Model& m, const std::vector<double>& y, std::size_t block,
                                   const Eigen::MatrixXd& X, const std::vector<int>& columns) {
  const std::size_t nb = y.size();
  if (nb < 2) throw Error("blockLogLikelihood: need at least 2 block means");
  if (block == 0) throw Error("blockLogLikelihood: block must be >= 1 sample");
  if (!(m.rate_hz > 0)) throw Error("blockLogLikelihood: the model needs a rate");
  if (X.cols() > 0 && static_cast<std::size_t>(X.rows()) != nb)
    throw Error("blockLogLikelihood: regressors have " + std::to_string(X.rows()) + " rows for " +
                std::to_string(nb) + " block means");
  std::vector<int> cols = columns;
  if (cols.empty())
    for (int j = 0; j < X.cols(); ++j) cols.push_back(j);
  for (int j : cols)
    if (j < 0 || j >= X.cols()) throw Error("blockLogLikelihood: no regressor column " + std::to_string(j));

  // Terms: white ones (H = 0) only add to R; the others carry a state.
  double R = 0;
  std::vector<TermBlock> st;
  for (const auto& p : m.terms) {
    const auto a = sampledArma(p, m.rate_hz);
    if (!a) continue;
    const TermBlock t = blockForm(*a, block);
    R += t.R;
    if (t.H != 0.0) st.push_back(t);
  }
  const int d = static_cast<int>(st.size());
  if (!(R > 0) && d == 0) throw Error("blockLogLikelihood: the model has no random term");

  const int nc = 1 + static_cast<int>(cols.size());  // y and the regressors
  std::vector<double> P(static_cast<std::size_t>(d * d), 0.0), Pn(P.size()), PH(d), K(d);
  for (int i = 0; i < d; ++i) P[i * d + i] = st[i].P0;
  std::vector<double> Xh(static_cast<std::size_t>(d * nc), 0.0), nu(nc);
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(nc, nc);  // sum nu nu' / S
  double sum_log_s = 0, S = R;
  bool steady = false;
  for (std::size_t k = 0; k < nb; ++k) {
    if (!steady) {
      S = R;
      for (int i = 0; i < d; ++i) {
        double v = 0;
        for (int j = 0; j < d; ++j) v += P[i * d + j] * st[j].H;
        PH[i] = v;
        S += st[i].H * v;
      }
      if (!(S > 0)) throw Error("blockLogLikelihood: innovation variance not positive");
      for (int i = 0; i < d; ++i) K[i] = (st[i].F * PH[i] + st[i].M) / S;
    }
    // Innovations of y and of every regressor (same filter).
    for (int c = 0; c < nc; ++c) {
      double pred = 0;
      for (int i = 0; i < d; ++i) pred += st[i].H * Xh[i * nc + c];
      const double obs = c == 0 ? y[k] : X(static_cast<Eigen::Index>(k), cols[c - 1]);
      nu[c] = obs - pred;
    }
    for (int i = 0; i < d; ++i)
      for (int c = 0; c < nc; ++c) Xh[i * nc + c] = st[i].F * Xh[i * nc + c] + K[i] * nu[c];
    sum_log_s += std::log(S);
    const double is = 1.0 / S;
    for (int a = 0; a < nc; ++a)
      for (int b = 0; b <= a; ++b) W(a, b) += nu[a] * nu[b] * is;
    if (!steady && d > 0) {
      // P <- F P F' + Q - K S K'
      double change = 0, scale = 0;
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) {
          double v = st[i].F * P[i * d + j] * st[j].F - K[i] * S * K[j];
          if (i == j) v += st[i].Q;
          Pn[i * d + j] = v;
          change = std::max(change, std::abs(v - P[i * d + j]));
          scale = std::max(scale, std::abs(v));
        }
      P.swap(Pn);
      // Converged to the steady state: gains and S no longer change.
      if (k > 4 && change <= 1e-13 * scale) steady = true;
    } else if (d == 0) {
      steady = true;
    }
  }
  for (int a = 0; a < nc; ++a)
    for (int b = a + 1; b < nc; ++b) W(a, b) = W(b, a);
  BlockLikelihood out;
  double quad = W(0, 0);
  const int p = nc - 1;
  if (p > 0) {
    const Eigen::MatrixXd G = W.bottomRightCorner(p, p);
    const Eigen::VectorXd g = W.bottomLeftCorner(p, 1);
    Eigen::LDLT<Eigen::MatrixXd> ldlt(G);
    const double dmax = G.diagonal().maxCoeff();
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * dmax))
      throw Error("blockLogLikelihood: the regressors are (nearly) collinear");
    out.beta = ldlt.solve(g);
    out.beta_cov = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
    quad -= g.dot(out.beta);
  }
  out.loglik = -0.5 * (static_cast<double>(nb) * kLn2Pi + sum_log_s + quad);
  return out;
}

/// Block log-likelihood maximised over the variance of every random term of
/// @p m (GM correlation times kept), by coordinate-wise search in the log of a
/// variance factor per term (a grid of e^-12..e^4, then golden section; two
/// sweeps until the log-likelihood gains less than 1e-4). @p m is updated
/// to the maximiser.
double profileBlockLogLikelihood(Model& m, const std::vector<double>& y, std::size_t b,
                      const Eigen::MatrixXd& X, const std::vector<int>& terms) {
  auto ll = [&](const Model& mm) {
    return blockLogLikelihood(mm, y, b, X).loglik;
  };
  double best = ll(m);
  for (int sweep = 0; sweep < 8; ++sweep) {
    const double before = best;
    for (std::size_t i = 0; i < m.terms.size(); ++i) {
      if (!isRandom(m.terms[i])) continue;
      if (!terms.empty() && std::find(terms.begin(), terms.end(), static_cast<int>(i)) == terms.end()) continue;
      const Process p0 = m.terms[i];
      auto at = [&](double lf) {
        m.terms[i] = p0;
        scaleVariance(m.terms[i], std::exp(lf));
        return ll(m);
      };
      double bl = 0, bv = best;
      for (int g = -12; g <= 4; ++g) {
        if (g == 0) continue;
        const double v = at(g);
        if (v > bv) {
          bv = v;
          bl = g;
        }
      }
      double a = bl - 1, c = bl + 1;
      const double r = 0.5 * (std::sqrt(5.0) - 1.0);
      double x1 = c - r * (c - a), x2 = a + r * (c - a), f1 = at(x1), f2 = at(x2);
      for (int it = 0; it < 16; ++it) {
        if (f1 > f2) {
          c = x2; x2 = x1; f2 = f1; x1 = c - r * (c - a); f1 = at(x1);
        } else {
          a = x1; x1 = x2; f1 = f2; x2 = a + r * (c - a); f2 = at(x2);
        }
      }
      if (f1 > bv) { bv = f1; bl = x1; }
      if (f2 > bv) { bv = f2; bl = x2; }
      m.terms[i] = p0;
      scaleVariance(m.terms[i], std::exp(bl));
      best = bv;
    }
    if (best - before < 1e-4) break;  // converged
  }
  return best;
}

std::vector<double> simulateBlockMeans(const Model& m, std::size_t nb, std::size_t block, std::uint64_t seed) {
  if (block == 0) throw Error("simulateBlockMeans: block must be >= 1 sample");
  if (!(m.rate_hz > 0)) throw Error("simulateBlockMeans: the model needs a rate");
  std::vector<double> y(nb, 0.0);
  const double bd = static_cast<double>(block);
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    const Process& p = m.terms[i];
    if (p.kind == ProcessKind::DR) {
      // Mean of omega k over k = kb .. kb + b - 1.
      for (std::size_t k = 0; k < nb; ++k) y[k] += p.omega * (static_cast<double>(k) * bd + 0.5 * (bd - 1.0));
      continue;
    }
    const auto a = sampledArma(p, m.rate_hz);
    if (!a) continue;
    const TermBlock t = blockForm(*a, block);
    detail::Rng rng(deriveSeed(seed, i));
    // (w, v) = (sqrt(R) z1, M / sqrt(R) z1 + sqrt(Q - M^2 / R) z2).
    const double sr = std::sqrt(std::max(t.R, 0.0));
    const double cv = sr > 0 ? t.M / sr : 0.0;
    const double sv = std::sqrt(std::max(t.Q - cv * cv, 0.0));
    double s = std::sqrt(std::max(t.P0, 0.0)) * rng.normal();
    for (std::size_t k = 0; k < nb; ++k) {
      const double z1 = rng.normal(), z2 = rng.normal();
      y[k] += t.H * s + sr * z1;
      s = t.F * s + cv * z1 + sv * z2;
    }
  }
  return y;
}

}  // namespace navimpact::stochastic
