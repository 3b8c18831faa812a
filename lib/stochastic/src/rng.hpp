// Gaussian and uniform draws from one std::mt19937_64 stream (internal to
// lib/stochastic). A ziggurat (Marsaglia & Tsang 2000, tables after Doornik
// 2005) rather than std::normal_distribution, whose algorithm is
// implementation-defined: the samples of a seed are the same with every
// standard library.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <random>

namespace navimpact::stochastic::detail {

/// Ziggurat tables for the standard normal, 128 layers (Doornik 2005, "An
/// Improved Ziggurat Method to Generate Normal Random Samples").
struct ZigTables {
  static constexpr int kC = 128;
  static constexpr double kR = 3.442619855899;         // start of the tail
  static constexpr double kV = 9.91256303526217e-3;    // area of each layer
  std::array<double, kC + 1> x{};
  std::array<double, kC> ratio{};
  ZigTables();
};

/// The tables, built once.
const ZigTables& zigTables();

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : eng_(seed), t_(zigTables()) {}

  /// Uniform in (0, 1), 53 random bits.
  double uniform() { return (static_cast<double>(eng_() >> 11) + 0.5) * 0x1.0p-53; }

  /// Standard normal N(0, 1).
  double normal() {
    for (;;) {
      const std::uint64_t b = eng_();
      const int i = static_cast<int>(b & 0x7F);                          // layer: bits 0..6
      const double u = static_cast<double>(b >> 11) * 0x1.0p-52 - 1.0;  // (-1,1): bits 11..63
      if (std::fabs(u) < t_.ratio[i]) return u * t_.x[i];              // inside the layer core
      if (i == 0) return tail(u < 0.0);
      const double x = u * t_.x[i];
      const double f0 = std::exp(-0.5 * (t_.x[i] * t_.x[i] - x * x));
      const double f1 = std::exp(-0.5 * (t_.x[i + 1] * t_.x[i + 1] - x * x));
      if (f1 + uniform() * (f0 - f1) < 1.0) return x;
    }
  }

 private:
  /// Marsaglia's exact tail sampler beyond kR.
  double tail(bool negative) {
    double x, y;
    do {
      x = std::log(uniform()) / ZigTables::kR;
      y = std::log(uniform());
    } while (-2.0 * y < x * x);
    return negative ? x - ZigTables::kR : ZigTables::kR - x;
  }

  std::mt19937_64 eng_;
  const ZigTables& t_;
};

}  // namespace navimpact::stochastic::detail
