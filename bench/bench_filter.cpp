// Speed of the error-state EKF and of the static covariance study.
#include <benchmark/benchmark.h>

#include "navimpact/analysis/covariance_study.hpp"
#include "navimpact/filter/ekf.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "bench_support.hpp"

using namespace navimpact;

namespace {
const std::string kModels = navimpact::bench::sourcePath("config/models/navchip_table1.yaml");

ins::NavState benchState() {
  ins::NavState x;
  x.lat = 0.8119;
  x.lon = 0.1147;
  x.h = 400.0;
  x.v_N = Eigen::Vector3d(20.0, -5.0, 0.3);
  x.setRollPitchYaw(0.05, -0.03, 1.2);
  return x;
}

void filterStep(benchmark::State& st, filter::Discretization d, int every,
                const std::string& model = "ref") {
  filter::EkfConfig cfg;
  cfg.discretization = d;
  cfg.propagate_every = every;
  filter::ErrorStateEkf ekf(benchState(), filter::Matrix9d::Identity(),
                            stochastic::loadImuModel(kModels + ":" + model), cfg);
  const double dt = 0.005;
  const Eigen::Vector3d w(0.01, -0.02, 0.03), f(0.3, -0.1, -9.8);
  double t = 0.0;
  for (auto _ : st) {
    t += dt;
    ekf.predict(ins::ImuSample::fromRates(t, dt, w, f));
    benchmark::DoNotOptimize(ekf.P().data());
  }
  st.counters["states"] = ekf.size();
}
}  // namespace

/// One predict() (mechanization + covariance propagation every sample), Ref models, 33 states.
static void BM_FilterStepRef(benchmark::State& st) {
  filterStep(st, filter::Discretization::Series, 1);
}
BENCHMARK(BM_FilterStepRef)->Unit(benchmark::kMicrosecond);

/// Same with covariance propagation every 10th sample.
static void BM_FilterStepRefEvery10(benchmark::State& st) {
  filterStep(st, filter::Discretization::Series, 10);
}
BENCHMARK(BM_FilterStepRefEvery10)->Unit(benchmark::kMicrosecond);

/// Same with covariance propagation every 20th sample.
static void BM_FilterStepRefEvery20(benchmark::State& st) {
  filterStep(st, filter::Discretization::Series, 20);
}
BENCHMARK(BM_FilterStepRefEvery20)->Unit(benchmark::kMicrosecond);

/// A small model: gyroscope white noise only (9 states), every sample and every 10th.
static void BM_FilterStepGyroWn(benchmark::State& st) {
  filterStep(st, filter::Discretization::Series, static_cast<int>(st.range(0)), "gyro_model1");
}
BENCHMARK(BM_FilterStepGyroWn)->Arg(1)->Arg(10)->Unit(benchmark::kMicrosecond);

/// Accelerometer model 2 (WN + GM + drift: 9 + 9 states), every sample and every 10th.
static void BM_FilterStepAcc2(benchmark::State& st) {
  filterStep(st, filter::Discretization::Series, static_cast<int>(st.range(0)), "acc_model2");
}
BENCHMARK(BM_FilterStepAcc2)->Arg(1)->Arg(10)->Unit(benchmark::kMicrosecond);

/// Same with exact Van Loan discretisation (66 x 66 matrix exponential per sample).
static void BM_FilterStepRefVanLoan(benchmark::State& st) {
  filterStep(st, filter::Discretization::VanLoan, 1);
}
BENCHMARK(BM_FilterStepRefVanLoan)->Unit(benchmark::kMicrosecond);

/// One GNSS position + velocity update with lever arm, Ref models.
static void BM_GnssUpdateRef(benchmark::State& st) {
  const ins::NavState x = benchState();
  filter::ErrorStateEkf ekf(x, filter::Matrix9d::Identity(), stochastic::loadImuModel(kModels + ":ref"));
  const Eigen::Vector3d lever(0.5, 0.1, -0.8), s(1, 1, 2), sv(0.1, 0.1, 0.1);
  for (auto _ : st) {
    ekf.updateGnssPosition(x.geodetic(), s, lever);
    ekf.updateGnssVelocity(x.v_N, sv, lever);
    benchmark::DoNotOptimize(ekf.P().data());
  }
}
BENCHMARK(BM_GnssUpdateRef)->Unit(benchmark::kMicrosecond);

/// One barometer update, Ref models.
static void BM_BaroUpdateRef(benchmark::State& st) {
  const ins::NavState x = benchState();
  filter::ErrorStateEkf ekf(x, filter::Matrix9d::Identity(), stochastic::loadImuModel(kModels + ":ref"));
  for (auto _ : st) {
    ekf.updateBaro(x.h, 0.5);
    benchmark::DoNotOptimize(ekf.P().data());
  }
}
BENCHMARK(BM_BaroUpdateRef)->Unit(benchmark::kMicrosecond);

/// The full static covariance study: 8 models, 60 s at 200 Hz, baro at 10 Hz (no file output).
static void BM_CovarianceStudy(benchmark::State& st) {
  const analysis::CovarianceStudyConfig cfg = analysis::loadCovarianceStudyConfig(
      navimpact::bench::sourcePath("config/paper/covariance_static.yaml"));
  for (auto _ : st) {
    const analysis::CovarianceStudyResult r = analysis::runCovarianceStudy(cfg);
    benchmark::DoNotOptimize(r.runs.data());
  }
}
BENCHMARK(BM_CovarianceStudy)->Unit(benchmark::kMillisecond);
