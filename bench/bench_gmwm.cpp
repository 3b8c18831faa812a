// GMWM fit speed. Target: WN+3GM+DR on a 10^6-sample WV (19 scales) < 0.2 s
// per axis (the R package gmwm 3.0.0 takes 1.7-3.6 s per fit on the same data).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>

#include "navimpact/core/csv_reader.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "bench_support.hpp"

namespace {

namespace gm = navimpact::gmwm;
namespace st = navimpact::stochastic;

/// WV of 10^6 samples simulated from the paper's Table 1 accelerometer
/// reference model converted to 100 Hz (19 scales), computed once.
const gm::WaveletVariance& simulatedWv() {
  static const gm::WaveletVariance wv = [] {
    const st::Model m = st::convertRate(st::parseModel("WN(sigma=5.521e-3) + GM(sigma=4.811e-4, T=3.22) + "
                                                       "GM(sigma=6.666e-4, T=47.40) + GM(sigma=4.003e-4, T=556) + "
                                                       "DR(omega=9.302e-10)",
                                                       200),
                                        100);
    const std::size_t n = 1000000;
    const auto x = st::simulate(m, n, 20190101);
    return gm::waveletVariance(x.data(), n, 100);
  }();
  return wv;
}

/// WV of acc_x of the first ADIS16405 acquisition (10^6 samples), or nullptr.
const gm::WaveletVariance* adisWv() {
  static std::unique_ptr<gm::WaveletVariance> wv = []() -> std::unique_ptr<gm::WaveletVariance> {
    const std::string path = navimpact::bench::sharedPath("data/imu_static/adis16405_static_1.csv.gz");
    if (!std::filesystem::exists(path)) return nullptr;
    navimpact::CsvImuOptions o;
    o.rate_hz = 100;
    o.gyro_unit = "deg/s";
    o.acc_unit = "g";
    const auto s = navimpact::readImuCsv(path, o);
    const auto& c = s.channel("acc_x");
    return std::make_unique<gm::WaveletVariance>(gm::waveletVariance(c.x.data(), c.x.size(), 100));
  }();
  return wv.get();
}

/// adisWv(), or nullptr with @p state skipped when the shared data is absent.
const gm::WaveletVariance* adisWvOrSkip(benchmark::State& state) {
  const gm::WaveletVariance* wv = adisWv();
  if (!wv) state.SkipWithError("shared data not found");
  return wv;
}

void runFit(benchmark::State& state, const gm::WaveletVariance& wv, const char* structure,
            gm::Weighting w = gm::Weighting::Fast) {
  const auto k = st::parseStructure(structure);
  gm::FitOptions o;
  o.weighting = w;
  double obj = 0;
  for (auto _ : state) {
    const auto f = gm::fit(k, wv, o);
    obj = f.objective;
    benchmark::DoNotOptimize(obj);
  }
  state.counters["scales"] = wv.scales();
}

}  // namespace

static void BM_FitSimulated_WN_3GM_DR(benchmark::State& state) {
  runFit(state, simulatedWv(), "WN+GM+GM+GM+DR");
}
BENCHMARK(BM_FitSimulated_WN_3GM_DR)->Unit(benchmark::kMillisecond);

// Efficient GMWM (full WV covariance, iterated): the fast fit plus reweighting passes.
static void BM_FitSimulatedEfficient_WN_3GM_DR(benchmark::State& state) {
  runFit(state, simulatedWv(), "WN+GM+GM+GM+DR", gm::Weighting::Efficient);
}
BENCHMARK(BM_FitSimulatedEfficient_WN_3GM_DR)->Unit(benchmark::kMillisecond);

// Asymptotic WV covariance (19 x 19, quadrature per pair of scales).
static void BM_WvCovariance(benchmark::State& state) {
  const st::Model m =
      st::parseModel("WN(sigma=5.5e-3) + GM(sigma=4.8e-4, T=3.2) + GM(sigma=6.7e-4, T=47) + GM(sigma=4e-4, T=556)", 100);
  for (auto _ : state) benchmark::DoNotOptimize(gm::wvCovariance(m, simulatedWv()).sum());
}
BENCHMARK(BM_WvCovariance)->Unit(benchmark::kMillisecond);

static void BM_FitSimulated_WN_GM(benchmark::State& state) { runFit(state, simulatedWv(), "WN+GM"); }
BENCHMARK(BM_FitSimulated_WN_GM)->Unit(benchmark::kMillisecond);

static void BM_FitAdisAccX_WN_3GM_DR(benchmark::State& state) {
  const auto* wv = adisWvOrSkip(state);
  if (!wv) return;
  runFit(state, *wv, "WN+GM+GM+GM+DR");
}
BENCHMARK(BM_FitAdisAccX_WN_3GM_DR)->Unit(benchmark::kMillisecond);

// Automatic selection over the 32 default candidates (WN + QN?/RW?/DR? + 0..3 GM).
static void BM_SelectAdisAccX(benchmark::State& state) {
  const auto* wv = adisWvOrSkip(state);
  if (!wv) return;
  const auto cands = gm::defaultCandidates(3);
  for (auto _ : state) {
    const auto r = gm::selectModel(cands, *wv, gm::FitOptions{});
    benchmark::DoNotOptimize(r.data());
  }
}
BENCHMARK(BM_SelectAdisAccX)->Unit(benchmark::kMillisecond)->Iterations(1);
