// Highway implementation of the SGM row kernels, compiled once per target and dispatched at run
// time. Every loop mirrors sgm_scalar_kernels.cc lane for lane; vectors are capped at 16 lanes so
// that the disparity count (a multiple of 16) is always a whole number of vectors.

#include <algorithm>
#include <bit>
#include <cstdlib>

#include "fpga/sgm_kernels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fpga/sgm_simd_kernels.cc"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace cairn {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D16 = hn::CappedTag<uint16_t, 16>;
using DI16 = hn::CappedTag<int16_t, 16>;
using DI32 = hn::CappedTag<int32_t, 16>;
using D32 = hn::CappedTag<uint32_t, 16>;

static void CensusSimd(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch,
                       uint32_t* out) {
  const DI32 di;
  const D32 du;
  const hn::Rebind<uint8_t, DI32> d8;
  const int n = static_cast<int>(hn::Lanes(di));
  const int rx = cw / 2, ry = ch / 2;
  const auto one = hn::Set(du, 1u);
  int x = 0;
  for (; x + n <= width; x += n) {
    auto bits = hn::Zero(du);
    for (int dy = -ry; dy <= 0; ++dy) {
      for (int dx = -rx; dx <= rx; ++dx) {
        if (dy == 0 && dx == 0) break;
        const auto a = hn::PromoteTo(di, hn::LoadU(d8, center + dy * stride + x + dx));
        const auto b = hn::PromoteTo(di, hn::LoadU(d8, center - dy * stride + x - dx));
        const auto bit = hn::And(hn::BitCast(du, hn::VecFromMask(di, hn::Gt(a, b))), one);
        bits = hn::Or(hn::ShiftLeft<1>(bits), bit);
      }
    }
    hn::StoreU(bits, du, out + x);
  }
  for (; x < width; ++x) {
    uint32_t bits = 0;
    for (int dy = -ry; dy <= 0; ++dy) {
      for (int dx = -rx; dx <= rx; ++dx) {
        if (dy == 0 && dx == 0) break;
        bits = (bits << 1) | (center[dy * stride + x + dx] > center[-dy * stride + x - dx] ? 1u : 0u);
      }
    }
    out[x] = bits;
  }
}

static void CostSimd(const uint32_t* left, const uint32_t* right_rev, const uint32_t* border,
                     const SgmRowGeometry& g, uint16_t* cost) {
  const D32 du;
  const DI32 di;
  const hn::Rebind<uint16_t, DI32> d16;
  const int n = static_cast<int>(hn::Lanes(du));
  const int d_count = g.disparities;
  for (int x = 0; x < g.width; ++x) {
    const auto vl = hn::Set(du, left[x]);
    const int base = g.rev_base - x;
    uint16_t* out = cost + x * d_count;
    for (int k = 0; k < d_count; k += n) {
      const auto pc = hn::PopulationCount(hn::Xor(vl, hn::LoadU(du, right_rev + base + k)));
      const auto c = hn::Max(pc, hn::LoadU(du, border + base + k));
      hn::StoreU(hn::DemoteTo(d16, hn::BitCast(di, c)), d16, out + k);
    }
  }
}

// One SGM recursion step (see Step in sgm_scalar_kernels.cc); dst[k] = (src ? src[k] : 0) + out[k].
template <bool kAddSrc>
HWY_INLINE uint16_t StepSimd(const uint16_t* c, const uint16_t* prev, uint16_t min_prev,
                             uint16_t p1, uint16_t p2, int d_count, uint16_t* out,
                             const uint16_t* src, uint16_t* dst) {
  const D16 d;
  const int n = static_cast<int>(hn::Lanes(d));
  const auto vp1 = hn::Set(d, p1);
  const auto vmp = hn::Set(d, min_prev);
  const auto jump = hn::SaturatedAdd(vmp, hn::Set(d, p2));
  auto best = hn::Set(d, uint16_t{0xFFFF});
  for (int k = 0; k < d_count; k += n) {
    const auto pv = hn::LoadU(d, prev + k);
    const auto lm = hn::SaturatedAdd(hn::LoadU(d, prev + k - 1), vp1);
    const auto lp = hn::SaturatedAdd(hn::LoadU(d, prev + k + 1), vp1);
    const auto m = hn::Min(hn::Min(pv, jump), hn::Min(lm, lp));
    const auto o = hn::Add(hn::LoadU(d, c + k), hn::Sub(m, vmp));
    hn::StoreU(o, d, out + k);
    best = hn::Min(best, o);
    if constexpr (kAddSrc) {
      hn::StoreU(hn::Add(hn::LoadU(d, src + k), o), d, dst + k);
    } else {
      hn::StoreU(o, d, dst + k);
    }
  }
  return hn::GetLane(hn::MinOfLanes(d, best));
}

