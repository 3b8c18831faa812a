// navimpact diagnose on records with one (or two) hidden effects whose every
// parameter is drawn at random over its documented range (seeded; the root
// seed, the draws and every miss are printed): sampling rate 50-1000 Hz,
// record length, white-noise level, base model (WN, WN+GM, WN+RW), channel,
// and per cause its own range (sinusoid 5/record to 0.45 rate, GM T 2/rate to
// record/5, level shifts anywhere in the middle 80 %, ...). The effect size
// is 5x the stated detection limit (README "Detection power"); the tests
// assert the issue's bars: null false alarms <= alpha + 3 Monte Carlo
// standard errors, power >= 0.9, right cause and parameter in >= 90 % of the
// detected cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <thread>
#include <sstream>
#include <string>
#include <vector>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"
#include "navimpact/analysis/diagnose_power.hpp"
#include "navimpact/report/diagnosis_report.hpp"
#include "test_support.hpp"

namespace na = navimpact::analysis;
namespace ns = navimpact::stochastic;
namespace pw = navimpact::analysis::power;

namespace {

int runs(int dflt) {
  if (const char* e = std::getenv("NAVIMPACT_DIAGNOSE_RUNS")) return std::max(5, std::atoi(e));
  return dflt;
}

std::uint64_t rootSeed() {
  std::uint64_t s = 20261124;
  if (const char* e = std::getenv("NAVIMPACT_DIAGNOSE_SEED")) s = std::strtoull(e, nullptr, 10);
  return s;
}

using navimpact::test::plausibleMaxCount;
using navimpact::test::plausiblyAtLeast;

pw::DrawRanges testRanges() {
  pw::DrawRanges r;
  r.min_samples = 1 << 15;  // shorter records than the command's defaults keep CI cheap
  r.max_samples = 1 << 17;
  return r;
}

/// The diagnosis of a drawn record as the tests run it: one thread, four
/// simulations of the model, the record's own seed.
na::Diagnosis diagnoseCase(const pw::Case& c, std::uint64_t seed) {
  na::DiagnoseOptions o;
  o.seed = seed;
  o.threads = 1;
  o.simulations = 4;
  return na::diagnose(c.data, c.model, o);
}

/// 2^15 samples at 100 Hz of white noise (gyros 1e-3 rad/s, accelerometers
/// 1e-2 m/s^2) from @p seed, and a model of that noise whose gyros add a
/// random walk of @p gamma the record lacks.
/// A 100 Hz record of the six channels, channel k @p n samples of @p truth(k)
/// from the seed @p seedOf(k); the model is left to the caller (at 100 Hz).
pw::Case simulatedCase(const std::function<ns::Model(int)>& truth, std::size_t n,
                       const std::function<std::uint64_t(int)>& seedOf) {
  pw::Case c;
  c.data.source = "simulated";
  c.data.rate_hz = c.model.rate_hz = 100.0;
  for (int k = 0; k < 6; ++k) {
    navimpact::ImuChannel ch;
    ch.name = navimpact::kChannelNames[k];
    ch.quantity = navimpact::channelQuantity(ch.name);
    ch.x = ns::simulate(truth(k), n, seedOf(k));
    c.data.channels.push_back(std::move(ch));
    c.model.axis[k].rate_hz = 100.0;
  }
  return c;
}

/// A model of one term at 100 Hz.
ns::Model oneTerm(const ns::Process& p) {
  ns::Model m;
  m.rate_hz = 100.0;
  m.terms = {p};
  return m;
}

pw::Case whiteNoiseUnderGyroRandomWalk(double gamma, std::uint64_t seed) {
  auto wn = [](int k) { return oneTerm(ns::Process::wn(k < 3 ? 1e-3 : 1e-2)); };
  pw::Case c = simulatedCase(wn, 1 << 15, [seed](int k) { return ns::deriveSeed(seed, k); });
  for (int k = 0; k < 6; ++k) {
    c.model.axis[k] = wn(k);
    if (k < 3) c.model.axis[k].terms.push_back(ns::Process::rw(gamma));
  }
  return c;
}

/// The diagnosis of whiteNoiseUnderGyroRandomWalk(gamma, data_seed) with root
/// seed @p seed, its summary printed under "trial @p trial".
na::Diagnosis diagnoseWhiteNoiseUnderRw(int trial, double gamma, std::uint64_t data_seed, std::uint64_t seed) {
  const na::Diagnosis d = diagnoseCase(whiteNoiseUnderGyroRandomWalk(gamma, data_seed), seed);
  std::printf("trial %d: gyro model WN(1e-3) + RW(gamma=%.4g) on white noise:\n%s", trial, gamma,
              navimpact::report::diagnosisSummary(d).c_str());
  return d;
}

/// Scales of @p ch the WV test rejects a factor 2 below the model.
int rejectedBelowModel(const na::ChannelDiagnosis& ch) {
  int rejected = 0;
  for (const auto& sc : ch.scales) rejected += sc.significant && sc.ratio < 0.5 ? 1 : 0;
  return rejected;
}

struct Tally {
  int total = 0, detected = 0, right = 0;
};

Tally powerOf(na::Cause cause, int R, std::uint64_t seed, double snr_factor) {
  Tally t;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(seed, static_cast<std::uint64_t>(r));
    const pw::Case c = pw::drawCase({cause}, testRanges(), snr_factor, s);
    const auto d = diagnoseCase(c, s);
    const pw::Outcome out = pw::judge(c, d);
    ++t.total;
    t.detected += out.detected[0];
    t.right += out.right[0];
    if (!out.right[0]) std::cout << "  [" << na::causeName(cause) << " seed " << s << "] " << out.why << "\n";
  }
  std::cout << "diagnose " << na::causeName(cause) << " at " << snr_factor << "x the limit: detected "
            << t.detected << "/" << t.total << ", right cause and parameter " << t.right << "/" << t.detected
            << " (root seed " << seed << ")\n";
  return t;
}

}  // namespace

TEST(Diagnose, NullRecordsFalseAlarmsAtAlpha) {
  // Six-channel records drawn from the model itself, alpha 5 % for the whole
  // record (so that the rate is measurable with few records).
  const int R = runs(40);
  int alarms = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(rootSeed(), 900000u + r);
    pw::DrawRanges rg = testRanges();
    rg.max_samples = 1 << 15;
    const pw::Case c = pw::drawCase({}, rg, 0.0, s, 6);
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 2;
    o.simulations = 4;
    o.alpha = 0.05;
    const auto d = na::diagnose(c.data, c.model, o);
    if (!d.adequate) {
      ++alarms;
      std::cout << "  [null seed " << s << "] " << c.text << ":" << pw::describe(d) << "\n";
    }
  }
  std::cout << "diagnose null: " << alarms << "/" << R << " records called inadequate at alpha 0.05\n";
  EXPECT_LE(alarms, plausibleMaxCount(R, 0.05));
}

