// Loading a full static recording (10^6 rows x 6 channels, gzip): target < 1.5 s.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "navimpact/core/csv_reader.hpp"
#include "bench_support.hpp"

static void BM_ReadStaticCsvGz(benchmark::State& state) {
  const std::string path = navimpact::bench::sharedPath("data/imu_static/adis16405_static_1.csv.gz");
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data not found");
    return;
  }
  navimpact::CsvImuOptions o;
  o.rate_hz = 100;
  o.gyro_unit = "deg/s";
  o.acc_unit = "g";
  for (auto _ : state) {
    auto s = navimpact::readImuCsv(path, o);
    benchmark::DoNotOptimize(s.channels.data());
  }
}
BENCHMARK(BM_ReadStaticCsvGz)->Unit(benchmark::kMillisecond)->Iterations(3);