static void HorizontalSimd(const uint16_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                           const uint16_t* p2_table, uint16_t p1, uint16_t* scratch,
                           uint16_t* sum) {
  const int d_count = g.disparities;
  uint16_t* a = scratch + kPathPad;
  uint16_t* b = scratch + g.block + kPathPad;
  for (int pass = 0; pass < 2; ++pass) {
    std::fill(a, a + d_count, uint16_t{0});
    uint16_t min_prev = 0;
    int prev_x = pass == 0 ? 0 : g.width - 1;
    for (int i = 0; i < g.width; ++i) {
      const int x = pass == 0 ? i : g.width - 1 - i;
      const uint16_t p2 = p2_table[std::abs(image_row[x] - image_row[prev_x])];
      uint16_t* s = sum + x * d_count;
      min_prev = pass == 0 ? StepSimd<false>(cost + x * d_count, a, min_prev, p1, p2, d_count, b, s, s)
                           : StepSimd<true>(cost + x * d_count, a, min_prev, p1, p2, d_count, b, s, s);
      std::swap(a, b);
      prev_x = x;
    }
  }
}

static void VerticalSimd(const uint16_t* cost, const uint8_t* image_row,
                         const uint8_t* prev_image_row, const SgmRowGeometry& g, int paths,
                         const uint16_t* p2_table, uint16_t p1, uint16_t* const* prev,
                         const uint16_t* const* prev_min, uint16_t* const* cur,
                         uint16_t* const* cur_min, const uint16_t* src, uint16_t* dst) {
  const int d_count = g.disparities;
  static constexpr int kOffsets[3] = {0, -1, 1};
  HWY_ALIGN uint16_t zero_block[512 + 2 * kPathPad];
  std::fill(zero_block, zero_block + g.block, uint16_t{0});
  zero_block[kPathPad - 1] = kPathSentinel;
  zero_block[kPathPad + d_count] = kPathSentinel;
  const uint16_t* zero = zero_block + kPathPad;
  for (int x = 0; x < g.width; ++x) {
    for (int p = 0; p < paths; ++p) {
      const int px = x + kOffsets[p];
      const bool inside = prev != nullptr && px >= 0 && px < g.width;
      const uint16_t* lp = inside ? prev[p] + px * g.block + kPathPad : zero;
      const uint16_t mp = inside ? prev_min[p][px] : 0;
      const uint16_t p2 =
          inside ? p2_table[std::abs(image_row[x] - prev_image_row[px])] : p2_table[0];
      uint16_t* out = cur[p] + x * g.block + kPathPad;
      const uint16_t* s = p == 0 ? src + x * d_count : dst + x * d_count;
      cur_min[p][x] = StepSimd<true>(cost + x * d_count, lp, mp, p1, p2, d_count, out, s,
                                     dst + x * d_count);
    }
  }
}

