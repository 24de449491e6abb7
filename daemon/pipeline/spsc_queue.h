#pragma once
// Bounded single-producer single-consumer ring. Lock free and allocation free after
// construction: the producer never blocks in live operation (a full queue drops the new item and
// counts it), and the consumer sleeps on a shared WorkSignal rather than spinning.

#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace cairn {

// Wakes a consumer that waits for any of several queues. Producers bump the sequence; the
// consumer waits until it differs from the value it last saw (C++20 atomic wait: a futex, no lock).
class WorkSignal {
 public:
  uint32_t sequence() const { return seq_.load(std::memory_order_acquire); }
  void Notify() {
    seq_.fetch_add(1, std::memory_order_acq_rel);
    seq_.notify_all();
  }
  void WaitChange(uint32_t seen) const { seq_.wait(seen, std::memory_order_acquire); }

 private:
  std::atomic<uint32_t> seq_{0};
};

template <class T>
class SpscQueue {
 public:
  // Capacity is rounded up to a power of two.
  explicit SpscQueue(size_t capacity)
      : slots_(std::bit_ceil(capacity < 2 ? size_t{2} : capacity)), mask_(slots_.size() - 1) {}

  size_t capacity() const { return slots_.size(); }

  // Producer side. False (and counted) when full.
  bool TryPush(const T& item) {
    const uint64_t head = head_.load(std::memory_order_relaxed);
    const uint64_t tail = tail_.load(std::memory_order_acquire);
    if (head - tail >= slots_.size()) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[head & mask_] = item;
    head_.store(head + 1, std::memory_order_release);
    const uint64_t depth = head + 1 - tail;
    if (depth > high_water_.load(std::memory_order_relaxed)) {
      high_water_.store(depth, std::memory_order_relaxed);
    }
    return true;
  }

  // Consumer side.
  const T* Front() const {
    const uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return nullptr;
    return &slots_[tail & mask_];
  }
  void PopFront() {
    const uint64_t tail = tail_.load(std::memory_order_relaxed);
    slots_[tail & mask_] = T{};  // release held buffers (images) promptly
    tail_.store(tail + 1, std::memory_order_release);
  }

  size_t size() const {
    return static_cast<size_t>(head_.load(std::memory_order_acquire) -
                               tail_.load(std::memory_order_acquire));
  }
  bool empty() const { return size() == 0; }
  uint64_t pushed() const { return head_.load(std::memory_order_acquire); }
  uint64_t popped() const { return tail_.load(std::memory_order_acquire); }
  uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  uint64_t high_water() const { return high_water_.load(std::memory_order_relaxed); }

 private:
  std::vector<T> slots_;
  const size_t mask_;
  alignas(64) std::atomic<uint64_t> head_{0};
  alignas(64) std::atomic<uint64_t> tail_{0};
  alignas(64) std::atomic<uint64_t> dropped_{0};
  std::atomic<uint64_t> high_water_{0};  // written by the producer only
};

}  // namespace cairn
