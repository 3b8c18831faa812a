// Where the time of `navimpact replay` goes: reading the rawlog (gzip + MRPT
// deserialisation) versus the navigation loop (runNav: mechanization,
// covariance propagation, updates), Table 1 Ref models, 200 Hz.
//   build-*/bin/navimpact_bench --benchmark_filter=Replay
// Default rawlog: the committed 260 s one; set NAVIMPACT_BENCH_RAWLOG to
// another (e.g. a 600 s one made with `navimpact emulate`).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <optional>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/analysis/scoring.hpp"
#include "navimpact/core/earth.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "bench_support.hpp"

namespace an = navimpact::analysis;
using namespace navimpact;

namespace {

std::string benchRawlog() {
  if (const char* e = std::getenv("NAVIMPACT_BENCH_RAWLOG")) return e;
  return bench::sourcePath("datasets/uav_flight_260s_ref.rawlog");
}

/// Inputs of runNav as the replay builds them (GT at every epoch as truth), and the Ref model.
struct Prepared {
  stochastic::ImuModel model;
  std::vector<ins::ImuSample> imu;
  Recording d;
  an::TruthSeries truth;
  ins::NavState x0;
  /// runNav's input pointing into this (which must outlive it).
  an::NavRunInput input() const {
    an::NavRunInput in;
    in.x0 = x0;
    in.imu = &imu;
    in.gnss = &d.gnss;
    in.baro = &d.baro;
    in.truth = &truth;
    return in;
  }
};

Prepared prepare(const std::string& path) {
  Prepared p;
  p.model = stochastic::loadImuModel(bench::sourcePath("config/models/navchip_table1.yaml:ref"));
  p.d = rawlog::readRawlog(path);
  const double dt = p.d.imu[1].t - p.d.imu[0].t;
  double prev = p.d.imu.front().t - dt;
  for (const auto& r : p.d.imu) {
    p.imu.push_back(ins::ImuSample::fromRates(r.t, r.t - prev, r.w_IB_B, r.f_B));
    prev = r.t;
  }
  for (auto& b : p.d.baro) b.sigma_m = 0.5;
  for (const auto& g : p.d.reference) {
    p.truth.t.push_back(g.t);
    p.truth.x.push_back(ins::navStateOf(g, p.d.origin));
  }
  p.x0 = p.truth.x.front();
  p.x0.t = p.d.imu.front().t - dt;
  return p;
}

/// The prepared benchmark rawlog, or nothing (and the benchmark skipped) when it is absent.
std::optional<Prepared> prepareOrSkip(benchmark::State& st) {
  const std::string path = benchRawlog();
  if (!std::filesystem::exists(path)) {
    st.SkipWithError(("no rawlog " + path).c_str());
    return std::nullopt;
  }
  return prepare(path);
}

}  // namespace

/// Reading the rawlog alone (gzip inflate + MRPT deserialisation + conversion).
static void BM_ReplayRead(benchmark::State& st) {
  const std::string path = benchRawlog();
  if (!std::filesystem::exists(path)) {
    st.SkipWithError(("no rawlog " + path).c_str());
    return;
  }
  std::size_t n = 0;
  for (auto _ : st) {
    const Recording d = rawlog::readRawlog(path);
    n = d.imu.size();
    benchmark::DoNotOptimize(d.imu.data());
  }
  st.counters["imu_samples"] = static_cast<double>(n);
}
BENCHMARK(BM_ReplayRead)->Unit(benchmark::kMillisecond);

/// The navigation loop of the replay on data already in memory, Ref model,
/// covariance every k samples (argument), GNSS 1 Hz, baro 10 Hz, GT 10 Hz epochs.
static void BM_ReplayFilter(benchmark::State& st) {
  const std::optional<Prepared> prepared = prepareOrSkip(st);
  if (!prepared) return;
  const Prepared& p = *prepared;
  const an::NavRunInput in = p.input();
  an::NavRunOptions opt;
  opt.ekf.propagate_every = static_cast<int>(st.range(0));
  opt.outages = {{p.x0.t + 200.0, p.x0.t + 260.0}};
  double steps = 0;
  for (auto _ : st) {
    const an::NavRunResult r = an::runNav(in, p.model, opt);
    steps += static_cast<double>(r.steps);
    benchmark::DoNotOptimize(r.epochs.data());
  }
  st.counters["us_per_step"] = benchmark::Counter(steps * 1e-6, benchmark::Counter::kIsRate |
                                                                    benchmark::Counter::kInvert);
  // seconds of data per second of wall time (the IMU rate of the rawlog)
  st.counters["x_realtime"] = benchmark::Counter(steps * p.imu.front().dt, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReplayFilter)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);

/// The scored replay: outages every 60 s (20 s each) laid along the run, the
/// run scored against GT (aided RMS, per-outage NEES, distribution);
/// covariance every 10 samples. Target: x_realtime >= 500 at 200 Hz.
static void BM_ReplayScored(benchmark::State& st) {
  const std::optional<Prepared> prepared = prepareOrSkip(st);
  if (!prepared) return;
  const Prepared& p = *prepared;
  const an::NavRunInput in = p.input();
  an::NavRunOptions opt;
  opt.ekf.propagate_every = 10;
  for (const auto& w : navimpact::outagesEvery({60.0, 20.0}, p.x0.t, p.imu.back().t)) opt.outages.push_back(w);
  double steps = 0;
  std::size_t scored = 0;
  for (auto _ : st) {
    const an::NavRunResult r = an::runNav(in, p.model, opt);
    const an::RunScore s = an::scoreRun(r, p.x0.t, p.x0.t, an::ReferenceInfo{});
    steps += static_cast<double>(r.steps);
    scored = s.outages.size();
    benchmark::DoNotOptimize(s.distribution.mean_nees);
  }
  st.counters["outages"] = static_cast<double>(scored);
  st.counters["x_realtime"] = benchmark::Counter(steps * p.imu.front().dt, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReplayScored)->Unit(benchmark::kMillisecond);
