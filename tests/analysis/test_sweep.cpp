// Tests of the model-sufficiency sweep (analysis/sweep.hpp):
//  - an outage of d seconds is the first d seconds of the longest one (values
//    bit-identical to a study with that single outage);
//  - any partition of shards merges to the unsharded result bit for bit, and a
//    merge refuses shards of another config, seed or build and names the
//    missing shards;
//  - the paired tests can say "no" and "yes" at their stated rates on
//    synthetic runs with effects drawn at random (seeded, logged);
//  - the white-noise threshold lands where the hidden effect crosses the
//    margin, and its bootstrap interval contains it;
//  - on the UAV excerpt the white-noise gyro model is insufficient over tens
//    of seconds of outage while the reference is sufficient.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <limits>
#include <random>
#include <sstream>

#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/report/sweep_report.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace an = navimpact::analysis;
namespace test = navimpact::test;
namespace fs = std::filesystem;

namespace {

std::string baseYaml(const std::string& sweep_block, const std::string& runs = "6") {
  const std::string traj = test::sourcePath("datasets/uav_flight_260s.csv.gz");
  const std::string mf = test::sourcePath("config/models/navchip_table1.yaml");
  return "trajectory: {file: " + traj + ", end_s: 100}\n"
         "imu: {rate_hz: 100}\n"
         "truth: {errors: model, model: " + mf + ":ref}\n"
         "candidates:\n"
         "  - {label: Gyro 1, gyroscope: " + mf + ":gyro_model1}\n"
         "  - {label: Gyro 2, gyroscope: " + mf + ":gyro_model2}\n"
         "  - {label: Ref both, model: " + mf + ":ref}\n"
         "sets:\n"
         "  - {name: gyro, models: [Gyro 1, Gyro 2, Ref both], reference: Ref both, white_noise: Gyro 1}\n"
         "monte_carlo: {runs: " + runs + ", seed: 17, threads: 2}\n"
         "filter: {propagate_every: 10}\n"
         "report: {margin: 0.25}\n" + sweep_block;
}

const std::string kSweep =
    "sweep:\n"
    "  outage: {start_s: 60, durations_s: [5, 15, 30]}\n"
    "  gnss:\n"
    "    - {name: Table 2}\n"
    "    - {name: coarse, sigma_pos_h_m: 5, sigma_pos_v_m: 10}\n"
    "  baro: [on]\n"
    "  bootstrap: 40\n";

std::string writeConfig(const std::string& text, const std::string& name = "sweep.yaml") {
  const auto dir = test::tempDir();
  const std::string p = (dir / name).string();
  std::ofstream(p) << text;
  return p;
}

std::string readFile(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// The unsharded sweep of kSweep (computed once).
const an::SweepRuns& sharedRuns() {
  static const an::SweepRuns r = [] {
    const auto cfg = an::loadSweepConfig(writeConfig(baseYaml(kSweep)));
    return an::runSweep(an::prepareSweep(cfg, "test"), an::Shard{}, 2);
  }();
  return r;
}

void expectError(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one mentioning '" << needle << "'";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(SweepConfig, EveryBadKeyIsNamed) {
  const auto load = [](const std::string& y) { return [y] { an::loadSweepConfig(writeConfig(y)); }; };
  expectError(load(baseYaml("")), "sweep");
  expectError(load(baseYaml(kSweep) + "outages: [{start_s: 1, duration_s: 2}]\n"), "outages");
  expectError(load(baseYaml("sweep: {outage: {start_s: 60, durations_s: [5, 5]}}\n")),
              "sweep.outage.durations_s[1]");
  expectError(load(baseYaml("sweep: {outage: {start_s: 60, durations_s: [0]}}\n")), "sweep.outage.durations_s[0]");
  expectError(load(baseYaml("sweep: {outage: {start_s: -1, durations_s: [5]}}\n")), "sweep.outage.start_s");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, alpha: 0.7}\n")), "sweep.alpha");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, colour: red}\n")), "sweep.colour");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, imu_rate_hz: [1e7]}\n")),
              "sweep.imu_rate_hz[0]");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, gnss: [{name: a, sigma_pos_h_m: 0}]}\n")),
              "sweep.gnss[0].sigma_pos_h_m");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, baro: [maybe]}\n")), "sweep.baro[0]");
  // a "95 %" interval of one resample; an IMU rate below the record rates (epochs fall on samples)
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}, bootstrap: 1}\n")),
              "key 'sweep.bootstrap': must be 0 or at least 39 resamples");
  expectError(load(baseYaml("record: {rate_hz: 10, outage_rate_hz: 50}\nsweep: {outage: {start_s: 6, durations_s: [5]}, imu_rate_hz: [100, 20]}\n")),
              "sweep.imu_rate_hz[1]");
  expectError(load(baseYaml("record: {outage_rate_hz: 500}\nsweep: {outage: {start_s: 6, durations_s: [5]}}\n")),
              "key 'record.outage_rate_hz': must not exceed imu.rate_hz (100 Hz)");
  expectError(load(baseYaml("sweep: {outage: {start_s: 6, durations_s: [5]}}\n", "1")), "monte_carlo.runs");
  // Outage past the trajectory: refused before any run, naming the column.
  const auto cfg = an::loadSweepConfig(writeConfig(baseYaml("sweep: {outage: {start_s: 90, durations_s: [5, 20]}}\n")));
  expectError([&] { an::prepareSweep(cfg, "test"); }, "s, after the end of the trajectory");
}

