// Wavelet variance of one static acquisition (10^6 samples x 6 channels).
// Target: classical WV of all six axes < 0.15 s on 2 cores.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>

#include "navimpact/core/csv_reader.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "bench_support.hpp"

namespace {

const navimpact::ImuSeries* staticSeries() {
  static std::unique_ptr<navimpact::ImuSeries> s = []() -> std::unique_ptr<navimpact::ImuSeries> {
    const std::string path =
        navimpact::bench::sharedPath("data/imu_static/adis16405_static_1.csv.gz");
    if (!std::filesystem::exists(path)) return nullptr;
    navimpact::CsvImuOptions o;
    o.rate_hz = 100;
    o.gyro_unit = "deg/s";
    o.acc_unit = "g";
    return std::make_unique<navimpact::ImuSeries>(navimpact::readImuCsv(path, o));
  }();
  return s.get();
}

}  // namespace

// state.range(0): worker threads (1 = sequential).
static void BM_WvSixAxes(benchmark::State& state) {
  const auto* s = staticSeries();
  if (!s) {
    state.SkipWithError("shared data not found");
    return;
  }
  navimpact::gmwm::WvOptions opt;
  opt.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto w = navimpact::gmwm::waveletVariances(*s, opt);
    benchmark::DoNotOptimize(w.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s->size() * s->channels.size()));
}
BENCHMARK(BM_WvSixAxes)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_RobustWvOneAxis(benchmark::State& state) {
  const auto* s = staticSeries();
  if (!s) {
    state.SkipWithError("shared data not found");
    return;
  }
  const auto& x = s->channel("gyro_x").x;
  for (auto _ : state) {
    auto w = navimpact::gmwm::robustWaveletVariance(x.data(), x.size(), s->rate_hz);
    benchmark::DoNotOptimize(w.wv.data());
  }
}
BENCHMARK(BM_RobustWvOneAxis)->Unit(benchmark::kMillisecond)->Iterations(1);

static void BM_AllanSixAxes(benchmark::State& state) {
  const auto* s = staticSeries();
  if (!s) {
    state.SkipWithError("shared data not found");
    return;
  }
  Eigen::VectorXd m(19);
  for (int j = 0; j < 19; ++j) m[j] = std::ldexp(1.0, j);
  for (auto _ : state) {
    for (const auto& ch : s->channels) {
      auto a = navimpact::gmwm::allanVariance(ch.x.data(), ch.x.size(), m);
      benchmark::DoNotOptimize(a.data());
    }
  }
}
BENCHMARK(BM_AllanSixAxes)->Unit(benchmark::kMillisecond)->Iterations(2);
