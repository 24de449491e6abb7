#pragma once
// Heap bytes reserved by contiguous containers, for memory accounting: what is held (capacity),
// not what is used, since that is what the process pays for.

#include <cstddef>

namespace cairn {

template <class... Containers>
size_t HeapBytes(const Containers&... c) {
  return (size_t{0} + ... + (c.capacity() * sizeof(typename Containers::value_type)));
}

}  // namespace cairn
