// Highway kernels of the SIMD backend's own schedule for the four horizontal and vertical paths
// (SgmFourPathKernels in sgm_kernels.h; SgmMatcher::MatchFourPath runs them). The arithmetic is
// the golden model's (sgm_scalar_kernels.cc) lane for lane; only the order of the work and the
// memory it touches differ:
// - the cost of a pixel is computed where the first path consumes it, from nibble lookup tables
//   (popcount(l ^ r) = sum over nibbles of T[l nibble][r nibble], one byte shuffle per nibble);
// - a path step of the horizontal recursions keeps its neighbours in registers (byte shifts
//   across vectors instead of unaligned reloads of what the previous step just stored);
// - the two horizontal paths, the two vertical ones and the sum happen in one pass over the row;
// - winner-take-all keeps the right-image minima in four interleaved copies so that no load waits
//   for the store of the pixel before.

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <utility>

#include "fpga/sgm_kernels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fpga/sgm_simd_four_path.cc"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace cairn {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#undef CAIRN_SGM_FOUR_PATH_KERNELS  // foreach_target includes this file once per target
#if HWY_TARGET != HWY_SCALAR && !HWY_HAVE_SCALABLE
#define CAIRN_SGM_FOUR_PATH_KERNELS 1

// kNibbleDistance.v[a][b] = popcount(a ^ b) for nibbles a, b.
struct NibbleDistance {
  alignas(16) uint8_t v[16][16] = {};
  constexpr NibbleDistance() {
    for (int a = 0; a < 16; ++a) {
      for (int b = 0; b < 16; ++b) v[a][b] = static_cast<uint8_t>(std::popcount(unsigned(a ^ b)));
    }
  }
};
static constexpr NibbleDistance kNibbleDistance{};

// Lanes of v moved up by one, lane 0 taken from the last lane of `before` (prev[k - 1]).
template <class D, class V>
HWY_INLINE V Before(D d, V v, V before) {
  if constexpr (hn::MaxLanes(D()) == 32) {
    return hn::CombineShiftRightBytes<15>(d, v, hn::ConcatLowerUpper(d, v, before));
  } else {
    return hn::CombineShiftRightBytes<15>(d, v, before);
  }
}
// Lanes of v moved down by one, the last lane taken from lane 0 of `after` (prev[k + 1]).
template <class D, class V>
HWY_INLINE V After(D d, V v, V after) {
  if constexpr (hn::MaxLanes(D()) == 32) {
    return hn::CombineShiftRightBytes<1>(d, hn::ConcatLowerUpper(d, after, v), v);
  } else {
    return hn::CombineShiftRightBytes<1>(d, after, v);
  }
}

// The minimum of the uint8 lanes of v, in every lane.
template <class D, class V>
HWY_INLINE V MinAllU8(D d, V v) {
  if constexpr (hn::MaxLanes(D()) == 32) v = hn::Min(v, hn::ConcatLowerUpper(d, v, v));
  const hn::Repartition<uint64_t, D> d64;
  const hn::Repartition<uint32_t, D> d32;
  v = hn::Min(v, hn::BitCast(d, hn::Shuffle01(hn::BitCast(d64, v))));
  v = hn::Min(v, hn::BitCast(d, hn::Shuffle2301(hn::BitCast(d32, v))));
  alignas(16) static constexpr uint8_t kSwap2[16] = {2, 3, 0, 1, 6, 7, 4, 5,
                                                     10, 11, 8, 9, 14, 15, 12, 13};
  alignas(16) static constexpr uint8_t kSwap1[16] = {1, 0, 3, 2, 5, 4, 7, 6,
                                                     9, 8, 11, 10, 13, 12, 15, 14};
  v = hn::Min(v, hn::TableLookupBytes(v, hn::LoadDup128(d, kSwap2)));
  return hn::Min(v, hn::TableLookupBytes(v, hn::LoadDup128(d, kSwap1)));
}