TEST(SweepRuns, AShortOutageIsTheStartOfTheLongestOneBitForBit) {
  const an::SweepRuns& sw = sharedRuns();
  const auto& meta = sw.meta;
  ASSERT_EQ(meta.columns.size(), 2u);
  // A study with the single outage (60, 75] in the first column's settings.
  an::StudyConfig sc = an::loadSweepConfig(writeConfig(baseYaml(kSweep))).study;
  sc.outages = {{60.0, 75.0}};
  const auto plan = an::prepareStudy(sc, "test");
  const auto& sm = an::studyMeta(*plan);
  std::size_t k_end = sm.epochs.size();
  for (std::size_t k = 0; k < sm.epochs.size(); ++k)
    if (std::abs(sm.epochs[k] - sm.outages[0].end_s) < 1e-9) k_end = k;
  ASSERT_LT(k_end, sm.epochs.size());
  std::vector<an::RunRecord> recs;
  an::runStudy(plan, an::Shard{}, 2, {}, [&](const an::RunRecord& r) { recs.push_back(r); });
  const auto& col = meta.columns[0];
  const std::size_t T = col.tau_s.size(), M = meta.labels.size(), kd = col.duration_epoch[1];
  EXPECT_DOUBLE_EQ(col.tau_s[kd], 15.0);
  ASSERT_EQ(recs.size(), meta.runs_total);
  for (std::size_t r = 0; r < recs.size(); ++r)
    for (std::size_t m = 0; m < M; ++m) {
      const double* d = &recs[r].models[m].epochs[k_end * 22];
      const double e = sw.values[0][((r * M + m) * T + kd) * 2], n = sw.values[0][((r * M + m) * T + kd) * 2 + 1];
      EXPECT_EQ(e, std::hypot(d[0], d[1])) << "run " << r << " model " << m;
      EXPECT_EQ(n, d[18]) << "run " << r << " model " << m;
    }
}

