#include "common/util/process_memory.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

namespace mbslam {
namespace {

TEST(ProcessMemory, SeesTheProcessAndItsHeap) {
  const ProcessMemory m = SampleProcessMemory();
  EXPECT_GT(m.rss_bytes, 0);
  if (m.heap_in_use_bytes < 0) GTEST_SKIP() << "no glibc heap figures in this build (sanitizer or other libc)";
  EXPECT_GT(m.heap_in_use_bytes, 0);
  EXPECT_GE(m.heap_held_bytes, m.heap_in_use_bytes);
}

// What is allocated shows in the heap in use and in the RSS, and is gone from the heap
// in use once freed, whether the allocator serves it from an arena (small blocks) or
// maps it (large ones).
TEST(ProcessMemory, HeapInUseFollowsAllocations) {
  if (SampleProcessMemory().heap_in_use_bytes < 0) GTEST_SKIP() << "no glibc heap figures in this build";
  for (const size_t block : {size_t{256}, size_t{4} << 20}) {
    const size_t total = size_t{32} << 20;
    const ProcessMemory before = SampleProcessMemory();
    std::vector<std::unique_ptr<char[]>> blocks;
    blocks.reserve(total / block);
    for (size_t done = 0; done < total; done += block) {
      blocks.emplace_back(new char[block]);
      std::memset(blocks.back().get(), 1, block);  // touched: resident
    }
    const ProcessMemory during = SampleProcessMemory();
    const auto t = static_cast<int64_t>(total);
    EXPECT_GT(during.heap_in_use_bytes - before.heap_in_use_bytes, t * 9 / 10) << block;
    EXPECT_GT(during.rss_bytes - before.rss_bytes, t * 9 / 10) << block;
    blocks.clear();
    const ProcessMemory after = SampleProcessMemory();
    EXPECT_LT(after.heap_in_use_bytes - before.heap_in_use_bytes, t / 10) << block;
  }
}

}  // namespace
}  // namespace mbslam