// One vertical path over a row with the cost computed on the fly (kPlanes nibble planes; 0: any
// count, from c.planes).
template <int kPlanes, class D>
void VerticalImpl(D d, const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
                  const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
                  const uint8_t* prev, const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
                  uint8_t* cost_out) {
  using V = hn::Vec<D>;
  const int n = static_cast<int>(hn::Lanes(d));
  const int dc = g.disparities;
  const int planes = kPlanes > 0 ? kPlanes : c.planes;
  const V vp1 = hn::Set(d, p1);
  const V ff = hn::Set(d, uint8_t{0xFF});
  const V first_ff = hn::IfThenElseZero(hn::FirstN(d, 1), ff);
  const V last_ff = hn::IfThenZeroElse(hn::FirstN(d, static_cast<size_t>(n - 1)), ff);
  for (int x = 0; x < g.width; ++x) {
    V tab[8];
    const uint32_t l = c.left[x];
    for (int b = 0; b < planes; ++b) tab[b] = hn::LoadDup128(d, kNibbleDistance.v[(l >> (4 * b)) & 15]);
    const uint8_t* right = c.nibbles + (g.rev_base - x);
    const uint8_t* border = c.border + (g.rev_base - x);
    const bool at_border = x < c.safe_begin || x >= c.safe_end;
    const uint8_t* lp = prev != nullptr ? prev + static_cast<size_t>(x) * dc : nullptr;
    uint8_t* o_row = out + static_cast<size_t>(x) * dc;
    V vmp = hn::Zero(d), jump = hn::Zero(d);
    if (lp != nullptr) {
      vmp = hn::Set(d, prev_min[x]);
      jump = hn::SaturatedAdd(vmp, hn::Set(d, p2_table[std::abs(image_row[x] - prev_image_row[x])]));
    }
    V best = ff;
    for (int k = 0; k < dc; k += n) {
      V cost = hn::TableLookupBytes(tab[0], hn::LoadU(d, right + k));
      for (int b = 1; b < planes; ++b) {
        cost = hn::Add(cost, hn::TableLookupBytes(tab[b], hn::LoadU(d, right + b * c.stride + k)));
      }
      if (at_border) cost = hn::Max(cost, hn::LoadU(d, border + k));
      if (cost_out != nullptr) hn::Store(cost, d, cost_out + static_cast<size_t>(x) * dc + k);
      V o = cost;
      if (lp != nullptr) {
        V lm = hn::LoadU(d, lp + k - 1);
        V lq = hn::LoadU(d, lp + k + 1);
        if (k == 0) lm = hn::Or(lm, first_ff);
        if (k + n == dc) lq = hn::Or(lq, last_ff);
        const V m = hn::Min(hn::Min(hn::Load(d, lp + k), jump),
                            hn::SaturatedAdd(hn::Min(lm, lq), vp1));
        o = hn::Add(cost, hn::Sub(m, vmp));
      }
      hn::Store(o, d, o_row + k);
      best = hn::Min(best, o);
    }
    out_min[x] = hn::GetLane(MinAllU8(d, best));
  }
}

