// Tests of the Monte Carlo emulation study (analysis/study.hpp) and the
// navigation loop it shares with the replay (analysis/nav_run.hpp).
// A short study on the committed UAV excerpt (first 100 s, 100 Hz IMU, a 30 s
// outage, a handful of runs) keeps the suite fast; the paper's findings that
// are robust at this size are asserted here, the rest is in the report.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <tuple>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/report/study_report.hpp"
#include "test_support.hpp"

namespace an = navimpact::analysis;
namespace test = navimpact::test;

namespace {

const std::string kModels = "models/navchip_table1.yaml";

std::string baseYaml(const std::string& extra_candidates = "", const std::string& outages =
                         "  - {start_s: 60, duration_s: 30}\n") {
  const std::string traj = test::sourcePath("datasets/uav_flight_260s.csv.gz");
  const std::string mf = test::sourcePath("config/" + kModels);
  return "trajectory: {file: " + traj + ", end_s: 100}\n"
         "imu: {rate_hz: 100}\n"
         "truth: {errors: model, model: " + mf + ":ref}\n"
         "candidates:\n"
         "  - {label: Acc 1, accelerometer: " + mf + ":acc_model1}\n"
         "  - {label: Acc Ref, accelerometer: " + mf + ":acc_ref}\n"
         "  - {label: Gyro 1, gyroscope: " + mf + ":gyro_model1}\n"
         "  - {label: Gyro Ref, gyroscope: " + mf + ":gyro_ref}\n"
         "  - {label: Ref both, model: " + mf + ":ref}\n" +
         extra_candidates +
         "sets:\n"
         "  - {name: accelerometer, models: [Acc 1, Acc Ref]}\n"
         "  - {name: gyroscope, models: [Gyro 1, Gyro Ref]}\n"
         "  - {name: combined, models: [Gyro 1, Ref both]}\n"
         "outages:\n" + outages +
         "monte_carlo: {runs: 6, seed: 11, threads: 2}\n"
         "filter: {propagate_every: 10}\n";
}

std::string writeConfig(const std::string& text) {
  const auto dir = test::tempDir();
  const std::string p = (dir / "study.yaml").string();
  std::ofstream(p) << text;
  return p;
}

/// One shared study for the finding tests (computed once).
const an::StudyResults& sharedStudy() {
  static const an::StudyResults r = [] {
    const an::StudyConfig cfg = an::loadStudyConfig(writeConfig(baseYaml()));
    return an::runStudy(an::prepareStudy(cfg, "test"), an::Shard{}, 2);
  }();
  return r;
}

std::size_t modelIndex(const an::StudyResults& r, const std::string& label) {
  for (std::size_t i = 0; i < r.meta.labels.size(); ++i)
    if (r.meta.labels[i] == label) return i;
  ADD_FAILURE() << "no model " << label;
  return 0;
}

std::size_t outageEndEpoch(const an::StudyResults& r) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < r.meta.epochs.size(); ++i)
    if (r.meta.epochs[i] <= r.meta.outages[0].end_s + 1e-9) k = i;
  return k;
}

double anees(const an::StudyResults& r, const std::string& label, std::size_t k, int block) {
  const auto& a = r.acc.models[modelIndex(r, label)];
  return a.nees[4 * k + block] / a.n_valid[4 * k + block];
}

double rmsH(const an::StudyResults& r, const std::string& label, std::size_t k) {
  const auto& a = r.acc.models[modelIndex(r, label)];
  return std::sqrt((a.e2[9 * k] + a.e2[9 * k + 1]) / double(r.acc.runs));
}

}  // namespace

TEST(StudyBand, ChiSquareQuantilesOfTheAverageNees) {
  // Textbook chi-square quantiles: chi2inv(0.025, 3) = 0.2158, chi2inv(0.975, 3) = 9.348.
  const auto b1 = an::aneesBand(1, 3);
  EXPECT_NEAR(b1.first, 0.2158, 1e-4);
  EXPECT_NEAR(b1.second, 9.348, 1e-3);
  // R runs: chi2inv(p, R n) / R; for R = 10, n = 3: chi2inv(0.025, 30) = 16.791, chi2inv(0.975, 30) = 46.979.
  const auto b10 = an::aneesBand(10, 3);
  EXPECT_NEAR(b10.first, 1.6791, 1e-4);
  EXPECT_NEAR(b10.second, 4.6979, 1e-4);
}

