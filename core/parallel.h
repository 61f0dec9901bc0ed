#pragma once

#include <functional>
#include <thread>
#include <vector>

namespace curvesfm {

/// Runs work(0) .. work(num_threads - 1) at once, work(0) on the calling thread, and returns
/// when all are done. Threads are started per call: the callers' parallel phases run for
/// milliseconds, against tens of microseconds to start a thread.
inline void runInParallel(int num_threads, const std::function<void(int thread)>& work) {
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads; ++t) threads.emplace_back(work, t);
  work(0);
  for (std::thread& thread : threads) thread.join();
}

}  // namespace curvesfm