// The channels go over the worker pool: diagnosis.json is the same whatever the
// thread count, on a six-channel record with one hidden effect of a cause
// drawn at random (seeded; printed) at 5x its detection limit.
TEST(DiagnoseThreads, ResultDoesNotDependOnTheThreadCount) {
  const std::uint64_t s = ns::deriveSeed(rootSeed(), 770000u);
  const std::vector<na::Cause> all = {na::Cause::WhiteNoise, na::Cause::QuantizationNoise, na::Cause::RandomWalk,
                                      na::Cause::Drift,      na::Cause::GaussMarkov,       na::Cause::Sinusoid,
                                      na::Cause::LevelShift, na::Cause::Outliers};
  const na::Cause cause = all[s % all.size()];
  pw::DrawRanges rg = testRanges();
  rg.max_samples = 1 << 15;
  const pw::Case c = pw::drawCase({cause}, rg, 5.0, s, 6);
  std::cout << "seed " << s << ": " << c.text << "\n";
  std::string one;
  for (int threads : {1, 2, 6}) {
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = threads;
    o.simulations = 4;
    const std::string json = navimpact::report::diagnosisJson(na::diagnose(c.data, c.model, o), "{}");
    if (threads == 1) {
      one = json;
    } else {
      EXPECT_EQ(json, one) << threads << " threads";
    }
  }
}

// diagnose-power's records go over the worker pool: every run (cause, SNR,
// rate, length, verdict and why) and the null alarms are the same on 1 and 3
// threads. Three causes drawn at random (seeded; printed), short records.
// All cores (threads 0) means as many workers as the memory budget holds, at
// least one; explicit threads are kept (and then judged by the budget): the
// defaults must not be refused on a machine with many cores.
TEST(DiagnoseThreads, PowerWorkersFitTheMemoryBudget) {
  pw::PowerOptions o;
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  o.ranges.min_samples = o.ranges.max_samples = 1 << 18;  // 38 MB per worker
  EXPECT_EQ(pw::powerThreads(o), std::min(hw, 52u));
  o.ranges.max_samples = 100000000;  // 14 GB per worker: one, which the budget then refuses
  EXPECT_EQ(pw::powerThreads(o), 1u);
  EXPECT_THROW(pw::checkPowerOptions(o), navimpact::Error);
  o.ranges.max_samples = 1 << 18;
  o.threads = 3;
  EXPECT_EQ(pw::powerThreads(o), 3u);
  EXPECT_NO_THROW(pw::checkPowerOptions(o));
}

TEST(DiagnoseThreads, PowerDoesNotDependOnTheThreadCount) {
  const std::uint64_t s = ns::deriveSeed(rootSeed(), 771000u);
  std::vector<na::Cause> all = {na::Cause::WhiteNoise, na::Cause::QuantizationNoise, na::Cause::RandomWalk,
                                na::Cause::Drift,      na::Cause::GaussMarkov,       na::Cause::Sinusoid,
                                na::Cause::LevelShift, na::Cause::Outliers};
  std::mt19937_64 g(s);
  std::shuffle(all.begin(), all.end(), g);
  pw::PowerOptions o;
  o.causes.assign(all.begin(), all.begin() + 3);
  o.runs_per_cause = 1;
  o.null_runs = 2;
  o.min_snr = 1.0;
  o.max_snr = 10.0;
  o.ranges.min_samples = 1 << 13;
  o.ranges.max_samples = 1 << 14;
  o.seed = s;
  std::cout << "seed " << s << ": causes";
  for (auto c : o.causes) std::cout << " " << na::causeName(c);
  std::cout << "\n";
  o.threads = 1;
  const pw::PowerResult one = pw::runPower(o);
  o.threads = 3;
  const pw::PowerResult three = pw::runPower(o);
  EXPECT_EQ(three.null_runs, one.null_runs);
  EXPECT_EQ(three.null_alarms, one.null_alarms);
  ASSERT_EQ(three.runs.size(), one.runs.size());
  for (std::size_t i = 0; i < one.runs.size(); ++i) {
    const pw::PowerRun &a = one.runs[i], &b = three.runs[i];
    EXPECT_EQ(b.cause, a.cause) << i;
    EXPECT_EQ(b.snr, a.snr) << i;
    EXPECT_EQ(b.rate_hz, a.rate_hz) << i;
    EXPECT_EQ(b.duration_s, a.duration_s) << i;
    EXPECT_EQ(b.detected, a.detected) << i;
    EXPECT_EQ(b.right, a.right) << i;
    EXPECT_EQ(b.why, a.why) << i;
  }
}

class HiddenCause : public ::testing::TestWithParam<na::Cause> {};

TEST_P(HiddenCause, FoundAtFiveTimesTheLimitWithTheRightCauseAndParameter) {
  const Tally t = powerOf(GetParam(), runs(24), ns::deriveSeed(rootSeed(), static_cast<int>(GetParam())), 5.0);
  // the issue's bars (90 % found, 90 % of those right), tested as rates
  EXPECT_TRUE(plausiblyAtLeast(t.detected, t.total, 0.9)) << t.detected << "/" << t.total << " found";
  EXPECT_TRUE(plausiblyAtLeast(t.right, t.detected, 0.9)) << t.right << "/" << t.detected << " right";
}

INSTANTIATE_TEST_SUITE_P(AllCauses, HiddenCause,
                         ::testing::Values(na::Cause::WhiteNoise, na::Cause::QuantizationNoise,
                                           na::Cause::RandomWalk, na::Cause::Drift,
                                           na::Cause::GaussMarkov, na::Cause::Sinusoid,
                                           na::Cause::LevelShift, na::Cause::Outliers),
                         [](const auto& info) { return std::string(na::causeName(info.param)); });

TEST(Diagnose, TwoEffectsOnOneChannel) {
  // A random pair of different causes (any two of the eight) on one channel,
  // each at 5x its limit in the noise it sits in (the base model plus the
  // other effect's random part), every other parameter drawn as for one
  // effect. Both must come out with the right cause and parameter and
  // nothing else on the record.
  const int R = runs(60);
  std::mt19937_64 rng(rootSeed() + 77);
  const std::vector<na::Cause> all = {na::Cause::WhiteNoise, na::Cause::QuantizationNoise, na::Cause::RandomWalk,
                                      na::Cause::Drift,      na::Cause::GaussMarkov,       na::Cause::Sinusoid,
                                      na::Cause::LevelShift, na::Cause::Outliers};
  int both = 0;
  for (int r = 0; r < R; ++r) {
    na::Cause a = all[rng() % all.size()], b = a;
    while (b == a) b = all[rng() % all.size()];
    const std::uint64_t s = rng();
    const pw::Case c = pw::drawCase({a, b}, testRanges(), 5.0, s);
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 1;
    o.simulations = 4;
    const auto d = na::diagnose(c.data, c.model, o);
    const pw::Outcome out = pw::judge(c, d);
    const bool ok = out.right[0] && out.right[1];
    both += ok;
    std::cout << "  [" << na::causeName(a) << "+" << na::causeName(b) << " seed " << s << "] "
              << (ok ? "right: " + c.text : out.why) << "\n";
  }
  // The issue's bar is 90 %, tested as a rate: the estimate from R draws has a
  // Monte Carlo standard error of about sqrt(0.9 * 0.1 / R) (3.9 points at R = 60).
  const double rate = static_cast<double>(both) / R, se = std::sqrt(0.9 * 0.1 / R);
  std::cout << "two effects on one channel: both right " << both << "/" << R << " (" << 100.0 * rate
            << " %, Monte Carlo se " << 100.0 * se << " points; root seed " << rootSeed() << ")\n";
  EXPECT_TRUE(plausiblyAtLeast(both, R, 0.9)) << both << "/" << R;
}

