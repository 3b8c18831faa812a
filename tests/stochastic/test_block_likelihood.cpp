// The exact likelihood of block means (block_likelihood.hpp) against the
// dense Gaussian likelihood written out from its definition: the covariance
// of the samples built from every term's sampled form, averaged over blocks
// (Sigma_y = A Sigma_x A'), and the regression coefficients by GLS. Models,
// block sizes, regressors and data are drawn at random (seeded, printed).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include <Eigen/Dense>

#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "stochastic_test_util.hpp"

using namespace navimpact::stochastic;

namespace {

constexpr double kLn2Pi = 1.8378770664093453;

/// Covariance of n samples of the random terms of @p m (from sampledArma).
Eigen::MatrixXd sampleCovariance(const Model& m, int n) {
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  for (const auto& p : m.terms) {
    const auto a = sampledArma(p, m.rate_hz);
    if (a) cov += navimpact::test::sampledFormCovariance(*a, n);
  }
  return cov;
}

/// Dense ML log-likelihood of y ~ N(X beta, Sigma), beta by GLS.
double denseLogLik(const Eigen::VectorXd& y, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Sigma,
                   Eigen::VectorXd* beta) {
  Eigen::LLT<Eigen::MatrixXd> llt(Sigma);
  const Eigen::VectorXd Siy = llt.solve(y);
  double quad = y.dot(Siy);
  if (X.cols() > 0) {
    const Eigen::MatrixXd SiX = llt.solve(X);
    const Eigen::MatrixXd G = X.transpose() * SiX;
    *beta = G.ldlt().solve(X.transpose() * Siy);
    const Eigen::VectorXd r = y - X * *beta;
    quad = r.dot(llt.solve(r));
  }
  const Eigen::MatrixXd L = llt.matrixL();
  return -0.5 * (static_cast<double>(y.size()) * kLn2Pi + 2.0 * L.diagonal().array().log().sum() + quad);
}

double logU(std::mt19937_64& g, double a, double b) {
  return a * std::pow(b / a, std::uniform_real_distribution<double>(0, 1)(g));
}

}  // namespace

TEST(BlockLikelihood, EqualsTheDenseGaussianLikelihoodOfBlockMeans) {
  const std::uint64_t seed = 20261201;
  std::cout << "[ block    ] seed " << seed << "\n";
  std::mt19937_64 g(seed);
  for (int r = 0; r < 24; ++r) {
    const int block = 1 + static_cast<int>(g() % 12);
    const int nb = 8 + static_cast<int>(g() % 40);
    const int n = block * nb;
    Model m;
    m.rate_hz = logU(g, 50, 1000);
    const double dur = n / m.rate_hz;
    // A random subset of WN, QN, RW and one or two GMs (T from one sample to 10 records).
    if (g() % 4 != 0) m.terms.push_back(Process::wn(logU(g, 1e-3, 1.0)));
    if (g() % 3 == 0) m.terms.push_back(Process::qn(logU(g, 1e-3, 1.0)));
    if (g() % 2 == 0) m.terms.push_back(Process::rw(logU(g, 1e-4, 0.1)));
    for (int q = 0; q < 1 + static_cast<int>(g() % 2); ++q)
      m.terms.push_back(Process::gm(logU(g, 1e-3, 1.0), logU(g, 0.5 / m.rate_hz, 10 * dur)));
    // Regressors: none, the mean, the mean and a trend, a step inside a block.
    Eigen::MatrixXd Xs(n, 3);
    const int c = 1 + static_cast<int>(g() % (n - 1));
    for (int t = 0; t < n; ++t) {
      Xs(t, 0) = 1.0;
      Xs(t, 1) = (t - 0.5 * n) / n;
      Xs(t, 2) = t >= c ? 1.0 : 0.0;
    }
    const int p = static_cast<int>(g() % 4);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nb, n);
    for (int k = 0; k < nb; ++k) A.block(k, k * block, 1, block).setConstant(1.0 / block);
    const Eigen::MatrixXd Xb = A * Xs.leftCols(p);
    const auto x = simulate(m, static_cast<std::size_t>(n), g());
    std::vector<double> y = blockMeans(x.data(), x.size(), static_cast<std::size_t>(block));
    for (int k = 0; k < nb; ++k) y[k] += 0.3 * (p > 0 ? Xb(k, 0) : 0.0);
    Eigen::VectorXd yv = Eigen::Map<Eigen::VectorXd>(y.data(), nb);
    const Eigen::MatrixXd Sy = A * sampleCovariance(m, n) * A.transpose();
    Eigen::VectorXd beta_dense;
    const double dense = denseLogLik(yv, Xb, Sy, &beta_dense);
    const auto kf = blockLogLikelihood(m, y, static_cast<std::size_t>(block), Xb);
    const std::string what = formatTerms(m.terms, 4) + " at " + std::to_string(m.rate_hz) + " Hz, block " +
                             std::to_string(block) + " x " + std::to_string(nb) + ", " + std::to_string(p) +
                             " regressor(s)";
    EXPECT_NEAR(kf.loglik, dense, 1e-8 * std::abs(dense) + 1e-8) << what;
    for (int j = 0; j < p; ++j)
      EXPECT_NEAR(kf.beta(j), beta_dense(j), 1e-6 * (std::abs(beta_dense(j)) + std::sqrt(Sy.diagonal().mean())))
          << what;
  }
}

