#ifndef MBSLAM_COMMON_UTIL_BOUNDED_QUEUE_H_
#define MBSLAM_COMMON_UTIL_BOUNDED_QUEUE_H_

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace mbslam {

// What Push does when the queue is full.
enum class QueueFullPolicy {
  kBlock,       // wait for room (lockstep replay: never lose an item)
  kDropOldest,  // discard the oldest item and count it (realtime: keep the newest)
};

// A FIFO with a fixed capacity and an explicit shutdown, for handing payloads
// between pipeline threads. All methods are thread-safe.
template <typename T>
class BoundedQueue {
 public:
  BoundedQueue(size_t capacity, QueueFullPolicy policy)
      : capacity_(capacity == 0 ? 1 : capacity), policy_(policy) {}

  BoundedQueue(const BoundedQueue&) = delete;
  BoundedQueue& operator=(const BoundedQueue&) = delete;

  // Adds an item. Returns false (and drops the item) only after Shutdown().
  // With kDropOldest a full queue loses its oldest item, counted in dropped().
  bool Push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (policy_ == QueueFullPolicy::kBlock) {
      not_full_.wait(lock, [&] { return shutdown_ || items_.size() < capacity_; });
    }
    if (shutdown_) return false;
    if (items_.size() >= capacity_) {
      items_.pop_front();
      ++dropped_;
    }
    items_.push_back(std::move(item));
    lock.unlock();
    not_empty_.notify_one();
    return true;
  }

  // Waits for an item. Returns nullopt once the queue is shut down AND empty, so
  // items pushed before Shutdown() are still delivered.
  std::optional<T> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return shutdown_ || !items_.empty(); });
    return PopLocked(&lock);
  }

  // Like Pop() but gives up after timeout_us microseconds.
  std::optional<T> PopFor(int64_t timeout_us) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait_for(lock, std::chrono::microseconds(timeout_us),
                        [&] { return shutdown_ || !items_.empty(); });
    return PopLocked(&lock);
  }

  std::optional<T> TryPop() {
    std::unique_lock<std::mutex> lock(mutex_);
    return PopLocked(&lock);
  }

  // Wakes every waiter; later pushes fail, pops drain what is left.
  void Shutdown() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      shutdown_ = true;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  bool is_shutdown() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return shutdown_;
  }
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t capacity() const { return capacity_; }
  QueueFullPolicy policy() const { return policy_; }
  int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  std::optional<T> PopLocked(std::unique_lock<std::mutex>* lock) {
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    lock->unlock();
    not_full_.notify_one();
    return item;
  }

  const size_t capacity_;
  const QueueFullPolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;
  std::condition_variable not_full_;
  std::deque<T> items_;
  bool shutdown_ = false;
  int64_t dropped_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_BOUNDED_QUEUE_H_