TEST(Diagnose, GainIsSignificantOnlyWhenTheHeldOutCriteriaImprove) {
  // On null records and on hidden effects alike, "significant" must never go
  // with a held-out objective or deviance that got worse.
  const int R = runs(16);
  int checked = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(rootSeed(), 500000u + r);
    const pw::Case c = pw::drawCase({r % 2 ? na::Cause::GaussMarkov : na::Cause::RandomWalk}, testRanges(), 1.0 + r % 5, s);
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 1;
    o.simulations = 4;
    const auto d = na::diagnose(c.data, c.model, o);
    for (const auto& ch : d.channels) {
      ++checked;
      if (ch.gain.significant) {
        EXPECT_LT(ch.gain.deviance_after, ch.gain.deviance_before) << c.text;
        EXPECT_LT(ch.gain.objective_after, ch.gain.objective_before) << c.text;
        EXPECT_LT(ch.gain.p_value, 0.05);
        EXPECT_EQ(ch.gain.direction, "better");
      }
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(Diagnose, FindingsHaveNoVanishingTermsAndNoOverlongGaussMarkov) {
  const int R = runs(16);
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(rootSeed(), 600000u + r);
    const std::vector<na::Cause> pool = {na::Cause::RandomWalk, na::Cause::Drift, na::Cause::GaussMarkov,
                                         na::Cause::LevelShift};
    const pw::Case c = pw::drawCase({pool[r % pool.size()]}, testRanges(), 2.0 + r % 4, s);
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 1;
    o.simulations = 4;
    const auto d = na::diagnose(c.data, c.model, o);
    const double record = c.data.size() / c.data.rate_hz;
    for (const auto& ch : d.channels) {
      for (const auto& p : ch.model_after.terms) {
        if (p.kind == ns::ProcessKind::GM) {
          EXPECT_LE(p.T, record / 5.0 * 1.0001) << c.text;
        }
      }
      for (const auto& f : ch.findings)
        for (const auto& kv : f.params)
          if (kv.first != "t_s") {
            EXPECT_NE(kv.second, 0.0) << na::causeName(f.cause) << " " << kv.first << " " << c.text;
          }
    }
  }
}

TEST(Diagnose, IssueCasesLowFrequencyLinesAndFourteenSeLevelShifts) {
  // The two synthetic cases of the issue, drawn at random: 2 h records at
  // 100 Hz of white noise; (a) a line of amplitude 0.2 sigma at a frequency
  // log-uniform from 5 cycles per record to 0.3 Hz must be a sinusoid (not a
  // Gauss-Markov process); (b) a level shift of 14 standard errors of the
  // difference of the two segment means, anywhere in the middle 80 %, must be
  // a level shift (not a random walk).
  std::mt19937_64 rng(rootSeed() + 1414);
  std::uniform_real_distribution<double> U(0, 1);
  const int R = runs(4);
  const double rate = 100, sigma = 0.01;
  const std::size_t n = 720000;
  int lines_ok = 0, steps_ok = 0;
  for (int r = 0; r < R; ++r) {
    for (int kind = 0; kind < 2; ++kind) {
      ns::ImuModel m;
      m.rate_hz = rate;
      m.source = "wn";
      const int ci = static_cast<int>(rng() % 6);
      m.axis[ci].rate_hz = rate;
      m.axis[ci].terms = {ns::Process::wn(sigma)};
      navimpact::ImuSeries s;
      s.rate_hz = rate;
      s.source = "issue case";
      navimpact::ImuChannel ch;
      ch.name = navimpact::kChannelNames[ci];
      ch.quantity = navimpact::channelQuantity(ch.name);
      ch.x = ns::simulate(m.axis[ci], n, rng());
      ch.x.resize(n);
      double f = 0, k0 = 0, size = 0;
      if (kind == 0) {
        f = 5.0 / (n / rate) * std::pow(0.3 / (5.0 / (n / rate)), U(rng));
        const double ph = 6.283185307179586 * U(rng);
        for (std::size_t k = 0; k < n; ++k) ch.x[k] += 0.2 * sigma * std::sin(6.283185307179586 * f * k / rate + ph);
      } else {
        k0 = std::floor((0.1 + 0.8 * U(rng)) * n);
        size = (U(rng) < 0.5 ? -1 : 1) * 14.0 * sigma * std::sqrt(1.0 / k0 + 1.0 / (n - k0));
        for (std::size_t k = static_cast<std::size_t>(k0); k < n; ++k) ch.x[k] += size;
      }
      s.channels.push_back(std::move(ch));
      na::DiagnoseOptions o;
      o.threads = 1;
      o.simulations = 4;
      const auto d = na::diagnose(s, m, o);
      bool ok = false, gm = false;
      for (const auto& fd : d.channels[0].findings) {
        if (kind == 0 && fd.cause == na::Cause::Sinusoid && std::abs(fd.get("freq_hz") - f) <= 2 * rate / n) ok = true;
        if (kind == 1 && fd.cause == na::Cause::LevelShift && std::abs(fd.get("t_s") - k0 / rate) <= 0.02 * n / rate) ok = true;
        if (fd.cause == na::Cause::GaussMarkov || fd.cause == na::Cause::RandomWalk) gm = true;
      }
      ok = ok && !gm;
      (kind == 0 ? lines_ok : steps_ok) += ok;
      std::cout << "  issue case " << (kind == 0 ? "line f=" + std::to_string(f) : "14-se step at t=" + std::to_string(k0 / rate) + " size=" + std::to_string(size))
                << ": " << (ok ? "right" : "WRONG") << pw::describe(d) << "\n";
    }
  }
  EXPECT_EQ(lines_ok, R);
  EXPECT_GE(steps_ok, R - 1);
}


TEST(Diagnose, ShiftsNearTheirLimitAreNeverAConfidentWrongName) {
  // One level shift at 1-2x its stated limit (log-uniform; the limit is the
  // window-contrast threshold, README "Detection power"), every other
  // parameter drawn as for one effect. Near the limit the likelihood-ratio
  // test of the shift against a random walk may not reject, and the WV then
  // asks for a slow term: the finding must then say "undecided" (decided =
  // false, a runner-up named). Allowed on the channel: a level shift at the
  // right time (2 % of the record), nothing, or undecided findings; a record
  // may also carry an unrelated false alarm at the level alpha (1 %), hence
  // the bound alpha + 3 Monte Carlo se on confident wrong names.
  const int R = runs(24);
  int right = 0, undecided = 0, missed = 0, wrong = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(rootSeed(), 700000u + r);
    std::mt19937_64 g(s);
    const double snr = std::exp(std::uniform_real_distribution<double>(0.0, std::log(2.0))(g));
    const pw::Case c = pw::drawCase({na::Cause::LevelShift}, testRanges(), snr, s);
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 1;
    o.simulations = 4;
    const auto d = na::diagnose(c.data, c.model, o);
    const auto& fs = d.channels[c.channel].findings;
    const double record = c.data.size() / c.data.rate_hz;
    bool bad = false, hit = false, open = false;
    for (const auto& f : fs) {
      if (f.cause == na::Cause::LevelShift && std::abs(f.get("t_s") - c.hidden[0].get("t_s")) <= 0.02 * record) hit = true;
      else if (!f.decided) open = true;
      else bad = true;
    }
    if (open) {
      // The report says so on page 1 and in the evidence; diagnosis.json
      // keeps the winner under "cause" and carries decided / runner_up.
      const std::string md = navimpact::report::diagnosisReport(d, {});
      const std::string js = navimpact::report::diagnosisJson(d, "{}");
      EXPECT_NE(md.find("| undecided between "), std::string::npos) << c.text;
      EXPECT_NE(md.find("*Undecided:*"), std::string::npos) << c.text;
      EXPECT_TRUE(js.find("\"decided\": false") != std::string::npos || js.find("\"decided\":false") != std::string::npos);
      EXPECT_NE(js.find("\"runner_up\""), std::string::npos);
    }
    wrong += bad;
    right += hit && !bad;
    undecided += open && !hit && !bad;
    missed += fs.empty();
    std::string found;
    for (const auto& f : fs)
      found += std::string(" [") + na::causeName(f.cause) + (f.decided ? "" : " undecided vs " + f.runner_up) + "]";
    std::cout << "  [shift at " << snr << "x seed " << s << "] " << (bad ? "CONFIDENT WRONG NAME: " : "") << c.text
              << " found:" << (found.empty() ? " nothing" : found) << "\n";
  }
  std::cout << "shifts at 1-2x their limit: " << right << " named a level shift, " << undecided << " undecided, " << missed
            << " not found, " << wrong << " confident wrong name(s) of " << R << " (root seed " << rootSeed() << ")\n";
  EXPECT_LE(wrong, plausibleMaxCount(R, 0.01));
}