// One step of a horizontal path at pixel x: out = step(prev), returns min out in every lane. The
// first of the two horizontal paths to reach x leaves its costs in `first`; the second adds
// them, the two vertical paths va, vb and its own into sum.
template <bool kSecond, class SumT, class D>
HWY_INLINE hn::Vec<D> ChainStep(D d, int dc, const uint8_t* cost, const uint8_t* prev,
                                uint8_t* out, hn::Vec<D> vmp, hn::Vec<D> vp1, uint8_t p2,
                                uint8_t* first, const uint8_t* va, const uint8_t* vb, SumT* sum) {
  using V = hn::Vec<D>;
  const int n = static_cast<int>(hn::Lanes(d));
  const V ff = hn::Set(d, uint8_t{0xFF});
  const V jump = hn::SaturatedAdd(vmp, hn::Set(d, p2));
  V best = ff;
  V before = ff;
  V pv = hn::Load(d, prev);
  for (int k = 0; k < dc; k += n) {
    const V after = k + n < dc ? hn::Load(d, prev + k + n) : ff;
    const V m = hn::Min(hn::Min(pv, jump),
                        hn::SaturatedAdd(hn::Min(Before(d, pv, before), After(d, pv, after)), vp1));
    const V o = hn::Add(hn::Load(d, cost + k), hn::Sub(m, vmp));
    hn::Store(o, d, out + k);
    best = hn::Min(best, o);
    if constexpr (!kSecond) {
      hn::Store(o, d, first + k);
    } else if constexpr (sizeof(SumT) == 1) {
      // Narrow sums: the matcher checked that four path costs cannot exceed 255.
      const V s = hn::Add(hn::Add(o, hn::Load(d, first + k)),
                          hn::Add(hn::Load(d, va + k), hn::Load(d, vb + k)));
      hn::Store(s, d, reinterpret_cast<uint8_t*>(sum) + k);
    } else {
      const hn::Half<D> dh;
      const hn::Rebind<uint16_t, decltype(dh)> dw;
      const int nh = n / 2;
      auto lo = hn::Add(hn::Add(hn::PromoteTo(dw, hn::LowerHalf(dh, o)),
                                hn::PromoteTo(dw, hn::Load(dh, first + k))),
                        hn::Add(hn::PromoteTo(dw, hn::Load(dh, va + k)),
                                hn::PromoteTo(dw, hn::Load(dh, vb + k))));
      auto hi = hn::Add(hn::Add(hn::PromoteTo(dw, hn::UpperHalf(dh, o)),
                                hn::PromoteTo(dw, hn::LoadU(dh, first + k + nh))),
                        hn::Add(hn::PromoteTo(dw, hn::LoadU(dh, va + k + nh)),
                                hn::PromoteTo(dw, hn::LoadU(dh, vb + k + nh))));
      hn::Store(lo, dw, sum + k);
      hn::Store(hi, dw, sum + k + nh);
    }
    before = pv;
    pv = after;
  }
  return MinAllU8(d, best);
}

