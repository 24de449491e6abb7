#include "drivers/aravis_buffer_pool.h"

#include <arv.h>

#include <functional>

namespace cairn {

std::shared_ptr<AravisBufferPool> AravisBufferPool::Create(ArvStream* stream, size_t payload, int count,
                                                           size_t gray_bytes) {
  std::shared_ptr<AravisBufferPool> pool(new AravisBufferPool());
  pool->stream_ = ARV_STREAM(g_object_ref(stream));
  pool->slots_.resize(static_cast<size_t>(count));
  for (Slot& s : pool->slots_) {
    s.buffer = arv_buffer_new_allocate(payload);
    s.begin =
        static_cast<const uint8_t*>(arv_buffer_get_data(s.buffer, nullptr));  // its size: what was received
    s.size = payload;
    arv_stream_push_buffer(stream, s.buffer);  // the stream now owns it until it is popped
  }
  if (gray_bytes > 0) {
    pool->gray_.resize(static_cast<size_t>(count));
    for (GraySlot& g : pool->gray_) g.pixels = std::make_unique<uint8_t[]>(gray_bytes);
  }
  return pool;
}

AravisBufferPool::~AravisBufferPool() {
  // Every image is gone (each holds the pool), so each buffer is in the stream's queues: the
  // stream frees them.
  Close();
}

void AravisBufferPool::Close() {
  ArvStream* stream = nullptr;
  {
    std::lock_guard lock(mutex_);
    stream = stream_;
    stream_ = nullptr;
  }
  if (stream == nullptr) return;
  arv_stream_set_emit_signals(stream, FALSE);
  g_object_unref(stream);  // joins the stream's thread, frees the queued buffers
}

unsigned char* AravisBufferPool::Storage(int slot) {
  return slot >= 0 ? slots_[static_cast<size_t>(slot)].control.bytes
                   : gray_[static_cast<size_t>(-1 - slot)].control.bytes;
}

std::shared_ptr<const uint8_t[]> AravisBufferPool::Share(ArvBuffer* buffer, const uint8_t* pixels) {
  int index = -1;
  {
    std::lock_guard lock(mutex_);
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (slots_[i].buffer == buffer && !slots_[i].out) {
        slots_[i].out = true;
        index = static_cast<int>(i);
        break;
      }
    }
  }
  if (index < 0) return nullptr;
  return std::shared_ptr<const uint8_t[]>(pixels, KeepPixels{},
                                          SlotAllocator<uint8_t>(shared_from_this(), index));
}

ArvBuffer* AravisBufferPool::TryPop() {
  std::lock_guard lock(mutex_);
  return stream_ != nullptr ? arv_stream_try_pop_buffer(stream_) : nullptr;
}

void AravisBufferPool::Requeue(ArvBuffer* buffer) {
  std::lock_guard lock(mutex_);
  if (stream_ != nullptr) {
    arv_stream_push_buffer(stream_, buffer);
  } else {
    g_object_unref(buffer);
  }
}

AravisBufferPool::GrayImage AravisBufferPool::AcquireGray() {
  int index = -1;
  {
    std::lock_guard lock(mutex_);
    for (size_t i = 0; i < gray_.size(); ++i) {
      if (!gray_[i].out) {
        gray_[i].out = true;
        index = static_cast<int>(i);
        break;
      }
    }
  }
  if (index < 0) return {};
  uint8_t* pixels = gray_[static_cast<size_t>(index)].pixels.get();
  return {pixels, std::shared_ptr<const uint8_t[]>(pixels, KeepPixels{},
                                                   SlotAllocator<uint8_t>(shared_from_this(), -1 - index))};
}

void AravisBufferPool::Release(int slot) {
  std::lock_guard lock(mutex_);
  if (slot < 0) {
    gray_[static_cast<size_t>(-1 - slot)].out = false;
    return;
  }
  Slot& s = slots_[static_cast<size_t>(slot)];
  s.out = false;
  if (stream_ != nullptr) {
    arv_stream_push_buffer(stream_, s.buffer);
  } else {
    g_object_unref(s.buffer);  // the stream is gone: nowhere to return it
    s.buffer = nullptr;
  }
}

bool AravisBufferPool::Owns(const uint8_t* p) const {
  std::lock_guard lock(mutex_);
  for (const Slot& s : slots_) {
    if (!std::less<const uint8_t*>()(p, s.begin) && std::less<const uint8_t*>()(p, s.begin + s.size))
      return true;
  }
  return false;
}

int AravisBufferPool::held() const {
  std::lock_guard lock(mutex_);
  int n = 0;
  for (const Slot& s : slots_) n += s.out ? 1 : 0;
  for (const GraySlot& g : gray_) n += g.out ? 1 : 0;
  return n;
}

}  // namespace cairn
