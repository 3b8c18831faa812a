// Stochastic models: simulation, theoretical WV and the PSD (the background of
// a spectral line test evaluates it at every periodogram bin).
#include <benchmark/benchmark.h>

#include <vector>

#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/spectrum.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace {

namespace st = navimpact::stochastic;

/// Table 1 gyroscope reference model with QN and RW added, at 100 Hz.
st::Model model() {
  return st::parseModel(
      "WN(sigma=9.788e-4) + QN(Q=1e-5) + RW(gamma=1e-7) + GM(sigma=4.805e-5, T=59.22) + "
      "GM(sigma=7.555e-5, T=2008) + DR(omega=1e-10) + SIN(amp=1e-4, freq=0.56)",
      100);
}

}  // namespace

// PSD of the seven-term model at the 2^19 bins of a 10^6-sample periodogram.
static void BM_PsdAtPeriodogramBins(benchmark::State& state) {
  const st::Model m = model();
  const int bins = 1 << 19;
  std::vector<double> out(bins);
  for (auto _ : state) {
    const st::Spectrum S(m);
    for (int k = 0; k < bins; ++k) out[k] = S((k + 1) * 0.5 * m.rate_hz / bins);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * bins);
}
BENCHMARK(BM_PsdAtPeriodogramBins)->Unit(benchmark::kMillisecond);

// Simulation of 10^6 samples of the same model.
static void BM_Simulate1e6(benchmark::State& state) {
  const st::Model m = model();
  for (auto _ : state) benchmark::DoNotOptimize(st::simulate(m, 1000000, 7));
}
BENCHMARK(BM_Simulate1e6)->Unit(benchmark::kMillisecond);

// Theoretical Haar WV at 20 dyadic scales.
static void BM_TheoreticalWv20Scales(benchmark::State& state) {
  const st::Model m = model();
  const auto tau = st::dyadicScales(20);
  for (auto _ : state) benchmark::DoNotOptimize(st::haarWv(m, tau));
}
BENCHMARK(BM_TheoreticalWv20Scales)->Unit(benchmark::kMicrosecond);
