#pragma once
// Heap bytes reserved by contiguous containers, for memory accounting: what is held (capacity),
// not what is used, since that is what the process pays for.

#include <cstddef>

namespace cairn {

// The heap one allocation of `request` bytes takes from glibc's malloc on 64-bit targets: the
// request plus an 8-byte header, rounded up to 16 bytes, at least 32. Small nodes (OctoMap's are
// 16 bytes) take twice their size.
constexpr size_t HeapBlockBytes(size_t request) {
  const size_t chunk = (request + 8 + 15) & ~size_t{15};
  return chunk < 32 ? 32 : chunk;
}

template <class... Containers>
size_t HeapBytes(const Containers&... c) {
  return (size_t{0} + ... + (c.capacity() * sizeof(typename Containers::value_type)));
}

}  // namespace cairn
