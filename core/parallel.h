#pragma once

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

}  // namespace curvesfm
