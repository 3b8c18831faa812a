// Overlapping Allan variance (IEEE Std 952-1997, annex C; El-Sheimy et al. 2008).
#include <cmath>
#include <string>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "wv_internal.hpp"

namespace navimpact::gmwm {

Eigen::VectorXd allanVariance(const double* x, std::size_t n, const Eigen::VectorXd& m_samples) {
  detail::checkSeries(x, n);
  // Integrated signal in sample units, theta_k = sum_{i<k} (x_i - mean), k = 0..n.
  // Removing the mean changes no second difference and keeps theta small; the
  // running sum is kept in long double so that small clusters stay exact to
  // ~1e-15 relative even on 1e7 samples.
  long double mean = 0.0L;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<long double>(n);
  std::vector<long double> theta(n + 1);
  theta[0] = 0.0L;
  for (std::size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + (x[i] - mean);

  Eigen::VectorXd avar(m_samples.size());
  for (Eigen::Index q = 0; q < m_samples.size(); ++q) {
    const double md = m_samples[q];
    if (!(md >= 1.0) || md != std::floor(md) || md > static_cast<double>(n / 2))
      throw Error("Allan variance: cluster size m = " + std::to_string(md) +
                  " must be an integer in 1.." + std::to_string(n / 2) + " for " +
                  std::to_string(n) + " samples");
    const std::size_t m = static_cast<std::size_t>(md);
    // AVAR(m) = 1 / (2 m^2 K) sum_{k=0}^{K-1} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2,
    // K = n - 2m + 1 (all fully overlapping clusters), IEEE 952 eq. C.2 in sample units.
    const std::size_t K = n - 2 * m + 1;
    long double acc = 0.0L;
    for (std::size_t k = 0; k < K; ++k) {
      const double d = static_cast<double>((theta[k + 2 * m] - theta[k + m]) - (theta[k + m] - theta[k]));
      acc += static_cast<long double>(d) * d;
    }
    avar[q] = static_cast<double>(acc / (2.0L * m * m * static_cast<long double>(K)));
  }
  return avar;
}

}  // namespace navimpact::gmwm
