// GMWM on every channel of a recording (gmwm/channels.hpp): the per-channel fit
// is gmwm::fit of each channel's WV with that channel's seed, the model file
// form keeps channels not fitted at "none", options are checked before any
// data, and the Allan deviation is the overlapping AVAR at octave cluster sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "gmwm_test_util.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/gmwm/channels.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

using namespace navimpact;
using stochastic::Process;

namespace {

/// Six channels of WN + GM with parameters drawn log-uniformly (seeded and printed).
ImuSeries simulatedRecording(std::uint64_t seed, std::size_t n, double rate_hz) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto logU = [&](double lo, double hi) { return lo * std::pow(hi / lo, u(g)); };
  ImuSeries s = gmwmtest::seriesOf("simulated.csv", rate_hz);
  for (std::size_t c = 0; c < kChannelNames.size(); ++c) {
    stochastic::Model m;
    m.rate_hz = rate_hz;
    const double sw = logU(1e-4, 1e-2);
    m.terms = {Process::wn(sw), Process::gm(sw * logU(0.05, 0.5), logU(0.5, 20.0))};
    std::printf("seed %llu, %s: %s\n", static_cast<unsigned long long>(seed), kChannelNames[c],
                stochastic::formatTerms(m.terms).c_str());
    s.channels.push_back({kChannelNames[c], channelQuantity(kChannelNames[c]),
                          stochastic::simulate(m, n, stochastic::deriveSeed(seed, c))});
  }
  return s;
}

}  // namespace

TEST(RecordingFit, EachChannelIsTheFitOfItsOwnWvWithItsOwnSeed) {
  const ImuSeries s = simulatedRecording(4242, 1u << 14, 100.0);
  gmwm::RecordingFitOptions o;
  o.structure = "WN+GM";
  o.channels = {"acc_y", "gyro_x"};
  o.intervals = "asymptotic";
  o.seed = 77;
  std::size_t calls = 0;
  const gmwm::RecordingFit f = gmwm::fitRecording(s, o, [&](std::size_t done, std::size_t total) {
    ++calls;
    EXPECT_EQ(done, calls);
    EXPECT_EQ(total, 2u);
  });
  EXPECT_EQ(calls, 2u);
  ASSERT_EQ(f.channels.size(), 2u);
  EXPECT_EQ(f.channels[0].name, "acc_y");  // in the order asked
  EXPECT_EQ(f.channels[1].name, "gyro_x");
  EXPECT_EQ(f.source, s.source);
  EXPECT_EQ(f.samples, s.size());
  for (const auto& c : f.channels) {
    const auto& x = s.channel(c.name).x;
    const gmwm::WaveletVariance wv = gmwm::waveletVariance(x.data(), x.size(), s.rate_hz);
    gmwm::FitOptions fo;
    fo.intervals = gmwm::IntervalMethod::Asymptotic;
    fo.seed = stochastic::deriveSeed(77, static_cast<std::uint64_t>(channelIndex(c.name)));
    const gmwm::FitResult direct = gmwm::fit(stochastic::parseStructure("WN+GM"), wv, fo);
    EXPECT_EQ(stochastic::formatTerms(c.fit.model.terms, 17), stochastic::formatTerms(direct.model.terms, 17))
        << c.name;
    EXPECT_EQ(c.fit.objective, direct.objective) << c.name;
    EXPECT_EQ(c.negligible, gmwm::negligibleTerms(direct.model, wv)) << c.name;
    EXPECT_TRUE(c.ranking.empty());
    EXPECT_EQ(stochastic::formatTerms(f.model.forChannel(c.name).terms, 17),
              stochastic::formatTerms(direct.model.terms, 17));
  }
  // The model file form: every axis at the data rate, channels not fitted "none".
  EXPECT_EQ(f.model.rate_hz, 100.0);
  for (const char* n : {"gyro_y", "gyro_z", "acc_x", "acc_z"}) {
    EXPECT_TRUE(f.model.forChannel(n).empty()) << n;
    EXPECT_EQ(f.model.forChannel(n).rate_hz, 100.0) << n;
  }
}

TEST(RecordingFit, AutoRanksWithRWeightsAndRecordsTheReason) {
  const ImuSeries s = simulatedRecording(9001, 1u << 13, 50.0);
  gmwm::RecordingFitOptions o;
  o.structure = "auto";
  o.max_gm = 1;
  o.intervals = "asymptotic";
  o.channels = {"gyro_z"};
  const gmwm::RecordingFit f = gmwm::fitRecording(s, o);
  ASSERT_EQ(f.channels.size(), 1u);
  const auto& c = f.channels[0];
  EXPECT_EQ(c.ranking.size(), gmwm::defaultCandidates(1).size());
  EXPECT_EQ(stochastic::formatTerms(c.fit.model.terms, 17),
            stochastic::formatTerms(c.ranking.front().fit.model.terms, 17));
  EXPECT_FALSE(c.why.empty());
  EXPECT_EQ(c.fit.weighting, gmwm::Weighting::Fast);
  // With other weights the pick is refitted under them and says so.
  o.weights = "model";
  const gmwm::RecordingFit fm = gmwm::fitRecording(s, o);
  EXPECT_EQ(fm.channels[0].fit.weighting, gmwm::Weighting::ModelBased);
  EXPECT_NE(fm.channels[0].why.find("refit with --weights model"), std::string::npos) << fm.channels[0].why;
}

