// Highway implementation of the SGM row kernels, compiled once per target and dispatched at run
// time. Every loop mirrors sgm_scalar_kernels.cc lane for lane. Loops over disparities use full
// vectors when the disparity count is a multiple of their length, else 16 lanes (the count is
// always a multiple of 16).

#include <algorithm>
#include <bit>
#include <cstdlib>

#include "stereo/sgm_kernels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "stereo/sgm_simd_kernels.cc"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/cache_control.h"
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace cairn {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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

// Hamming distances byte plane by byte plane: 8-bit popcounts need no widening.
template <class D8>
void CostImpl(D8 d, const uint32_t* left, const uint8_t* right_planes, int plane_stride,
              int planes, const uint8_t* border, const SgmRowGeometry& g, uint8_t* cost) {
  const int n = static_cast<int>(hn::Lanes(d));
  const int d_count = g.disparities;
  for (int x = 0; x < g.width; ++x) {
    const int base = g.rev_base - x;
    uint8_t* out = cost + x * d_count;
    for (int k = 0; k < d_count; k += n) {
      auto acc = hn::Zero(d);
      for (int b = 0; b < planes; ++b) {
        const auto lb = hn::Set(d, static_cast<uint8_t>(left[x] >> (8 * b)));
        const auto v = hn::Xor(hn::LoadU(d, right_planes + b * plane_stride + base + k), lb);
        acc = hn::Add(acc, hn::PopulationCount(v));
      }
      hn::StoreU(hn::Max(acc, hn::LoadU(d, border + base + k)), d, out + k);
    }
  }
}

static void CostSimd(const uint32_t* left, const uint8_t* right_planes, int plane_stride,
                     int planes, const uint8_t* border, const SgmRowGeometry& g, uint8_t* cost) {
  const hn::ScalableTag<uint8_t> full;
  if (g.disparities % static_cast<int>(hn::Lanes(full)) == 0) {
    CostImpl(full, left, right_planes, plane_stride, planes, border, g, cost);
  } else {
    CostImpl(hn::CappedTag<uint8_t, 16>(), left, right_planes, plane_stride, planes, border, g,
             cost);
  }
}

// One SGM recursion step (see Step in sgm_scalar_kernels.cc), on 8-bit lanes; also
// dst[k] = (kAddSrc ? src[k] : 0) + out[k] in 16 bits.
template <bool kAddSrc, class D8, bool kStream = false>
HWY_INLINE uint8_t StepSimd(D8 d, const uint8_t* c, const uint8_t* prev, uint8_t min_prev,
                            uint8_t p1, uint8_t p2, int d_count, uint8_t* out,
                            const uint16_t* src, uint16_t* dst) {
#if HWY_TARGET != HWY_SCALAR
  const hn::Half<D8> dh;
  const hn::Rebind<uint16_t, decltype(dh)> dw;
#endif
  const int n = static_cast<int>(hn::Lanes(d));
  const auto vp1 = hn::Set(d, p1);
  const auto vmp = hn::Set(d, min_prev);
  const auto jump = hn::SaturatedAdd(vmp, hn::Set(d, p2));
  auto best = hn::Set(d, uint8_t{0xFF});
  for (int k = 0; k < d_count; k += n) {
    const auto pv = hn::LoadU(d, prev + k);
    const auto lm = hn::SaturatedAdd(hn::LoadU(d, prev + k - 1), vp1);
    const auto lp = hn::SaturatedAdd(hn::LoadU(d, prev + k + 1), vp1);
    const auto m = hn::Min(hn::Min(pv, jump), hn::Min(lm, lp));
    const auto o = hn::Add(hn::LoadU(d, c + k), hn::Sub(m, vmp));
    hn::StoreU(o, d, out + k);
    best = hn::Min(best, o);
#if HWY_TARGET == HWY_SCALAR  // one lane: nothing to split
    dst[k] = static_cast<uint16_t>((kAddSrc ? src[k] : 0) + out[k]);
  }
  return hn::GetLane(best);
#else
    const int nh = n / 2;
    auto lo = hn::PromoteTo(dw, hn::LowerHalf(dh, o));
    auto hi = hn::PromoteTo(dw, hn::UpperHalf(dh, o));
    if constexpr (kAddSrc) {
      lo = hn::Add(lo, hn::LoadU(dw, src + k));
      hi = hn::Add(hi, hn::LoadU(dw, src + k + nh));
    }
    if constexpr (kStream) {  // dst is aligned to whole vectors here (see VerticalSimd)
      hn::Stream(lo, dw, dst + k);
      hn::Stream(hi, dw, dst + k + nh);
    } else {
      hn::StoreU(lo, dw, dst + k);
      hn::StoreU(hi, dw, dst + k + nh);
    }
  }
  const auto bw = hn::Min(hn::PromoteTo(dw, hn::LowerHalf(dh, best)),
                          hn::PromoteTo(dw, hn::UpperHalf(dh, best)));
  return static_cast<uint8_t>(hn::GetLane(hn::MinOfLanes(dw, bw)));
#endif
}