TEST(Diagnose, StepsOfEightToTwelveStandardErrorsAreNeverMissed) {
  // White noise (sigma log-uniform 1e-4-1e-1, rate log-uniform 50-1000 Hz,
  // 2^15-2^17 samples) with one level shift of 8-12 standard errors of the
  // difference of the two segment means (uniform), at a time uniform in the
  // middle 80 %: the record leaves the model, and the test of step 3 against
  // the model alone (chi2_1 Bonferroni over 127 block boundaries, LR >= 22,
  // i.e. 4.7 standard errors at the boundary; snapping to a block boundary
  // costs well under a standard error here) misses such a shift with
  // probability below 1e-3, so a record without a finding on its channel is
  // an event of rate <= 1e-3 (at most one in 40 draws: P(2 or more) = 7.8e-4;
  // "no miss" asserted it at 4 % per run: one miss came at root seeds 1 and 4). (Tested only against the explanation without shifts, whose
  // random walk took it up, such shifts were found by nothing when the cause
  // search then found no random walk: 2, 3 and 1 of 40 records with root
  // seeds 20261124, 7, 11.) Named a level shift at the right time (2 % of
  // the record): printed; the others are a random walk or a drift,
  // undecided (README, "Small level shifts against a random walk").
  std::mt19937_64 rng(rootSeed() + 8120);
  std::uniform_real_distribution<double> U(0, 1);
  const int R = runs(40);
  int named = 0, missed = 0;
  for (int r = 0; r < R; ++r) {
    const double rate = 50.0 * std::pow(20.0, U(rng));
    const double sigma = 1e-4 * std::pow(1e3, U(rng));
    const auto n = static_cast<std::size_t>(std::pow(2.0, 15.0 + 2.0 * U(rng)));
    const int ci = static_cast<int>(rng() % 6);
    ns::ImuModel m;
    m.rate_hz = rate;
    m.source = "wn";
    m.axis[ci].rate_hz = rate;
    m.axis[ci].terms = {ns::Process::wn(sigma)};
    navimpact::ImuSeries s;
    s.rate_hz = rate;
    s.source = "step";
    navimpact::ImuChannel ch;
    ch.name = navimpact::kChannelNames[ci];
    ch.quantity = navimpact::channelQuantity(ch.name);
    ch.x = ns::simulate(m.axis[ci], n, rng());
    ch.x.resize(n);
    const double k0 = std::floor((0.1 + 0.8 * U(rng)) * static_cast<double>(n));
    const double z = 8.0 + 4.0 * U(rng);
    const double size = (U(rng) < 0.5 ? -1 : 1) * z * sigma * std::sqrt(1.0 / k0 + 1.0 / (static_cast<double>(n) - k0));
    for (std::size_t k = static_cast<std::size_t>(k0); k < n; ++k) ch.x[k] += size;
    s.channels.push_back(std::move(ch));
    na::DiagnoseOptions o;
    o.seed = rng();
    o.threads = 1;
    o.simulations = 4;
    const auto d = na::diagnose(s, m, o);
    bool hit = false;
    for (const auto& f : d.channels[0].findings)
      hit = hit || (f.cause == na::Cause::LevelShift && std::abs(f.get("t_s") - k0 / rate) <= 0.02 * static_cast<double>(n) / rate);
    named += hit;
    missed += d.channels[0].findings.empty();
    if (!hit)
      std::cout << "  [" << z << "-se step at " << k0 / static_cast<double>(n) << " of the record, " << n << " samples at " << rate
                << " Hz] found:" << pw::describe(d) << "\n";
  }
  std::cout << "steps of 8-12 standard errors: " << named << " named a level shift at the right time, " << missed
            << " with nothing found, of " << R << " (root seed " << rootSeed() << ")\n";
  EXPECT_LE(missed, plausibleMaxCount(R, 1e-3)) << "a miss rate of at most 1e-3";
}

