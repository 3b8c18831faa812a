// The one number formatter: each mode equals the stream/printf conversion it
// stands for (the outputs written before it existed stay byte-identical), on
// doubles drawn over the whole range (seeded, logged) and on the edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>

#include "navimpact/core/format.hpp"

using navimpact::formatExact;
using navimpact::formatFixed;
using navimpact::formatNumber;
using navimpact::formatReadable;

namespace {

/// Random doubles: sign, mantissa and decimal exponent in [-300, 300] uniform,
/// plus integers, powers of ten and the edge values.
std::vector<double> samples(std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> m(1.0, 10.0), e(-300.0, 300.0);
  std::vector<double> v;
  for (int i = 0; i < 4000; ++i) {
    const double x = m(g) * std::pow(10.0, std::floor(e(g)));
    v.push_back(i % 2 ? -x : x);
    v.push_back(std::round(m(g) * 1e3) / 8.0);
  }
  for (double x : {0.0, -0.0, 1.0, 0.1, 0.05, 200.0, 1e-3, 9.999e-4, 1e5, 99999.5, 1e-5, 123456789.0,
                   std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::epsilon()})
    v.push_back(x);
  return v;
}

std::string stream(double x, int precision, std::ios_base::fmtflags f = {}) {
  std::ostringstream s;
  s.flags(f);
  s << std::setprecision(precision) << x;
  return s.str();
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST(Format, NumberIsTheStreamDefaultAtEveryPrecision) {
  const std::uint64_t seed = 20240611;
  std::cout << "seed " << seed << "\n";
  for (double x : samples(seed))
    for (int p : {1, 3, 4, 6, 9, 10, 12, 17}) ASSERT_EQ(formatNumber(x, p), stream(x, p)) << x << " p=" << p;
  EXPECT_EQ(formatNumber(0.1), "0.1");
  EXPECT_EQ(formatNumber(1e-5), "1e-05");
  EXPECT_EQ(formatNumber(200.0, 17), "200");
  EXPECT_EQ(formatNumber(0.05, 17), "0.050000000000000003");
  EXPECT_EQ(formatNumber(kInf), "inf");
  EXPECT_EQ(formatNumber(-kInf), "-inf");
  EXPECT_EQ(formatNumber(kNaN), "nan");
}

TEST(Format, ExactIsTheLowestPrecisionThatReadsBack) {
  const std::uint64_t seed = 77;
  std::cout << "seed " << seed << "\n";
  for (double x : samples(seed)) {
    const std::string s = formatExact(x);
    ASSERT_EQ(std::strtod(s.c_str(), nullptr), x) << s;
    // it is %.{d}g with the smallest d in 15..17 that reads back
    int d = 15;
    while (d < 17 && std::strtod(formatNumber(x, d).c_str(), nullptr) != x) ++d;
    ASSERT_EQ(s, formatNumber(x, d)) << x;
  }
  EXPECT_EQ(formatExact(0.1), "0.1");
  EXPECT_EQ(formatExact(5.521e-3), "0.005521");
  EXPECT_EQ(formatExact(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(formatExact(kNaN), "nan");
}

TEST(Format, FixedIsTheStreamFixedForFiniteAndNotAvailableOtherwise) {
  for (double x : samples(5))
    for (int d : {0, 2, 3, 6})
      if (std::abs(x) < 1e30) {
        ASSERT_EQ(formatFixed(x, d), stream(x, d, std::ios_base::fixed)) << x << " d=" << d;
      }
  EXPECT_EQ(formatFixed(1.005, 2), stream(1.005, 2, std::ios_base::fixed));
  EXPECT_EQ(formatFixed(-0.5, 0), "-0");
  EXPECT_EQ(formatFixed(1e300, 2).size(), 304u);  // no truncation of large values
  EXPECT_EQ(formatFixed(kNaN, 2), "n/a");
  EXPECT_EQ(formatFixed(-kInf, 2), "n/a");
}

TEST(Format, ReadableSwitchesToExponentOutsideOneThousandthToOneHundredThousand) {
  for (double x : samples(11)) {
    const double a = std::abs(x);
    const bool sci = a != 0.0 && (a < 1e-3 || a >= 1e5);
    for (int p : {2, 3, 4})
      ASSERT_EQ(formatReadable(x, p), sci ? stream(x, p - 1, std::ios_base::scientific) : stream(x, p)) << x;
  }
  EXPECT_EQ(formatReadable(0.0), "0");
  EXPECT_EQ(formatReadable(12.345), "12.3");
  EXPECT_EQ(formatReadable(9.99e-4), "9.99e-04");
  EXPECT_EQ(formatReadable(123456.0), "1.23e+05");
  EXPECT_EQ(formatReadable(kNaN), "n/a");
  EXPECT_EQ(formatReadable(kInf), "n/a");
}
