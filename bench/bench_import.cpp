// Import of a measured run: 10^6 IMU rows (time + 6 channels, gzip CSV, deg/s and
// g in a rotated sensor frame) through the manifest; target < 2 s for the
// import, reported alone and with the rawlog written (the whole command).
#include <benchmark/benchmark.h>
#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "navimpact/import/manifest.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path& runDir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("navimpact_bench_import_" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::mt19937_64 rng(20261124);
    std::normal_distribution<double> n(0.0, 1.0);
    gzFile f = gzopen((d / "imu.csv.gz").c_str(), "wb1");
    gzputs(f, "t_s,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n");
    char line[256];
    for (int k = 0; k < 1000000; ++k) {
      const int len = std::snprintf(line, sizeof line, "%.4f,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f\n", k * 0.005, 0.1 * n(rng),
                                    0.1 * n(rng), 0.1 * n(rng), 0.01 * n(rng), 0.01 * n(rng), 1.0 + 0.01 * n(rng));
      gzwrite(f, line, static_cast<unsigned>(len));
    }
    gzclose(f);
    std::ofstream(d / "run.yaml") << "imu:\n  file: imu.csv.gz\n  time: {column: t_s, unit: s}\n"
                                     "  gyro: {columns: [gyro_x, gyro_y, gyro_z], unit: deg/s}\n"
                                     "  acc: {columns: [acc_x, acc_y, acc_z], unit: g}\n  axes: [-y, x, z]\n";
    return d;
  }();
  static const struct Cleanup {
    ~Cleanup() { std::error_code ec; fs::remove_all(dir, ec); }
  } cleanup;
  return dir;
}

void BM_ImportMillionImuRows(benchmark::State& state) {
  const std::string manifest = (runDir() / "run.yaml").string();
  for (auto _ : state) {
    auto d = navimpact::import::importManifest(manifest);
    benchmark::DoNotOptimize(d.imu.data());
  }
}
BENCHMARK(BM_ImportMillionImuRows)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ImportMillionImuRowsToRawlog(benchmark::State& state) {
  const std::string manifest = (runDir() / "run.yaml").string();
  const std::string out = (runDir() / "run.rawlog").string();
  for (auto _ : state) {
    auto d = navimpact::import::importManifest(manifest);
    navimpact::rawlog::writeRawlog(out, d, {true, 1});
  }
}
BENCHMARK(BM_ImportMillionImuRowsToRawlog)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