TEST(SweepShards, AnyPartitionMergesToTheUnshardedResultBitForBit) {
  const std::string cfg_path = writeConfig(baseYaml(kSweep));
  const auto cfg = an::loadSweepConfig(cfg_path);
  const auto plan = an::prepareSweep(cfg, "test");
  const an::SweepRuns whole = an::runSweep(plan, an::Shard{}, 2);
  const auto dir = test::tempDir();
  auto shard = [&](const std::string& name, an::Shard s, const std::string& build = "B1", unsigned threads = 1) {
    navimpact::OutputSet out(dir / name);
    an::writeSweepShard(an::runSweep(plan, s, threads), build, out);
    out.commit();
    return (dir / name).string();
  };
  // Two partitions: thirds, and a mixed one {1/2, 2/4, 4/4}.
  const std::string a = shard("a", {1, 3}), b = shard("b", {2, 3}, "B1", 2), c = shard("c", {3, 3});
  const std::string h = shard("h", {1, 2}), q2 = shard("q2", {2, 4}), q4 = shard("q4", {4, 4});
  const an::SweepResults rw = an::judgeSweep(whole);
  for (const auto& dirs : {std::vector<std::string>{c, a, b}, std::vector<std::string>{q4, h, q2}}) {
    const an::SweepRuns merged = an::mergeSweepShards(dirs, "B1");
    ASSERT_EQ(merged.values.size(), whole.values.size());
    for (std::size_t k = 0; k < whole.values.size(); ++k)
      EXPECT_TRUE(merged.values[k] == whole.values[k]) << "column " << k;
    EXPECT_EQ(navimpact::report::sweepJson(an::judgeSweep(merged)), navimpact::report::sweepJson(rw));
    // Report files (JSON, Markdown, PNG heat maps) byte for byte.
    const std::string tag = fs::path(dirs[0]).filename().string();
    const fs::path o1 = dir / ("out_whole_" + tag), o2 = dir / ("out_merged_" + tag);
    {
      navimpact::OutputSet x(o1), y(o2);
      navimpact::report::writeSweepOutputs(rw, x);
      navimpact::report::writeSweepOutputs(an::judgeSweep(merged), y);
      x.commit();
      y.commit();
    }
    for (const char* f : {"sweep.json", "report.md", "map_1.png", "map_2.png"}) {
      ASSERT_TRUE(fs::exists(o1 / f)) << f;
      EXPECT_EQ(readFile(o1 / f), readFile(o2 / f)) << f;
    }
  }
  // Refusals: a missing shard (named), an overlap, another build, seed, config.
  expectError([&] { an::mergeSweepShards({a, c}, "B1"); }, "2/3");
  expectError([&] { an::mergeSweepShards({a, b, c, h}, "B1"); }, "is in both");
  expectError([&] { an::mergeSweepShards({a, b, c}, "B2"); }, "another build");
  const std::string other_build = shard("ob", {2, 3}, "B9");
  expectError([&] { an::mergeSweepShards({a, other_build, c}, "B1"); }, "another build");
  // A shard not as navimpact writes it is refused naming its file (found by a
  // bad-input probe: shard n = 0 and a duration's epoch beyond tau_s segfaulted,
  // bootstrap -5 hung, trailing bytes and a broken timing.json passed or were
  // internal errors)
  auto edited = [&](const std::string& name, const std::string& file, const std::string& from, const std::string& to) {
    const fs::path d = dir / name;
    fs::copy(b, d);
    std::string text = readFile(d / file);
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    std::ofstream(d / file, std::ios::binary | std::ios::trunc) << text;
    return d.string();
  };
  expectError([&] { an::mergeSweepShards({a, edited("n0", "sweep_shard.json", "\"n\": 3", "\"n\": 0"), c}, "B1"); },
              "sweep_shard.json: shard 2/0 is not K/N with 1 <= K <= N");
  expectError([&] { an::mergeSweepShards({a, edited("boot", "sweep_shard.json", "\"bootstrap\": ", "\"bootstrap\": -5"), c}, "B1"); },
              "is outside [0, 100000]");
  expectError([&] { an::mergeSweepShards({a, edited("ep", "sweep_shard.json", "\"duration_epoch\": [", "\"duration_epoch\": [1000000000,"), c}, "B1"); },
              "sweep_shard.json: ");
  {
    const fs::path d = dir / "tj";
    fs::copy(b, d);
    std::ofstream(d / "timing.json") << "{garbage";
    expectError([&] { an::mergeSweepShards({a, d.string(), c}, "B1"); }, "timing.json: not a navimpact shard's timing");
  }
  {
    const fs::path d = dir / "trail";
    fs::copy(b, d);
    std::ofstream(d / "sweep_runs.bin", std::ios::app | std::ios::binary) << std::string(1000, '\0');
    expectError([&] { an::mergeSweepShards({a, d.string(), c}, "B1"); }, "sweep_runs.bin: bytes after its last column");
  }
  // values no run writes (found by a probe: NaN, inf, 1e300 and -1 merged with
  // exit 0 and moved the threshold): the first run's first horizontal error
  // (after the magic, two counts and the column's count) and its NEES
  for (const auto& [offset, value, expect] : std::vector<std::tuple<std::size_t, double, std::string>>{
           {32, -1.0, "a horizontal error not finite and >= 0"},
           {32, std::numeric_limits<double>::quiet_NaN(), "a horizontal error not finite and >= 0"},
           {32, 1e300, "a horizontal error not finite and >= 0"},
           {40, std::numeric_limits<double>::infinity(), "a position NEES neither missing nor finite and >= 0"}}) {
    const fs::path d = dir / ("val" + std::to_string(offset) + "_" + std::to_string(expect.size()) +
                              (std::isnan(value) ? "n" : std::to_string(value > 0)));
    fs::copy(b, d);
    std::fstream f(d / "sweep_runs.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offset));
    f.write(reinterpret_cast<const char*>(&value), 8);
    f.close();
    expectError([&] { an::mergeSweepShards({a, d.string(), c}, "B1"); }, "sweep_runs.bin: column 1, run ");
    expectError([&] { an::mergeSweepShards({a, d.string(), c}, "B1"); }, expect);
  }
  {
    auto cfg2 = cfg;
    cfg2.study.seed = 18;
    navimpact::OutputSet out(dir / "seed");
    an::writeSweepShard(an::runSweep(an::prepareSweep(cfg2, "test"), {2, 3}, 1), "B1", out);
    out.commit();
    expectError([&] { an::mergeSweepShards({a, (dir / "seed").string(), c}, "B1"); }, "another seed");
  }
  {
    const auto cfg3 = an::loadSweepConfig(writeConfig(baseYaml(kSweep) + "# another config\n"));
    navimpact::OutputSet out(dir / "cfg");
    an::writeSweepShard(an::runSweep(an::prepareSweep(cfg3, "test"), {2, 3}, 1), "B1", out);
    out.commit();
    expectError([&] { an::mergeSweepShards({a, (dir / "cfg").string(), c}, "B1"); }, "another config");
  }
}

// ---------------------------------------------------------------------------
// The paired tests on synthetic runs (no filter): one column, one set of two
// models (candidate 0 against reference 1), T epochs.

namespace {

struct Synthetic {
  an::SweepRuns runs;
  std::size_t R, T;
  Synthetic(std::size_t R_, std::vector<double> tau, double margin, std::size_t bootstrap, std::uint64_t seed)
      : R(R_), T(tau.size()) {
    an::SweepMeta& m = runs.meta;
    m.seed = seed;
    m.runs_total = R;
    m.margin = margin;
    m.alpha = 0.05;
    m.bootstrap = bootstrap;
    m.labels = {"WN", "Ref"};
    m.sets = {{"s", "s", {"WN", "Ref"}, "Ref", "WN"}};
    m.durations_s = {tau.back()};
    an::SweepMeta::Column col;
    col.name = "synthetic";
    col.states = {9, 18};
    col.tau_s = tau;
    col.duration_epoch = {T - 1};
    m.columns = {col};
    runs.values.assign(1, std::vector<double>(R * 2 * T * 2, 0.0));
    for (std::size_t i = 0; i < R; ++i) runs.run_indices.push_back(i);
  }
  /// Horizontal errors: Rayleigh with scale s (2-D normal), NEES: scale * chi2(3).
  /// As in a filter run, the errors of one run evolve smoothly over the
  /// outage: one draw per run, scaled by the epoch's factor.
  void fill(std::size_t model, const std::function<double(std::size_t)>& err_scale,
            const std::function<double(std::size_t)>& nees_scale, std::uint64_t seed) {
    const auto z = navimpact::emulation::standardNormal(R * 5, seed);
    for (std::size_t i = 0; i < R; ++i)
      for (std::size_t k = 0; k < T; ++k) {
        const double* g = &z[i * 5];
        double* v = &runs.values[0][((i * 2 + model) * T + k) * 2];
        v[0] = err_scale(k) * std::hypot(g[0], g[1]);
        v[1] = nees_scale(k) * (g[2] * g[2] + g[3] * g[3] + g[4] * g[4]);
      }
  }
};

}  // namespace

TEST(SweepJudge, AccuracyTestHoldsItsLevelAtTheMarginAndHasPowerBeyondIt) {
  // Candidate errors (1 + m) times the reference's in distribution (the
  // boundary of "not worse"): false alarms at most alpha + 3 Monte Carlo
  // sigmas. Candidate errors f (1 + m) times, f drawn in [1.4, 3]: found worse
  // in at least 90 % of the cells.
  const double m = 0.25;
  const std::size_t R = 200, cells = 300;
  std::mt19937_64 rng(20240611);
  int false_alarms = 0, detected = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    Synthetic s(R, {10.0}, m, 0, 1);
    const std::uint64_t seed = rng();
    s.fill(1, [](std::size_t) { return 1.0; }, [](std::size_t) { return 1.0; }, navimpact::stochastic::deriveSeed(seed, 1));
    s.fill(0, [&](std::size_t) { return 1.0 + m; }, [](std::size_t) { return 1.0; }, navimpact::stochastic::deriveSeed(seed, 2));
    false_alarms += an::judgeSweep(s.runs).columns[0].sets[0].cells[0].models[0].worse ? 1 : 0;
    const double f = 1.4 + 1.6 * double(rng() >> 11) * 0x1.0p-53;
    s.fill(0, [&](std::size_t) { return f * (1.0 + m); }, [](std::size_t) { return 1.0; },
           navimpact::stochastic::deriveSeed(seed, 3));
    const bool w = an::judgeSweep(s.runs).columns[0].sets[0].cells[0].models[0].worse;
    detected += w ? 1 : 0;
    if (!w) std::cout << "not detected: cell " << c << ", seed " << seed << ", factor " << f << "\n";
  }
  const double alpha = 0.05, mc = 3.0 * std::sqrt(alpha * (1 - alpha) / double(cells));
  std::cout << "seed 20240611: false alarms " << false_alarms << "/" << cells << ", detected " << detected << "/"
            << cells << "\n";
  EXPECT_LE(false_alarms, int((alpha + mc) * cells));
  EXPECT_GE(detected, int(0.9 * cells));
}

