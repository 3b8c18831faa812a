// Speed of the stochastic module: theoretical WV of the Table 1 accelerometer
// reference model (WN + 3 GM + DR) and seeded simulation of it.
#include <benchmark/benchmark.h>

#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace {

namespace st = navimpact::stochastic;

st::Model accRef() {
  st::Model m;
  m.rate_hz = 200.0;
  m.terms = {st::Process::wn(5.521e-3), st::Process::gm(4.811e-4, 3.22),
             st::Process::gm(6.666e-4, 47.40), st::Process::gm(4.003e-4, 556),
             st::Process::dr(9.302e-10)};
  return m;
}

void BM_TheoreticalWv_WN3GMDR_20scales(benchmark::State& state) {
  const st::Model m = accRef();
  const Eigen::VectorXd tau = st::dyadicScales(20);
  for (auto _ : state) benchmark::DoNotOptimize(st::haarWv(m, tau));
}
BENCHMARK(BM_TheoreticalWv_WN3GMDR_20scales);

void BM_Simulate_WN3GMDR(benchmark::State& state) {
  const st::Model m = accRef();
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<double> x(n);
  std::uint64_t seed = 1;
  for (auto _ : state) {
    std::fill(x.begin(), x.end(), 0.0);
    st::simulateAdd(m, seed++, x.data(), n);
    benchmark::DoNotOptimize(x.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_Simulate_WN3GMDR)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_Simulate_OneProcess(benchmark::State& state) {
  st::Model m;
  m.rate_hz = 200.0;
  switch (state.range(0)) {
    case 0: m.terms = {st::Process::wn(1.0)}; state.SetLabel("WN"); break;
    case 1: m.terms = {st::Process::gm(1.0, 3.0)}; state.SetLabel("GM"); break;
    case 2: m.terms = {st::Process::rw(1.0)}; state.SetLabel("RW"); break;
    case 3: m.terms = {st::Process::qn(1.0)}; state.SetLabel("QN"); break;
    default: m.terms = {st::Process::sin(1.0, 3.0)}; state.SetLabel("SIN"); break;
  }
  const std::size_t n = 1000000;
  std::vector<double> x(n);
  for (auto _ : state) {
    st::simulateAdd(m, 7, x.data(), n);
    benchmark::DoNotOptimize(x.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_Simulate_OneProcess)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

}  // namespace