// Both directions advance in the same loop: each step waits for the previous pixel's minimum,
// so two independent chains keep the core busy. The first of the two to reach a pixel writes its
// sum, the second adds.
template <class D8>
void HorizontalImpl(D8 d, const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                    const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum) {
  const int d_count = g.disparities;
  const int w = g.width;
  uint8_t* a0 = scratch;
  uint8_t* b0 = scratch + g.block;
  uint8_t* a1 = scratch + 2 * g.block;
  uint8_t* b1 = scratch + 3 * g.block;
  std::fill(a0, a0 + d_count, uint8_t{0});
  std::fill(a1, a1 + d_count, uint8_t{0});
  uint8_t min0 = 0, min1 = 0;
  for (int i = 0; i < w; ++i) {
    const int x0 = i, x1 = w - 1 - i;
    const uint8_t p20 = p2_table[std::abs(image_row[x0] - image_row[i > 0 ? x0 - 1 : x0])];
    const uint8_t p21 = p2_table[std::abs(image_row[x1] - image_row[i > 0 ? x1 + 1 : x1])];
    uint16_t* s0 = sum + x0 * d_count;
    uint16_t* s1 = sum + x1 * d_count;
    min0 = x0 <= x1 ? StepSimd<false>(d, cost + x0 * d_count, a0, min0, p1, p20, d_count, b0, s0, s0)
                    : StepSimd<true>(d, cost + x0 * d_count, a0, min0, p1, p20, d_count, b0, s0, s0);
    min1 = x1 > x0 ? StepSimd<false>(d, cost + x1 * d_count, a1, min1, p1, p21, d_count, b1, s1, s1)
                   : StepSimd<true>(d, cost + x1 * d_count, a1, min1, p1, p21, d_count, b1, s1, s1);
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
}

// The left-to-right path alone (raster_paths mode).
template <class D8>
void HorizontalForwardImpl(D8 d, const uint8_t* cost, const uint8_t* image_row,
                           const SgmRowGeometry& g, const uint8_t* p2_table, uint8_t p1,
                           uint8_t* scratch, uint16_t* sum) {
  const int d_count = g.disparities;
  uint8_t* a = scratch;
  uint8_t* b = scratch + g.block;
  std::fill(a, a + d_count, uint8_t{0});
  uint8_t min_prev = 0;
  for (int x = 0; x < g.width; ++x) {
    const uint8_t p2 = p2_table[std::abs(image_row[x] - image_row[x > 0 ? x - 1 : x])];
    uint16_t* s = sum + x * d_count;
    min_prev = StepSimd<false>(d, cost + x * d_count, a, min_prev, p1, p2, d_count, b, s, s);
    std::swap(a, b);
  }
}

template <bool kStream, class D8>
void VerticalImpl(D8 d, const uint8_t* cost, const uint8_t* image_row,
                  const uint8_t* prev_image_row, const SgmRowGeometry& g, int paths,
                  const uint8_t* p2_table, uint8_t p1, uint8_t* const* prev,
                  const uint8_t* const* prev_min, uint8_t* const* cur, uint8_t* const* cur_min,
                  const uint16_t* src, uint16_t* dst) {
  const int d_count = g.disparities;
  static constexpr int kOffsets[3] = {0, -1, 1};
  HWY_ALIGN uint8_t zero_block[kPathLead + 512 + kPathTail];
  HWY_ALIGN uint16_t partial[512];  // sums of the earlier paths of one pixel
  std::fill(zero_block, zero_block + kPathLead + g.block, kPathSentinel);
  std::fill(zero_block + kPathLead, zero_block + kPathLead + d_count, uint8_t{0});
  const uint8_t* zero = zero_block + kPathLead;
  for (int x = 0; x < g.width; ++x) {
    for (int p = 0; p < paths; ++p) {
      const int px = x + kOffsets[p];
      const bool inside = prev != nullptr && px >= 0 && px < g.width;
      const uint8_t* lp = inside ? prev[p] + px * g.block : zero;
      const uint8_t mp = inside ? prev_min[p][px] : 0;
      const uint8_t p2 =
          inside ? p2_table[std::abs(image_row[x] - prev_image_row[px])] : p2_table[0];
      uint8_t* out = cur[p] + x * g.block;
      const uint16_t* s = p == 0 ? src + x * d_count : partial;
      const uint8_t* c = cost + x * d_count;
      if (p + 1 < paths) {
        cur_min[p][x] = StepSimd<true>(d, c, lp, mp, p1, p2, d_count, out, s, partial);
      } else {
        cur_min[p][x] =
            StepSimd<true, D8, kStream>(d, c, lp, mp, p1, p2, d_count, out, s, dst + x * d_count);
      }
    }
  }
  if constexpr (kStream) hwy::FlushStream();
}

// Full vectors when the disparity count is a multiple of their length, else 16 lanes.
static void HorizontalSimd(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                           const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum) {
  const hn::ScalableTag<uint8_t> full;
  if (g.disparities % static_cast<int>(hn::Lanes(full)) == 0) {
    HorizontalImpl(full, cost, image_row, g, p2_table, p1, scratch, sum);
  } else {
    HorizontalImpl(hn::CappedTag<uint8_t, 16>(), cost, image_row, g, p2_table, p1, scratch, sum);
  }
}

static void HorizontalForwardSimd(const uint8_t* cost, const uint8_t* image_row,
                                  const SgmRowGeometry& g, const uint8_t* p2_table, uint8_t p1,
                                  uint8_t* scratch, uint16_t* sum) {
  const hn::ScalableTag<uint8_t> full;
  if (g.disparities % static_cast<int>(hn::Lanes(full)) == 0) {
    HorizontalForwardImpl(full, cost, image_row, g, p2_table, p1, scratch, sum);
  } else {
    HorizontalForwardImpl(hn::CappedTag<uint8_t, 16>(), cost, image_row, g, p2_table, p1, scratch,
                          sum);
  }
}

static void VerticalSimd(const uint8_t* cost, const uint8_t* image_row,
                         const uint8_t* prev_image_row, const SgmRowGeometry& g, int paths,
                         const uint8_t* p2_table, uint8_t p1, uint8_t* const* prev,
                         const uint8_t* const* prev_min, uint8_t* const* cur,
                         uint8_t* const* cur_min, const uint16_t* src, uint16_t* dst,
                         bool stream_dst) {
  const hn::ScalableTag<uint8_t> full;
  const size_t vector_bytes = hn::Lanes(full);  // = bytes of one half-width uint16 vector
  // Streaming stores need whole-vector alignment: every pixel's sums then start aligned.
  const bool aligned = reinterpret_cast<uintptr_t>(dst) % vector_bytes == 0;
  if (g.disparities % static_cast<int>(hn::Lanes(full)) == 0) {
    if (stream_dst && aligned && src != dst) {
      VerticalImpl<true>(full, cost, image_row, prev_image_row, g, paths, p2_table, p1, prev,
                         prev_min, cur, cur_min, src, dst);
    } else {
      VerticalImpl<false>(full, cost, image_row, prev_image_row, g, paths, p2_table, p1, prev,
                          prev_min, cur, cur_min, src, dst);
    }
  } else {
    VerticalImpl<false>(hn::CappedTag<uint8_t, 16>(), cost, image_row, prev_image_row, g, paths,
                        p2_table, p1, prev, prev_min, cur, cur_min, src, dst);
  }
}

template <class DI>
void WtaImpl(DI d, const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent,
             uint16_t* scratch, int16_t* best, int16_t* right_best) {
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

static void WtaSimd(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent,
                    uint16_t* scratch, int16_t* best, int16_t* right_best) {
  const hn::ScalableTag<int16_t> full;
  if (g.disparities % static_cast<int>(hn::Lanes(full)) == 0) {
    WtaImpl(full, sum, g, uniqueness_percent, scratch, best, right_best);
  } else {
    WtaImpl(hn::CappedTag<int16_t, 16>(), sum, g, uniqueness_percent, scratch, best, right_best);
  }
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
HWY_EXPORT(HorizontalForwardSimd);
HWY_EXPORT(VerticalSimd);
HWY_EXPORT(WtaSimd);
HWY_EXPORT(TargetSimd);

void Census(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch, uint32_t* out) {
  HWY_DYNAMIC_DISPATCH(CensusSimd)(center, stride, width, cw, ch, out);
}
void Cost(const uint32_t* left, const uint8_t* right_planes, int plane_stride, int planes,
          const uint8_t* border, const SgmRowGeometry& g, uint8_t* cost) {
  HWY_DYNAMIC_DISPATCH(CostSimd)(left, right_planes, plane_stride, planes, border, g, cost);
}
void Horizontal(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum) {
  HWY_DYNAMIC_DISPATCH(HorizontalSimd)(cost, image_row, g, p2_table, p1, scratch, sum);
}
void HorizontalForward(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                       const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum) {
  HWY_DYNAMIC_DISPATCH(HorizontalForwardSimd)(cost, image_row, g, p2_table, p1, scratch, sum);
}
void Vertical(const uint8_t* cost, const uint8_t* image_row, const uint8_t* prev_image_row,
              const SgmRowGeometry& g, int paths, const uint8_t* p2_table, uint8_t p1,
              uint8_t* const* prev, const uint8_t* const* prev_min, uint8_t* const* cur,
              uint8_t* const* cur_min, const uint16_t* src, uint16_t* dst, bool stream_dst) {
  HWY_DYNAMIC_DISPATCH(VerticalSimd)(cost, image_row, prev_image_row, g, paths, p2_table, p1, prev,
                                     prev_min, cur, cur_min, src, dst, stream_dst);
}
void Wta(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent, uint16_t* scratch,
         int16_t* best, int16_t* right_best) {
  HWY_DYNAMIC_DISPATCH(WtaSimd)(sum, g, uniqueness_percent, scratch, best, right_best);
}

}  // namespace

const SgmKernels& SimdSgmKernels() {
  static const SgmKernels kernels{Census, Cost, Horizontal, HorizontalForward, Vertical, Wta};
  return kernels;
}

const char* SimdTargetName() {
  return hwy::TargetName(HWY_DYNAMIC_DISPATCH(TargetSimd)());
}

}  // namespace cairn
#endif  // HWY_ONCE