TEST(SweepJudge, ConsistencyIsTheWidenedNeesBandOrAsConsistentAsTheReference) {
  const double m = 0.25;
  std::mt19937_64 rng(77);
  for (int trial = 0; trial < 40; ++trial) {
    const std::uint64_t seed = rng();
    const double over = 2.0 + 8.0 * double(rng() >> 11) * 0x1.0p-53;  // over-confidence factor in [2, 10]
    Synthetic s(200, {10.0}, m, 0, 1);
    s.fill(1, [](std::size_t) { return 1.0; }, [](std::size_t) { return 1.0; }, navimpact::stochastic::deriveSeed(seed, 1));
    s.fill(0, [](std::size_t) { return 1.0; }, [&](std::size_t) { return over; }, navimpact::stochastic::deriveSeed(seed, 2));
    const auto cell = an::judgeSweep(s.runs).columns[0].sets[0].cells[0];
    EXPECT_TRUE(cell.reference_consistent) << "seed " << seed;
    EXPECT_FALSE(cell.models[0].consistent) << "seed " << seed << " over-confidence " << over;
    EXPECT_EQ(cell.recommended, "Ref") << "seed " << seed;
    // Both over-confident by the same factor: the reference is outside its
    // band, the candidate is as consistent as the reference.
    s.fill(1, [](std::size_t) { return 1.0; }, [&](std::size_t) { return over; }, navimpact::stochastic::deriveSeed(seed, 1));
    const auto cell2 = an::judgeSweep(s.runs).columns[0].sets[0].cells[0];
    EXPECT_FALSE(cell2.reference_consistent) << "seed " << seed;
    EXPECT_TRUE(cell2.models[0].consistent_as_reference) << "seed " << seed << " over-confidence " << over;
    EXPECT_EQ(cell2.recommended, "WN") << "seed " << seed;
  }
}

