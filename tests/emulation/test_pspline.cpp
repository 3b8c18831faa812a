// P-spline smoother: exactness on its null space and the documented cutoff.
#include <cmath>

#include "navimpact/core/error.hpp"
#include "navimpact/emulation/pspline.hpp"
#include "test_support.hpp"

using navimpact::emulation::PSpline;
using navimpact::emulation::PSplineOptions;

namespace {
std::vector<double> grid(double rate, double dur) {
  std::vector<double> t;
  for (int i = 0; i <= int(dur * rate); ++i) t.push_back(i / rate);
  return t;
}
}  // namespace

TEST(PSpline, ReproducesQuadraticExactlyWithDerivatives) {
  const auto t = grid(100.0, 20.0);
  std::vector<double> y(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) y[i] = 3.0 - 2.0 * t[i] + 0.7 * t[i] * t[i];
  PSpline s(t, {y}, PSplineOptions{0.5, 0.05, 3});
  for (double tt : {0.0, 0.013, 5.4321, 12.0, 19.999}) {
    double v, d1, d2;
    s.eval(0, tt, &v, &d1, &d2);
    EXPECT_NEAR(v, 3.0 - 2.0 * tt + 0.7 * tt * tt, 1e-7);  // rounding of a banded solve, condition ~1e9
    EXPECT_NEAR(d1, -2.0 + 1.4 * tt, 1e-7);
    EXPECT_NEAR(d2, 1.4, 1e-6);
  }
}

TEST(PSpline, GainAtCutoffIsAboutOneHalfAndPassbandIsFlat) {
  const double fc = 1.0;
  const auto t = grid(100.0, 60.0);
  auto gainAt = [&](double f) {
    std::vector<double> y(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) y[i] = std::sin(2 * M_PI * f * t[i]);
    PSpline s(t, {y}, PSplineOptions{fc, 0.05, 3});
    // amplitude by projection over the middle 40 s (away from the ends)
    double sc = 0, ss = 0;
    int n = 0;
    for (double tt = 10.0; tt < 50.0; tt += 0.003) {
      double v;
      s.eval(0, tt, &v, nullptr, nullptr);
      sc += v * std::cos(2 * M_PI * f * tt);
      ss += v * std::sin(2 * M_PI * f * tt);
      ++n;
    }
    return 2.0 * std::hypot(sc, ss) / n;
  };
  EXPECT_NEAR(gainAt(fc), 0.5, 0.05);
  EXPECT_NEAR(gainAt(0.1 * fc), 1.0, 1e-3);
  EXPECT_LT(gainAt(3.0 * fc), 0.01);
}

TEST(PSpline, KnotsInsideSplitsIntervals) {
  const auto t = grid(100.0, 2.0);
  std::vector<double> y(t.size(), 1.0);
  PSpline s(t, {y}, PSplineOptions{1.0, 0.05, 3});
  std::vector<double> k;
  s.knotsInside(0.02, 0.17, k);
  ASSERT_EQ(k.size(), 3u);
  EXPECT_NEAR(k[0], 0.05, 1e-12);
  s.knotsInside(0.05, 0.1, k);  // knots at the ends are not inside
  EXPECT_TRUE(k.empty());
}

TEST(PSpline, RejectsBadOptions) {
  const auto t = grid(100.0, 2.0);
  std::vector<double> y(t.size(), 1.0);
  EXPECT_THROW(PSpline(t, {y}, PSplineOptions{10.0, 0.05, 3}), navimpact::Error);
  EXPECT_THROW(PSpline({0, 1, 2}, {{1, 2, 3}}, PSplineOptions{}), navimpact::Error);
}