TEST(Diagnose, AKnockIsOneTransientEventAndNothingElse) {
  // A mechanical knock: the level of 1-3 accelerometers (a random subset)
  // leaves and comes back (a box) at a time uniform in the middle 90 % of the
  // record, for a duration log-uniform in 0.02-1 s (at least 2 samples), with
  // an amplitude per channel (random sign) log-uniform in 3-100x its
  // detection limit (README "Diagnosis", transients): the edge contrast at
  // the window matched to the duration, m = max(8, L) samples, reaching the
  // threshold of the level-shift search (alpha 0.2 x 1 % / 6) under the
  // channel's model, i.e. A_lim = z_thr 2 nu(2m) m / min(L, m). Every other
  // draw (rate 50-1000 Hz, length, noise, base model WN / WN+GM / WN+RW per
  // channel) as for the null records, and the model given is the one
  // simulated: right but for the knock. The knock must be one outlier event
  // (across its channels when several) starting within max(0.05 s, 3
  // samples) of the truth, and the knocked channels must carry nothing else
  // (no short Gauss-Markov, quantisation or white-noise finding taking up
  // its energy). The same records without the knock: no finding. A record
  // may carry an unrelated false alarm at alpha (1 %): bound alpha + 3
  // Monte Carlo se on the misses of each kind.
  const int R = runs(12);
  int wrong = 0, null_alarms = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = ns::deriveSeed(rootSeed(), 810000u + r);
    pw::DrawRanges rg = testRanges();
    rg.max_samples = 1 << 16;
    pw::Case c = pw::drawCase({}, rg, 0.0, s, 6);
    std::mt19937_64 g(ns::deriveSeed(s, 1));
    std::uniform_real_distribution<double> U(0, 1);
    const std::size_t n = c.data.size();
    const double rate = c.data.rate_hz;
    const std::size_t L = std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(0.02 * std::pow(50.0, U(g)) * rate)));
    const std::size_t k0 = static_cast<std::size_t>((0.05 + 0.9 * U(g)) * static_cast<double>(n - L));
    std::vector<int> knocked = {3, 4, 5};
    std::shuffle(knocked.begin(), knocked.end(), g);
    knocked.resize(1 + g() % 3);
    std::sort(knocked.begin(), knocked.end());
    const double alpha_steps = 0.2 * 0.01 / 6.0;
    std::ostringstream txt;
    txt << c.text << "; knock at t=" << k0 / rate << " s for " << L << " samples (" << L / rate << " s) on";
    na::Diagnosis d_null;
    {
      na::DiagnoseOptions o;
      o.seed = s;
      o.threads = 2;
      o.simulations = 4;
      d_null = na::diagnose(c.data, c.model, o);
    }
    for (int ci : knocked) {
      const auto& m = c.model.axis[ci];
      const std::vector<double> zero(n, 0.0);
      const auto tt = navimpact::detect::testTransient(zero, k0, k0 + L, navimpact::detect::haarWvOf(m), alpha_steps);
      const double hm = static_cast<double>(tt.half_width);
      const double lim = tt.threshold * 2.0 * std::sqrt(navimpact::detect::haarWvOf(m)(2.0 * hm)) * hm /
                         std::min(static_cast<double>(L), hm);
      const double snr = 3.0 * std::pow(100.0 / 3.0, U(g));
      const double a = (U(g) < 0.5 ? -1 : 1) * snr * lim;
      for (std::size_t k = k0; k < k0 + L; ++k) c.data.channels[ci].x[k] += a;
      txt << " " << navimpact::kChannelNames[ci] << " (" << a << ", " << snr << "x limit)";
    }
    na::DiagnoseOptions o;
    o.seed = s;
    o.threads = 2;
    o.simulations = 4;
    const auto d = na::diagnose(c.data, c.model, o);
    const double tol = std::max(0.05, 3.0 / rate);
    const double t_true = c.data.t0_s + static_cast<double>(k0) / rate;
    std::string why;
    // One event: across channels (listed once) or the one channel's span.
    if (knocked.size() >= 2) {
      if (d.events.size() != 1) why += " " + std::to_string(d.events.size()) + " events;";
      else {
        const auto& ev = d.events[0];
        std::vector<std::string> want;
        for (int ci : knocked) want.push_back(navimpact::kChannelNames[ci]);
        std::vector<std::string> got = ev.channels;
        std::sort(got.begin(), got.end());
        if (ev.cause != na::Cause::Outliers) why += " event not outliers;";
        if (got != want) why += " event on other channels;";
        if (std::abs(ev.t_s - t_true) > tol) why += " event at t=" + std::to_string(ev.t_s) + ";";
      }
    } else if (!d.events.empty()) {
      why += " cross-channel event for a one-channel knock;";
    }
    bool unrelated = false;
    for (std::size_t q = 0; q < d.channels.size(); ++q) {
      const auto& ch = d.channels[q];
      const bool hit = std::find(knocked.begin(), knocked.end(), static_cast<int>(q)) != knocked.end();
      if (!hit) {
        unrelated = unrelated || !ch.findings.empty();
        continue;
      }
      if (ch.outlier_events.size() != 1 || std::abs(ch.outlier_events[0].t_s - t_true) > tol)
        why += " " + ch.name + ": " + std::to_string(ch.outlier_events.size()) + " outlier span(s);";
      for (const auto& f : ch.findings)
        if (f.cause != na::Cause::Outliers) why += " " + ch.name + ": " + na::causeName(f.cause) + ";";
    }
    const bool miss = !why.empty() || unrelated;
    wrong += miss;
    null_alarms += !d_null.adequate;
    std::cout << "  [knock seed " << s << "] " << txt.str() << ": " << (miss ? "WRONG" + why + (unrelated ? " finding on an unknocked channel;" : "") : "one event, nothing else")
              << pw::describe(d) << (d_null.adequate ? "" : "; WITHOUT THE KNOCK:" + pw::describe(d_null)) << "\n";
  }
  std::cout << "knocks: " << wrong << "/" << R << " not one event or with other findings; " << null_alarms << "/" << R
            << " records without the knock called inadequate (root seed " << rootSeed() << ")\n";
  EXPECT_LE(wrong, plausibleMaxCount(R, 0.01));
  EXPECT_LE(null_alarms, plausibleMaxCount(R, 0.01));
}

