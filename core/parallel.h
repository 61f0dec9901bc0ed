#pragma once

#include <algorithm>
#include <atomic>
#include <functional>

namespace curvesfm {

/// Runs work(0) .. work(num_threads - 1) at once, work(0) on the calling thread, and returns
/// when all are done. The others run on a process-wide pool of worker threads, started when
/// first needed and kept for later calls: on the machine we measured, starting and ending a
/// thread per call cost 50 us, up to 190 us when its stack had to be paged in again, and with
/// both cores busy a new thread began 3.9 ms late (a kept one 3.3 us), at thousands of calls a
/// run (each LM iteration, each keyframe's registration). The pool grows so that every work(t)
/// gets a thread of its own at once, also when several callers (or a work(t) itself) call this
/// concurrently, unless the process may start no more threads; the calling thread takes a
/// work(t) no worker has started yet once it is done with work(0). An exception thrown by any
/// work(t) is rethrown here, the lowest t's, once all have ended: on a thread of its own it would
/// end the process instead of reaching the caller's error message.
void runInParallel(int num_threads, const std::function<void(int thread)>& work);

/// The cores this process may run on (its CPU affinity; the hardware's thread count where that
/// is unknown), at least 1.
int availableCores();

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
