#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
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

}  // namespace
}  // namespace curvesfm