TEST(Diagnose, SlowCausesAreNeverAConfidentWrongName) {
  // The slow causes differ only at the coarsest scales: a random walk, a
  // drift and a Gauss-Markov process with T from record/10 to record/5
  // (log-uniform), alone or two of them on one channel, each at 1-100x its
  // stated limit (log-uniform) in the noise it sits in, every other
  // parameter drawn as for one effect. A finding may be undecided (its
  // runner-up named) or miss an effect the data do not show, but a decided
  // finding must name a hidden cause: a confident wrong name (a random walk
  // named a Gauss-Markov process, a drift where there is none) is allowed
  // at most at the bootstrap's level (5 %) plus 3 Monte Carlo se. Also
  // counted (printed): both right, undecided, a right cause whose parameter
  // took up an effect the data do not separate from it.
  const int R = runs(36);
  std::mt19937_64 rng(rootSeed() + 4242);
  const std::vector<std::vector<na::Cause>> sets = {
      {na::Cause::RandomWalk}, {na::Cause::GaussMarkov}, {na::Cause::Drift},
      {na::Cause::RandomWalk, na::Cause::GaussMarkov}, {na::Cause::RandomWalk, na::Cause::Drift},
      {na::Cause::GaussMarkov, na::Cause::Drift}};
  int right = 0, undecided = 0, absorbed = 0, missed = 0, wrong = 0;
  for (int r = 0; r < R; ++r) {
    const auto& causes = sets[static_cast<std::size_t>(r) % sets.size()];
    const std::uint64_t s = rng();
    const double snr = std::exp(std::uniform_real_distribution<double>(0.0, std::log(100.0))(rng));
    pw::DrawRanges rg = testRanges();
    rg.min_gm_T_record = 0.1;
    const pw::Case c = pw::drawCase(causes, rg, snr, s);
    const auto d = diagnoseCase(c, s);
    const pw::Outcome out = pw::judge(c, d);
    const auto& fs = d.channels[c.channel].findings;
    bool bad = false, open = false, off = false;
    for (const auto& f : fs) {
      if (!f.decided) {
        open = true;
        continue;
      }
      bool hidden = false;
      for (const auto& h : c.hidden) hidden = hidden || h.cause == f.cause;
      bad = bad || !hidden;
    }
    for (std::size_t q = 0; q < d.channels.size(); ++q)
      if (static_cast<int>(q) != c.channel && !d.channels[q].findings.empty()) bad = true;
    bool all = true;
    for (bool x : out.right) all = all && x;
    off = !bad && !open && !all && !fs.empty();
    wrong += bad;
    right += all && !open && !bad;
    undecided += open && !bad;
    absorbed += off;
    missed += fs.empty();
    std::string what;
    for (auto cs : causes) what += std::string(what.empty() ? "" : "+") + na::causeName(cs);
    std::cout << "  [" << what << " at " << snr << "x seed " << s << "] " << (bad ? "CONFIDENT WRONG NAME: " : "")
              << c.text << " found:" << pw::describe(d) << "\n";
  }
  std::cout << "slow causes at 1-100x their limits: " << right << " right, " << undecided << " undecided, " << absorbed
            << " a right cause taking up another effect, " << missed << " nothing found, " << wrong
            << " confident wrong name(s) of " << R << " (root seed " << rootSeed() << ")\n";
  EXPECT_LE(wrong, plausibleMaxCount(R, 0.05));
}



TEST(Diagnose, RandomWalkIntervalsCoverTheTruth) {
  // A random walk hidden at 2-50x its stated limit (log-uniform), every
  // other parameter drawn as for one effect: where it is found, its
  // reported 95 % interval of gamma holds the hidden gamma in at least
  // 95 % of the findings less 3 Monte Carlo se. (A profile of the WV
  // deviance treats the coarse scales as independent, which they are not
  // for a random walk: its interval was too narrow.)
  const int R = runs(40);
  std::mt19937_64 rng(rootSeed() + 5151);
  int found = 0, covered = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = rng();
    const double snr = std::exp(std::uniform_real_distribution<double>(std::log(2.0), std::log(50.0))(rng));
    const pw::Case c = pw::drawCase({na::Cause::RandomWalk}, testRanges(), snr, s);
    const auto d = diagnoseCase(c, s);
    const double truth = c.hidden.front().get("gamma_total");
    for (const auto& f : d.channels[c.channel].findings) {
      if (f.cause != na::Cause::RandomWalk) continue;
      for (const auto& kv : f.intervals)
        if (kv.first == "gamma") {
          ++found;
          const bool in = kv.second.first <= truth && truth <= kv.second.second;
          covered += in;
          if (!in)
            std::cout << "  [random_walk at " << snr << "x seed " << s << "] gamma " << truth << " outside ["
                      << kv.second.first << ", " << kv.second.second << "]: " << c.text << "\n";
        }
    }
  }
  std::cout << "random-walk intervals: " << covered << " of " << found << " hold the hidden gamma (" << R
            << " records, root seed " << rootSeed() << ")\n";
  ASSERT_GE(found, R / 2);
  const double lo = 0.95 - 3.0 * std::sqrt(0.95 * 0.05 / found);
  EXPECT_GE(covered, lo * found);
}

TEST(Diagnose, ABurstPartlyFlaggedAsSpikesIsOneEvent) {
  // Regression draw of diagnose-power (root seed 777, outliers run 10, 82.5x
  // the limit, records of 2^16-10^6 samples): the second difference flags 16
  // samples of an alternating burst, the transient test the 23 samples that
  // contain them; that is one event, not two (it was counted 20 for 19).
  pw::DrawRanges rg;
  rg.min_samples = 65536;
  rg.max_samples = 1000000;
  const std::uint64_t s = ns::deriveSeed(777, 1000000u * (static_cast<std::uint64_t>(na::Cause::Outliers) + 1) + 10);
  const pw::Case c = pw::drawCase({na::Cause::Outliers}, rg, 82.51079206538158, s);
  const auto d = diagnoseCase(c, s);
  const pw::Outcome out = pw::judge(c, d);
  EXPECT_TRUE(out.right[0]) << out.why;
  EXPECT_EQ(d.channels[c.channel].outlier_events.size(), static_cast<std::size_t>(c.hidden[0].events)) << pw::describe(d);
}


TEST(Diagnose, LargeShiftsLeaveNothingBehind) {
  // Level shifts of 20-200x their limit (log-uniform), every other
  // parameter drawn as for one effect: one finding, the right time and size.
  // A shift sized with the tests' snapped regressors left a residue the WV
  // named a random walk (regression draw of diagnose-power, root seed 777,
  // level_shift run 9, 142x: 0.01276 for 0.0129, 18 inflated se).
  {
    pw::DrawRanges rg;
    rg.min_samples = 65536;
    rg.max_samples = 1000000;
    const std::uint64_t s = ns::deriveSeed(777, 1000000u * (static_cast<std::uint64_t>(na::Cause::LevelShift) + 1) + 9);
    const pw::Case c = pw::drawCase({na::Cause::LevelShift}, rg, 142.34155249444458, s);
    const auto d = diagnoseCase(c, s);
    const pw::Outcome out = pw::judge(c, d);
    EXPECT_TRUE(out.right[0]) << out.why;
  }
  const int R = runs(24);
  std::mt19937_64 rng(rootSeed() + 2020);
  int right = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = rng();
    const double snr = 20.0 * std::exp(std::uniform_real_distribution<double>(0.0, std::log(10.0))(rng));
    const pw::Case c = pw::drawCase({na::Cause::LevelShift}, testRanges(), snr, s);
    const auto d = diagnoseCase(c, s);
    const pw::Outcome out = pw::judge(c, d);
    right += out.right[0];
    if (!out.right[0]) std::cout << "  [level_shift at " << snr << "x seed " << s << "] " << out.why << "\n";
  }
  std::cout << "level shifts at 20-200x their limit: " << right << "/" << R << " one finding, right time and size (root seed "
            << rootSeed() << ")\n";
  EXPECT_GE(right, 0.9 * R);
}

