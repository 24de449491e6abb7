#pragma once
// Cycle-accurate model of fpga/rtl/sgm_top.v (built by Verilator). The pins are plain structs so
// that no Verilator header reaches the rest of the code base; SimulatedStereoDevice drives them.

#include <cstdint>
#include <memory>

namespace cairn {

struct SgmTopInputs {
  bool rst = false;
  bool reg_wr = false;
  bool reg_rd = false;
  uint16_t reg_addr = 0;
  uint32_t reg_wdata = 0;
  bool rd_req_ready = true;
  bool rd_resp_valid = false;
  uint64_t rd_resp_data = 0;
  bool rd_resp_tag = false;
  bool rd_resp_err = false;
  bool wr_ready = true;
  bool wr_err = false;
};

struct SgmTopOutputs {
  uint32_t reg_rdata = 0;
  bool irq = false;
  bool rd_req_valid = false;
  uint64_t rd_req_addr = 0;
  bool rd_req_tag = false;
  bool wr_valid = false;
  uint64_t wr_addr = 0;
  uint64_t wr_data = 0;
  uint8_t wr_strb = 0;
};

// Synthesis parameters the model was built with (sgm_top's LANES, DMAX, WMAX).
inline constexpr int kSgmModelLanes = 32;
inline constexpr int kSgmModelMaxDisparities = 128;
inline constexpr int kSgmModelMaxWidth = 1024;

class SgmTopModel {
 public:
  SgmTopModel();
  ~SgmTopModel();
  SgmTopModel(const SgmTopModel&) = delete;
  SgmTopModel& operator=(const SgmTopModel&) = delete;

  // Applies `in` for one clock cycle: settles the logic, returns the outputs seen before the
  // rising edge (what the other side samples), then clocks the edge.
  SgmTopOutputs Cycle(const SgmTopInputs& in);
  // Outputs after the last edge (registered outputs such as reg_rdata).
  SgmTopOutputs Outputs() const;
  uint64_t cycles() const { return cycles_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  uint64_t cycles_ = 0;
};

}  // namespace cairn
