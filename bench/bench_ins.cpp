// Speed of one strapdown mechanization step (Groves §5.5 precision form).
#include <benchmark/benchmark.h>

#include "navimpact/ins/mechanization.hpp"

using namespace navimpact;

static void BM_MechanizationStep(benchmark::State& st) {
  ins::NavState x0;
  x0.lat = 0.8128;
  x0.lon = 0.1335;
  x0.h = 550.0;
  x0.v_N = Eigen::Vector3d(20.0, 5.0, -0.5);
  x0.setRollPitchYaw(0.05, -0.02, 2.2);
  ins::Mechanization mech(x0);
  const double dt = 0.005;
  const Eigen::Vector3d w(0.01, -0.02, 0.03), f(0.3, -0.1, -9.8);
  double t = 0.0;
  for (auto _ : st) {
    t += dt;
    mech.step(ins::ImuSample::fromRates(t, dt, w, f));
    benchmark::DoNotOptimize(mech.state().v_N.data());
  }
}
BENCHMARK(BM_MechanizationStep);
