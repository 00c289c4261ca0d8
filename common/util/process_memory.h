#ifndef MBSLAM_COMMON_UTIL_PROCESS_MEMORY_H_
#define MBSLAM_COMMON_UTIL_PROCESS_MEMORY_H_

// The process' own memory, for PERCEPTION_STATUS and the soak test: what the system
// holds for it (resident set) and what the C allocator holds and hands out. The RSS
// alone cannot tell a leak from an allocator that keeps freed memory for reuse
// (fragmentation); the heap in use can.

#include <cstdint>

namespace mbslam {

struct ProcessMemory {
  int64_t rss_bytes = -1;          // resident set (/proc/self/statm; -1 when unreadable)
  int64_t heap_in_use_bytes = -1;  // allocated and not freed: glibc's mallinfo2 uordblks + hblkhd (-1 elsewhere)
  int64_t heap_held_bytes = -1;    // obtained from the system by the allocator: arena + hblkhd (-1 elsewhere)
};

// Samples the figures above; the heap ones only `with_heap` (else -1). mallinfo2 walks
// every arena's free lists under their locks: 0.3-0.5 ms on the perception service's
// heap (sim-multi), 85 ms on a synthetic heap with 200,000 free chunks. Sample it
// rarely, never per image.
ProcessMemory SampleProcessMemory(bool with_heap = true);

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_PROCESS_MEMORY_H_
