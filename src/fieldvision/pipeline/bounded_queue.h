// A bounded, thread-safe FIFO between pipeline stages. kBlock makes the producer wait when the
// queue is full (offline files: nothing is lost); kDropOldest discards the oldest item to make
// room (live input: the newest items are kept, as in the seed's 3-message queues). Dropped items
// are counted. Written by hand: the standard library has no bounded concurrent queue.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

#include "fieldvision/util/error.h"

namespace fv::pipeline {

enum class QueuePolicy { kBlock, kDropOldest };

template <typename T>
class BoundedQueue {
 public:
  BoundedQueue(size_t capacity, QueuePolicy policy) : capacity_(capacity), policy_(policy) {
    FV_REQUIRE(capacity >= 1, "BoundedQueue: capacity must be >= 1 (got {})", capacity);
  }

  // Adds an item; blocks while full (kBlock) or drops the oldest (kDropOldest). Returns false
  // (and drops the item) when the queue is closed.
  bool Push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (policy_ == QueuePolicy::kBlock) {
      not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    }
    if (closed_) return false;
    if (items_.size() >= capacity_) {
      items_.pop_front();
      ++dropped_;
    }
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  // The oldest item; blocks until one arrives. nullopt once the queue is closed and empty.
  std::optional<T> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    return TakeLocked();
  }

  // The oldest item or nullopt at once.
  std::optional<T> TryPop() {
    std::lock_guard<std::mutex> lock(mutex_);
    return TakeLocked();
  }

  // No more pushes; waiting consumers get the remaining items, then nullopt.
  void Close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  size_t capacity() const { return capacity_; }
  QueuePolicy policy() const { return policy_; }

 private:
  std::optional<T> TakeLocked() {
    if (items_.empty()) return std::nullopt;
    std::optional<T> item(std::move(items_.front()));
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  const size_t capacity_;
  const QueuePolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  size_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace fv::pipeline
