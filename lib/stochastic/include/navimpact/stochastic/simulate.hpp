/**
 * @file simulate.hpp
 * @brief Seeded simulation of processes and composite models.
 *
 * Every stream is created from an explicit 64-bit seed; the same seed gives
 * the same samples on every run and thread count. Term i of a model uses its
 * own stream std::mt19937_64(deriveSeed(seed, i)), so adding a term leaves the
 * others unchanged. Gaussian draws use a ziggurat (Marsaglia & Tsang 2000)
 * implemented in simulate.cpp rather than std::normal_distribution, whose
 * algorithm is implementation-defined: the samples of a seed are therefore the
 * same with every standard library. No MRPT dependency.
 */
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/**
 * Simulate @p n samples of a composite model at its rate_hz.
 * GM starts from its stationary distribution, RW and DR from 0, SIN with a
 * uniform random phase, QN as in the R package (difference of uniforms).
 * @param[in] seed  any 64-bit value; derive sub-seeds with deriveSeed().
 */
std::vector<double> simulate(const Model& m, std::size_t n, std::uint64_t seed);

/// Simulate into an existing buffer (added to its content: out[k] += model_k).
void simulateAdd(const Model& m, std::uint64_t seed, double* out, std::size_t n);

/**
 * The samples of simulate(m, N, seed) in consecutive blocks, for a record too
 * long to hold: addNext(out, n) adds the next n samples to out[0..n). The
 * blocks joined are simulate(m, N, seed) bit for bit, whatever their sizes
 * (each term keeps its own stream and state between blocks); memory does not
 * grow with N.
 */
class ModelStream {
 public:
  /// @throws navimpact::Error for an invalid model (as simulate).
  ModelStream(const Model& m, std::uint64_t seed);
  ~ModelStream();
  ModelStream(ModelStream&&) noexcept;
  ModelStream& operator=(ModelStream&&) noexcept;

  /// Add the next @p n samples to @p out.
  void addNext(double* out, std::size_t n);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Deterministic sub-seed (SplitMix64 of seed and index): independent streams
/// per run/channel that do not depend on execution order.
std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t index);

}  // namespace navimpact::stochastic
