#pragma once
// The SGM offload board, simulated cycle by cycle: the Verilator model of fpga/rtl/sgm_top.v
// (registers, DMA engine, census, SGM core) plus the host side the board talks to over PCIe: host
// memory reached through an IOMMU-like map of the DMA buffers (reads answered after a fixed
// latency, faults for unmapped addresses) and the interrupt line. Time advances only while the
// driver accesses registers or waits for the interrupt, at `clock_hz` simulated cycles per second.
//
// Fault injection for the driver's error paths: a DMA read fault, writes that never complete (a
// hung bus), and surprise removal after a number of cycles.

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "fpga/cosim/sgm_top_model.h"
#include "fpga/stereo_device.h"

namespace cairn {

class SimulatedStereoDevice final : public StereoDevice {
 public:
  explicit SimulatedStereoDevice(double clock_hz = 150e6, int read_latency_cycles = 8);

  std::string_view name() const override { return "fpga-sim"; }
  uint32_t Read32(uint32_t offset) override;
  void Write32(uint32_t offset, uint32_t value) override;
  Expected<DmaBuffer> AllocateDma(size_t bytes) override;
  void ReleaseDma() override;
  Status WaitForInterrupt(std::chrono::nanoseconds timeout) override;

  // The next DMA read answers with an error (as an IOMMU fault or a poisoned completion would).
  void InjectDmaReadFault() { read_fault_pending_ = true; }
  // While set, the host never accepts DMA writes.
  void HangDmaWrites(bool hang) { hang_writes_ = hang; }
  // The device disappears once `cycles` more cycles have run.
  void RemoveAfterCycles(uint64_t cycles) { remove_at_ = model_.cycles() + cycles; }

  uint64_t cycles() const { return model_.cycles(); }
  double clock_hz() const { return clock_hz_; }

 private:
  struct Region {
    uint64_t iova = 0;
    std::vector<uint8_t> memory;  // over-allocated for alignment
    uint8_t* base = nullptr;
    size_t bytes = 0;
  };
  struct Response {
    uint64_t due = 0;
    uint64_t data = 0;
    bool tag = false;
    bool error = false;
  };

  bool removed() const { return model_.cycles() >= remove_at_; }
  // One clock cycle with the given register access; serves the DMA side.
  SgmTopOutputs Tick(SgmTopInputs in);
  uint8_t* Translate(uint64_t iova, size_t bytes);

  SgmTopModel model_;
  double clock_hz_;
  int read_latency_;
  std::vector<std::unique_ptr<Region>> regions_;
  uint64_t next_iova_ = 0x100000000ull;
  std::deque<Response> responses_;
  bool write_error_pending_ = false;
  bool read_fault_pending_ = false;
  bool hang_writes_ = false;
  uint64_t remove_at_ = UINT64_MAX;
};

}  // namespace cairn