TEST(BlockLikelihood, BadInputIsAnError) {
  Model m;
  m.rate_hz = 100;
  std::vector<double> y = {1, 2, 3};
  EXPECT_THROW(blockLogLikelihood(m, y, 4, Eigen::MatrixXd()), navimpact::Error);  // no random term
  m.terms = {Process::wn(1.0)};
  EXPECT_THROW(blockLogLikelihood(m, {1.0}, 4, Eigen::MatrixXd()), navimpact::Error);
  EXPECT_THROW(blockLogLikelihood(m, y, 4, Eigen::MatrixXd::Ones(2, 1)), navimpact::Error);
  EXPECT_THROW(blockLogLikelihood(m, y, 4, Eigen::MatrixXd::Ones(3, 2)), navimpact::Error);  // collinear
  EXPECT_THROW(blockMeans(y.data(), y.size(), 0), navimpact::Error);
}

// profileBlockLogLikelihood: at least the likelihood it starts from, and a
// maximum over every term's variance (no +-20 % change of one variance gains
// more than 1e-3), on random models, records and starting points (variances
// off by up to 10x either way).
TEST(BlockLikelihood, ProfileMaximisesOverEveryVariance) {
  const std::uint64_t seed = 20261202;
  std::cout << "[ block    ] seed " << seed << "\n";
  std::mt19937_64 g(seed);
  for (int r = 0; r < 12; ++r) {
    Model truth;
    truth.rate_hz = logU(g, 50, 1000);
    truth.terms.push_back(Process::wn(logU(g, 1e-3, 1.0)));
    if (g() % 2 == 0) truth.terms.push_back(Process::rw(truth.terms[0].sigma * logU(g, 1e-4, 1e-2)));
    if (g() % 2 == 0) truth.terms.push_back(Process::gm(truth.terms[0].sigma * logU(g, 0.05, 1.0), logU(g, 0.1, 100.0)));
    const std::size_t n = 1u << 15, block = 64;
    const auto x = simulate(truth, n, g());
    const auto y = blockMeans(x.data(), n, block);
    const Eigen::MatrixXd X = Eigen::MatrixXd::Ones(static_cast<Eigen::Index>(y.size()), 1);
    Model m = truth;
    m.terms[0].sigma *= logU(g, 0.3, 3.0);
    for (auto& p : m.terms) {
      if (p.kind == ProcessKind::RW) p.gamma *= logU(g, 0.3, 3.0);
      if (p.kind == ProcessKind::GM) p.sigma *= logU(g, 0.3, 3.0);
    }
    const double start = blockLogLikelihood(m, y, block, X).loglik;
    const double best = profileBlockLogLikelihood(m, y, block, X);
    const std::string what = formatTerms(truth.terms, 3) + " -> " + formatTerms(m.terms, 3);
    EXPECT_GE(best, start - 1e-9) << what;
    EXPECT_NEAR(blockLogLikelihood(m, y, block, X).loglik, best, 1e-9 * std::abs(best)) << what;
    for (std::size_t i = 0; i < m.terms.size(); ++i)
      for (double f : {0.8, 1.25}) {
        Model q = m;
        auto& p = q.terms[i];
        const double r2 = std::sqrt(f);
        if (p.kind == ProcessKind::WN) p.sigma *= r2;
        if (p.kind == ProcessKind::RW) p.gamma *= r2;
        if (p.kind == ProcessKind::GM) p.sigma *= r2;
        EXPECT_LE(blockLogLikelihood(q, y, block, X).loglik, best + 1e-3) << what << " term " << i << " x" << f;
      }
  }
}