static void WtaSimd(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent,
                    uint16_t* scratch, int16_t* best, int16_t* right_best) {
  const DI16 d;
  const int n = static_cast<int>(hn::Lanes(d));
  const int d_count = g.disparities;
  const int n_rev = g.rev_base + d_count;
  int16_t* rmin = reinterpret_cast<int16_t*>(scratch);
  int16_t* rk = reinterpret_cast<int16_t*>(scratch + n_rev);
  std::fill(rmin, rmin + n_rev, int16_t{0x7FFF});
  std::fill(rk, rk + n_rev, int16_t{-1});
  const auto iota = hn::Iota(d, 0);
  const auto big = hn::Set(d, int16_t{0x7FFF});
  for (int x = 0; x < g.width; ++x) {
    const int16_t* s = reinterpret_cast<const int16_t*>(sum + x * d_count);
    auto vmin = big;
    for (int k = 0; k < d_count; k += n) vmin = hn::Min(vmin, hn::LoadU(d, s + k));
    const int16_t m = hn::GetLane(hn::MinOfLanes(d, vmin));
    const auto vm = hn::Set(d, m);
    int bk = 0;
    for (int k = 0; k < d_count; k += n) {
      const intptr_t i = hn::FindFirstTrue(d, hn::Eq(hn::LoadU(d, s + k), vm));
      if (i >= 0) {
        bk = k + static_cast<int>(i);
        break;
      }
    }
    const auto lo = hn::Set(d, static_cast<int16_t>(bk - 1));
    const auto hi = hn::Set(d, static_cast<int16_t>(bk + 1));
    auto vsec = big;
    const int base = g.rev_base - x;
    for (int k = 0; k < d_count; k += n) {
      const auto v = hn::LoadU(d, s + k);
      const auto kv = hn::Add(iota, hn::Set(d, static_cast<int16_t>(k)));
      const auto keep = hn::Or(hn::Lt(kv, lo), hn::Gt(kv, hi));
      vsec = hn::Min(vsec, hn::IfThenElse(keep, v, big));
      const auto mo = hn::LoadU(d, rmin + base + k);
      const auto lt = hn::Lt(v, mo);
      hn::StoreU(hn::IfThenElse(lt, v, mo), d, rmin + base + k);
      hn::StoreU(hn::IfThenElse(lt, kv, hn::LoadU(d, rk + base + k)), d, rk + base + k);
    }
    const uint32_t second = static_cast<uint32_t>(hn::GetLane(hn::MinOfLanes(d, vsec)));
    const bool unique = second * static_cast<uint32_t>(100 - uniqueness_percent) >=
                        static_cast<uint32_t>(m) * 100u;
    best[x] = static_cast<int16_t>(unique ? bk : -1 - bk);
  }
  for (int xr = 0; xr < g.width; ++xr) right_best[xr] = rk[g.rev_base - g.min_disparity - xr];
}

static int64_t TargetSimd() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace cairn
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cairn {
namespace {

HWY_EXPORT(CensusSimd);
HWY_EXPORT(CostSimd);
HWY_EXPORT(HorizontalSimd);
HWY_EXPORT(VerticalSimd);
HWY_EXPORT(WtaSimd);
HWY_EXPORT(TargetSimd);

void Census(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch, uint32_t* out) {
  HWY_DYNAMIC_DISPATCH(CensusSimd)(center, stride, width, cw, ch, out);
}
void Cost(const uint32_t* left, const uint32_t* right_rev, const uint32_t* border,
          const SgmRowGeometry& g, uint16_t* cost) {
  HWY_DYNAMIC_DISPATCH(CostSimd)(left, right_rev, border, g, cost);
}
void Horizontal(const uint16_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                const uint16_t* p2_table, uint16_t p1, uint16_t* scratch, uint16_t* sum) {
  HWY_DYNAMIC_DISPATCH(HorizontalSimd)(cost, image_row, g, p2_table, p1, scratch, sum);
}
void Vertical(const uint16_t* cost, const uint8_t* image_row, const uint8_t* prev_image_row,
              const SgmRowGeometry& g, int paths, const uint16_t* p2_table, uint16_t p1,
              uint16_t* const* prev, const uint16_t* const* prev_min, uint16_t* const* cur,
              uint16_t* const* cur_min, const uint16_t* src, uint16_t* dst) {
  HWY_DYNAMIC_DISPATCH(VerticalSimd)(cost, image_row, prev_image_row, g, paths, p2_table, p1, prev,
                                     prev_min, cur, cur_min, src, dst);
}
void Wta(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent, uint16_t* scratch,
         int16_t* best, int16_t* right_best) {
  HWY_DYNAMIC_DISPATCH(WtaSimd)(sum, g, uniqueness_percent, scratch, best, right_best);
}

}  // namespace

const SgmKernels& SimdSgmKernels() {
  static const SgmKernels kernels{Census, Cost, Horizontal, Vertical, Wta};
  return kernels;
}

const char* SimdTargetName() {
  return hwy::TargetName(HWY_DYNAMIC_DISPATCH(TargetSimd)());
}

}  // namespace cairn
#endif  // HWY_ONCE
