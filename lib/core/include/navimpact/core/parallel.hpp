/**
 * @file parallel.hpp
 * @brief The one worker pool of navimpact: tasks 0..count-1 over threads,
 *        results by index, failures rethrown in index order.
 *
 * Every loop of independent tasks in the libraries (channels of a wavelet
 * variance or a diagnosis, Monte Carlo runs of a study, simulated records of
 * diagnose-power, realisations and cause fits of a run diagnosis) goes through
 * parallelFor(). A task writes its result into a slot of its own index, so the
 * result never depends on the number of threads nor on which thread ran which
 * task: only the order in which the tasks finish does, and a caller that
 * needs results in index order as they come (a running sum) merges them
 * itself under its own lock.
 */
#pragma once

#include <cstddef>
#include <functional>

namespace navimpact {

/// Called after each task that finished without throwing, one call at a time,
/// with done = 1, 2, ..., count (tasks finished so far) and count.
using TaskProgress = std::function<void(std::size_t done, std::size_t count)>;

/// Threads a pool of @p requested threads uses for @p count tasks:
/// @p requested (0 = the hardware's threads, at least 1), at most @p count, at least 1.
unsigned workerThreads(unsigned requested, std::size_t count);

/**
 * Runs body(i) once for every i in [0, count) on workerThreads(threads, count)
 * threads (the calling thread is one of them; with one thread the tasks run
 * in index order on the calling thread). Tasks are started in index order.
 *
 * A task that throws stops the pool: tasks not yet started are not started,
 * tasks running finish, and once every thread is done the exception of the
 * lowest index that threw is rethrown as it was thrown. Since tasks start in
 * index order, every task below that index has run: for tasks that do not
 * depend on each other, the exception is the same whatever the thread count.
 *
 * @param progress  may be empty; see TaskProgress. An exception it throws
 *                  counts as one of the task it reports.
 * Library code: never prints.
 */
void parallelFor(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& body,
                 const TaskProgress& progress = {});

}  // namespace navimpact