// simulateBlockMeans draws from the distribution the likelihood assumes: on
// random models (WN, QN, RW, GM with T from one sample to 10 records, a
// drift) and block sizes, the sample mean and covariance of many draws match
// the block means' mean and covariance A Sigma_x A' written out from the
// definition, within 5 Monte Carlo standard errors per element.
TEST(BlockLikelihood, SimulatedBlockMeansHaveTheLikelihoodsDistribution) {
  const std::uint64_t seed = 20261128;
  std::cout << "[ block    ] seed " << seed << "\n";
  std::mt19937_64 g(seed);
  for (int r = 0; r < 8; ++r) {
    const int block = 1 + static_cast<int>(g() % 40);
    const int nb = 4 + static_cast<int>(g() % 6);
    const int n = block * nb;
    Model m;
    m.rate_hz = logU(g, 50, 1000);
    const double dur = n / m.rate_hz;
    m.terms.push_back(Process::wn(logU(g, 1e-3, 1.0)));
    if (g() % 3 == 0) m.terms.push_back(Process::qn(logU(g, 1e-3, 1.0)));
    if (g() % 2 == 0) m.terms.push_back(Process::rw(logU(g, 1e-4, 0.1)));
    if (g() % 2 == 0) m.terms.push_back(Process::gm(logU(g, 1e-3, 1.0), logU(g, 1.0 / m.rate_hz, 10 * dur)));
    const bool drift = g() % 3 == 0;
    if (drift) m.terms.push_back(Process::dr(logU(g, 1e-5, 1e-3)));
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nb, n);
    for (int k = 0; k < nb; ++k) A.block(k, k * block, 1, block).setConstant(1.0 / block);
    const Eigen::MatrixXd S = A * sampleCovariance(m, n) * A.transpose();
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(nb);
    if (drift)
      for (int k = 0; k < nb; ++k) mean(k) = m.terms.back().omega * (k * block + 0.5 * (block - 1));
    const int R = 20000;
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(nb);
    Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(nb, nb);
    const std::uint64_t s0 = g();
    for (int q = 0; q < R; ++q) {
      const auto y = simulateBlockMeans(m, static_cast<std::size_t>(nb), static_cast<std::size_t>(block), deriveSeed(s0, q));
      ASSERT_EQ(static_cast<int>(y.size()), nb);
      const Eigen::VectorXd d = Eigen::Map<const Eigen::VectorXd>(y.data(), nb) - mean;
      sum += d;
      cross += d * d.transpose();
    }
    const std::string what = formatTerms(m.terms, 3) + " at " + std::to_string(m.rate_hz) + " Hz, block " +
                             std::to_string(block) + " x " + std::to_string(nb);
    for (int i = 0; i < nb; ++i) {
      EXPECT_NEAR(sum(i) / R, 0.0, 5.0 * std::sqrt(S(i, i) / R)) << what << " mean " << i;
      for (int j = 0; j <= i; ++j) {
        const double se = std::sqrt((S(i, i) * S(j, j) + S(i, j) * S(i, j)) / R);
        EXPECT_NEAR(cross(i, j) / R, S(i, j), 5.0 * se) << what << " cov " << i << "," << j;
      }
    }
  }
  // Same seed, same draws; another seed, other draws.
  Model m;
  m.rate_hz = 100;
  m.terms = {Process::wn(0.1), Process::gm(0.05, 3.0), Process::rw(0.01)};
  EXPECT_EQ(simulateBlockMeans(m, 32, 16, 7), simulateBlockMeans(m, 32, 16, 7));
  EXPECT_NE(simulateBlockMeans(m, 32, 16, 7), simulateBlockMeans(m, 32, 16, 8));
  EXPECT_THROW(simulateBlockMeans(m, 32, 0, 7), navimpact::Error);
}
