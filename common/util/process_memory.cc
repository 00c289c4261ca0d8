#include "common/util/process_memory.h"

#include <unistd.h>

#include <cstdio>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// Under AddressSanitizer the allocator is the sanitizer's, and glibc's figures say nothing.
#if defined(__SANITIZE_ADDRESS__)
#define MBSLAM_ASAN_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MBSLAM_ASAN_ALLOCATOR 1
#endif
#endif

namespace mbslam {

ProcessMemory SampleProcessMemory(bool with_heap) {
  ProcessMemory m;
  // statm: size resident shared text lib data dt, in pages.
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    long long size = 0, resident = 0;
    if (std::fscanf(f, "%lld %lld", &size, &resident) == 2) {
      m.rss_bytes = static_cast<int64_t>(resident) * static_cast<int64_t>(sysconf(_SC_PAGESIZE));
    }
    std::fclose(f);
  }
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33)) && \
    !defined(MBSLAM_ASAN_ALLOCATOR)
  if (with_heap) {
    const struct mallinfo2 mi = mallinfo2();
    m.heap_in_use_bytes = static_cast<int64_t>(mi.uordblks + mi.hblkhd);
    m.heap_held_bytes = static_cast<int64_t>(mi.arena + mi.hblkhd);
  }
#endif
  return m;
}

}  // namespace mbslam
