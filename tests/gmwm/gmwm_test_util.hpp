// Helpers shared by the GMWM tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "navimpact/core/imu_series.hpp"

namespace gmwmtest {

/// A recording from @p source at @p rate_hz without channels yet.
inline navimpact::ImuSeries seriesOf(const std::string& source, double rate_hz) {
  navimpact::ImuSeries s;
  s.source = source;
  s.rate_hz = rate_hz;
  return s;
}

/// The channel @p name (canonical, e.g. "gyro_z") with its quantity and no samples yet.
inline navimpact::ImuChannel channelOf(const std::string& name) {
  return {name, navimpact::channelQuantity(name), {}};
}

/// @p n samples of mean + wn_sigma e_k + z_k with z_k = phi z_{k-1} + z_sigma e'_k
/// (phi = 1: a random walk), e' then e drawn from mt19937_64(@p seed) at each sample.
inline std::vector<double> levelNoiseAndAr1(std::size_t n, std::uint64_t seed, double mean, double wn_sigma,
                                            double phi, double z_sigma) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> x(n);
  double z = 0;
  for (auto& v : x) {
    z = phi * z + z_sigma * nd(rng);
    v = mean + wn_sigma * nd(rng) + z;
  }
  return x;
}

}  // namespace gmwmtest
