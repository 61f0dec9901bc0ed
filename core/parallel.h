#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <thread>
#include <vector>

namespace curvesfm {

/// Runs work(0) .. work(num_threads - 1) at once, work(0) on the calling thread, and returns
/// when all are done. Threads are started per call: the callers' parallel phases run for
/// milliseconds, against tens of microseconds to start a thread. An exception thrown by any
/// work(t) is rethrown here, the lowest t's, once all have ended: on a thread of its own it
/// would end the process instead of reaching the caller's error message.
inline void runInParallel(int num_threads, const std::function<void(int thread)>& work) {
  std::vector<std::exception_ptr> errors(num_threads > 1 ? num_threads : 1);
  const auto guarded = [&](int t) {
    try {
      work(t);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads; ++t) threads.emplace_back(guarded, t);
  guarded(0);
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

/// Runs work(thread, i) for every i in [0, count) on up to num_threads threads (thread 0 the
/// calling one), each thread taking the next `block` items whenever it is done with its last:
/// a thread that shares its core with other work takes fewer, where a fixed split would leave the
/// others idle at the end, waiting for it. Which thread runs an item, and when, is not fixed, so
/// work must write its item's result alone. Exceptions as runInParallel.
inline void forEachInParallel(int num_threads, int count, int block,
                              const std::function<void(int thread, int item)>& work) {
  if (count <= 0) return;
  block = std::max(block, 1);
  std::atomic<int> next{0};
  const int threads = std::clamp((count - 1) / block + 1, 1, std::max(num_threads, 1));
  runInParallel(threads, [&](int t) {
    for (int first = next.fetch_add(block); first < count; first = next.fetch_add(block)) {
      const int last = first + std::min(block, count - first);
      for (int i = first; i < last; ++i) work(t, i);
    }
  });
}

}  // namespace curvesfm