// The chance that k of J marginal 95 % intervals miss a correct model is the
// binomial tail: 1 for k = 0, 1 - 0.95^J for k = 1, 0.05^J for k = J,
// falling with k.
TEST(OutsideCi, ChanceIsTheBinomialTail) {
  for (int J : {1, 5, 18, 27}) {
    EXPECT_EQ(gmwm::outsideCiChance(0, J), 1.0);
    EXPECT_NEAR(gmwm::outsideCiChance(1, J), 1.0 - std::pow(0.95, J), 1e-12);
    EXPECT_NEAR(gmwm::outsideCiChance(J, J), std::pow(0.05, J), 1e-12 * std::pow(0.05, J) + 1e-15);
    EXPECT_EQ(gmwm::outsideCiChance(J + 1, J), 0.0);
    for (int k = 1; k <= J; ++k) EXPECT_LT(gmwm::outsideCiChance(k, J), gmwm::outsideCiChance(k - 1, J));
  }
  // P(X >= 2), J = 18: 1 - 0.95^18 - 18 * 0.05 * 0.95^17.
  EXPECT_NEAR(gmwm::outsideCiChance(2, 18), 1.0 - std::pow(0.95, 18) - 18 * 0.05 * std::pow(0.95, 17), 1e-12);
}

// scalesOutsideCi lists exactly the scales where the model WV leaves the CI.
// The true model of a simulated record misses beyond chance (outsideCiChance
// < 0.05) in about 5 % of records; a model without the record's GM misses
// beyond chance on every record. Parameters drawn log-uniformly (seeded, printed):
// WN sigma in [1e-4, 1e-2], GM sigma / WN sigma in [0.3, 3], T in [20, 400] samples.
TEST(OutsideCi, TrueModelWithinChanceModelWithoutItsGmBeyond) {
  const std::uint64_t seed = 8128;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto logU = [&](double lo, double hi) { return lo * std::pow(hi / lo, u(g)); };
  const int records = 60;
  const double rate = 100.0;
  int true_beyond = 0;
  for (int r = 0; r < records; ++r) {
    stochastic::Model m;
    m.rate_hz = rate;
    const double sw = logU(1e-4, 1e-2);
    m.terms = {Process::wn(sw), Process::gm(sw * logU(0.3, 3.0), logU(20.0, 400.0) / rate)};
    const std::vector<double> x = stochastic::simulate(m, 1u << 15, stochastic::deriveSeed(seed, r));
    const gmwm::WaveletVariance wv = gmwm::waveletVariance(x.data(), x.size(), rate);
    const std::vector<int> out = gmwm::scalesOutsideCi(m, wv);
    const Eigen::VectorXd nu = stochastic::haarWv(m, wv.tau);
    std::vector<int> direct;
    for (int j = 0; j < wv.scales(); ++j)
      if (nu[j] < wv.ci_low[j] || nu[j] > wv.ci_high[j]) direct.push_back(j);
    EXPECT_EQ(out, direct);
    const double chance = gmwm::outsideCiChance(static_cast<int>(out.size()), wv.scales());
    true_beyond += chance < 0.05;
    stochastic::Model wn_only = m;
    wn_only.terms.pop_back();
    const std::vector<int> out_wn = gmwm::scalesOutsideCi(wn_only, wv);
    const double chance_wn = gmwm::outsideCiChance(static_cast<int>(out_wn.size()), wv.scales());
    EXPECT_LT(chance_wn, 0.05) << "seed " << seed << " record " << r << ": " << stochastic::formatTerms(m.terms);
    std::printf("seed %llu record %d: %s: true model outside at %zu of %d (chance %.3g), without GM at %zu (chance %.3g)\n",
                static_cast<unsigned long long>(seed), r, stochastic::formatTerms(m.terms).c_str(), out.size(),
                wv.scales(), chance, out_wn.size(), chance_wn);
  }
  // 5 % of 60 is 3; P(Binomial(60, 0.05) > 8) < 0.005.
  std::printf("true model beyond chance on %d of %d records\n", true_beyond, records);
  EXPECT_LE(true_beyond, 8);
}