TEST(SweepJudge, WhiteNoiseThresholdLandsWhereTheHiddenEffectCrossesTheMargin) {
  // The WN model's error grows as 1 + a tau relative to the reference's, with
  // a drawn at random so that the crossing tau* = m / a lies in [5, 40] s;
  // epochs every 0.2 s up to 60 s, R = 400 runs. The threshold (the estimated
  // crossing, for good) must lie within 3 sigma of tau*: the RMS of R Rayleigh
  // errors scatters by 0.5 / sqrt(R) relative, the ratio of two independent
  // ones by sqrt(2) times that, i.e. sigma_ratio = (1 + m) 0.035 at the
  // crossing, and the crossing moves by sigma_ratio / a = (sigma_ratio / m) tau*
  // = 0.18 tau*. Its bootstrap interval must cover tau* in at least 10 of 12
  // draws. The cell test's own departure is a 5 %-level test at the margin: it
  // may come before tau* in at most 3 of 12 draws (binomial, p = 0.002 at
  // 5 %). Without the effect the white-noise model never departs.
  const double m = 0.25;
  std::vector<double> tau;
  for (int k = 1; k <= 300; ++k) tau.push_back(0.2 * k);
  std::mt19937_64 rng(99);
  int covered = 0, early = 0;
  const int trials = 12;
  for (int trial = 0; trial < trials; ++trial) {
    const std::uint64_t seed = rng();
    const double tstar = 5.0 + 35.0 * double(rng() >> 11) * 0x1.0p-53, a = m / tstar;
    Synthetic s(400, tau, m, 100, seed);
    s.fill(1, [](std::size_t) { return 1.0; }, [](std::size_t) { return 1.0; }, navimpact::stochastic::deriveSeed(seed, 1));
    s.fill(0, [&](std::size_t k) { return 1.0 + a * tau[k]; }, [](std::size_t) { return 1.0; },
           navimpact::stochastic::deriveSeed(seed, 2));
    const auto th = an::judgeSweep(s.runs).columns[0].sets[0].threshold;
    std::cout << "seed " << seed << ": tau* " << tstar << " s, threshold " << th.departs_s << " s, 95 % ["
              << th.lo_s << ", " << th.hi_s << "], first " << th.first_departure_s << ", significant "
              << th.significant_s << "\n";
    ASSERT_TRUE(th.defined);
    const double sigma_rel = std::sqrt(2.0) * 0.5 / std::sqrt(400.0) * (1.0 + m) / m;
    EXPECT_NEAR(th.departs_s, tstar, 3.0 * sigma_rel * tstar + 0.2) << "seed " << seed;
    covered += th.lo_s >= 0 && th.lo_s <= tstar && (th.hi_s < 0 || th.hi_s >= tstar) ? 1 : 0;
    early += th.significant_s >= 0 && th.significant_s < tstar - 0.2 ? 1 : 0;
    // The same runs without the effect: white noise never departs for good.
    s.fill(0, [](std::size_t) { return 1.0; }, [](std::size_t) { return 1.0; }, navimpact::stochastic::deriveSeed(seed, 3));
    EXPECT_LT(an::judgeSweep(s.runs).columns[0].sets[0].threshold.departs_s, 0.0) << "seed " << seed;
  }
  std::cout << "bootstrap interval covered tau* in " << covered << " of " << trials << " draws (seed 99)\n";
  std::cout << "cell test significant before tau* in " << early << " of " << trials << " draws\n";
  EXPECT_GE(covered, 10);
  EXPECT_LE(early, 3);
}

TEST(SweepFindings, WhiteNoiseGyroModelIsInsufficientOverTensOfSecondsOnTheUavFlight) {
  const an::SweepResults r = an::judgeSweep(sharedRuns());
  for (std::size_t c = 0; c < r.columns.size(); ++c) {
    const auto& set = r.columns[c].sets[0];
    const auto& last = set.cells.back();  // 30 s outage
    EXPECT_FALSE(last.models[0].sufficient) << r.meta.columns[c].name << ": Gyro 1 ANEES " << last.models[0].anees;
    EXPECT_TRUE(last.models[2].sufficient) << r.meta.columns[c].name << ": reference ANEES " << last.models[2].anees;
    EXPECT_NE(last.recommended, "Gyro 1");
    EXPECT_TRUE(set.threshold.defined);
    EXPECT_GE(set.threshold.departs_s, 0.0);
    EXPECT_LE(set.threshold.departs_s, 30.0);
  }
}
