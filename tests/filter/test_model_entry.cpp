// The one model-entry path: layoutFor() converts a model to the filter's IMU
// rate, returns the layout the EKF itself builds and says what changed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/stochastic/model_file.hpp"

using namespace navimpact;

namespace {

stochastic::ImuModel model(double rate_hz, double gm_T_s, double gm_sigma) {
  stochastic::ImuModel m;
  m.rate_hz = rate_hz;
  m.source = "test";
  for (int i = 0; i < 6; ++i) {
    m.axis[i].rate_hz = rate_hz;
    m.axis[i].terms = {stochastic::Process::wn(1e-3), stochastic::Process::gm(gm_sigma, gm_T_s),
                       stochastic::Process::rw(1e-6)};
  }
  return m;
}

}  // namespace

// Drawn over rates 50-1000 Hz, filter rates 50-1000 Hz, propagation 1-20
// samples and GM correlation times 1 ms - 100 s (log-uniform); seed printed.
TEST(ModelEntry, ConvertsToTheFilterRateAndAgreesWithTheFilter) {
  const std::uint64_t seed = 20261124;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> lograte(std::log(50.0), std::log(1000.0)), logT(std::log(1e-3), std::log(100.0));
  std::uniform_int_distribution<int> every(1, 20);
  std::printf("seed %llu: 40 draws\n", static_cast<unsigned long long>(seed));
  int whites = 0;
  for (int it = 0; it < 40; ++it) {
    const double model_rate = std::round(std::exp(lograte(rng))), imu_rate = std::round(std::exp(lograte(rng)));
    const double T = std::exp(logT(rng));
    filter::EkfConfig cfg;
    cfg.propagate_every = every(rng);
    SCOPED_TRACE("seed " + std::to_string(seed) + " draw " + std::to_string(it) + ": model " +
                 std::to_string(model_rate) + " Hz, filter " + std::to_string(imu_rate) + " Hz, T " +
                 std::to_string(T) + " s, propagate_every " + std::to_string(cfg.propagate_every));
    const stochastic::ImuModel m = model(model_rate, T, 1e-4);
    const filter::ModelEntry e = filter::layoutFor(m, cfg, imu_rate);
    // the model the filter gets is the exact conversion, and the first note says so
    const stochastic::ImuModel c = stochastic::convertRate(m, imu_rate);
    EXPECT_EQ(e.model.rate_hz, imu_rate);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(e.model.axis[i].terms, c.axis[i].terms);
    const bool converted = model_rate != imu_rate;
    ASSERT_EQ(e.notes.size(), (converted ? 1u : 0u) + e.layout.notes().size());
    if (converted) {
      EXPECT_NE(e.notes[0].find("converted exactly to " + std::to_string(static_cast<int>(imu_rate)) + " Hz"),
                std::string::npos)
          << e.notes[0];
    }
    // the GM is a state exactly when its T exceeds the propagation interval
    const bool white = T <= cfg.propagate_every / imu_rate;
    whites += white;
    std::printf("  draw %d: model %.0f Hz, filter %.0f Hz, GM T %.3g s, propagate_every %d: GM %s\n", it, model_rate,
                imu_rate, T, cfg.propagate_every, white ? "as white noise" : "a state");
    EXPECT_EQ(e.layout.imuSize(), white ? 6 : 12) << e.layout.describe();
    EXPECT_EQ(e.layout.notes().size(), white ? 6u : 0u);
    // the EKF builds the same layout from the same model and configuration
    const filter::ErrorStateEkf ekf(ftest::staticState(), filter::Matrix9d::Identity(), e.model, cfg);
    EXPECT_EQ(ekf.size(), e.layout.size());
  }
  // both cases were drawn
  EXPECT_GT(whites, 0);
  EXPECT_LT(whites, 40);
}

TEST(ModelEntry, ZeroRateKeepsTheModelsOwnRate) {
  const stochastic::ImuModel m = model(200.0, 10.0, 1e-4);
  const filter::ModelEntry e = filter::layoutFor(m, filter::EkfConfig{});
  EXPECT_EQ(e.model.rate_hz, 200.0);
  EXPECT_TRUE(e.notes.empty());
  EXPECT_EQ(e.layout.imuSize(), 12);
}
