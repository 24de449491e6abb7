#include "fpga/simulated_stereo_device.h"

#include <cstring>

namespace cairn {
namespace {

constexpr uint64_t kPage = 4096;

}  // namespace

SimulatedStereoDevice::SimulatedStereoDevice(double clock_hz, int read_latency_cycles)
    : clock_hz_(clock_hz), read_latency_(read_latency_cycles) {
  SgmTopInputs in;
  in.rst = true;
  for (int i = 0; i < 4; ++i) Tick(in);
}

uint8_t* SimulatedStereoDevice::Translate(uint64_t iova, size_t bytes) {
  for (const auto& r : regions_) {
    if (iova >= r->iova && iova + bytes <= r->iova + r->bytes) return r->base + (iova - r->iova);
  }
  return nullptr;
}

SgmTopOutputs SimulatedStereoDevice::Tick(SgmTopInputs in) {
  if (!responses_.empty() && responses_.front().due <= model_.cycles()) {
    const Response& r = responses_.front();
    in.rd_resp_valid = true;
    in.rd_resp_data = r.data;
    in.rd_resp_tag = r.tag;
    in.rd_resp_err = r.error;
    responses_.pop_front();
  }
  in.rd_req_ready = true;
  in.wr_ready = !hang_writes_;
  in.wr_err = write_error_pending_;
  write_error_pending_ = false;
  const SgmTopOutputs out = model_.Cycle(in);
  if (out.rd_req_valid) {
    Response r;
    r.due = model_.cycles() + static_cast<uint64_t>(read_latency_);
    r.tag = out.rd_req_tag;
    const uint8_t* p = Translate(out.rd_req_addr, 8);
    if (p == nullptr || read_fault_pending_) {
      r.error = true;
      read_fault_pending_ = false;
    } else {
      std::memcpy(&r.data, p, 8);  // little endian, like PCIe payloads
    }
    responses_.push_back(r);
  }
  if (out.wr_valid && in.wr_ready) {
    uint8_t* p = Translate(out.wr_addr, 8);
    if (p == nullptr) {
      write_error_pending_ = true;
    } else {
      for (int b = 0; b < 8; ++b) {
        if ((out.wr_strb >> b) & 1u) p[b] = static_cast<uint8_t>(out.wr_data >> (8 * b));
      }
    }
  }
  return out;
}

uint32_t SimulatedStereoDevice::Read32(uint32_t offset) {
  if (removed()) return 0xFFFFFFFFu;
  SgmTopInputs in;
  in.reg_rd = true;
  in.reg_addr = static_cast<uint16_t>(offset & 0xFFF);
  Tick(in);
  return model_.Outputs().reg_rdata;
}

void SimulatedStereoDevice::Write32(uint32_t offset, uint32_t value) {
  if (removed()) return;
  SgmTopInputs in;
  in.reg_wr = true;
  in.reg_addr = static_cast<uint16_t>(offset & 0xFFF);
  in.reg_wdata = value;
  Tick(in);
}

Expected<DmaBuffer> SimulatedStereoDevice::AllocateDma(size_t bytes) {
  if (bytes == 0) return InvalidArgumentError("SimulatedStereoDevice: empty DMA buffer");
  auto r = std::make_unique<Region>();
  r->memory.assign(bytes + kPage, 0);
  const uintptr_t raw = reinterpret_cast<uintptr_t>(r->memory.data());
  r->base = r->memory.data() + ((kPage - raw % kPage) % kPage);
  r->bytes = bytes;
  r->iova = next_iova_;
  next_iova_ += (bytes + 2 * kPage - 1) / kPage * kPage + kPage;  // unmapped guard page between
  DmaBuffer b{r->base, r->iova, bytes};
  regions_.push_back(std::move(r));
  return b;
}

void SimulatedStereoDevice::ReleaseDma() { regions_.clear(); }

Status SimulatedStereoDevice::WaitForInterrupt(std::chrono::nanoseconds timeout) {
  const double budget = static_cast<double>(timeout.count()) * 1e-9 * clock_hz_;
  const uint64_t end = model_.cycles() + static_cast<uint64_t>(budget);
  while (model_.cycles() < end) {
    if (removed()) return UnavailableError("fpga-sim: device removed");
    const SgmTopOutputs out = Tick(SgmTopInputs{});
    if (out.irq) return Status::Ok();
  }
  if (removed()) return UnavailableError("fpga-sim: device removed");
  return TimeoutError("fpga-sim: no interrupt within " +
                      std::to_string(std::chrono::duration<double, std::milli>(timeout).count()) +
                      " ms (" + std::to_string(static_cast<uint64_t>(budget)) + " cycles)");
}

}  // namespace cairn