TEST(StudyConfig, BadInputIsRejectedBeforeAnyRun) {
  // An outage beyond the 100 s of trajectory.
  {
    const auto cfg = an::loadStudyConfig(writeConfig(baseYaml("", "  - {start_s: 80, duration_s: 60}\n")));
    try {
      an::prepareStudy(cfg, "test");
      FAIL() << "outage outside the trajectory accepted";
    } catch (const navimpact::Error& e) {
      EXPECT_NE(std::string(e.what()).find("s, after the end of the trajectory"), std::string::npos) << e.what();
    }
  }
  // A model name that the file does not have.
  {
    const std::string mf = test::sourcePath("config/" + kModels);
    const auto cfg = an::loadStudyConfig(
        writeConfig(baseYaml("  - {label: Bad, gyroscope: " + mf + ":gyro_model9}\n")));
    try {
      an::prepareStudy(cfg, "test");
      FAIL() << "unknown model name accepted";
    } catch (const navimpact::Error& e) {
      EXPECT_NE(std::string(e.what()).find("Bad"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("gyro_model9"), std::string::npos) << e.what();
    }
  }
  // Zero runs, an unknown key, a set naming an unknown candidate.
  std::string y = baseYaml();
  EXPECT_THROW(an::loadStudyConfig(writeConfig(y + "report: {margin: 0.2, colour: red}\n")), navimpact::Error);
  const auto pos = y.find("runs: 6");
  std::string y0 = y;
  y0.replace(pos, 7, "runs: 0");
  EXPECT_THROW(an::loadStudyConfig(writeConfig(y0)), navimpact::Error);
  std::string y1 = y;
  y1.replace(y1.find("[Acc 1, Acc Ref]"), 16, "[Acc 1, Acc 9]");
  EXPECT_THROW(an::loadStudyConfig(writeConfig(y1)), navimpact::Error);
  EXPECT_THROW(an::loadStudyConfig("/nonexistent/study.yaml"), navimpact::Error);
  EXPECT_THROW(an::parseShard("3/2"), navimpact::Error);
  EXPECT_THROW(an::parseShard("0/2"), navimpact::Error);
  EXPECT_THROW(an::parseShard("1"), navimpact::Error);
}

TEST(StudyRuns, IndependentOfThreadsAndShardingAndPaired) {
  // A duplicate of "Gyro Ref" under another label: paired runs must give it identical numbers.
  const std::string mf = test::sourcePath("config/" + kModels);
  std::string y = baseYaml("  - {label: Gyro Ref copy, gyroscope: " + mf + ":gyro_ref}\n");
  y.replace(y.find("runs: 6"), 7, "runs: 5");
  const auto cfg = an::loadStudyConfig(writeConfig(y));
  const auto plan = an::prepareStudy(cfg, "test");
  const an::StudyResults one = an::runStudy(plan, an::Shard{}, 1);
  const an::StudyResults two = an::runStudy(plan, an::Shard{}, 2);
  const std::string m1 = navimpact::report::studyMetricsJson(one), m2 = navimpact::report::studyMetricsJson(two);
  EXPECT_EQ(m1, m2) << "metrics depend on the thread count";

  // Shards 1/2 and 2/2 written to disk and merged: the same metrics, bit for bit.
  std::vector<std::string> dirs;
  for (unsigned k : {2u, 1u}) {  // merge order must not matter either
    const an::StudyResults part = an::runStudy(plan, an::Shard{k, 2}, 2);
    EXPECT_EQ(part.acc.runs, k == 1 ? 3u : 2u);
    const auto dir = test::tempDir() / ("shard" + std::to_string(k));
    navimpact::OutputSet out(dir);
    an::writeShard(part, "B1", out);
    out.commit();
    dirs.push_back(dir.string());
  }
  const an::StudyResults merged = an::mergeShards(dirs, "B1");
  EXPECT_EQ(navimpact::report::studyMetricsJson(merged), m1) << "merged shards differ from the unsharded study";

  // Missing shard: a clear error.
  EXPECT_THROW(an::mergeShards({dirs[0]}, "B1"), navimpact::Error);

  // A shard not as navimpact writes it is refused naming its file, never read on
  // (found by a bad-input probe: a set naming an unknown reference, duplicate
  // labels segfaulted; runs_total 1e12 ran out of memory; trailing bytes passed)
  auto edited = [&](const std::string& name, const std::string& from, const std::string& to) {
    const auto dir = test::tempDir() / name;
    std::filesystem::copy(dirs[1], dir);
    std::ifstream in(dir / "shard.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    std::ofstream(dir / "shard.json") << text;
    return dir.string();
  };
  auto mergeError = [&](const std::string& shard) {
    try {
      an::mergeShards({shard, dirs[0]}, "B1");
    } catch (const navimpact::Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  for (const auto& [from, to, expect] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"\"runs_total\": 5", "\"runs_total\": 1000000000000", "runs_total 1000000000000 is outside [1, 1000000]"},
           {"\"Gyro Ref copy\"", "\"Gyro Ref\"", "candidate label 'Gyro Ref' appears twice"},
           {"\"reference\": \"", "\"reference\": \"Nope", "has the unknown reference"},
           {"\"meta\"", "\"nometa\"", "not a navimpact study shard ("},
           {"\"build_id\": \"B1\"", "\"build_id\": \"B0\"", "shard written by another build of navimpact (B0"},
       }) {
    const std::string e = mergeError(edited("bad" + std::to_string(from.size() + to.size()), from, to));
    EXPECT_NE(e.find("shard.json: "), std::string::npos) << e;
    EXPECT_NE(e.find(expect), std::string::npos) << e;
  }
  {
    const auto dir = test::tempDir() / "trailing";
    std::filesystem::copy(dirs[1], dir);
    std::ofstream(dir / "runs.bin", std::ios::app | std::ios::binary) << std::string(1000, '\0');
    const std::string e = mergeError(dir.string());
    EXPECT_NE(e.find("runs.bin: bytes after its last run"), std::string::npos) << e;
  }
  {
    // a NaN where the first run's first error is (magic, four counts, index,
    // seed, the model's time and steps before it): no run writes it
    const auto dir = test::tempDir() / "nan";
    std::filesystem::copy(dirs[1], dir);
    std::fstream f(dir / "runs.bin", std::ios::in | std::ios::out | std::ios::binary);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    f.seekp(8 + 4 * 8 + 2 * 8 + 2 * 8);
    f.write(reinterpret_cast<const char*>(&nan), 8);
    f.close();
    const std::string e = mergeError(dir.string());
    EXPECT_NE(e.find("runs.bin: run "), std::string::npos) << e;
    EXPECT_NE(e.find("model 1: an error of epoch 0 is not finite (not as navimpact writes it)"), std::string::npos)
        << e;
  }
  // values no run writes, though finite (found by a probe: a drift of -1e308
  // printed a 300-digit mean, an error of 1e300 an inf RMS, a NEES of +inf
  // counted as missing): offsets of the first run's first error, first sigma,
  // first NEES and first drift
  const std::size_t first = 8 + 4 * 8 + 2 * 8 + 2 * 8, E = merged.meta.epochs.size();
  for (const auto& [offset, value, expect] : std::vector<std::tuple<std::size_t, double, std::string>>{
           {first, 1e300, "an error of epoch 0 is not finite"},
           {first + 9 * 8, -1.0, "a sigma of epoch 0 is not finite and >= 0"},
           {first + 18 * 8, std::numeric_limits<double>::infinity(), "a NEES of epoch 0 is neither missing nor finite"},
           {first + 22 * 8 * E, -1e308, "the drift of outage 0 is not finite and >= 0"}}) {
    const auto dir = test::tempDir() / ("absurd" + std::to_string(offset));
    std::filesystem::copy(dirs[1], dir);
    std::fstream f(dir / "runs.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offset));
    f.write(reinterpret_cast<const char*>(&value), 8);
    f.close();
    const std::string e = mergeError(dir.string());
    EXPECT_NE(e.find("model 1: " + expect), std::string::npos) << e;
  }

  // Paired comparison: identical models see identical realisations.
  const auto& a = one.acc.models[modelIndex(one, "Gyro Ref")];
  const auto& b = one.acc.models[modelIndex(one, "Gyro Ref copy")];
  EXPECT_EQ(a.e2, b.e2);
  EXPECT_EQ(a.s2, b.s2);
  EXPECT_EQ(a.nees, b.nees);

  // The outputs are written (study.json, CSV, figures, report).
  navimpact::OutputSet out(test::tempDir() / "study");
  navimpact::report::writeStudyOutputs(merged, out);
  out.commit();
  for (const char* f : {"study.json", "timeseries.csv", "report.md", "fig_gyroscope_errors_o1.png",
                        "fig_gyroscope_nees_o1.png", "fig_accelerometer_outage_end.png"})
    EXPECT_TRUE(std::filesystem::exists(out.dir() / f)) << f;
}

// --- Findings of Khaghani et al. (2019), those robust at a few runs --------

TEST(StudyFindings, FullModelIsConsistentAtTheOutageEnd) {
  // The filter that models every error source the emulation contains is
  // consistent: its ANEES lies inside the two-sided 99.9 % band.
  const auto& r = sharedStudy();
  const std::size_t k = outageEndEpoch(r);
  const auto b3 = an::aneesBand(r.acc.runs, 3, 0.999), b9 = an::aneesBand(r.acc.runs, 9, 0.999);
  for (int blk = 0; blk < 3; ++blk) {
    const double v = anees(r, "Ref both", k, blk);
    EXPECT_GT(v, b3.first) << "block " << blk;
    EXPECT_LT(v, b3.second) << "block " << blk;
  }
  EXPECT_GT(anees(r, "Ref both", k, 3), b9.first);
  EXPECT_LT(anees(r, "Ref both", k, 3), b9.second);
}

TEST(StudyFindings, WhiteNoiseGyroModelIsOverOptimisticOverTensOfSeconds) {
  // 30 s into the outage the WN-only gyro model predicts far too small an
  // attitude and position uncertainty (ANEES above the 99.9 % band), while
  // the reference gyro model does not.
  const auto& r = sharedStudy();
  const std::size_t k = outageEndEpoch(r);
  const auto b3 = an::aneesBand(r.acc.runs, 3, 0.999);
  EXPECT_GT(anees(r, "Gyro 1", k, 2), b3.second);
  EXPECT_GT(anees(r, "Gyro 1", k, 0), b3.second);
  EXPECT_LT(anees(r, "Gyro Ref", k, 0), anees(r, "Gyro 1", k, 0));
}

TEST(StudyFindings, GyroscopeModellingMattersMoreThanAccelerometerModelling) {
  // Without a gyroscope model (accelerometer set) even the best accelerometer
  // model is inconsistent (paper Fig. 8), far more than the gyro reference
  // model without an accelerometer model (Fig. 9).
  const auto& r = sharedStudy();
  const std::size_t k = outageEndEpoch(r);
  const auto b3 = an::aneesBand(r.acc.runs, 3, 0.999);
  EXPECT_GT(anees(r, "Acc Ref", k, 0), b3.second);
  EXPECT_GT(anees(r, "Acc Ref", k, 0), 3.0 * anees(r, "Gyro Ref", k, 0));
  // And the accuracy gained by a better gyro model exceeds that of a better accelerometer model.
  const double gain_gyro = rmsH(r, "Gyro 1", k) - rmsH(r, "Gyro Ref", k);
  const double gain_acc = std::abs(rmsH(r, "Acc 1", k) - rmsH(r, "Acc Ref", k));
  EXPECT_GT(gain_gyro, gain_acc);
}

TEST(StudyFindings, ModelsAgreeEarlyInTheOutage) {
  // One second into the outage, the WN-only gyro model and the reference give
  // nearly the same horizontal error (same realisation, little coasting yet):
  // the differences build up over tens of seconds.
  const auto& r = sharedStudy();
  std::size_t k1 = 0;
  for (std::size_t i = 0; i < r.meta.epochs.size(); ++i)
    if (r.meta.epochs[i] <= r.meta.outages[0].start_s + 1.0 + 1e-9) k1 = i;
  const std::size_t ke = outageEndEpoch(r);
  const double early = rmsH(r, "Gyro 1", k1) / rmsH(r, "Ref both", k1);
  const double late = rmsH(r, "Gyro 1", ke) / rmsH(r, "Ref both", ke);
  EXPECT_LT(std::abs(early - 1.0), std::abs(late - 1.0));
}
