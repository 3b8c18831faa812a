// Cost of navimpact diagnose (analysis::diagnose, analysis::addNavigationGain):
//  - Diagnose/simulated/N: a simulated six-channel record of N samples at 100 Hz
//    (gyro WN+RW, acc WN+GM) against its own model, default simulations (8), 2 threads;
//  - Diagnose/adis: the real ADIS16405 recording 1 (10^6 samples) against a
//    fitted WN model (the heaviest real case: lines, level shifts, outliers found);
//  - Diagnose/adis_nav: the same plus the navigation gain along the 600 s UAV
//    flight, outage 200:60, 10 paired runs (skipped without ../shared).
// Wall time per iteration (UseRealTime); the record is made outside the timing.
//   build-*/bin/navimpact_bench --benchmark_filter=Diagnose
#include <benchmark/benchmark.h>

#include <filesystem>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "bench_support.hpp"

namespace na = navimpact::analysis;
namespace ns = navimpact::stochastic;

namespace {

ns::ImuModel benchModel() {
  ns::ImuModel m;
  m.rate_hz = 100.0;
  m.source = "bench";
  for (int c = 0; c < 6; ++c) {
    m.axis[c].rate_hz = 100.0;
    if (c < 3) m.axis[c].terms = {ns::Process::wn(2e-3), ns::Process::rw(2e-6)};
    else m.axis[c].terms = {ns::Process::wn(5e-3), ns::Process::gm(3e-4, 200.0)};
  }
  return m;
}

navimpact::ImuSeries simulated(std::size_t n) {
  const ns::ImuModel m = benchModel();
  navimpact::ImuSeries s;
  s.source = "simulated";
  s.rate_hz = 100.0;
  for (int c = 0; c < 6; ++c) {
    navimpact::ImuChannel ch;
    ch.name = navimpact::kChannelNames[c];
    ch.quantity = navimpact::channelQuantity(ch.name);
    ch.x = ns::simulate(m.axis[c], n, ns::deriveSeed(1, c));
    ch.x.resize(n);
    s.channels.push_back(std::move(ch));
  }
  return s;
}

void BM_DiagnoseSimulated(benchmark::State& st) {
  const auto data = simulated(static_cast<std::size_t>(st.range(0)));
  na::DiagnoseOptions o;
  o.threads = 2;
  for (auto _ : st) benchmark::DoNotOptimize(na::diagnose(data, benchModel(), o));
}

std::string adisPath() {
  return navimpact::bench::sharedPath("data/imu_static/adis16405_static_1.csv.gz");
}

navimpact::ImuSeries loadAdis() {
  navimpact::CsvImuOptions c;
  c.rate_hz = 100.0;
  c.gyro_unit = "deg/s";
  c.acc_unit = "g";
  return navimpact::readImuCsv(adisPath(), c);
}

ns::ImuModel fitWn(const navimpact::ImuSeries& s) {
  ns::ImuModel m;
  m.rate_hz = s.rate_hz;
  m.source = "fit:WN";
  for (auto& a : m.axis) a.rate_hz = s.rate_hz;
  for (const auto& ch : s.channels) {
    const auto wv = navimpact::gmwm::waveletVariance(ch.x.data(), ch.x.size(), s.rate_hz);
    m.forChannel(ch.name) = navimpact::gmwm::fit({ns::ProcessKind::WN}, wv).model;
    m.forChannel(ch.name).rate_hz = s.rate_hz;
  }
  return m;
}

void BM_DiagnoseAdis(benchmark::State& st, bool nav) {
  if (!std::filesystem::exists(adisPath())) {
    st.SkipWithError("shared ADIS16405 recording not found");
    return;
  }
  const auto data = loadAdis();
  const auto model = fitWn(data);
  std::shared_ptr<const na::NavGainPlan> plan;
  if (nav) {
    na::NavGainOptions no;
    no.trajectory.file =
        navimpact::bench::sharedPath("data/trajectories/uav_flight_600s_ellipsoidal.csv");
    no.outages = {{200.0, 260.0}};
    no.threads = 2;
    plan = na::prepareNavGain(no, data.rate_hz, data.size());
  }
  na::DiagnoseOptions o;
  o.threads = 2;
  for (auto _ : st) {
    na::Diagnosis d = na::diagnose(data, model, o);
    if (plan) na::addNavigationGain(d, data, *plan);
    benchmark::DoNotOptimize(d);
  }
}

}  // namespace

BENCHMARK(BM_DiagnoseSimulated)->Arg(1 << 18)->Arg(1000000)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_DiagnoseAdis, adis, false)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_DiagnoseAdis, adis_nav, true)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
