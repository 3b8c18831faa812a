// Emulation and replay of the full 600 s UAV flight at 200 Hz with the
// Navchip Table 1 Ref models. Targets: emulation < 1 s, replay < 0.25 s.
// The stages are timed separately to show where the time goes.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "bench_support.hpp"

namespace {

namespace emu = navimpact::emulation;
namespace fs = std::filesystem;

const std::string kTraj = navimpact::bench::sharedPath("data/trajectories/uav_flight_600s_ellipsoidal.csv");
const std::string kModel = navimpact::bench::sourcePath("config/models/navchip_table1.yaml:ref");

emu::EmulationConfig config() {
  emu::EmulationConfig c;
  c.trajectory.file = kTraj;
  c.imu_rate_hz = 200.0;
  c.imu_errors = "model";
  c.model_spec = kModel;
  return c;
}

bool haveData(benchmark::State& state) {
  if (!fs::exists(kTraj)) {
    state.SkipWithError("shared trajectory not found");
    return false;
  }
  return true;
}

/// Emulated 600 s data (and its rawlog in the temp folder), made once.
struct Fixture {
  navimpact::Recording data;
  std::string rawlog;
  static const Fixture& get() {
    static std::unique_ptr<Fixture> f;
    if (!f) {
      f = std::make_unique<Fixture>();
      f->data = emu::runEmulation(config(), "bench");
      f->rawlog = (fs::temp_directory_path() / "navimpact_bench_uav600.rawlog").string();
      navimpact::rawlog::writeRawlog(f->rawlog, f->data);
    }
    return *f;
  }
};

}  // namespace

// Whole emulation: read CSV, smooth, perfect IMU, errors, GNSS, baro, GT (no file).
static void BM_Emulate600s(benchmark::State& state) {
  if (!haveData(state)) return;
  const auto c = config();
  for (auto _ : state) benchmark::DoNotOptimize(emu::runEmulation(c, "bench").imu.data());
}
BENCHMARK(BM_Emulate600s)->Unit(benchmark::kMillisecond)->Iterations(3);

static void BM_Emulate600s_ReadCsv(benchmark::State& state) {
  if (!haveData(state)) return;
  emu::TrajectorySpec s;
  s.file = kTraj;
  for (auto _ : state) benchmark::DoNotOptimize(emu::readTrajectoryCsv(s).t.data());
}
BENCHMARK(BM_Emulate600s_ReadCsv)->Unit(benchmark::kMillisecond)->Iterations(3);

static void BM_Emulate600s_Smooth(benchmark::State& state) {
  if (!haveData(state)) return;
  emu::TrajectorySpec s;
  s.file = kTraj;
  const auto samples = emu::readTrajectoryCsv(s);
  for (auto _ : state) benchmark::DoNotOptimize(emu::SmoothTrajectory(samples, {}).tEnd());
}
BENCHMARK(BM_Emulate600s_Smooth)->Unit(benchmark::kMillisecond)->Iterations(3);

static void BM_Emulate600s_PerfectImu(benchmark::State& state) {
  if (!haveData(state)) return;
  emu::TrajectorySpec s;
  s.file = kTraj;
  const emu::SmoothTrajectory tr(emu::readTrajectoryCsv(s), {});
  for (auto _ : state) benchmark::DoNotOptimize(emu::perfectImu(tr, 200.0).data());
}
BENCHMARK(BM_Emulate600s_PerfectImu)->Unit(benchmark::kMillisecond)->Iterations(3);

static void BM_Emulate600s_ModelErrors(benchmark::State& state) {
  const auto m = navimpact::stochastic::loadImuModel(kModel);
  for (auto _ : state) benchmark::DoNotOptimize(emu::modelImuErrors(m, 200.0, 120000, 1).axis[0].data());
}
BENCHMARK(BM_Emulate600s_ModelErrors)->Unit(benchmark::kMillisecond)->Iterations(3);

static void BM_Emulate600s_WriteRawlog(benchmark::State& state) {
  if (!haveData(state)) return;
  const auto& f = Fixture::get();
  const auto p = (fs::temp_directory_path() / "navimpact_bench_write.rawlog").string();
  for (auto _ : state) navimpact::rawlog::writeRawlog(p, f.data);
  state.counters["MB"] = double(fs::file_size(p)) / 1e6;
}
BENCHMARK(BM_Emulate600s_WriteRawlog)->Unit(benchmark::kMillisecond)->Iterations(2);

// Replay = read the rawlog + run the filter (the report is not timed).
static void BM_Replay600s_ReadRawlog(benchmark::State& state) {
  if (!haveData(state)) return;
  const auto& f = Fixture::get();
  for (auto _ : state) benchmark::DoNotOptimize(navimpact::rawlog::readRawlog(f.rawlog).imu.data());
}
BENCHMARK(BM_Replay600s_ReadRawlog)->Unit(benchmark::kMillisecond)->Iterations(2);

static void replayFilter(benchmark::State& state, int every) {
  if (!haveData(state)) return;
  const auto& f = Fixture::get();
  const auto& d = f.data;
  std::vector<navimpact::ins::ImuSample> imu;
  double prev = d.t_start_s;
  for (const auto& r : d.imu) {
    imu.push_back(navimpact::ins::ImuSample::fromRates(r.t, r.t - prev, r.w_IB_B, r.f_B));
    prev = r.t;
  }
  // truth at 10 Hz from the GT records
  navimpact::analysis::TruthSeries truth;
  for (const auto& g : d.reference) {
    truth.t.push_back(g.t);
    truth.x.push_back(navimpact::ins::navStateOf(g, d.origin));
  }
  navimpact::analysis::NavRunInput in;
  in.x0 = truth.x.front();
  in.imu = &imu;
  in.gnss = &d.gnss;
  in.baro = &d.baro;
  in.truth = &truth;
  navimpact::analysis::NavRunOptions opt;
  opt.ekf.propagate_every = every;
  opt.P0_nav = navimpact::filter::Matrix9d::Identity() * 1e-2;
  opt.outages.push_back({200.0, 260.0});
  const auto model = navimpact::stochastic::loadImuModel(kModel);
  for (auto _ : state) benchmark::DoNotOptimize(navimpact::analysis::runNav(in, model, opt).epochs.data());
}
static void BM_Replay600s_Filter_every10(benchmark::State& state) { replayFilter(state, 10); }
static void BM_Replay600s_Filter_every1(benchmark::State& state) { replayFilter(state, 1); }
BENCHMARK(BM_Replay600s_Filter_every10)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Replay600s_Filter_every1)->Unit(benchmark::kMillisecond)->Iterations(1);