// whiteNoiseNote names each GM below kWhiteGmMaxSamples samples with T in s and
// samples and its lag-1 correlation, and says when the WN term vanished; a
// model without such a GM has no note. T drawn uniformly in samples (seeded).
TEST(WhiteNoiseNote, NamesShortGmsAndAVanishedWn) {
  std::mt19937_64 g(3141);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int r = 0; r < 20; ++r) {
    stochastic::Model m;
    m.rate_hz = 50.0 + 950.0 * u(g);
    const double samples = 0.05 + (stochastic::kWhiteGmMaxSamples - 0.05) * u(g);
    const double long_samples = stochastic::kWhiteGmMaxSamples * (1.0 + 1000.0 * u(g));
    m.terms = {Process::wn(1e-3), Process::gm(2e-3, long_samples / m.rate_hz),
               Process::gm(5e-3, samples / m.rate_hz)};
    std::printf("record %d: %s at %.1f Hz (%.3g samples)\n", r, stochastic::formatTerms(m.terms).c_str(), m.rate_hz,
                samples);
    const std::string kept = gmwm::whiteNoiseNote(m, {false, false, false});
    EXPECT_NE(kept.find("GM 2 (T = "), std::string::npos) << kept;
    EXPECT_EQ(kept.find("GM 1 "), std::string::npos) << kept;
    char lag[64];
    std::snprintf(lag, sizeof lag, "lag-1 correlation %.3g", std::exp(-1.0 / samples));
    EXPECT_NE(kept.find(lag), std::string::npos) << kept << " / " << lag;
    EXPECT_EQ(kept.find("negligible"), std::string::npos) << kept;
    const std::string gone = gmwm::whiteNoiseNote(m, {true, false, false});
    EXPECT_NE(gone.find("the WN term is negligible"), std::string::npos) << gone;
    m.terms.pop_back();
    EXPECT_EQ(gmwm::whiteNoiseNote(m, {false, false}), "");
  }
  stochastic::Model m;
  m.rate_hz = 100.0;
  m.terms = {Process::gm(1.0, 0.01)};
  EXPECT_THROW(gmwm::whiteNoiseNote(m, {}), Error);
}

// slowGmNote: a GM with T beyond the record, seen by the data, is a random walk
// over it, RW(gamma = sigma sqrt(1 - phi^2)), when the two WVs differ by less
// than 0.1 CI width. Over the record GM and RW WVs differ by about v (T_rec/T)
// times 0.1 CI width for a GM of visibility v (its WV at the longest scale in
// units of 0.1 CI width; measured: the note starts near T = 7 v records), so
// T >= 20 v records must give the note naming that gamma and T <= 2 v records
// must not. T drawn log-uniformly over [1, 1000] records (the fit's bound), v
// over [1, 100] (seeded, printed). T below the record, or a GM the data cannot
// see: no note.
TEST(SlowGmNote, AGmBeyondTheRecordIsNamedAsItsRandomWalk) {
  std::mt19937_64 g(2718);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto logU = [&](double lo, double hi) { return lo * std::pow(hi / lo, u(g)); };
  stochastic::Model data;
  data.rate_hz = 100.0;
  data.terms = {Process::wn(1e-3), Process::rw(1e-6)};
  const std::size_t n = std::size_t{1} << 15;
  const std::vector<double> x = stochastic::simulate(data, n, 99);
  const gmwm::WaveletVariance wv = gmwm::waveletVariance(x.data(), n, data.rate_hz);
  const int J = wv.scales() - 1;
  const double record_s = n / data.rate_hz;
  const double width = wv.ci_high[J] - wv.ci_low[J];
  int named = 0, kept_apart = 0;
  for (int r = 0; r < 60; ++r) {
    const bool beyond = r % 3 != 0;
    const double T = record_s * (beyond ? logU(1.0, 1000.0) : logU(0.01, 0.99));
    const double visible = logU(1.0, 100.0);
    // gamma^2 from the RW's WV at the longest scale (linear in gamma^2)
    const double g2 = visible * gmwm::kNegligibleFraction * width /
                      stochastic::haarWv(Process::rw(1.0), data.rate_hz, wv.tau[J]);
    const double sigma = std::sqrt(g2 / -std::expm1(-2.0 / (data.rate_hz * T)));
    stochastic::Model m;
    m.rate_hz = data.rate_hz;
    m.terms = {Process::wn(1e-3), Process::gm(sigma, T)};
    const std::string note = gmwm::slowGmNote(m, wv);
    std::printf("case %d: T = %.3g records, %.3g x 0.1 CI width: %s\n", r, T / record_s, visible,
                note.empty() ? "no note" : "note");
    if (beyond && T >= 20.0 * visible * record_s) {
      ++named;
      char rw[64];
      std::snprintf(rw, sizeof rw, "RW(gamma=%.3g)", std::sqrt(g2));
      EXPECT_NE(note.find("GM 1 (T = "), std::string::npos) << note;
      EXPECT_NE(note.find(rw), std::string::npos) << note << " / " << rw;
      EXPECT_NE(note.find("is a random walk over this record"), std::string::npos) << note;
      EXPECT_EQ(note.find("upper bound"), std::string::npos) << note;
    } else if (!beyond || T <= 2.0 * visible * record_s) {
      ++kept_apart;
      EXPECT_EQ(note, "") << "T = " << T;
    }
    m.terms[1].sigma = sigma * 1e-3;  // a millionth of the WV: the data cannot see it
    EXPECT_EQ(gmwm::slowGmNote(m, wv), "");
  }
  std::printf("%d cases named, %d kept apart, the rest between\n", named, kept_apart);
  EXPECT_GE(named, 5);
  EXPECT_GE(kept_apart, 25);
  // on the fit's bound the note says so (a visible GM there: its increments as the data's RW)
  stochastic::Model m;
  m.rate_hz = data.rate_hz;
  const double T = 1000.0 * record_s;
  m.terms = {Process::wn(1e-3), Process::gm(1e-6 / std::sqrt(-std::expm1(-2.0 / (data.rate_hz * T))), T)};
  EXPECT_NE(gmwm::slowGmNote(m, wv).find("the fit's upper bound"), std::string::npos) << gmwm::slowGmNote(m, wv);
}

