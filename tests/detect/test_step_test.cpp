// The level-shift likelihood-ratio test (step_test.hpp): its level under
// random null models with random walks, Gauss-Markov processes, quantisation
// and drifts, on the times the change-point detector proposes (the
// diagnosis' use), and its power and size
// estimate at 5x its stated limit (the Bonferroni threshold times the GLS
// standard error of the step at its boundary). Every model, length, position
// and size is drawn at random from a seeded stream (root seed printed; set
// NAVIMPACT_DETECT_SEED to replay).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>

#include <Eigen/Core>
#include <boost/math/distributions/normal.hpp>

#include "detect_test_util.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/detect/step_test.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace nd = navimpact::detect;
namespace ns = navimpact::stochastic;

namespace {

std::uint64_t rootSeed() { return navimpact::test::envOr("NAVIMPACT_DETECT_SEED", 20261125); }

struct Drawn {
  ns::Model model;
  std::size_t n = 0;
};

/// WN plus a random subset of QN, RW, GM (T from 2 samples to 10 records) and DR.
Drawn drawModel(std::mt19937_64& g) {
  auto logU = [&](double a, double b) { return detecttest::logUniform(g, a, b); };
  const detecttest::WhiteRecord w = detecttest::drawWhiteRecord(g, 4096, 32768);
  Drawn d{w.model, w.n};
  const double sw = w.sigma, record = d.n / d.model.rate_hz;
  if (g() % 4 == 0) d.model.terms.push_back(ns::Process::qn(sw * logU(0.1, 1.0)));
  if (g() % 2 == 0) d.model.terms.push_back(ns::Process::rw(sw * logU(1e-4, 3e-2)));
  if (g() % 2 == 0)
    d.model.terms.push_back(ns::Process::gm(sw * logU(0.05, 2.0), logU(2.0 / d.model.rate_hz, 10 * record)));
  if (g() % 4 == 0) d.model.terms.push_back(ns::Process::dr(sw * logU(1e-6, 1e-3)));
  return d;
}

std::string describe(const Drawn& d) {
  return ns::formatTerms(d.model.terms, 3) + " at " + std::to_string(d.model.rate_hz) + " Hz, n " +
         std::to_string(d.n);
}

/// GLS standard error of a step at block boundary kb (the model's random terms; mean, trend).
double stepSe(const Drawn& d, std::size_t block, std::size_t nb, std::size_t kb, const std::vector<double>& y) {
  const bool trend = d.model.count(ns::ProcessKind::DR) > 0;
  Eigen::MatrixXd X(static_cast<Eigen::Index>(nb), trend ? 3 : 2);
  for (std::size_t k = 0; k < nb; ++k) {
    int c = 0;
    X(k, c++) = 1.0;
    if (trend) X(k, c++) = (static_cast<double>(k) - 0.5 * nb) / nb;
    X(k, c++) = k >= kb ? 1.0 : 0.0;
  }
  const auto f = ns::blockLogLikelihood(d.model, y, block, X);
  return std::sqrt(f.beta_cov(X.cols() - 1, X.cols() - 1));
}

}  // namespace

TEST(StepTest, CandidatesOfTheDetectorHoldAlphaUnderTheModel) {
  // The diagnosis' use: the change-point detector (at a loose level, so that
  // it proposes candidates in most records) picks the times, the test judges
  // them under the model with every variance profiled and a random walk added.
  const double alpha = 0.05;
  const int R = 200;
  std::mt19937_64 g(rootSeed());
  std::cout << "[ steps    ] root seed " << rootSeed() << "\n";
  int alarms = 0, proposed = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawModel(g);
    const std::uint64_t s = g();
    const auto x = ns::simulate(d.model, d.n, s);
    std::vector<double> xc = x;
    const auto cp = nd::detectChangePoints(xc, nd::haarWvOf(d.model), 0.9);
    std::vector<std::size_t> idx;
    for (const auto& c : cp.changes) idx.push_back(c.index);
    if (idx.empty()) continue;
    ++proposed;
    const auto t = nd::testLevelShifts(x, d.model, idx, alpha);
    if (t.accepted() > 0) {
      ++alarms;
      std::cout << "  alarm: " << describe(d) << " seed " << s << " p " << t.tests.front().p_value << "\n";
    }
  }
  const double bound = alpha + 3.0 * std::sqrt(alpha * (1 - alpha) / R);
  std::cout << "step test null: " << alarms << "/" << R << " records with a shift at alpha " << alpha << " ("
            << proposed << " with candidates from the detector at level 0.9)\n";
  EXPECT_LE(alarms, bound * R);
  EXPECT_GE(proposed, R / 8);  // the detector did propose times to judge (not a vacuous test)
}

