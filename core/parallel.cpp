#include "core/parallel.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace curvesfm {
namespace {

// One call of runInParallel: work(0) is the caller's, work(1) .. work(count - 1) go to whichever
// thread claims them first. Lives on the caller's stack until every work(t) has finished.
struct Job {
  Job(const std::function<void(int)>& work, int count) : work(work), count(count), errors(count) {}

  void run(int t) {
    try {
      work(t);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  }

  const std::function<void(int)>& work;
  const int count;
  int next = 1;      // The next work(t) to claim (guarded by the pool's mutex).
  int finished = 0;  // Guarded by the pool's mutex.
  std::vector<std::exception_ptr> errors;
  std::condition_variable all_finished;
};

// Threads that wait for jobs until the process ends. Invariant (under mutex_): idle_ >=
// unclaimed_, so every posted work(t) has a thread free to start it at once; that keeps
// runInParallel's promise that the work(t) run concurrently (a caller may wait on another t).
class WorkerPool {
 public:
  void run(int count, const std::function<void(int)>& work) {
    Job job(work, count);
    post(&job);
    job.run(0);
    std::unique_lock<std::mutex> lock(mutex_);
    ++job.finished;
    // A work(t) no worker has woken up for yet is the caller's: it would only wait for it.
    while (job.next < job.count) {
      const int t = claim(&job);
      lock.unlock();
      job.run(t);
      lock.lock();
      ++job.finished;
    }
    job.all_finished.wait(lock, [&] { return job.finished == job.count; });
    lock.unlock();
    for (const std::exception_ptr& error : job.errors) {
      if (error) std::rethrow_exception(error);
    }
  }

 private:
  void post(Job* job) {
    const int helpers = job->count - 1;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      pending_.push_back(job);
      unclaimed_ += helpers;
      try {
        for (; idle_ < unclaimed_; ++idle_) std::thread([this] { serve(); }).detach();
      } catch (const std::system_error&) {
        // No thread to be had (a process limit): the callers run what no worker claims.
      }
    }
    if (helpers == 1) {
      wake_.notify_one();
    } else {
      wake_.notify_all();
    }
  }

  // Takes job's next work(t); mutex_ held, job->next < job->count.
  int claim(Job* job) {
    const int t = job->next++;
    --unclaimed_;
    if (job->next == job->count) pending_.erase(std::find(pending_.begin(), pending_.end(), job));
    return t;
  }

  [[noreturn]] void serve() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return !pending_.empty(); });
      Job* job = pending_.front();
      const int t = claim(job);
      --idle_;
      lock.unlock();
      job->run(t);
      lock.lock();
      ++idle_;
      // Under the mutex: the caller cannot see the count and leave (ending job) before this.
      if (++job->finished == job->count) job->all_finished.notify_one();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Job*> pending_;  // Jobs with a work(t) nobody has claimed.
  int idle_ = 0;              // Threads not running a work(t).
  int unclaimed_ = 0;         // Posted work(t) not claimed yet.
};

// The process's pool, made at the first parallel call. Never destroyed: joining its threads at
// exit would hang or abort when exit() is called while a work(t) runs, or from one. A child of
// fork() has none of its parent's threads (and perhaps a mutex one of them held), so it leaves
// the parent's pool and makes its own when it first needs one.
std::atomic<WorkerPool*> shared_pool{nullptr};

WorkerPool& sharedPool() {
  static const int fork_handler =
      pthread_atfork(nullptr, nullptr, [] { shared_pool.store(nullptr); });
  (void)fork_handler;
  WorkerPool* pool = shared_pool.load();
  if (pool != nullptr) return *pool;
  auto* made = new WorkerPool;
  if (shared_pool.compare_exchange_strong(pool, made)) return *made;
  delete made;  // Another thread's came first; `pool` is now that one.
  return *pool;
}

}  // namespace

void runInParallel(int num_threads, const std::function<void(int thread)>& work) {
  if (num_threads <= 1) {
    work(0);
    return;
  }
  sharedPool().run(num_threads, work);
}

int availableCores() {
  cpu_set_t cores;
  CPU_ZERO(&cores);
  if (sched_getaffinity(0, sizeof(cores), &cores) == 0) return std::max(1, CPU_COUNT(&cores));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace curvesfm
