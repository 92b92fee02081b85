#include "apps/heap_settings.h"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace auvdock::cli {

bool ApplyHeapSettings(const HeapSettings& settings) {
#if defined(__GLIBC__)
  if (settings.mmap_threshold_bytes > static_cast<std::size_t>(INT_MAX) ||
      settings.trim_threshold_bytes > static_cast<std::size_t>(INT_MAX)) {
    return false;
  }
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, static_cast<int>(settings.mmap_threshold_bytes));
  const bool trim_ok = mallopt(M_TRIM_THRESHOLD, static_cast<int>(settings.trim_threshold_bytes));
  return mmap_ok && trim_ok;
#else
  (void)settings;
  return false;
#endif
}

}  // namespace auvdock::cli
