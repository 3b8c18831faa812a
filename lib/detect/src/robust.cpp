#include "robust.hpp"

#include <algorithm>
#include <cmath>

#include <boost/math/distributions/normal.hpp>

namespace navimpact::detect {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  const double hi = v[h];
  if (v.size() % 2 == 1) return hi;
  const double lo = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h));
  return 0.5 * (lo + hi);
}

double madScale(const std::vector<double>& v, double* med_out) {
  const double m = median(v);
  std::vector<double> d(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) d[i] = std::abs(v[i] - m);
  if (med_out) *med_out = m;
  return 1.4826 * median(std::move(d));
}

double twoSidedNormalQuantile(double p) {
  p = std::clamp(p, 1e-300, 1.0);
  return boost::math::quantile(boost::math::complement(boost::math::normal(), 0.5 * p));
}

}  // namespace navimpact::detect
