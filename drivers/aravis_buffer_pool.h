#pragma once
// The buffers of one camera's Aravis stream, published as Image data without a copy. A buffer the
// driver publishes stays out of the stream until the last consumer drops its image; then it is
// queued on the stream again, from whichever thread that was (Aravis' queues are thread-safe).
// The pool outlives the stream: every published image keeps it alive, so a buffer released after
// the camera was closed (Stop(), a reconnection) is freed instead of pushed into a dead stream.
//
// Formats the driver converts (Mono16, Bayer) go into gray images preallocated here as well. No
// memory is allocated per frame: the shared_ptr control block of a published image is built in
// storage reserved for its buffer, through an allocator whose deallocate() is the release (it
// runs last, after the control block is destroyed, so the storage is free to reuse).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

typedef struct _ArvStream ArvStream;
typedef struct _ArvBuffer ArvBuffer;

namespace cairn {

class AravisBufferPool : public std::enable_shared_from_this<AravisBufferPool> {
 public:
  // Allocates `count` buffers of `payload` bytes and queues them on `stream` (referenced until
  // Close()); `gray_bytes` > 0 also preallocates `count` gray images of that size.
  static std::shared_ptr<AravisBufferPool> Create(ArvStream* stream, size_t payload, int count,
                                                  size_t gray_bytes);
  ~AravisBufferPool();
  AravisBufferPool(const AravisBufferPool&) = delete;
  AravisBufferPool& operator=(const AravisBufferPool&) = delete;

  // `pixels` (inside `buffer`, popped from the stream) as image data: the last reference queues
  // the buffer again. Null for a buffer that is not this pool's.
  std::shared_ptr<const uint8_t[]> Share(ArvBuffer* buffer, const uint8_t* pixels);
  // The next finished buffer of the stream, or null (none, or closed).
  ArvBuffer* TryPop();
  // Queues a buffer the driver does not publish (failed, or converted into a gray image).
  void Requeue(ArvBuffer* buffer);

  struct GrayImage {
    uint8_t* pixels = nullptr;  // null when consumers hold every gray image
    std::shared_ptr<const uint8_t[]> data;
  };
  GrayImage AcquireGray();

  // Stops the stream and drops it (its queued buffers go with it); buffers still held by
  // consumers are freed when released. Idempotent.
  void Close();

  // True when `p` points into one of this pool's stream buffers (a zero-copy image).
  bool Owns(const uint8_t* p) const;
  int count() const { return static_cast<int>(slots_.size()); }
  int held() const;  // buffers and gray images consumers hold now

 private:
  static constexpr size_t kControlBlockBytes = 128;
  struct alignas(std::max_align_t) ControlStorage {
    unsigned char bytes[kControlBlockBytes];
  };
  struct Slot {
    ArvBuffer* buffer = nullptr;
    const uint8_t* begin = nullptr;
    size_t size = 0;
    bool out = false;  // held by consumers
    ControlStorage control;
  };
  struct GraySlot {
    std::unique_ptr<uint8_t[]> pixels;
    bool out = false;
    ControlStorage control;
  };
  // Slot i >= 0: stream buffer i; slot -1 - i: gray image i.
  template <class T>
  struct SlotAllocator {
    using value_type = T;
    SlotAllocator(std::shared_ptr<AravisBufferPool> p, int s) : pool(std::move(p)), slot(s) {}
    template <class U>
    SlotAllocator(const SlotAllocator<U>& o) : pool(o.pool), slot(o.slot) {}  // NOLINT: rebinding
    T* allocate(size_t n) {
      static_assert(sizeof(T) <= kControlBlockBytes, "the control block outgrew its storage");
      return n == 1 ? reinterpret_cast<T*>(pool->Storage(slot)) : nullptr;
    }
    void deallocate(T*, size_t) { pool->Release(slot); }
    template <class U>
    bool operator==(const SlotAllocator<U>& o) const {
      return pool == o.pool && slot == o.slot;
    }
    std::shared_ptr<AravisBufferPool> pool;
    int slot;
  };
  struct KeepPixels {
    void operator()(const uint8_t*) const {}  // the allocator's deallocate() releases the slot
  };

  AravisBufferPool() = default;
  unsigned char* Storage(int slot);
  void Release(int slot);

  mutable std::mutex mutex_;  // slots' `out`, and the stream against Close()
  ArvStream* stream_ = nullptr;
  std::vector<Slot> slots_;
  std::vector<GraySlot> gray_;
};

}  // namespace cairn
