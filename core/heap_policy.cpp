#include "core/heap_policy.h"

#include <climits>
#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace curvesfm {
namespace {

HeapPolicy policy_in_effect = HeapPolicy::kGlibcDefault;

bool userSetsMallocTunables() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return tunables != nullptr && std::strstr(tunables, "glibc.malloc.") != nullptr;
}

HeapPolicy applyPolicy() {
  if (userSetsMallocTunables()) return HeapPolicy::kUserTunables;
#if defined(__GLIBC__)
  // mallopt returns 1 on success; a sanitizer's allocator intercepts it and changes nothing.
  const bool no_mmap = mallopt(M_MMAP_MAX, 0) == 1;
  const bool no_trim = mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
  if (no_mmap && no_trim) return HeapPolicy::kKeptInProcess;
#endif
  return HeapPolicy::kUnavailable;
}

}  // namespace

HeapPolicy keepFreedMemoryInProcess() {
  policy_in_effect = applyPolicy();
  return policy_in_effect;
}

HeapPolicy heapPolicy() { return policy_in_effect; }

std::string describe(HeapPolicy policy) {
  switch (policy) {
    case HeapPolicy::kGlibcDefault:
      return "glibc's default (large freed blocks returned to the kernel)";
    case HeapPolicy::kKeptInProcess:
      return "freed memory kept in the process";
    case HeapPolicy::kUserTunables:
      return "GLIBC_TUNABLES' glibc.malloc settings";
    case HeapPolicy::kUnavailable:
      return "unchanged (not glibc's allocator)";
  }
  return "unknown";
}

}  // namespace curvesfm
