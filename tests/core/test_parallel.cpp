// The one worker pool, read as its contract: every task runs once, results by
// index do not depend on the thread count, the failure rethrown is the one of
// the lowest index that threw (as it was thrown), progress counts 1..count one
// call at a time. Counts, thread counts and failing indices are drawn at
// random (seeded; the seed is printed).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <iostream>
#include <mutex>
#include <new>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/parallel.hpp"

using navimpact::parallelFor;

namespace {

constexpr std::uint64_t kSeed = 20261125;

/// A result of task i that takes some work to compute: a seeded stream of i.
double work(std::size_t i) {
  std::mt19937_64 g(kSeed + i);
  std::normal_distribution<double> n;
  double s = 0.0;
  for (int k = 0; k < 200 + static_cast<int>(i % 7) * 50; ++k) s += n(g);
  return s;
}

}  // namespace

TEST(Parallel, WorkerThreadsAreTheRequestBoundedByTheTasks) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_EQ(navimpact::workerThreads(0, 1000), hw);
  EXPECT_EQ(navimpact::workerThreads(3, 1000), 3u);
  EXPECT_EQ(navimpact::workerThreads(8, 5), 5u);
  EXPECT_EQ(navimpact::workerThreads(8, 0), 1u);
  EXPECT_EQ(navimpact::workerThreads(0, 1), 1u);
}

TEST(Parallel, EveryTaskRunsOnceAndResultsByIndexDoNotDependOnTheThreadCount) {
  std::mt19937_64 g(kSeed);
  std::cout << "seed " << kSeed << "\n";
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t count = std::uniform_int_distribution<std::size_t>(0, 300)(g);
    std::vector<double> serial(count);
    parallelFor(count, 1, [&](std::size_t i) { serial[i] = work(i); });
    for (unsigned threads : {0u, 2u, 3u, 8u, 64u}) {
      std::vector<double> out(count, 0.0);
      std::vector<std::atomic<int>> runs(count);
      parallelFor(count, threads, [&](std::size_t i) {
        ++runs[i];
        out[i] = work(i);
      });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << "task " << i << " of " << count;
      EXPECT_EQ(out, serial) << count << " tasks on " << threads << " threads";
    }
  }
}

TEST(Parallel, OneThreadRunsTheTasksInIndexOrderOnTheCallingThread) {
  std::vector<std::size_t> order;
  std::set<std::thread::id> ids;
  parallelFor(50, 1, [&](std::size_t i) {
    order.push_back(i);
    ids.insert(std::this_thread::get_id());
  });
  ASSERT_EQ(order.size(), 50u);
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i);
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(Parallel, SeveralThreadsRunTasksAtTheSameTime) {
  // Each of the first tasks waits (at most 10 s) for a second one to be running.
  std::atomic<int> running{0}, most{0};
  parallelFor(4, 2, [&](std::size_t) {
    const int now = ++running;
    int m = most.load();
    while (now > m && !most.compare_exchange_weak(m, now)) {
    }
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (most.load() < 2 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    --running;
  });
  EXPECT_EQ(most.load(), 2);
}

TEST(Parallel, TheFailureOfTheLowestIndexIsRethrownWhateverTheThreadCount) {
  std::mt19937_64 g(kSeed + 1);
  std::cout << "seed " << kSeed + 1 << "\n";
  for (int trial = 0; trial < 30; ++trial) {
    const std::size_t count = std::uniform_int_distribution<std::size_t>(1, 200)(g);
    std::set<std::size_t> failing;
    const int nf = std::uniform_int_distribution<int>(1, 5)(g);
    for (int k = 0; k < nf; ++k) failing.insert(std::uniform_int_distribution<std::size_t>(0, count - 1)(g));
    const std::size_t first = *failing.begin();
    for (unsigned threads : {1u, 2u, 4u, 16u}) {
      std::vector<std::atomic<int>> ran(count);
      try {
        parallelFor(count, threads, [&](std::size_t i) {
          ++ran[i];
          (void)work(i);
          if (failing.count(i)) throw navimpact::Error("task " + std::to_string(i));
        });
        ADD_FAILURE() << "no exception, " << count << " tasks, first failing " << first;
      } catch (const navimpact::Error& e) {
        EXPECT_EQ(std::string(e.what()), "task " + std::to_string(first))
            << count << " tasks on " << threads << " threads";
      }
      // Every task below the failure ran (once); none ran twice.
      for (std::size_t i = 0; i < count; ++i) {
        if (i <= first) EXPECT_EQ(ran[i].load(), 1) << "task " << i;
        else EXPECT_LE(ran[i].load(), 1) << "task " << i;
      }
    }
  }
}

TEST(Parallel, AFailureKeepsItsType) {
  for (unsigned threads : {1u, 3u}) {
    EXPECT_THROW(parallelFor(10, threads, [](std::size_t i) {
                   if (i == 4) throw std::bad_alloc();
                   if (i == 7) throw navimpact::Error("later");
                 }),
                 std::bad_alloc);
    EXPECT_THROW(parallelFor(10, threads, [](std::size_t i) {
                   if (i == 2) throw std::out_of_range("x");
                 }),
                 std::out_of_range);
  }
}

TEST(Parallel, ProgressCountsTheFinishedTasksOneCallAtATime) {
  for (unsigned threads : {1u, 2u, 5u}) {
    std::vector<std::size_t> seen;
    std::atomic<bool> inside{false};
    bool overlapped = false;
    parallelFor(
        123, threads, [](std::size_t i) { (void)work(i); },
        [&](std::size_t done, std::size_t count) {
          if (inside.exchange(true)) overlapped = true;
          EXPECT_EQ(count, 123u);
          seen.push_back(done);
          std::this_thread::yield();
          inside = false;
        });
    EXPECT_FALSE(overlapped) << threads << " threads";
    ASSERT_EQ(seen.size(), 123u) << threads << " threads";
    for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], k + 1);
  }
}

TEST(Parallel, AFailingProgressCallFailsTheTaskItReports) {
  for (unsigned threads : {1u, 2u}) {
    EXPECT_THROW(parallelFor(
                     20, threads, [](std::size_t) {},
                     [](std::size_t done, std::size_t) {
                       if (done == 5) throw navimpact::Error("cancelled");
                     }),
                 navimpact::Error);
  }
}

TEST(Parallel, NoTaskNoCall) {
  bool called = false;
  parallelFor(0, 4, [&](std::size_t) { called = true; }, [&](std::size_t, std::size_t) { called = true; });
  EXPECT_FALSE(called);
}
