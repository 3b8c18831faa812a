/**
 * @file golden_section.hpp
 * @brief Golden-section search for the minimum of a unimodal function on [a, b].
 */
#pragma once

#include <cmath>
#include <utility>

namespace navimpact {

/// Shrinks [a, b] around the minimum of @p f by golden-section search (Kiefer
/// 1953; Press et al., Numerical Recipes 3rd ed. sec. 10.2): at most
/// @p max_iter steps, stopping early once b - a <= @p tol (tol < 0: never).
/// Returns the final bracket; one evaluation of f per step.
template <class F>
std::pair<double, double> goldenSectionBracket(F&& f, double a, double b, int max_iter, double tol = -1.0) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = f(c), fd = f(d);
  for (int it = 0; it < max_iter && b - a > tol; ++it) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - r * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + r * (b - a);
      fd = f(d);
    }
  }
  return {a, b};
}

}  // namespace navimpact