TEST(Diagnose, NoiseTermsAreNotContestedBySlowExplanations) {
  // White or quantization noise found together with a slow term (a random
  // walk, drift, long Gauss-Markov process or a level shift competing with
  // them): the slow decision compares explanations on block means that
  // every one of them computes with the same fast terms, so its runner-up
  // says nothing of the noise. A noise finding may be undecided only
  // against an explanation without that noise (the WV's), never against a
  // level shift, a drift or a random walk alone. Pairs of one noise and one
  // slow cause, each at 1-3x its limit (log-uniform: near their limits the
  // slow decision is often open), every other parameter drawn as for one
  // effect. (Without the rule, 1-4 of ~58 noise findings were undecided
  // against a slow explanation at root seeds 7, 20261124 and 11, 60 draws.)
  const int R = runs(60);
  std::mt19937_64 rng(rootSeed() + 5150);
  const std::vector<na::Cause> noise = {na::Cause::WhiteNoise, na::Cause::QuantizationNoise};
  const std::vector<na::Cause> slow = {na::Cause::RandomWalk, na::Cause::Drift, na::Cause::GaussMarkov,
                                       na::Cause::LevelShift};
  int noise_findings = 0, contested = 0;
  for (int r = 0; r < R; ++r) {
    const na::Cause a = noise[rng() % noise.size()], b = slow[rng() % slow.size()];
    const std::uint64_t s = rng();
    const double snr = std::exp(std::uniform_real_distribution<double>(0.0, std::log(3.0))(rng));
    const pw::Case c = pw::drawCase({a, b}, testRanges(), snr, s);
    const auto d = diagnoseCase(c, s);
    for (const auto& f : d.channels[c.channel].findings) {
      if (f.cause != na::Cause::WhiteNoise && f.cause != na::Cause::QuantizationNoise) continue;
      ++noise_findings;
      const bool slow_only = !f.decided && (f.runner_up == "level_shift" || f.runner_up == "random_walk" ||
                                            f.runner_up == "drift" || f.runner_up == "drift+random_walk");
      contested += slow_only;
      EXPECT_FALSE(slow_only) << c.text << " found:" << pw::describe(d);
    }
    std::cout << "  [" << na::causeName(a) << "+" << na::causeName(b) << " at " << snr << "x seed " << s << "] "
              << c.text << " found:" << pw::describe(d) << "\n";
  }
  std::cout << "noise with a slow cause: " << noise_findings << " noise finding(s), " << contested
            << " undecided against a slow explanation alone (root seed " << rootSeed() << ")\n";
}

// A model far from the record at every scale (a random walk of gamma drawn
// log-uniform over [1e2, 1e5], the upper part of the documented amplitude range,
// on white noise): the per-scale chi-square test meets dof and statistics where
// boost's incomplete gamma overflows (from gamma ~ 1e4 it threw "tgamma too
// large", exit 4 "internal error" from the command); the tails fall back to
// Wilson-Hilferty.
// Every scale's p-value is a probability, and the misfit is significant.
TEST(Diagnose, AModelFarFromTheRecordGivesProbabilitiesNotAnInternalError) {
  std::mt19937_64 g(rootSeed() + 77);
  for (int trial = 0; trial < 5; ++trial) {
    const double gamma = std::pow(10.0, std::uniform_real_distribution<double>(2.0, 5.0)(g));
    const pw::Case c = whiteNoiseUnderGyroRandomWalk(gamma, rootSeed() + trial);
    std::printf("trial %d: gyro model WN(1e-3) + RW(gamma=%.4g) on white noise\n", trial, gamma);
    na::Diagnosis d;
    ASSERT_NO_THROW(d = diagnoseCase(c, 5 + trial));
    for (int k = 0; k < 3; ++k) {
      int significant = 0;
      for (const auto& sc : d.channels[k].scales) {
        EXPECT_TRUE(sc.p_value >= 0.0 && sc.p_value <= 1.0) << d.channels[k].name << " tau " << sc.tau_s;
        significant += sc.significant ? 1 : 0;
      }
      EXPECT_GT(significant, 0) << d.channels[k].name;
    }
  }
}

// A model that overstates the noise by a random walk the record lacks (gamma
// log-uniform over [1e-6, 1e-2] on white noise of 1e-3 rad/s, 2^15 samples at
// 100 Hz: the measured WV 30x to 1e7x below the model at the coarsest scales):
// a gyro channel whose WV test rejects scales a factor 2 below the model is
// inadequate, by a finding or by the unexplained misfit the WV test leaves
// (where the coarse scales have too few dof the test may not reject: adequate).
// Before, a channel whose WV test rejected was reported adequate whenever no cause of the catalogue was kept (gyro_x and gyro_y of
// a probe at gamma 1e-5, with 7 scales rejected at p down to 1e-19).
TEST(Diagnose, AnOverstatedModelIsNeverAdequate) {
  std::mt19937_64 g(rootSeed() + 78);
  int checked = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const double gamma = std::pow(10.0, std::uniform_real_distribution<double>(-6.0, -2.0)(g));
    const na::Diagnosis d = diagnoseWhiteNoiseUnderRw(trial, gamma, rootSeed() + 100 + trial, 9 + trial);
    for (int k = 0; k < 3; ++k) {
      const auto& ch = d.channels[k];
      const int rejected = rejectedBelowModel(ch);
      if (rejected > 0) {
        ++checked;
        EXPECT_FALSE(ch.adequate) << ch.name << ": " << rejected << " scale(s) rejected";
        if (ch.findings.empty()) {
          EXPECT_LT(ch.unexplained.ratio, 0.5) << ch.name;  // named below the model
        }
      }
    }
  }
  EXPECT_GT(checked, 0);  // the draws reached the test's power at least once
}