TEST(StepTest, HoldsAlphaWhenTheModelUnderstatesItsRandomWalk) {
  // A fitted model can carry a random walk far below the data's (a GMWM fit
  // that put it at gamma = 1e-65). The records are white noise plus a random
  // walk; the model given has that walk with gamma scaled by a factor drawn
  // log-uniformly over [1e-60, 1]. The detector, run under that model, sees
  // the wander as steps; the test, with the walk's variance profiled, must
  // still hold its level.
  const double alpha = 0.05;
  const int R = 100;
  std::mt19937_64 g(rootSeed() + 1);
  int alarms = 0, proposed = 0;
  for (int r = 0; r < R; ++r) {
    auto logU = [&](double a, double b) { return detecttest::logUniform(g, a, b); };
    const detecttest::WhiteRecord w = detecttest::drawWhiteRecord(g, 4096, 32768);
    Drawn d{w.model, w.n};
    d.model.terms.push_back(ns::Process::rw(w.sigma * logU(1e-3, 3e-2)));
    const std::uint64_t s = g();
    const auto x = ns::simulate(d.model, d.n, s);
    Drawn given = d;
    given.model.terms.back().gamma *= logU(1e-60, 1.0);
    std::vector<double> xc = x;
    const auto cp = nd::detectChangePoints(xc, nd::haarWvOf(given.model), 0.9);
    std::vector<std::size_t> idx;
    for (const auto& c : cp.changes) idx.push_back(c.index);
    if (idx.empty()) continue;
    ++proposed;
    const auto t = nd::testLevelShifts(x, given.model, idx, alpha);
    if (t.accepted() > 0) {
      ++alarms;
      std::cout << "  alarm: " << describe(d) << " given " << describe(given) << " seed " << s << "\n";
    }
  }
  std::cout << "step test, understated random walk: " << alarms << "/" << R << " records with a shift at alpha "
            << alpha << " (" << proposed << " with candidates)\n";
  EXPECT_LE(alarms, navimpact::test::plausibleMaxCount(R, alpha));
  EXPECT_GE(proposed, R / 4);
}

TEST(StepTest, ShiftsAtFiveTimesTheLimitAreAcceptedAndSized) {
  const double alpha = 0.01;
  const int R = 40;
  std::mt19937_64 g(rootSeed() + 1);
  std::uniform_real_distribution<double> U(0, 1);
  int accepted = 0, sized = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawModel(g);
    auto x = ns::simulate(d.model, d.n, g());
    const nd::StepTestOptions o;
    const std::size_t block = std::max<std::size_t>(1, d.n / o.target_blocks), nb = d.n / block;
    // Anywhere in the middle 80 %, at a sample (not necessarily a block boundary).
    const std::size_t at = static_cast<std::size_t>((0.1 + 0.8 * U(g)) * static_cast<double>(d.n));
    const std::size_t kb = static_cast<std::size_t>(std::llround(static_cast<double>(at) / block));
    const auto y0 = ns::blockMeans(x.data(), x.size(), block);
    const double z = boost::math::quantile(boost::math::complement(boost::math::normal(), alpha / (2.0 * (nb - 1))));
    const double limit = z * stepSe(d, block, nb, kb, y0);
    const double size = (g() % 2 ? 1.0 : -1.0) * 5.0 * limit;
    for (std::size_t k = at; k < d.n; ++k) x[k] += size;
    const auto t = nd::testLevelShifts(x, d.model, {at}, alpha, o);
    const bool ok = t.accepted() == 1;
    accepted += ok;
    bool good = false;
    if (ok) good = std::abs(t.tests[0].size - size) <= 3.0 * t.tests[0].size_se && std::abs(t.tests[0].size - size) <= 0.3 * std::abs(size);
    sized += good;
    if (!good)
      std::cout << "  " << describe(d) << " shift " << size << " at " << at << ": "
                << (ok ? "size " + std::to_string(t.tests[0].size) + " se " + std::to_string(t.tests[0].size_se) : "not accepted, p " + std::to_string(t.tests.empty() ? 1.0 : t.tests[0].p_value))
                << "\n";
  }
  std::cout << "step test at 5x the limit: accepted " << accepted << "/" << R << ", size within 3 se and 30 % "
            << sized << "/" << accepted << "\n";
  EXPECT_GE(accepted, 0.9 * R);
  EXPECT_GE(sized, 0.9 * accepted);
}

TEST(StepTest, BadInputIsAnError) {
  ns::Model m;
  m.rate_hz = 100;
  m.terms = {ns::Process::wn(1.0)};
  std::vector<double> x(100, 0.0);
  EXPECT_THROW(nd::testLevelShifts(x, m, {50}, 0.0), navimpact::Error);
  EXPECT_THROW(nd::testLevelShifts({1.0, 2.0}, m, {1}, 0.05), navimpact::Error);
  ns::Model none;
  none.rate_hz = 100;
  EXPECT_THROW(nd::testLevelShifts(x, none, {50}, 0.05), navimpact::Error);
}
