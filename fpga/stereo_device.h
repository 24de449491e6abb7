#pragma once
// What the FPGA stereo driver needs from a device: its register window (PCIe BAR0), memory the
// device can reach by DMA, and its interrupt. UioStereoDevice provides them on the board,
// SimulatedStereoDevice from the Verilator model, so FpgaStereoMatcher runs unchanged on both.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "common/status.h"

namespace cairn {

// Memory shared with the device: `cpu` for the host, `iova` for the device's DMA engine.
struct DmaBuffer {
  uint8_t* cpu = nullptr;
  uint64_t iova = 0;
  size_t bytes = 0;
};

class StereoDevice {
 public:
  virtual ~StereoDevice() = default;
  virtual std::string_view name() const = 0;
  // Like a PCIe read, a register read of a device that has gone returns 0xFFFFFFFF.
  virtual uint32_t Read32(uint32_t offset) = 0;
  virtual void Write32(uint32_t offset, uint32_t value) = 0;
  // DMA memory, at least 4 KB aligned on both sides. Buffers live until ReleaseDma() or the
  // device's destruction.
  virtual Expected<DmaBuffer> AllocateDma(size_t bytes) = 0;
  virtual void ReleaseDma() = 0;
  // Ok when the interrupt fired, TimeoutError after `timeout`, UnavailableError when the device
  // has gone.
  virtual Status WaitForInterrupt(std::chrono::nanoseconds timeout) = 0;
};

}  // namespace cairn
