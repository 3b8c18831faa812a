// The nominal interval of IMU time stamps (nominalStep): the true rate of an
// IMU whose stamps are quantised coarser than its step or jitter between two
// values, drawn at random over the documented rates (1 Hz - 10 kHz; seeded,
// logged); the median where it is right (regular stamps, stamps with gaps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <vector>

#include "navimpact/core/recording.hpp"

using navimpact::nominalStep;

namespace {

/// Successive differences of stamps t_k = q round(k h / q) (quantum q).
std::vector<double> quantisedSteps(double h, double q, std::size_t n) {
  std::vector<double> steps;
  double prev = 0.0;
  for (std::size_t k = 1; k <= n; ++k) {
    const double t = q * std::round(double(k) * h / q);
    steps.push_back(t - prev);
    prev = t;
  }
  return steps;
}

}  // namespace

TEST(NominalStep, RegularStampsGiveTheirStepEvenWithGaps) {
  std::vector<double> steps(1000, 0.005);
  EXPECT_EQ(nominalStep(steps), 0.005);
  for (std::size_t k = 0; k < steps.size(); k += 97) steps[k] = 0.5;  // gaps of 100 steps
  EXPECT_EQ(nominalStep(steps), 0.005);
  EXPECT_EQ(nominalStep({0.01}), 0.01);
  EXPECT_FALSE(nominalStep({}) > 0.0);
  EXPECT_FALSE(nominalStep({0.0, 0.0, 0.01}) > 0.0);  // the median is 0: the callers' error
}

TEST(NominalStep, QuantisedAndAlternatingStampsGiveTheTrueRate) {
  // 400 Hz stamped in ms (2, 3, 2, 3 ms): the median is 2 or 3 ms, the rate 400 Hz.
  EXPECT_NEAR(1.0 / nominalStep(quantisedSteps(0.0025, 0.001, 8000)), 400.0, 1e-9);
  // steps alternating 11 and 9 ms (mean 100 Hz), with a 0.3 s gap among them
  std::vector<double> alt;
  for (int k = 0; k < 2000; ++k) alt.push_back(k % 2 ? 0.011 : 0.009);
  alt[700] = 0.3;
  EXPECT_NEAR(1.0 / nominalStep(alt), 100.0, 0.06);  // one 9/11 pair lost to the gap: 1999 of 2000 steps

  // Rates over the documented range, quanta from 1/20 to 1/2 of the step (a
  // coarser quantum makes steps of two quanta, over 1.5 steps: gaps by the gap rule).
  const std::uint64_t seed = 20261129;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::cout << "seed " << seed << ": 300 IMUs, rate log-U(1, 1e4) Hz, quantum h / U(2, 20)\n";
  for (int i = 0; i < 300; ++i) {
    const double rate = std::pow(10.0, 4.0 * U(g)), h = 1.0 / rate;
    const double q = h / (2.0 + 18.0 * U(g));
    const std::size_t n = 500 + std::size_t(U(g) * 5000);
    const std::vector<double> steps = quantisedSteps(h, q, n);
    const double span = q * std::round(double(n) * h / q);  // the stamps' own span
    const double got = nominalStep(steps);
    // within 1 % of the true step: the median, or else the mean of all steps
    EXPECT_NEAR(got, h, 0.0101 * h) << "rate " << rate << " Hz, quantum " << q << " s, " << n << " steps";
    // and it is the median or the mean (span / n)
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + long(n / 2), sorted.end());
    EXPECT_TRUE(got == sorted[n / 2] || std::abs(got - span / double(n)) <= 1e-9 * h) << "rate " << rate;
  }
}
