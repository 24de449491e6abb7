#pragma once
// Integer voxel keys and an open-addressing hash map over them. The maps here see millions of
// lookups per second (per-pixel voxel filtering, composition), where std::unordered_map's node
// allocations and pointer chasing cost several times more than a flat, linearly probed table.

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mapping/huge_page_allocator.h"

namespace cairn {

// Three signed 21-bit cell indices packed into 63 bits (x lowest). At 0.05 m a key spans +-52 km.
struct VoxelKey {
  static constexpr int32_t kBits = 21;
  static constexpr int32_t kOffset = 1 << (kBits - 1);
  static constexpr uint64_t kMask = (uint64_t{1} << kBits) - 1;
  // Never a packed key: bit 63 is always clear in one.
  static constexpr uint64_t kEmpty = ~uint64_t{0};

  static bool InRange(int64_t i) { return i >= -kOffset && i < kOffset; }
  static uint64_t Pack(int32_t x, int32_t y, int32_t z) {
    return (static_cast<uint64_t>(x + kOffset) & kMask) |
           ((static_cast<uint64_t>(y + kOffset) & kMask) << kBits) |
           ((static_cast<uint64_t>(z + kOffset) & kMask) << (2 * kBits));
  }
  static Eigen::Vector3i Unpack(uint64_t k) {
    return {static_cast<int32_t>(k & kMask) - kOffset,
            static_cast<int32_t>((k >> kBits) & kMask) - kOffset,
            static_cast<int32_t>((k >> (2 * kBits)) & kMask) - kOffset};
  }
  // std::floor for |s| < 2^31, without the rounding-mode dance that costs a dozen instructions
  // where SSE4.1's roundss is not available (the x86-64 baseline).
  static int32_t Floor(float s) {
    const int32_t t = static_cast<int32_t>(s);
    return t - (static_cast<float>(t) > s);
  }
  static int32_t Floor(double s) {
    const int32_t t = static_cast<int32_t>(s);
    return t - (static_cast<double>(t) > s);
  }
  // Slot of a key in a direct-mapped cache of 2^bits entries (Fibonacci hashing: the high bits of
  // the product mix every bit of the key).
  static size_t Slot(uint64_t key, int bits) { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits)); }
  // Cell of a point at `inv_res` cells per metre; false when outside the key range or not finite.
  static bool Of(const Eigen::Vector3f& p, float inv_res, uint64_t* key) {
    const float sx = p.x() * inv_res, sy = p.y() * inv_res, sz = p.z() * inv_res;
    // floor(s) is in [-lim, lim) exactly when s is (lim is an integer); also rejects NaN.
    constexpr float lim = static_cast<float>(kOffset);
    if (!(sx >= -lim && sx < lim && sy >= -lim && sy < lim && sz >= -lim && sz < lim)) return false;
    *key = Pack(Floor(sx), Floor(sy), Floor(sz));
    return true;
  }
};

// Linear probing, power-of-two capacity, load factor <= 1/2. No erase: callers keep zero-weight
// values instead, which keeps probing simple and iteration cheap.
template <class V>
class VoxelHashMap {
 public:
  explicit VoxelHashMap(size_t expected = 1024) { Rehash(std::bit_ceil(std::max<size_t>(16, 2 * expected))); }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  size_t memory_bytes() const { return slots_.capacity() * sizeof(Slot); }

  // Keeps the capacity (no allocation when refilled to a similar size).
  void Clear() {
    if (size_ == 0) return;
    for (Slot& s : slots_) s.key = VoxelKey::kEmpty;
    size_ = 0;
  }
  void Reserve(size_t n) {
    if (2 * n > slots_.size()) Rehash(std::bit_ceil(2 * n));
  }

  // The value for `key`, default-constructed when new.
  V& operator[](uint64_t key) {
    if (2 * (size_ + 1) > slots_.size()) Rehash(2 * slots_.size());
    size_t i = Hash(key) & mask_;
    while (true) {
      Slot& s = slots_[i];
      if (s.key == key) return s.value;
      if (s.key == VoxelKey::kEmpty) {
        s.key = key;
        s.value = V{};
        ++size_;
        return s.value;
      }
      i = (i + 1) & mask_;
    }
  }
  // Starts loading the slot `key` hashes to, for loops over many scattered keys in a large table.
  void Prefetch(uint64_t key) const { __builtin_prefetch(&slots_[Hash(key) & mask_]); }

  const V* Find(uint64_t key) const {
    size_t i = Hash(key) & mask_;
    while (true) {
      const Slot& s = slots_[i];
      if (s.key == key) return &s.value;
      if (s.key == VoxelKey::kEmpty) return nullptr;
      i = (i + 1) & mask_;
    }
  }
  V* Find(uint64_t key) { return const_cast<V*>(static_cast<const VoxelHashMap*>(this)->Find(key)); }

  // Calls f(key, value) for every entry.
  template <class F>
  void ForEach(F&& f) const {
    for (const Slot& s : slots_) {
      if (s.key != VoxelKey::kEmpty) f(s.key, s.value);
    }
  }
  template <class F>
  void ForEachMutable(F&& f) {
    for (Slot& s : slots_) {
      if (s.key != VoxelKey::kEmpty) f(s.key, s.value);
    }
  }

 private:
  struct Slot {
    uint64_t key = VoxelKey::kEmpty;
    V value{};
  };
  static size_t Hash(uint64_t k) {
    k ^= k >> 31;
    k *= 0x7FB5D329728EA185ull;
    k ^= k >> 27;
    return static_cast<size_t>(k);
  }
  void Rehash(size_t capacity) {
    std::vector<Slot, HugePageAllocator<Slot>> old;
    old.swap(slots_);
    slots_.assign(capacity, Slot{});
    mask_ = capacity - 1;
    size_ = 0;
    for (const Slot& s : old) {
      if (s.key != VoxelKey::kEmpty) (*this)[s.key] = s.value;
    }
  }

  std::vector<Slot, HugePageAllocator<Slot>> slots_;
  size_t mask_ = 0;
  size_t size_ = 0;
};

}  // namespace cairn
