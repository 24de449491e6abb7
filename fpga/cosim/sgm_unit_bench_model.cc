#include "fpga/cosim/sgm_unit_bench_model.h"

#include "Vsgm_unit_bench.h"
#include "verilated.h"

namespace cairn {

struct SgmUnitBenchModel::Impl {
  VerilatedContext context;
  Vsgm_unit_bench top{&context};
};

namespace {

// Packs `count` fields of `bits` bits into a Verilator wide signal (32-bit words, LSB first).
template <class Wide, class T>
void Pack(Wide& wide, const T* fields, int count, int bits) {
  for (auto& word : wide.m_storage) word = 0;
  for (int i = 0; i < count; ++i) {
    for (int b = 0; b < bits; ++b) {
      if ((static_cast<uint32_t>(fields[i]) >> b) & 1u) {
        const int bit = i * bits + b;
        wide[bit / 32] |= 1u << (bit % 32);
      }
    }
  }
}

template <class Wide>
uint32_t Field(const Wide& wide, int index, int bits) {
  uint32_t v = 0;
  for (int b = 0; b < bits; ++b) {
    const int bit = index * bits + b;
    v |= ((wide[bit / 32] >> (bit % 32)) & 1u) << b;
  }
  return v;
}

}  // namespace

SgmUnitBenchModel::SgmUnitBenchModel() : impl_(std::make_unique<Impl>()) {}
SgmUnitBenchModel::~SgmUnitBenchModel() { impl_->top.final(); }

uint32_t SgmUnitBenchModel::Census(const uint8_t window[25]) {
  Pack(impl_->top.census_win, window, 25, 8);
  impl_->top.eval();
  return impl_->top.census_bits;
}

void SgmUnitBenchModel::Cost(uint32_t left, const uint32_t right[kLanes], uint32_t outside,
                             uint8_t cost[kLanes]) {
  Vsgm_unit_bench& t = impl_->top;
  t.cost_left = left & 0xFFF;
  Pack(t.cost_right, right, kLanes, 12);
  t.cost_outside = outside;
  t.eval();
  for (int i = 0; i < kLanes; ++i) cost[i] = static_cast<uint8_t>(Field(t.cost_out, i, 8));
}

uint8_t SgmUnitBenchModel::PathStep(const uint8_t cost[kLanes], const uint8_t prev[kLanes],
                                    uint8_t prev_lo, uint8_t prev_hi, uint8_t min_prev,
                                    uint8_t p1, uint8_t p2, uint8_t out[kLanes]) {
  Vsgm_unit_bench& t = impl_->top;
  Pack(t.step_cost, cost, kLanes, 8);
  Pack(t.step_prev, prev, kLanes, 8);
  t.step_prev_lo = prev_lo;
  t.step_prev_hi = prev_hi;
  t.step_min_prev = min_prev;
  t.step_p1 = p1;
  t.step_p2 = p2;
  t.eval();
  for (int i = 0; i < kLanes; ++i) out[i] = static_cast<uint8_t>(Field(t.step_out, i, 8));
  return t.step_min;
}

int SgmUnitBenchModel::Subpixel(int below, int at, int above) {
  Vsgm_unit_bench& t = impl_->top;
  t.sub_below = static_cast<uint16_t>(below);
  t.sub_at = static_cast<uint16_t>(at);
  t.sub_above = static_cast<uint16_t>(above);
  t.eval();
  const int v = t.sub_offset & 0x1F;
  return v >= 16 ? v - 32 : v;  // 5-bit two's complement
}

int16_t SgmUnitBenchModel::LrCheck(int x, bool unique, int best, int value, int right_best,
                                   bool lr_enable, int lr_max_diff) {
  Vsgm_unit_bench& t = impl_->top;
  t.lr_x = static_cast<uint16_t>(x);
  t.lr_unique = unique;
  t.lr_best = static_cast<uint8_t>(best);
  t.lr_value = static_cast<uint16_t>(value);
  t.lr_right_best = static_cast<uint8_t>(right_best);
  t.lr_enable = lr_enable;
  t.lr_max_diff = static_cast<uint8_t>(lr_max_diff);
  t.eval();
  return static_cast<int16_t>(t.lr_disparity);
}

}  // namespace cairn
