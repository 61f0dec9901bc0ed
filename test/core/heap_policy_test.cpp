#include "core/heap_policy.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace curvesfm {
namespace {

long minorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Written through, so the compiler can neither drop the allocations nor fold them together.
char* volatile last_block = nullptr;

// Minor page faults taken while one block of `bytes` is allocated, written to and freed.
long faultsOfOneBlock(std::size_t bytes) {
  const long before = minorFaults();
  last_block = static_cast<char*>(std::malloc(bytes));
  std::memset(last_block, 1, bytes);
  std::free(last_block);
  return minorFaults() - before;
}

// 64 MiB is above glibc's largest mmap threshold (32 MiB): by default each such block is a fresh
// mapping, faulted in page by page (16,384 faults of 4 KiB) every time it is allocated again.
TEST(HeapPolicy, ABlockFreedAndAllocatedAgainIsNotFaultedInAgain) {
  const HeapPolicy policy = keepFreedMemoryInProcess();
  if (policy != HeapPolicy::kKeptInProcess) GTEST_SKIP() << describe(policy);
  EXPECT_EQ(heapPolicy(), HeapPolicy::kKeptInProcess);
  constexpr std::size_t kBytes = std::size_t(64) << 20;
  faultsOfOneBlock(kBytes);  // The first time, the heap grows: its pages are new.
  const long pages = static_cast<long>(kBytes / 4096);
  EXPECT_LT(faultsOfOneBlock(kBytes), pages / 16);
}

TEST(HeapPolicy, LeavesTheUsersMallocTunablesAlone) {
  const char* saved = std::getenv("GLIBC_TUNABLES");
  const std::string previous = saved ? saved : "";
  setenv("GLIBC_TUNABLES", "glibc.malloc.tcache_count=7", 1);
  EXPECT_EQ(keepFreedMemoryInProcess(), HeapPolicy::kUserTunables);
  EXPECT_EQ(describe(heapPolicy()), "GLIBC_TUNABLES' glibc.malloc settings");
  if (saved) {
    setenv("GLIBC_TUNABLES", previous.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace
}  // namespace curvesfm
