// navimpact diagnose, navigation gain: measured (here: simulated "measured")
// static errors as the truth along the committed UAV flight excerpt, filter
// with the model before and after, paired runs.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace na = navimpact::analysis;
namespace ns = navimpact::stochastic;
using navimpact::ImuSeries;

namespace {

constexpr double kRate = 100.0;
constexpr std::size_t kN = std::size_t(1) << 16;  // 655 s: held-out half 327 s

ns::ImuModel wnModel() {
  ns::ImuModel m;
  m.rate_hz = kRate;
  m.source = "test-wn";
  for (int c = 0; c < 6; ++c) {
    m.axis[c].rate_hz = kRate;
    m.axis[c].terms = {ns::Process::wn(c < 3 ? 1e-3 : 3e-3)};
  }
  return m;
}

/// "Measured" record: the WN model plus, when @p hidden, a strong gyro random
/// walk on every gyro axis (what a white-noise-only model misses).
ImuSeries record(bool hidden, std::uint64_t seed) {
  const ns::ImuModel m = wnModel();
  ImuSeries s;
  s.source = "simulated";
  s.rate_hz = kRate;
  for (int c = 0; c < 6; ++c) {
    navimpact::ImuChannel ch;
    ch.name = navimpact::kChannelNames[c];
    ch.quantity = navimpact::channelQuantity(ch.name);
    ns::Model a = m.axis[c];
    if (hidden && c < 3) a.terms.push_back(ns::Process::rw(2e-5));
    ch.x = ns::simulate(a, kN, ns::deriveSeed(seed, c));
    ch.x.resize(kN);
    s.channels.push_back(std::move(ch));
  }
  return s;
}

na::NavGainOptions navOptions() {
  na::NavGainOptions o;
  o.trajectory.file = navimpact::test::sourcePath("datasets/uav_flight_260s.csv.gz");
  o.trajectory.end_s = 150.0;
  o.outages = {{90.0, 120.0}};
  o.runs = 6;
  o.seed = 11;
  o.threads = 2;
  return o;
}

na::DiagnoseOptions diagOptions() {
  na::DiagnoseOptions d;
  d.simulations = 4;
  d.threads = 2;
  d.seed = 5;
  return d;
}

/// The navigation gain of @p d on @p data, planned along the test's flight.
void addGain(na::Diagnosis& d, const ImuSeries& data) {
  const auto plan = na::prepareNavGain(navOptions(), kRate, kN);
  na::addNavigationGain(d, data, *plan);
}

}  // namespace

TEST(DiagnoseNav, BadInputFailsInPreparation) {
  auto o = navOptions();
  o.outages = {{140.0, 170.0}};  // ends after the 150 s trajectory
  try {
    na::prepareNavGain(o, kRate, kN);
    FAIL() << "outage past the trajectory accepted";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find("after the end of the trajectory"), std::string::npos) << e.what();
  }
  o = navOptions();
  try {
    na::prepareNavGain(o, kRate, 10000);  // 100 s of recording for 150 s of flight
    FAIL() << "too short recording accepted";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
  }
}

// Same model before and after (data drawn from it, so the diagnosis extends
// nothing on the WV): the paired runs must give identical errors, hence no
// gain. Fails if the two filters saw different realisations.
TEST(DiagnoseNav, IdenticalModelsGiveIdenticalPairedRuns) {
  const ImuSeries data = record(false, 3);
  na::Diagnosis d = na::diagnose(data, wnModel(), diagOptions());
  ASSERT_TRUE(d.adequate);
  addGain(d, data);
  ASSERT_TRUE(d.navigation.has_value());
  ASSERT_EQ(d.navigation->outages.size(), 1u);
  const auto& o = d.navigation->outages[0];
  ASSERT_EQ(o.h_before.size(), 6u);
  for (std::size_t r = 0; r < o.h_before.size(); ++r) {
    EXPECT_EQ(o.h_before[r], o.h_after[r]);
    EXPECT_EQ(o.nees_before[r], o.nees_after[r]);
  }
  EXPECT_EQ(o.wins, 0);
  EXPECT_FALSE(o.significant);
  // Windows from the held-out second half, spread over it.
  EXPECT_GE(d.navigation->window_offsets_s.front(), kN / 2 / kRate - 1e-9);
  EXPECT_GT(d.navigation->window_offsets_s.back(), d.navigation->window_offsets_s.front());
}

// A gyro random walk hidden from a white-noise-only model: the model before
// is overconfident (position NEES at the outage end above its 95 % band);
// the extension (a random walk, found by the WV diagnosis) brings the NEES
// down and does not make the position worse on average.
TEST(DiagnoseNav, HiddenGyroRandomWalkImprovesConsistency) {
  const ImuSeries data = record(true, 4);
  na::Diagnosis d = na::diagnose(data, wnModel(), diagOptions());
  ASSERT_FALSE(d.adequate);
  addGain(d, data);
  const auto& o = d.navigation->outages.at(0);
  std::cout << "NEES before " << o.anees_before << " after " << o.anees_after << " band "
            << o.nees_band.first << ".." << o.nees_band.second << "; h " << o.mean_h_before
            << " -> " << o.mean_h_after << " m, wins " << o.wins << "\n";
  EXPECT_GT(o.anees_before, o.nees_band.second);
  EXPECT_LT(o.anees_after, o.anees_before);
  EXPECT_LE(o.mean_h_after, o.mean_h_before * 1.05);
}
