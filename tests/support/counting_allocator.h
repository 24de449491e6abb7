#pragma once
// Counts the global allocations a thread makes while armed, for tests that prove a hot path
// allocates nothing. Linking the counting_allocator library replaces the global operator new and
// delete of the whole binary: give such a test a binary of its own.

namespace cairn::testing {

class CountingAllocator {
 public:
  // Starts counting the calling thread's allocations from zero.
  static void Arm();
  // Stops counting; returns how many allocations the thread made since Arm().
  static long Disarm();
};

}  // namespace cairn::testing
