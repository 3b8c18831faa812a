// The filter's state count is bounded: a model with more error states on one
// axis than limits::kMaxImuStatesPerAxis is refused when the layout is built
// (2000 GM terms per axis used to hang in the covariance factorisation).
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/filter/state_layout.hpp"

using namespace navimpact;

namespace {
stochastic::ImuModel gms(int axis, int count, std::mt19937_64& rng) {
  stochastic::ImuModel m;
  m.source = "many.yaml:big";
  m.rate_hz = 100.0;
  for (auto& a : m.axis) {
    a.rate_hz = 100.0;
    a.terms = {stochastic::Process::wn(1e-3)};
  }
  std::uniform_real_distribution<> u(0.0, 1.0);
  for (int k = 0; k < count; ++k)
    m.axis[axis].terms.push_back(stochastic::Process::gm(1e-4 * (0.5 + u(rng)), 1.0 + 1000.0 * u(rng)));
  return m;
}
}  // namespace

TEST(StateLimits, ModelWithMoreStatesPerAxisThanTheLimitIsRefused) {
  const std::uint64_t seed = 321;
  std::mt19937_64 rng(seed);
  for (int k = 0; k < 5; ++k) {
    const int axis = static_cast<int>(rng() % 6);
    const int count = limits::kMaxImuStatesPerAxis + 1 + static_cast<int>(rng() % 2000);
    std::printf("seed %llu case %d: axis %d, %d GM terms\n", static_cast<unsigned long long>(seed), k, axis, count);
    const auto m = gms(axis, count, rng);
    try {
      filter::StateLayout::build(m);
      FAIL() << count << " GM terms accepted";
    } catch (const Error& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find("model many.yaml:big: "), std::string::npos) << w;
      EXPECT_NE(w.find("needs more than 32 error states (" + std::to_string(count + 1) + " terms)"), std::string::npos)
          << w;
    }
  }
  const auto ok = gms(static_cast<int>(rng() % 6), limits::kMaxImuStatesPerAxis, rng);  // exactly the limit
  EXPECT_EQ(filter::StateLayout::build(ok).size(), 9 + limits::kMaxImuStatesPerAxis);
}
