#pragma once
// The SGM offload board through Linux UIO (uio_pci_generic or a small board driver, see
// fpga/REGISTERS.md "Kernel side"): map 0 is BAR0 with the registers, map 1 a physically
// contiguous DMA window that the board driver reserved (its bus address is in
// /sys/class/uio/uioN/maps/map1/addr); the interrupt is the UIO file descriptor (read blocks until
// it fires, writing 1 re-enables it).

#include <cstdint>
#include <memory>
#include <string>

#include "fpga/stereo_device.h"

namespace cairn {

class UioStereoDevice final : public StereoDevice {
 public:
  // `path` is the device node, e.g. "/dev/uio0". NotFound when it does not exist.
  static Expected<std::unique_ptr<UioStereoDevice>> Open(const std::string& path);
  ~UioStereoDevice() override;
  UioStereoDevice(const UioStereoDevice&) = delete;
  UioStereoDevice& operator=(const UioStereoDevice&) = delete;

  std::string_view name() const override { return path_; }
  uint32_t Read32(uint32_t offset) override;
  void Write32(uint32_t offset, uint32_t value) override;
  Expected<DmaBuffer> AllocateDma(size_t bytes) override;
  void ReleaseDma() override { dma_used_ = 0; }
  Status WaitForInterrupt(std::chrono::nanoseconds timeout) override;

 private:
  explicit UioStereoDevice(std::string path) : path_(std::move(path)) {}

  std::string path_;
  int fd_ = -1;
  volatile uint32_t* regs_ = nullptr;
  size_t regs_bytes_ = 0;
  uint8_t* dma_ = nullptr;
  size_t dma_bytes_ = 0;
  uint64_t dma_bus_ = 0;
  size_t dma_used_ = 0;
};

}  // namespace cairn
