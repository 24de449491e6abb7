#pragma once
// A first-in first-out queue of at most N elements whose slots are reused rather than destroyed:
// an element's buffers keep their capacity for the next one put in its slot, so a queue of large
// images allocates nothing once its slots have held one each. The slot given up last is the one
// reused first, so only as many slots grow buffers as elements are ever held at once (plus the one
// being filled).

#include <array>
#include <cassert>
#include <cstddef>

namespace cairn {

template <class T, size_t N>
class ReuseRing {
  static_assert(N > 0, "a ring holds at least one element");

 public:
  ReuseRing() {
    for (size_t i = 0; i < N; ++i) spare_[i] = N - 1 - i;
  }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == N; }

  // A spare slot, holding whatever it held before, to be filled and then added with Push(). Not
  // while full.
  T& Next() {
    assert(!full());
    return slots_[spare_[N - 1 - size_]];
  }
  // Adds the slot Next() gave as the last element.
  void Push() {
    assert(!full());
    order_[(head_ + size_) % N] = spare_[N - 1 - size_];
    ++size_;
  }
  const T& Front() const {
    assert(!empty());
    return slots_[order_[head_]];
  }
  // Removes the first element; its slot keeps its contents and is the next one Next() gives.
  void Pop() {
    assert(!empty());
    --size_;
    spare_[N - 1 - size_] = order_[head_];
    head_ = (head_ + 1) % N;
  }

 private:
  std::array<T, N> slots_{};
  std::array<size_t, N> order_{};  // the elements' slots, first at head_
  // Spare slots as a stack: N - size_ of them at the front, the top at index N - 1 - size_.
  std::array<size_t, N> spare_{};
  size_t head_ = 0;
  size_t size_ = 0;
};

}  // namespace cairn
