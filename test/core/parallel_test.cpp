#include "core/parallel.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace curvesfm {
namespace {

TEST(RunInParallel, RunsEveryThreadIndexOnce) {
  std::vector<std::atomic<int>> runs(4);
  runInParallel(4, [&](int t) { ++runs[t]; });
  for (const std::atomic<int>& count : runs) EXPECT_EQ(count.load(), 1);
}

// An exception on a worker thread reaches the caller, as on one thread, instead of ending the
// process; with several, the lowest thread index's.
TEST(RunInParallel, RethrowsAWorkersExceptionOnTheCallingThread) {
  std::atomic<int> finished{0};
  try {
    runInParallel(3, [&](int t) {
      if (t > 0) throw std::runtime_error("thread " + std::to_string(t));
      ++finished;
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "thread 1");
  }
  EXPECT_EQ(finished.load(), 1);
}

// Spins until `done` or 10 s have passed, so that a broken promise fails a check instead of
// hanging the suite.
bool waitUpTo10s(const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::yield();
  }
  return true;
}

// Whether num_threads work(t) ran at once: each waits for all the others to start, and only
// threads that run at once get through.
bool runsAtOnce(int num_threads) {
  std::atomic<int> started{0};
  std::atomic<int> timed_out{0};
  runInParallel(num_threads, [&](int) {
    ++started;
    if (!waitUpTo10s([&] { return started.load() == num_threads; })) ++timed_out;
  });
  return timed_out.load() == 0;
}

void expectRunsAtOnce(int num_threads) {
  EXPECT_TRUE(runsAtOnce(num_threads)) << num_threads << " threads did not all run at once";
}

TEST(RunInParallel, RunsAllThreadsAtOnce) {
  expectRunsAtOnce(2);
  expectRunsAtOnce(5);
}

// The threads are kept between calls: work(1), held until the caller's work(0) has seen it start
// (so that the caller cannot take it over), runs on a thread that ran it in an earlier call.
TEST(RunInParallel, KeepsItsThreadsBetweenCalls) {
  thread_local int runs_on_this_thread = 0;
  int most_runs_on_one_thread = 0;
  for (int call = 0; call < 20; ++call) {
    std::atomic<bool> second_started{false};
    runInParallel(2, [&](int t) {
      if (t == 0) {
        EXPECT_TRUE(waitUpTo10s([&] { return second_started.load(); }));
        return;
      }
      most_runs_on_one_thread = std::max(most_runs_on_one_thread, ++runs_on_this_thread);
      second_started = true;
    });
  }
  EXPECT_GT(most_runs_on_one_thread, 1) << "a new thread for every call";
}

// Callers on several threads at once, and work that itself runs work in parallel: every work(t)
// once, each caller's threads at once.
TEST(RunInParallel, ServesConcurrentAndNestedCallers) {
  constexpr int kCallers = 4;
  constexpr int kCalls = 50;
  std::vector<std::atomic<int>> runs(kCallers);
  std::vector<std::thread> callers;
  for (int c = 0; c < kCallers; ++c) {
    callers.emplace_back([&, c] {
      for (int call = 0; call < kCalls; ++call) {
        runInParallel(3, [&](int) { runInParallel(2, [&](int) { ++runs[c]; }); });
      }
      expectRunsAtOnce(3);
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (const std::atomic<int>& count : runs) EXPECT_EQ(count.load(), kCalls * 3 * 2);
}

// A child of fork() has none of its parent's threads: its calls still get a thread per work(t)
// at once (the benchmarks run their configurations in forked children).
TEST(RunInParallel, RunsAllThreadsAtOnceInAForkedChild) {
  expectRunsAtOnce(3);  // The parent's threads exist from here on.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) _exit(runsAtOnce(3) ? 0 : 1);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the child's threads did not all run at once";
}

TEST(ForEachInParallel, RunsEveryItemOnceOnNoMoreThreadsThanBlocks) {
  std::vector<std::atomic<int>> runs(103);
  std::vector<std::atomic<int>> by_thread(8);
  forEachInParallel(8, 103, 10, [&](int t, int i) {
    ++runs[i];
    ++by_thread[t];
  });
  for (const std::atomic<int>& count : runs) EXPECT_EQ(count.load(), 1);
  int items = 0;
  for (const std::atomic<int>& count : by_thread) items += count.load();
  EXPECT_EQ(items, 103);
  // Two blocks of 10: no more than two threads.
  std::vector<std::atomic<int>> two_blocks(8);
  forEachInParallel(8, 20, 10, [&](int t, int) { ++two_blocks[t]; });
  for (int t = 2; t < 8; ++t) EXPECT_EQ(two_blocks[t].load(), 0) << "thread " << t;
  forEachInParallel(4, 0, 10, [](int, int) { FAIL() << "no item to run"; });
}

// A thread that is held up takes fewer blocks: the others go on with the rest (a fixed split
// fails the checks).
TEST(ForEachInParallel, AThreadHeldUpTakesFewerBlocks) {
  std::vector<std::atomic<int>> by_thread(2);
  std::atomic<bool> released{false};
  forEachInParallel(2, 100, 1, [&](int t, int) {
    if (t == 0) {  // Held until the other thread has run every other item.
      ++by_thread[0];
      waitUpTo10s([&] { return released.load(); });
      return;
    }
    waitUpTo10s([&] { return by_thread[0].load() > 0; });
    if (++by_thread[1] == 99) released = true;
  });
  EXPECT_EQ(by_thread[0].load(), 1);
  EXPECT_EQ(by_thread[1].load(), 99);
}

// One thread, and a block larger than the items: every item once, on the calling thread.
TEST(ForEachInParallel, OneThreadOrOneBlockRunsOnTheCallingThread) {
  for (const auto& [threads, block] : {std::pair{1, 4}, std::pair{4, 64}}) {
    std::vector<int> runs(10, 0);
    const std::thread::id caller = std::this_thread::get_id();
    forEachInParallel(threads, 10, block, [&](int t, int i) {
      EXPECT_EQ(t, 0);
      EXPECT_EQ(std::this_thread::get_id(), caller);
      ++runs[i];
    });
    EXPECT_EQ(runs, std::vector<int>(10, 1)) << threads << " threads, block " << block;
  }
}

TEST(ForEachInParallel, RethrowsAnItemsException) {
  EXPECT_THROW(forEachInParallel(3, 50, 4,
                                 [](int, int i) {
                                   if (i == 37) throw std::runtime_error("item 37");
                                 }),
               std::runtime_error);
}

}  // namespace
}  // namespace curvesfm
