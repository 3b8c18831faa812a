// Cost of one filter step inside the emulation study (analysis::runNav via
// runStudy): the UAV excerpt (first 60 s), 200 Hz IMU, one run, one candidate
// model, covariance propagated every k samples. Reports us per filter step.
//   build-*/bin/navimpact_bench --benchmark_filter=Study
#include <benchmark/benchmark.h>

#include "navimpact/analysis/study.hpp"
#include "bench_support.hpp"

namespace an = navimpact::analysis;

namespace {

std::shared_ptr<const an::StudyPlan> makePlan(const std::string& model, int every) {
  an::StudyConfig cfg;
  cfg.trajectory.file = navimpact::bench::sourcePath("datasets/uav_flight_260s.csv.gz");
  cfg.trajectory.end_s = 60.0;
  cfg.imu_rate_hz = 200.0;
  cfg.truth.model = navimpact::bench::sourcePath("config/models/navchip_table1.yaml:ref");
  an::CandidateSpec c;
  c.label = model;
  c.model = navimpact::bench::sourcePath("config/models/navchip_table1.yaml:" + model);
  cfg.candidates = {c};
  cfg.sets = {{"all", "all", {model}, model, model}};
  cfg.outages = {{30.0, 50.0}};
  cfg.runs = 1;
  cfg.ekf.propagate_every = every;
  return an::prepareStudy(cfg, "bench");
}

void BM_StudyFilterStep(benchmark::State& st, const std::string& model) {
  const auto plan = makePlan(model, static_cast<int>(st.range(0)));
  double wall = 0.0, steps = 0.0;
  for (auto _ : st) {
    const an::StudyResults r = an::runStudy(plan, an::Shard{}, 1);
    wall += r.acc.models[0].wall_s;
    steps += r.acc.models[0].steps;
  }
  st.counters["us_per_step"] = 1e6 * wall / steps;
}

}  // namespace

BENCHMARK_CAPTURE(BM_StudyFilterStep, ref_both, std::string("ref"))
    ->Arg(1)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_StudyFilterStep, gyro_wn, std::string("gyro_model1"))
    ->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

/// One Monte Carlo run of the paper study (config/paper/study_navchip_uav.yaml:
/// 260 s at 200 Hz, all its candidate models, propagate_every from the file):
/// emulation of the run's IMU errors, GNSS and baro plus every model's filter.
/// Times are process CPU time (the run executes on a worker thread). Counters:
/// wall-clock filter us per step and filter seconds per run (both inflated when
/// the machine is loaded; compare the CPU time per iteration).
static void BM_StudyOneRunPaper(benchmark::State& st) {
  an::StudyConfig cfg =
      an::loadStudyConfig(navimpact::bench::sourcePath("config/paper/study_navchip_uav.yaml"));
  cfg.runs = 1;
  cfg.threads = 1;
  if (st.range(0) > 0) cfg.ekf.propagate_every = static_cast<int>(st.range(0));
  const auto plan = an::prepareStudy(cfg, "bench");
  double wall = 0.0, steps = 0.0;
  for (auto _ : st) {
    const an::StudyResults r = an::runStudy(plan, an::Shard{}, 1);
    for (const auto& m : r.acc.models) {
      wall += m.wall_s;
      steps += m.steps;
    }
  }
  st.counters["models"] = static_cast<double>(cfg.candidates.size());
  st.counters["us_per_step"] = 1e6 * wall / steps;
  // process CPU time per filter step, everything of the run included (its
  // emulation, every model's filter, the records): robust on a loaded machine
  st.counters["cpu_per_step"] = benchmark::Counter(steps, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["filter_s_per_run"] = wall / static_cast<double>(st.iterations());
}
BENCHMARK(BM_StudyOneRunPaper)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2)->MeasureProcessCPUTime();
