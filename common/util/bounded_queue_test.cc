#include "common/util/bounded_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace mbslam {
namespace {

TEST(BoundedQueue, FifoOrder) {
  BoundedQueue<int> queue(4, QueueFullPolicy::kBlock);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(queue.Push(i));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(*queue.Pop(), i);
  EXPECT_FALSE(queue.TryPop().has_value());
}

TEST(BoundedQueue, DropOldestKeepsNewestAndCounts) {
  BoundedQueue<int> queue(2, QueueFullPolicy::kDropOldest);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(queue.Push(i));
  EXPECT_EQ(queue.dropped(), 3);
  EXPECT_EQ(queue.size(), 2u);
  EXPECT_EQ(*queue.Pop(), 3);
  EXPECT_EQ(*queue.Pop(), 4);
}

TEST(BoundedQueue, BlockingPushWaitsForConsumerAndLosesNothing) {
  BoundedQueue<int> queue(1, QueueFullPolicy::kBlock);
  constexpr int kCount = 2000;
  std::vector<int> received;
  std::thread consumer([&] {
    while (auto item = queue.Pop()) received.push_back(*item);
  });
  for (int i = 0; i < kCount; ++i) ASSERT_TRUE(queue.Push(i));
  queue.Shutdown();
  consumer.join();
  ASSERT_EQ(received.size(), static_cast<size_t>(kCount));
  for (int i = 0; i < kCount; ++i) EXPECT_EQ(received[i], i);
  EXPECT_EQ(queue.dropped(), 0);
}

TEST(BoundedQueue, ShutdownWakesBlockedPopAndDrainsRemaining) {
  BoundedQueue<int> queue(4, QueueFullPolicy::kBlock);
  std::atomic<bool> woke{false};
  std::thread waiter([&] {
    auto item = queue.Pop();
    EXPECT_FALSE(item.has_value());
    woke = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.Shutdown();
  waiter.join();
  EXPECT_TRUE(woke);

  BoundedQueue<int> full(2, QueueFullPolicy::kBlock);
  full.Push(1);
  full.Push(2);
  full.Shutdown();
  EXPECT_FALSE(full.Push(3));
  EXPECT_EQ(*full.Pop(), 1);
  EXPECT_EQ(*full.Pop(), 2);
  EXPECT_FALSE(full.Pop().has_value());
}

TEST(BoundedQueue, ShutdownWakesBlockedPush) {
  BoundedQueue<int> queue(1, QueueFullPolicy::kBlock);
  queue.Push(0);
  std::thread pusher([&] { EXPECT_FALSE(queue.Push(1)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.Shutdown();
  pusher.join();
}

TEST(BoundedQueue, PopForTimesOut) {
  BoundedQueue<int> queue(1, QueueFullPolicy::kBlock);
  EXPECT_FALSE(queue.PopFor(1000).has_value());
}

}  // namespace
}  // namespace mbslam
