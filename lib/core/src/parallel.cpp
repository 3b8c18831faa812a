// The one worker pool (see parallel.hpp).
#include "navimpact/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace navimpact {

unsigned workerThreads(unsigned requested, std::size_t count) {
  unsigned t = requested > 0 ? requested : std::max(1u, std::thread::hardware_concurrency());
  if (count < t) t = static_cast<unsigned>(std::max<std::size_t>(count, 1));
  return t;
}

void parallelFor(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& body,
                 const TaskProgress& progress) {
  if (count == 0) return;
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mu;  // guards done, failed, failure and the progress calls
  std::size_t done = 0;
  std::size_t failed = count;  // lowest index that threw so far
  std::exception_ptr failure;
  auto work = [&]() {
    while (!stop.load()) {
      const std::size_t i = next++;
      if (i >= count) return;
      try {
        body(i);
        if (progress) {
          std::lock_guard<std::mutex> lk(mu);
          progress(++done, count);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lk(mu);
        if (i < failed) {
          failed = i;
          failure = std::current_exception();
        }
        stop = true;
      }
    }
  };
  const unsigned t = workerThreads(threads, count);
  std::vector<std::thread> pool;
  pool.reserve(t - 1);
  for (unsigned k = 1; k < t; ++k) {
    try {
      pool.emplace_back(work);
    } catch (...) {  // no more threads to be had: the ones running do the work (same results)
      break;
    }
  }
  work();
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace navimpact
