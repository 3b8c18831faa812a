// Speed of `navimpact diagnose --run`: a 600 s run at 200 Hz (the lemniscate
// of the shared data folder emulated with the Navchip Table 1 Ref errors and a
// GT reference), 30 outages of 10 s (one every 20 s), 50 realisations, the
// seven causes with 5 folds (/1; /0 the comparison alone), on the threads of
// the machine. Measure process CPU too (e.g. GNU time): the table's CPU
// column is the main thread's only.
//   build/bin/navimpact_bench --benchmark_filter=RunDiagnosis
// The emulation of the run (not timed) writes a temporary rawlog once.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <unistd.h>

#include "navimpact/analysis/run_diagnosis.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "bench_support.hpp"

namespace an = navimpact::analysis;
namespace emu = navimpact::emulation;

namespace {

/// The temporary rawlog, removed at exit.
struct TempRawlog {
  std::string path;
  ~TempRawlog() {
    if (!path.empty()) std::filesystem::remove(path);
  }
};

std::string runRawlog() {
  static TempRawlog tmp;
  std::string& path = tmp.path;
  if (!path.empty()) return path;
  const std::string cfgFile = navimpact::bench::sourcePath("config/emulation/lemniscate_600s.yaml");
  emu::EmulationConfig c = emu::loadEmulationConfig(cfgFile);
  if (!std::filesystem::exists(c.trajectory.file)) return "";
  path = (std::filesystem::temp_directory_path() / ("navimpact_bench_run_" + std::to_string(::getpid()) + ".rawlog"))
             .string();
  navimpact::rawlog::writeRawlog(path, emu::runEmulation(c, "bench"));
  return path;
}

}  // namespace

static void BM_RunDiagnosis600s(benchmark::State& st) {
  const std::string path = runRawlog();
  if (path.empty()) {
    st.SkipWithError("no lemniscate trajectory in the shared data folder");
    return;
  }
  an::RunDiagnosisOptions o;
  o.replay.rawlog = path;
  o.replay.model_spec = navimpact::bench::sourcePath("config/models/navchip_table1.yaml:ref");
  o.durations_s = {10.0};
  o.reconverge_s = 10.0;
  o.realisations = 50;
  o.causes = st.range(0) != 0;
  std::size_t outages = 0;
  for (auto _ : st) {
    const an::RunDiagnosis d = an::diagnoseRun(o);
    outages = d.durations.front().measured.size();
    benchmark::DoNotOptimize(d.verdict.data());
  }
  st.counters["outages"] = static_cast<double>(outages);
  st.counters["realisations"] = 50;
}
BENCHMARK(BM_RunDiagnosis600s)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
