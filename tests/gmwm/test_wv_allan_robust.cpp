// Allan variance (identity with the Haar WV, white-noise slope) and the
// robust (Tukey biweight) wavelet variance under contamination.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"

using namespace navimpact;

namespace {

std::vector<double> whiteNoise(std::size_t n, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, sigma);
  std::vector<double> x(n);
  for (auto& v : x) v = nd(rng);
  return x;
}

}  // namespace

TEST(Allan, EqualsTwiceHaarWvAtDoubleCluster) {
  // Haar: W_{j,t} = (theta_{t+1} - 2 theta_{t+1-m} + theta_{t+1-2m}) / (2m), m = 2^{j-1},
  // so AVAR(m) = 2 nu^2(2m) term by term with the same n - 2m + 1 terms (gmwm_formulas.md §1).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> x(50000);
  double rw = 0;
  for (auto& v : x) {
    rw += 0.01 * nd(rng);
    v = 9.81 + 0.05 * nd(rng) + rw;
  }
  const auto wv = gmwm::waveletVariance(x.data(), x.size(), 100.0);
  Eigen::VectorXd m(wv.scales());
  for (int i = 0; i < wv.scales(); ++i) m[i] = wv.tau[i] / 2.0;
  const Eigen::VectorXd avar = gmwm::allanVariance(x.data(), x.size(), m);
  for (int i = 0; i < wv.scales(); ++i)
    EXPECT_NEAR(avar[i] / (2.0 * wv.wv[i]), 1.0, 1e-11) << "m=" << m[i];
}

TEST(Allan, WhiteNoiseDecaysAsSigma2OverM) {
  // WN: AVAR(m) = sigma^2 / m (IEEE Std 952, annex C). Tolerance 5 sqrt(2m/n),
  // several standard errors of the overlapping estimator.
  const std::size_t n = 1 << 17;
  const double sigma = 0.3;
  for (unsigned seed : {21u, 22u}) {
    const auto x = whiteNoise(n, sigma, seed);
    Eigen::VectorXd m(5);
    m << 1, 3, 10, 50, 200;
    const Eigen::VectorXd a = gmwm::allanVariance(x.data(), n, m);
    for (int i = 0; i < m.size(); ++i)
      EXPECT_NEAR(a[i] * m[i] / (sigma * sigma), 1.0, 5.0 * std::sqrt(2.0 * m[i] / n))
          << "seed " << seed << " m=" << m[i];
  }
}

TEST(Allan, RejectsBadClusterSizes) {
  const auto x = whiteNoise(100, 1.0, 1);
  Eigen::VectorXd m(1);
  m << 1.5;
  EXPECT_THROW(gmwm::allanVariance(x.data(), x.size(), m), Error);
  m << 0;
  EXPECT_THROW(gmwm::allanVariance(x.data(), x.size(), m), Error);
  m << 51;
  EXPECT_THROW(gmwm::allanVariance(x.data(), x.size(), m), Error);
  m << 50;
  EXPECT_NO_THROW(gmwm::allanVariance(x.data(), x.size(), m));
}

TEST(RobustWv, ResistsOutliersWhereClassicalInflates) {
  // WN sigma^2 = 1 plus 0.1 % of samples shifted by +-50 sigma. Truth nu^2 = 1/tau.
  const std::size_t n = 1 << 16;
  for (unsigned seed : {31u, 32u, 33u}) {
    auto x = whiteNoise(n, 1.0, seed);
    std::mt19937_64 rng(seed + 1000);
    std::uniform_int_distribution<std::size_t> pos(0, n - 1);
    for (std::size_t k = 0; k < n / 1000; ++k) x[pos(rng)] += (k % 2 ? 50.0 : -50.0);
    const auto cl = gmwm::waveletVariance(x.data(), n, 100.0);
    const auto rb = gmwm::robustWaveletVariance(x.data(), n, 100.0);
    ASSERT_EQ(rb.scales(), cl.scales());
    EXPECT_TRUE(rb.robust);
    for (int i = 0; i < 4; ++i) {
      const double truth = 1.0 / cl.tau[i];
      EXPECT_GT(cl.ci_low[i], 2.0 * truth) << "classical not inflated, seed " << seed << " j=" << i + 1;
      EXPECT_LE(rb.ci_low[i], truth) << "seed " << seed << " j=" << i + 1;
      EXPECT_GE(rb.ci_high[i], truth) << "seed " << seed << " j=" << i + 1;
    }
  }
}

TEST(RobustWv, AgreesWithClassicalOnCleanData) {
  const std::size_t n = 1 << 15;
  for (unsigned seed : {41u, 42u}) {
    const auto x = whiteNoise(n, 2.0, seed);
    const auto cl = gmwm::waveletVariance(x.data(), n, 100.0);
    const auto rb = gmwm::robustWaveletVariance(x.data(), n, 100.0);
    for (int i = 0; i < cl.scales() - 3; ++i) {
      EXPECT_GE(cl.wv[i], rb.ci_low[i]) << "seed " << seed << " j=" << i + 1;
      EXPECT_LE(cl.wv[i], rb.ci_high[i]) << "seed " << seed << " j=" << i + 1;
      // The robust CI is the classical one widened by 1/sqrt(eff).
      EXPECT_GT((rb.ci_high[i] - rb.ci_low[i]) / rb.wv[i], (cl.ci_high[i] - cl.ci_low[i]) / cl.wv[i]);
    }
  }
}

TEST(RobustWv, BadInput) {
  std::vector<double> cst(64, 1.0);
  EXPECT_THROW(gmwm::robustWaveletVariance(cst.data(), cst.size(), 1.0), Error);
  const auto x = whiteNoise(64, 1.0, 3);
  EXPECT_THROW(gmwm::robustWaveletVariance(x.data(), x.size(), 1.0, 1.5), Error);
  EXPECT_THROW(gmwm::robustWaveletVariance(x.data(), 3, 1.0), Error);
}
