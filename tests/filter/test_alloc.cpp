// predict() allocates no heap memory once the filter is warm (the
// preallocated scratch is reused), with the covariance propagated every
// sample and every 10th sample. Counts malloc calls (glibc: Eigen and
// operator new both end in malloc) inside a window.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>

#include "filter_test_util.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "test_support.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_mallocs{0};
}  // namespace

#if defined(__GLIBC__)
extern "C" void* __libc_malloc(std::size_t n);
extern "C" void* __libc_calloc(std::size_t n, std::size_t s);
extern "C" void* __libc_realloc(void* p, std::size_t n);
extern "C" void* malloc(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t s) {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, s);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
#endif

using namespace navimpact;

namespace {
long mallocsInPredict(int every) {
  const stochastic::ImuModel m =
      stochastic::loadImuModel(test::sourcePath("config/models/navchip_table1.yaml") + ":ref");
  filter::EkfConfig cfg;
  cfg.propagate_every = every;
  ins::NavState x = ftest::staticState();
  x.v_N = Eigen::Vector3d(20.0, -5.0, 0.3);
  filter::ErrorStateEkf ekf(x, filter::Matrix9d::Identity(), m, cfg);
  const double dt = 0.005;
  const Eigen::Vector3d w(0.01, -0.02, 0.03), f(0.3, -0.1, -9.8);
  double t = 0.0;
  for (int k = 0; k < 50; ++k) {  // warm-up: scratch sized, blocks cached
    t += dt;
    ekf.predict(ins::ImuSample::fromRates(t, dt, w, f));
  }
  g_mallocs = 0;
  g_counting = true;
  for (int k = 0; k < 1000; ++k) {
    t += dt;
    ekf.predict(ins::ImuSample::fromRates(t, dt, w, f));
  }
  g_counting = false;
  EXPECT_GT(ekf.P()(0, 0), 0.0);
  return g_mallocs.load();
}
}  // namespace

TEST(Allocation, PredictDoesNotAllocateOnceWarm) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "malloc counting needs glibc";
#endif
  // the counter works: an Eigen dynamic matrix allocates
  g_mallocs = 0;
  g_counting = true;
  {
    Eigen::MatrixXd big(20, 20);
    big.setZero();
    EXPECT_EQ(big(0, 0), 0.0);
  }
  g_counting = false;
  ASSERT_GT(g_mallocs.load(), 0) << "malloc counting is not active";
  EXPECT_EQ(mallocsInPredict(10), 0) << "propagate_every = 10";
  EXPECT_EQ(mallocsInPredict(1), 0) << "propagate_every = 1";
}
