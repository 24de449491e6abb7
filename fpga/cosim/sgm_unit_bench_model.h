#pragma once
// The combinational RTL building blocks (fpga/rtl/sgm_unit_bench.v, built by Verilator) behind
// plain functions, for the unit benches against the golden model.

#include <cstdint>
#include <memory>

namespace cairn {

class SgmUnitBenchModel {
 public:
  static constexpr int kLanes = 32;

  SgmUnitBenchModel();
  ~SgmUnitBenchModel();
  SgmUnitBenchModel(const SgmUnitBenchModel&) = delete;
  SgmUnitBenchModel& operator=(const SgmUnitBenchModel&) = delete;

  // sgm_census5x5: window[5 * row + column].
  uint32_t Census(const uint8_t window[25]);
  // sgm_cost_lanes: bit i of `outside` marks lane i's candidate outside the right image.
  void Cost(uint32_t left, const uint32_t right[kLanes], uint32_t outside, uint8_t cost[kLanes]);
  // sgm_path_step; returns the minimum over the lanes.
  uint8_t PathStep(const uint8_t cost[kLanes], const uint8_t prev[kLanes], uint8_t prev_lo,
                   uint8_t prev_hi, uint8_t min_prev, uint8_t p1, uint8_t p2,
                   uint8_t out[kLanes]);
  // sgm_subpixel (1/16 px).
  int Subpixel(int below, int at, int above);
  // sgm_lr_check: the output disparity word (INT16_MIN when invalid).
  int16_t LrCheck(int x, bool unique, int best, int value, int right_best, bool lr_enable,
                  int lr_max_diff);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cairn