// A model RW the record lacks is named: random_walk, overstated, also where
// its best fit is zero (that retune was refused as "a vanishing term", and the
// misfit was named quantization noise + white noise). It is retuned on the
// first half too, also where the half's best fit of it is zero: the held-out
// gain compares that extension with the model. (A retune to zero was skipped, so the first
// half kept the model's RW at its old gamma and the gain compared the model
// with itself: "14 -> 14 scales outside the CI, gain not significant" beside a
// random_walk finding.) gamma log-uniform over [1e-6, 1e-2] (as the test above) on white noise of
// 1e-3 rad/s (seeded, printed).
TEST(Diagnose, AnOverstatedTermIsRetunedOnTheHeldOutHalfToo) {
  std::mt19937_64 g(rootSeed() + 79);
  int checked = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const double gamma = std::pow(10.0, std::uniform_real_distribution<double>(-6.0, -2.0)(g));
    const na::Diagnosis d = diagnoseWhiteNoiseUnderRw(trial, gamma, rootSeed() + 200 + trial, 13 + trial);
    for (int k = 0; k < 3; ++k) {
      const auto& ch = d.channels[k];
      const int rejected = rejectedBelowModel(ch);
      bool overstated = false;
      for (const auto& f : ch.findings) {
        overstated = overstated || (f.cause == na::Cause::RandomWalk && f.direction == "overstated");
        // the cause is the model's RW (a retune to zero included), not noise the record lacks
        EXPECT_NE(f.cause, na::Cause::QuantizationNoise) << ch.name;
      }
      if (rejected > 0) {
        EXPECT_TRUE(overstated) << ch.name << ": " << rejected << " scale(s) rejected, no overstated RW named";
      }
      if (!overstated) continue;
      ++checked;
      for (const auto& t : ch.model_after_half.terms)
        if (t.kind == ns::ProcessKind::RW) {
          EXPECT_LT(t.gamma, 0.5 * gamma) << ch.name << ": the half kept the model's RW";
        }
      EXPECT_LT(ch.gain.outside_after, ch.gain.outside_before) << ch.name;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(Diagnose, ChannelsQuantisedBelowTheirQuantumAreNotAllOutliers) {
  // One channel of white noise sigma = (0.15..0.35) q rounded to a quantum q
  // drawn over 1e-4..1e-2: most samples sit on one level and each change of a
  // quantum is a many-sigma event for Gaussian noise of the record's sd. In
  // half of the records a spike of 20..1000 quanta sits at a sample drawn over
  // the whole record. The channel must be diagnosed (not emptied to a
  // constant and refused), with an outlier finding exactly when a spike was
  // hidden, and no level shift.
  const int R = runs(24);
  std::mt19937_64 g(ns::deriveSeed(rootSeed(), 77));
  std::uniform_real_distribution<double> U(0, 1);
  auto logU = [&](double a, double b) { return a * std::pow(b / a, U(g)); };
  int right = 0;
  for (int r = 0; r < R; ++r) {
    const std::uint64_t s = g();
    pw::Case c = whiteNoiseUnderGyroRandomWalk(0.0, s);
    const int ch = static_cast<int>(g() % 6);
    const double q = logU(1e-4, 1e-2), ratio = 0.15 + 0.2 * U(g);
    auto& x = c.data.channels[ch].x;
    std::normal_distribution<double> N(0.0, ratio * q);
    double m2 = 0;
    for (double& v : x) {
      v = q * std::round(N(g) / q);
      m2 += v * v;
    }
    ns::Model w;
    w.rate_hz = 100.0;
    w.terms = {ns::Process::wn(std::max(std::sqrt(m2 / static_cast<double>(x.size())), 1e-3 * q))};
    c.model.axis[ch] = w;
    for (int k = 0; k < 3; ++k) c.model.axis[k].terms.resize(1);  // no random walk
    const bool spiked = U(g) < 0.5;
    const std::size_t at = g() % x.size();
    if (spiked) x[at] += (U(g) < 0.5 ? -1.0 : 1.0) * q * std::round(logU(20, 1000));
    std::string got;
    bool ok = true;
    try {
      const auto d = diagnoseCase(c, s);
      bool outliers = false, shift = false;
      for (const auto& f : d.channels[ch].findings) {
        got += std::string(got.empty() ? "" : "+") + na::causeName(f.cause);
        if (f.cause == na::Cause::Outliers)
          outliers = f.times_s.size() == 1 && std::abs(f.times_s[0] - static_cast<double>(at) / 100.0) < 0.05;
        shift = shift || f.cause == na::Cause::LevelShift;
      }
      ok = outliers == spiked && !shift;
    } catch (const std::exception& e) {
      ok = false;
      got = e.what();
    }
    right += ok;
    std::cout << "  [seed " << s << "] " << c.data.channels[ch].name << " q " << q << " sigma/q " << ratio
              << (spiked ? " spike at sample " + std::to_string(at) : std::string(" no spike")) << ": "
              << (got.empty() ? "no finding" : got) << (ok ? "" : "  WRONG") << "\n";
  }
  EXPECT_EQ(right, R);
}

// A record with no white noise at all, a random walk only, under a model of
// white noise as large as the record's spread (what fit:WN gives it): the
// white noise is overstated (retuned to nothing) and the random walk missing.
// Restated in their joint fit, the walk is compared with the model holding the
// other term found, a white noise of zero: its text said "the measured WV is
// infx above the model". Every explanation is finite and says what it compares
// with. gamma drawn log-uniform over [1e-5, 1e-2] (seeded, printed).
TEST(Diagnose, ExplanationsAreFiniteAndSayWhatTheyCompareWith) {
  std::mt19937_64 g(navimpact::test::envOr("NAVIMPACT_DIAGNOSE_SEED", 20261124) + 77);
  const double gamma = std::exp(std::uniform_real_distribution<double>(std::log(1e-5), std::log(1e-2))(g));
  std::printf("random walk gamma %.3g per sample, no white noise\n", gamma);
  pw::Case c = simulatedCase([gamma](int) { return oneTerm(ns::Process::rw(gamma)); }, 1 << 14,
                             [&g](int k) { return ns::deriveSeed(g(), k); });
  for (int k = 0; k < 6; ++k) {
    const auto& x = c.data.channels[k].x;
    double m = 0, s = 0;
    for (double v : x) m += v / x.size();
    for (double v : x) s += (v - m) * (v - m) / (x.size() - 1);
    c.model.axis[k] = oneTerm(ns::Process::wn(std::sqrt(s)));
  }
  const na::Diagnosis d = diagnoseCase(c, 5);
  int joint = 0;
  for (const auto& ch : d.channels)
    for (const auto& f : ch.findings) {
      SCOPED_TRACE(ch.name + ": " + f.explanation);
      EXPECT_EQ(f.explanation.find("inf"), std::string::npos);
      EXPECT_EQ(f.explanation.find("nan"), std::string::npos);
      if (ch.findings.size() > 1 && f.cause == na::Cause::RandomWalk && f.explanation.find("the measured WV") != std::string::npos) {
        EXPECT_NE(f.explanation.find("the model with the other terms found"), std::string::npos);
        ++joint;
      }
    }
  std::printf("%d random-walk findings restated in a joint fit\n", joint);
}
