#pragma once

#include <string>

namespace curvesfm {

/// What the process's allocator does with memory it frees.
enum class HeapPolicy {
  kGlibcDefault,   ///< Not changed (yet): glibc returns large freed blocks to the kernel.
  kKeptInProcess,  ///< Freed memory stays in the process for the next allocation.
  kUserTunables,   ///< GLIBC_TUNABLES sets glibc.malloc.*: the user's choice is left alone.
  kUnavailable,    ///< Not glibc's allocator (a sanitizer's, another libc): nothing changed.
};

/// Makes the allocator keep the memory the process frees instead of handing it back to the
/// kernel: every block from the heap (no mmap per large block) and the heap's top trimmed only
/// above 2 GiB. Why: glibc serves each block above its mmap threshold (at most 32 MiB) with a
/// fresh mapping and unmaps it on free, and trims the heap's top past twice that, so memory freed
/// and allocated again is faulted in again page by page. OpenCV's SIFT allocates its scale space
/// afresh for every image (about 1.4 GiB on a 3072 x 2048 photo), and on the virtual machine we
/// measured a page fault cost about 6 us: fountain-P11's initialiser made 3.3 million of them,
/// 20 s of its 48-59 s (docs/benchmarks.md, session 43). Peak memory measured within 3 % or
/// lower (what is kept had been in use, and is reused rather than mapped anew).
/// Call once, first thing in main(), before any thread starts. Left alone when the environment's
/// GLIBC_TUNABLES sets any glibc.malloc.* tunable, so a user can still choose (or restore
/// glibc's default with e.g. GLIBC_TUNABLES=glibc.malloc.tcache_count=7, its default value).
HeapPolicy keepFreedMemoryInProcess();

/// The policy in effect: kGlibcDefault until keepFreedMemoryInProcess() was called.
HeapPolicy heapPolicy();

/// One line for report.json and logs, e.g. "freed memory kept in the process".
std::string describe(HeapPolicy policy);

}  // namespace curvesfm
