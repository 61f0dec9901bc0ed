#include "core/peak_memory.h"

#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h>
#endif

namespace curvesfm {

double peakResidentMiB() {
#if defined(__unix__) || defined(__APPLE__)
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return -1.0;
#if defined(__APPLE__)
  return static_cast<double>(usage.ru_maxrss) / (1024.0 * 1024.0);  // Bytes on macOS.
#else
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB on Linux and the BSDs.
#endif
#else
  return -1.0;
#endif
}

}  // namespace curvesfm