// Left-to-right and right-to-left in one loop (two independent dependency chains), then the sum
// of all four paths.
template <class SumT, class D>
void HorizontalSumImpl(D d, const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                       const uint8_t* p2_table, uint8_t p1, const uint8_t* va, const uint8_t* vb,
                       uint8_t* first, uint8_t* scratch, SumT* sum) {
  using V = hn::Vec<D>;
  const int dc = g.disparities, w = g.width;
  uint8_t* a0 = scratch;
  uint8_t* b0 = scratch + dc;
  uint8_t* a1 = scratch + 2 * dc;
  uint8_t* b1 = scratch + 3 * dc;
  std::fill(a0, a0 + dc, uint8_t{0});  // paths enter the image from zero costs
  std::fill(a1, a1 + dc, uint8_t{0});
  const V vp1 = hn::Set(d, p1);
  V m0 = hn::Zero(d), m1 = hn::Zero(d);
  const auto p2 = [&](int x, int from) { return p2_table[std::abs(image_row[x] - image_row[from])]; };
  const auto at = [dc](int x) { return static_cast<size_t>(x) * dc; };
  int i = 0;
  for (; i < w / 2; ++i) {
    const int x0 = i, x1 = w - 1 - i;
    const uint8_t p20 = p2(x0, i > 0 ? x0 - 1 : x0), p21 = p2(x1, i > 0 ? x1 + 1 : x1);
    m0 = ChainStep<false, SumT>(d, dc, cost + at(x0), a0, b0, m0, vp1, p20, first + at(x0), va, vb, sum);
    m1 = ChainStep<false, SumT>(d, dc, cost + at(x1), a1, b1, m1, vp1, p21, first + at(x1), va, vb, sum);
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
  if (w % 2 == 1) {  // the middle pixel: left-to-right arrives first
    const int x = i;
    const uint8_t p20 = p2(x, i > 0 ? x - 1 : x), p21 = p2(x, i > 0 ? x + 1 : x);
    m0 = ChainStep<false, SumT>(d, dc, cost + at(x), a0, b0, m0, vp1, p20, first + at(x), va, vb, sum);
    m1 = ChainStep<true, SumT>(d, dc, cost + at(x), a1, b1, m1, vp1, p21, first + at(x),
                               va + at(x), vb + at(x), sum + at(x));
    std::swap(a0, b0);
    std::swap(a1, b1);
    ++i;
  }
  for (; i < w; ++i) {
    const int x0 = i, x1 = w - 1 - i;
    const uint8_t p20 = p2(x0, x0 - 1), p21 = p2(x1, x1 + 1);
    m0 = ChainStep<true, SumT>(d, dc, cost + at(x0), a0, b0, m0, vp1, p20, first + at(x0),
                               va + at(x0), vb + at(x0), sum + at(x0));
    m1 = ChainStep<true, SumT>(d, dc, cost + at(x1), a1, b1, m1, vp1, p21, first + at(x1),
                               va + at(x1), vb + at(x1), sum + at(x1));
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
}

// Winner-take-all over a sum row of T (uint8_t, or int16_t holding the uint16 sums, which stay
// below 2^15). Same results as WtaScalar.
template <class T, class D>
void WtaImpl(D d, const T* sum, const SgmRowGeometry& g, int uniqueness_percent, T* scratch,
             int16_t* best, int16_t* right_best) {
  using V = hn::Vec<D>;
  constexpr uint32_t kMaxT = sizeof(T) == 1 ? 0xFF : 0x7FFF;  // also "no candidate yet"
  const int n = static_cast<int>(hn::Lanes(d));
  const int dc = g.disparities;
  const int n_rev = g.rev_base + dc;
  const size_t stride = static_cast<size_t>(n_rev) + 64;
  // Right-image minima and their k, one copy per x mod kCopies: a pixel updates the copy that
  // the pixel kCopies earlier wrote, long after those stores have left the store queue.
  constexpr int kCopies = 4;
  for (int r = 0; r < kCopies; ++r) {
    std::fill(scratch + 2 * r * stride, scratch + 2 * r * stride + n_rev, static_cast<T>(kMaxT));
  }
  const V iota = hn::Iota(d, 0);
  const V vn = hn::Set(d, static_cast<T>(n));
  const uint32_t keep = static_cast<uint32_t>(100 - uniqueness_percent);
  for (int x = 0; x < g.width; ++x) {
    const T* s = sum + static_cast<size_t>(x) * dc;
    V vmin = hn::Load(d, s);
    for (int k = n; k < dc; k += n) vmin = hn::Min(vmin, hn::Load(d, s + k));
    T m;
    if constexpr (sizeof(T) == 1) {
      m = hn::GetLane(MinAllU8(d, vmin));
    } else {
      m = hn::GetLane(hn::MinOfLanes(d, vmin));
    }
    const V vm = hn::Set(d, m);
    int bk = 0;
    for (int k = 0; k < dc; k += n) {
      const intptr_t f = hn::FindFirstTrue(d, hn::Eq(hn::Load(d, s + k), vm));
      if (f >= 0) {
        bk = k + static_cast<int>(f);
        break;
      }
    }
    // Not unique iff a sum outside bk-1..bk+1 is below t = ceil(100 m / (100 - u)).
    bool unique = true;
    if (keep < 100 && m > 0) {
      const uint32_t t = (static_cast<uint32_t>(m) * 100u + keep - 1) / keep;
      size_t below = static_cast<size_t>(dc);
      if (t <= kMaxT) {
        below = 0;
        const V vt1 = hn::Set(d, static_cast<T>(t - 1));
        for (int k = 0; k < dc; k += n) {
          const V v = hn::Load(d, s + k);
          below += hn::CountTrue(d, hn::Eq(hn::Min(v, vt1), v));  // v <= t - 1
        }
      }
      size_t near = 0;
      for (int k = std::max(0, bk - 1); k <= std::min(dc - 1, bk + 1); ++k) {
        near += static_cast<uint32_t>(s[k]) < t;
      }
      unique = below == near;
    }
    best[x] = static_cast<int16_t>(unique ? bk : -1 - bk);
    T* rmin = scratch + 2 * static_cast<size_t>(x % kCopies) * stride + (g.rev_base - x);
    T* rk = rmin + stride;
    V kv = iota;
    for (int k = 0; k < dc; k += n) {
      const V v = hn::Load(d, s + k);
      const V mo = hn::LoadU(d, rmin + k);
      const V nm = hn::Min(v, mo);
      hn::StoreU(hn::IfThenElse(hn::Eq(nm, mo), hn::LoadU(d, rk + k), kv), d, rk + k);  // v >= mo keeps
      hn::StoreU(nm, d, rmin + k);
      kv = hn::Add(kv, vn);
    }
  }
  // Merge the copies: the smaller sum wins, on a tie the smaller k (the golden model's first).
  for (int xr = 0; xr < g.width; ++xr) {
    const size_t i = static_cast<size_t>(g.rev_base - g.min_disparity - xr);
    uint32_t bm = kMaxT;
    int bkk = -1;
    for (int r = 0; r < kCopies; ++r) {
      const T* cm = scratch + 2 * r * stride;
      const uint32_t v = static_cast<uint32_t>(cm[i]);
      if (v == kMaxT) continue;
      const int kk = static_cast<int>(static_cast<std::make_unsigned_t<T>>(cm[stride + i]));
      if (v < bm || (v == bm && kk < bkk)) {
        bm = v;
        bkk = kk;
      }
    }
    right_best[xr] = static_cast<int16_t>(bkk);
  }
}

#endif  // HWY_TARGET != HWY_SCALAR && !HWY_HAVE_SCALABLE

static bool HasFourPathSimd() {
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  return true;
#else
  return false;
#endif
}

// Full 32-byte vectors when the disparity count is a multiple of 32, else 16 bytes.
static void FourPathVerticalSimd(const SgmCostRow& c, const SgmRowGeometry& g,
                                 const uint8_t* image_row, const uint8_t* prev_image_row,
                                 const uint8_t* p2_table, uint8_t p1, const uint8_t* prev,
                                 const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
                                 uint8_t* cost_out) {
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  const auto run = [&](auto d) {
    if (c.planes == 3) {
      VerticalImpl<3>(d, c, g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out,
                      out_min, cost_out);
    } else {
      VerticalImpl<0>(d, c, g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out,
                      out_min, cost_out);
    }
  };
  const hn::CappedTag<uint8_t, 32> d32;
  if (g.disparities % static_cast<int>(hn::Lanes(d32)) == 0) {
    run(d32);
  } else {
    run(hn::CappedTag<uint8_t, 16>());
  }
#else
  (void)c, (void)g, (void)image_row, (void)prev_image_row, (void)p2_table, (void)p1, (void)prev;
  (void)prev_min, (void)out, (void)out_min, (void)cost_out;
#endif
}

static void FourPathHorizontalSimd(const uint8_t* cost, const uint8_t* image_row,
                                   const SgmRowGeometry& g, const uint8_t* p2_table, uint8_t p1,
                                   const uint8_t* va, const uint8_t* vb, uint8_t* first,
                                   uint8_t* scratch, void* sum, bool narrow) {
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  const auto run = [&](auto d) {
    if (narrow) {
      HorizontalSumImpl<uint8_t>(d, cost, image_row, g, p2_table, p1, va, vb, first, scratch,
                                 static_cast<uint8_t*>(sum));
    } else {
      HorizontalSumImpl<uint16_t>(d, cost, image_row, g, p2_table, p1, va, vb, first, scratch,
                                  static_cast<uint16_t*>(sum));
    }
  };
  const hn::CappedTag<uint8_t, 32> d32;
  if (g.disparities % static_cast<int>(hn::Lanes(d32)) == 0) {
    run(d32);
  } else {
    run(hn::CappedTag<uint8_t, 16>());
  }
#else
  (void)cost, (void)image_row, (void)g, (void)p2_table, (void)p1, (void)va, (void)vb;
  (void)first, (void)scratch, (void)sum, (void)narrow;
#endif
}

static void FourPathWtaSimd(const void* sum, bool narrow, const SgmRowGeometry& g,
                            int uniqueness_percent, void* scratch, int16_t* best,
                            int16_t* right_best) {
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  if (narrow) {
    const hn::CappedTag<uint8_t, 32> d32;
    if (g.disparities % static_cast<int>(hn::Lanes(d32)) == 0) {
      WtaImpl(d32, static_cast<const uint8_t*>(sum), g, uniqueness_percent,
              static_cast<uint8_t*>(scratch), best, right_best);
    } else {
      WtaImpl(hn::CappedTag<uint8_t, 16>(), static_cast<const uint8_t*>(sum), g,
              uniqueness_percent, static_cast<uint8_t*>(scratch), best, right_best);
    }
  } else {
    const hn::CappedTag<int16_t, 16> d16;
    if (g.disparities % static_cast<int>(hn::Lanes(d16)) == 0) {
      WtaImpl(d16, static_cast<const int16_t*>(sum), g, uniqueness_percent,
              static_cast<int16_t*>(scratch), best, right_best);
    } else {
      WtaImpl(hn::CappedTag<int16_t, 8>(), static_cast<const int16_t*>(sum), g,
              uniqueness_percent, static_cast<int16_t*>(scratch), best, right_best);
    }
  }
#else
  (void)sum, (void)narrow, (void)g, (void)uniqueness_percent, (void)scratch, (void)best;
  (void)right_best;
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace cairn
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cairn {
namespace {

HWY_EXPORT(HasFourPathSimd);
HWY_EXPORT(FourPathVerticalSimd);
HWY_EXPORT(FourPathHorizontalSimd);
HWY_EXPORT(FourPathWtaSimd);

void Vertical(const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
              const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
              const uint8_t* prev, const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
              uint8_t* cost_out) {
  HWY_DYNAMIC_DISPATCH(FourPathVerticalSimd)(c, g, image_row, prev_image_row, p2_table, p1, prev,
                                             prev_min, out, out_min, cost_out);
}
void HorizontalSum(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                   const uint8_t* p2_table, uint8_t p1, const uint8_t* va, const uint8_t* vb,
                   uint8_t* first, uint8_t* scratch, void* sum, bool narrow) {
  HWY_DYNAMIC_DISPATCH(FourPathHorizontalSimd)(cost, image_row, g, p2_table, p1, va, vb, first,
                                               scratch, sum, narrow);
}
void Wta(const void* sum, bool narrow, const SgmRowGeometry& g, int uniqueness_percent,
         void* scratch, int16_t* best, int16_t* right_best) {
  HWY_DYNAMIC_DISPATCH(FourPathWtaSimd)(sum, narrow, g, uniqueness_percent, scratch, best,
                                        right_best);
}

}  // namespace

const SgmFourPathKernels* SimdFourPathKernels() {
  static const SgmFourPathKernels kernels{Vertical, HorizontalSum, Wta};
  return HWY_DYNAMIC_DISPATCH(HasFourPathSimd)() ? &kernels : nullptr;
}

}  // namespace cairn
#endif  // HWY_ONCE