TEST(RecordingFit, BadOptionsAreRefusedBeforeAnyData) {
  auto msg = [](gmwm::RecordingFitOptions o) {
    try {
      gmwm::checkRecordingFitOptions(o);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  gmwm::RecordingFitOptions o;
  EXPECT_EQ(msg(o), "");
  o.structure = "WN+XX";
  EXPECT_NE(msg(o).find("'XX'"), std::string::npos) << msg(o);
  o = {};
  o.max_gm = 4;
  EXPECT_NE(msg(o).find("--max-gm"), std::string::npos);
  o = {};
  o.weights = "fast";
  EXPECT_NE(msg(o).find("--weights"), std::string::npos);
  o = {};
  o.intervals = "bootstrap";
  EXPECT_NE(msg(o).find("--intervals"), std::string::npos);
  o = {};
  o.bootstrap = -1;
  EXPECT_NE(msg(o).find("--bootstrap"), std::string::npos);
  o.bootstrap = 5;  // fewer than a 95 % percentile interval needs
  EXPECT_NE(msg(o).find("--bootstrap must be 0 or at least 39"), std::string::npos) << msg(o);
  o = {};
  o.channels = {"gyro_w"};
  EXPECT_NE(msg(o).find("'gyro_w'"), std::string::npos);
  // A channel the recording lacks names the recording.
  ImuSeries s = simulatedRecording(1, 1u << 12, 100.0);
  s.channels.pop_back();
  o = {};
  o.channels = {"acc_z"};
  try {
    gmwm::fitRecording(s, o);
    ADD_FAILURE() << "no error for a missing channel";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("simulated.csv"), std::string::npos) << e.what();
  }
}

TEST(RecordingWv, AllanDeviationAtOctaveClusterSizes) {
  const std::size_t n = 5000;  // not a power of two: the largest cluster is 2048 <= n/2
  const ImuSeries s = simulatedRecording(31337, n, 200.0);
  const gmwm::RecordingWv w = gmwm::recordingWv(s, {}, true);
  ASSERT_EQ(w.channels.size(), 6u);
  EXPECT_TRUE(w.allan);
  for (std::size_t c = 0; c < 6; ++c) {
    const auto& ch = w.channels[c];
    EXPECT_EQ(ch.name, s.channels[c].name);
    const gmwm::WaveletVariance direct = gmwm::waveletVariance(s.channels[c].x.data(), n, 200.0);
    EXPECT_EQ(ch.wv.wv, direct.wv);
    ASSERT_EQ(ch.allan_tau_s.size(), 12u);  // m = 1 .. 2048
    ASSERT_EQ(ch.adev.size(), 12u);
    Eigen::VectorXd m(12);
    for (int k = 0; k < 12; ++k) {
      m[k] = std::ldexp(1.0, k);
      EXPECT_DOUBLE_EQ(ch.allan_tau_s[k], m[k] / 200.0);
    }
    const Eigen::VectorXd avar = gmwm::allanVariance(s.channels[c].x.data(), n, m);
    for (int k = 0; k < 12; ++k) EXPECT_DOUBLE_EQ(ch.adev[k] * ch.adev[k], avar[k]);
  }
  const gmwm::RecordingWv w0 = gmwm::recordingWv(s, {}, false);
  EXPECT_TRUE(w0.channels[0].adev.empty());
}
