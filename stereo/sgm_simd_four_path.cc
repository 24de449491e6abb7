// Highway kernels of the SIMD backend's own schedule for the four horizontal and vertical paths
// (SgmFourPathKernels in sgm_kernels.h; SgmMatcher::MatchFourPath runs them). The arithmetic is
// the golden model's (sgm_scalar_kernels.cc) lane for lane; only the order of the work and the
// memory it touches differ:
// - the census is computed 32 pixels at a time straight into nibble planes, and the cost of a
//   pixel where the first path consumes it, from nibble lookup tables (popcount(l ^ r) = sum
//   over nibbles of T[l nibble][r nibble], one byte shuffle per nibble);
// - a path step of the horizontal recursions keeps its neighbours in registers (byte shifts
//   across vectors instead of unaligned reloads of what the previous step just stored);
// - the two horizontal paths, the two vertical ones and the sum happen in one pass over the row;
// - winner-take-all keeps the right-image minima in four interleaved copies so that no load waits
//   for the store of the pixel before.

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <type_traits>
#include <utility>

#include "stereo/sgm_kernels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "stereo/sgm_simd_four_path.cc"
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

// The disparity count, a compile-time constant where kNV (vectors per pixel) is given.
template <int kNV, class D>
HWY_INLINE int Disparities(D /*d*/, const SgmRowGeometry& g) {
  if constexpr (kNV > 0) {
    return kNV * static_cast<int>(hn::MaxLanes(D()));
  } else {
    return g.disparities;
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

// The minimum of the uint8 lanes of v as a number (x86: phminposuw on 16-bit pairs).
template <class D, class V>
HWY_INLINE uint8_t MinU8(D d, V v) {
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_SSE4
  const hn::Full128<uint8_t> d16;
  hn::Vec128<uint8_t> x;
  if constexpr (hn::MaxLanes(D()) == 32) {
    x = hn::Min(hn::LowerHalf(v), hn::UpperHalf(hn::Half<D>(), v));
  } else {
    x = v;
  }
  const hn::Full128<uint16_t> dw;
  const auto w = hn::BitCast(dw, x);
  const auto m = hn::Min(hn::And(w, hn::Set(dw, uint16_t{0xFF})), hn::ShiftRight<8>(w));
  (void)d16;
  return static_cast<uint8_t>(hn::GetLane(hn::MinOfLanes(dw, m)));
#else
  return hn::GetLane(MinAllU8(d, v));
#endif
}

// One vertical path over a row with the cost computed on the fly (kPlanes nibble planes; 0: any
// count, from c.planes).
template <int kNV, int kPlanes, class D>
void VerticalImpl(D d, const SgmCostRow& c_in, const SgmRowGeometry& g_in,
                  const uint8_t* image_row, const uint8_t* prev_image_row,
                  const uint8_t* p2_table, uint8_t p1, const uint8_t* prev,
                  const uint8_t* prev_min, uint8_t* out, uint8_t* out_min, uint8_t* cost_out) {
  // Local copies: byte stores may alias anything the compiler cannot see is local, which would
  // reload every field after every store.
  const SgmCostRow c = c_in;
  const SgmRowGeometry g = g_in;
  using V = hn::Vec<D>;
  const int n = static_cast<int>(hn::Lanes(d));
  const int dc = Disparities<kNV>(d, g);
  const int planes = kPlanes > 0 ? kPlanes : c.planes;
  const V vp1 = hn::Set(d, p1);
  const V ff = hn::Set(d, uint8_t{0xFF});
  const V first_ff = hn::IfThenElseZero(hn::FirstN(d, 1), ff);
  const V last_ff = hn::IfThenZeroElse(hn::FirstN(d, static_cast<size_t>(n - 1)), ff);
  for (int x = 0; x < g.width; ++x) {
    V tab[8];
    for (int b = 0; b < planes; ++b) {
      tab[b] = hn::LoadDup128(d, kNibbleDistance.v[c.left[b * c.left_stride + x]]);
    }
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
#pragma GCC unroll 8
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
    out_min[x] = MinU8(d, best);
  }
}

// Everything one row of the second half needs, for the per-pixel visits below.
struct RowArgs {
  const SgmCostRow* c;
  const SgmRowGeometry* g;
  const uint8_t* image_row;
  const uint8_t* prev_image_row;
  const uint8_t* p2_table;
  uint8_t p1;
  const uint8_t* prev;  // the own vertical path of the previous row (nullptr: none)
  const uint8_t* prev_min;
  uint8_t* out;
  uint8_t* out_min;
  const uint8_t* vb;  // the opposite vertical path (volume row)
  void* partial;      // horizontal path of the first visit + both vertical paths, per pixel
  uint8_t* cost;      // the cost row, from the first visit for the second
  const uint32_t* threshold;  // ceil(100 m / (100 - uniqueness)) for every sum m
  int uniqueness_percent;
  bool subpixel;
  int16_t* best;
  int16_t* offset;
};

// The cost lookup tables of pixel x: popcount(l ^ r) = sum over the nibbles b of
// tab[b][r nibble b].
template <int kPlanes, class D>
HWY_INLINE void CostTables(D d, const SgmCostRow& c, int x, hn::Vec<D>* tab) {
  const int planes = kPlanes > 0 ? kPlanes : c.planes;
  for (int b = 0; b < planes; ++b) {
    tab[b] = hn::LoadDup128(d, kNibbleDistance.v[c.left[b * c.left_stride + x]]);
  }
}

template <int kPlanes, class D>
HWY_INLINE hn::Vec<D> CostAt(D d, const SgmCostRow& c, const hn::Vec<D>* tab, const uint8_t* right,
                             const uint8_t* border, bool at_border, int k) {
  const int planes = kPlanes > 0 ? kPlanes : c.planes;
  auto cost = hn::TableLookupBytes(tab[0], hn::LoadU(d, right + k));
  for (int b = 1; b < planes; ++b) {
    cost = hn::Add(cost, hn::TableLookupBytes(tab[b], hn::LoadU(d, right + b * c.stride + k)));
  }
  if (at_border) cost = hn::Max(cost, hn::LoadU(d, border + k));
  return cost;
}

// The first of the two horizontal paths to reach pixel x: its cost, the own vertical path (prev
// -> out), the horizontal step hprev -> hout (returns its minimum in every lane), and the
// partial sum of these two and the opposite vertical path.
template <int kNV, int kPlanes, class SumT, class D>
HWY_INLINE hn::Vec<D> FirstVisit(D d, const RowArgs& a, int x, const uint8_t* hprev, uint8_t* hout,
                                 hn::Vec<D> vmp, uint8_t p2h) {
  using V = hn::Vec<D>;
  const SgmCostRow& c = *a.c;
  const SgmRowGeometry& g = *a.g;
  const int n = static_cast<int>(hn::Lanes(d));
  const int dc = Disparities<kNV>(d, g);
  const size_t at = static_cast<size_t>(x) * dc;
  V tab[8];
  CostTables<kPlanes>(d, c, x, tab);
  const uint8_t* right = c.nibbles + (g.rev_base - x);
  const uint8_t* border = c.border + (g.rev_base - x);
  const bool at_border = x < c.safe_begin || x >= c.safe_end;
  const V ff = hn::Set(d, uint8_t{0xFF});
  const V vp1 = hn::Set(d, a.p1);
  const uint8_t* lp = a.prev != nullptr ? a.prev + at : nullptr;
  V vmv = hn::Zero(d), jv = hn::Zero(d);
  if (lp != nullptr) {
    vmv = hn::Set(d, a.prev_min[x]);
    jv = hn::SaturatedAdd(vmv, hn::Set(d, a.p2_table[std::abs(a.image_row[x] - a.prev_image_row[x])]));
  }
  const V jh = hn::SaturatedAdd(vmp, hn::Set(d, p2h));
  V best_v = ff, best_h = ff, before = ff;
  V pv = hn::Load(d, hprev);
#pragma GCC unroll 8
  for (int k = 0; k < dc; k += n) {
    const V cost = CostAt<kPlanes>(d, c, tab, right, border, at_border, k);
    hn::Store(cost, d, a.cost + at + k);
    V ov = cost;
    if (lp != nullptr) {
      V lm = hn::LoadU(d, lp + k - 1);
      V lq = hn::LoadU(d, lp + k + 1);
      if (k == 0) lm = hn::Or(lm, hn::IfThenElseZero(hn::FirstN(d, 1), ff));
      if (k + n == dc) lq = hn::Or(lq, hn::IfThenZeroElse(hn::FirstN(d, static_cast<size_t>(n - 1)), ff));
      const V m = hn::Min(hn::Min(hn::Load(d, lp + k), jv), hn::SaturatedAdd(hn::Min(lm, lq), vp1));
      ov = hn::Add(cost, hn::Sub(m, vmv));
    }
    hn::Store(ov, d, a.out + at + k);
    best_v = hn::Min(best_v, ov);
    const V after = k + n < dc ? hn::Load(d, hprev + k + n) : ff;
    const V m = hn::Min(hn::Min(pv, jh),
                        hn::SaturatedAdd(hn::Min(Before(d, pv, before), After(d, pv, after)), vp1));
    const V oh = hn::Add(cost, hn::Sub(m, vmp));
    hn::Store(oh, d, hout + k);
    best_h = hn::Min(best_h, oh);
    const V vb = hn::Load(d, a.vb + at + k);
    if constexpr (sizeof(SumT) == 1) {
      // Narrow sums: four path costs, so also three, cannot exceed 255 (the matcher checked).
      hn::Store(hn::Add(hn::Add(oh, ov), vb), d, static_cast<uint8_t*>(a.partial) + at + k);
    } else {
      const hn::Half<D> dh;
      const hn::Rebind<uint16_t, decltype(dh)> dw;
      uint16_t* p = static_cast<uint16_t*>(a.partial) + at + k;
      hn::Store(hn::Add(hn::Add(hn::PromoteTo(dw, hn::LowerHalf(dh, oh)),
                                hn::PromoteTo(dw, hn::LowerHalf(dh, ov))),
                        hn::PromoteTo(dw, hn::LowerHalf(dh, vb))),
                dw, p);
      hn::Store(hn::Add(hn::Add(hn::PromoteTo(dw, hn::UpperHalf(dh, oh)),
                                hn::PromoteTo(dw, hn::UpperHalf(dh, ov))),
                        hn::PromoteTo(dw, hn::UpperHalf(dh, vb))),
                dw, p + n / 2);
    }
    before = pv;
    pv = after;
  }
  a.out_min[x] = MinU8(d, best_v);
  return MinAllU8(d, best_h);
}

// Right-image minima: one copy per direction of the second visits (the pixel before in the same
// copy was stored a whole step of the other direction earlier, so no load waits for its store).
// Ascending x keeps the first of equal sums (strict <),
// descending x the last (<=): both the smallest k, as the golden model's scan.
template <class T>
struct RightMinima {
  T* min[2];
  T* k[2];
};

// The second of the two horizontal paths to reach pixel x: its step, the complete sum (into
// `sums`, one pixel), winner-take-all with the uniqueness test, the sub-pixel offset and the
// right-image minima.
template <int kNV, int kPlanes, class SumT, bool kAscending, class D>
HWY_INLINE hn::Vec<D> SecondVisit(D d, const RowArgs& a, int x, const uint8_t* hprev,
                                  uint8_t* hout, hn::Vec<D> vmp, uint8_t p2h, SumT* sums,
                                  const RightMinima<std::conditional_t<sizeof(SumT) == 1, uint8_t, int16_t>>& rm) {
  using V = hn::Vec<D>;
  using T = std::conditional_t<sizeof(SumT) == 1, uint8_t, int16_t>;
  const SgmRowGeometry& g = *a.g;
  const int n = static_cast<int>(hn::Lanes(d));
  const int dc = Disparities<kNV>(d, g);
  const size_t at = static_cast<size_t>(x) * dc;
  const V ff = hn::Set(d, uint8_t{0xFF});
  const V vp1 = hn::Set(d, a.p1);
  const V jh = hn::SaturatedAdd(vmp, hn::Set(d, p2h));
  V best_h = ff, before = ff;
  V pv = hn::Load(d, hprev);
#pragma GCC unroll 8
  for (int k = 0; k < dc; k += n) {
    const V cost = hn::Load(d, a.cost + at + k);
    const V after = k + n < dc ? hn::Load(d, hprev + k + n) : ff;
    const V m = hn::Min(hn::Min(pv, jh),
                        hn::SaturatedAdd(hn::Min(Before(d, pv, before), After(d, pv, after)), vp1));
    const V oh = hn::Add(cost, hn::Sub(m, vmp));
    hn::Store(oh, d, hout + k);
    best_h = hn::Min(best_h, oh);
    if constexpr (sizeof(SumT) == 1) {
      hn::Store(hn::Add(oh, hn::Load(d, static_cast<const uint8_t*>(a.partial) + at + k)), d, sums + k);
    } else {
      const hn::Half<D> dh;
      const hn::Rebind<uint16_t, decltype(dh)> dw;
      const uint16_t* p = static_cast<const uint16_t*>(a.partial) + at + k;
      hn::Store(hn::Add(hn::PromoteTo(dw, hn::LowerHalf(dh, oh)), hn::Load(dw, p)), dw, sums + k);
      hn::Store(hn::Add(hn::PromoteTo(dw, hn::UpperHalf(dh, oh)), hn::Load(dw, p + n / 2)), dw,
                sums + k + n / 2);
    }
    before = pv;
    pv = after;
  }
  // Winner-take-all of pixel x (as WtaScalar).
  const hn::Repartition<T, D> dt;
  using VT = hn::Vec<decltype(dt)>;
  constexpr uint32_t kMaxT = sizeof(T) == 1 ? 0xFF : 0x7FFF;
  const int nt = static_cast<int>(hn::Lanes(dt));
  const T* s = reinterpret_cast<const T*>(sums);
  VT vmin = hn::Load(dt, s);
#pragma GCC unroll 16
  for (int k = nt; k < dc; k += nt) vmin = hn::Min(vmin, hn::Load(dt, s + k));
  T m;
  if constexpr (sizeof(T) == 1) {
    m = MinU8(dt, vmin);
  } else {
    m = hn::GetLane(hn::MinOfLanes(dt, vmin));
  }
  const VT vm = hn::Set(dt, m);
  // The first k with the minimum: the chunks from the last to the first, without branches (where
  // the minimum lies is data, so an early exit mispredicts).
  int bk = 0;
#pragma GCC unroll 16
  for (int k = dc - nt; k >= 0; k -= nt) {
    const intptr_t f = hn::FindFirstTrue(dt, hn::Eq(hn::Load(dt, s + k), vm));
    bk = f >= 0 ? k + static_cast<int>(f) : bk;
  }
  // Not unique iff a sum outside bk-1..bk+1 is below t = ceil(100 m / (100 - u)).
  bool unique = true;
  if (a.uniqueness_percent > 0 && m > 0) {
    const uint32_t t = a.threshold[m];
    size_t below = static_cast<size_t>(dc);
    if (t <= kMaxT) {
      below = 0;
      const VT vt1 = hn::Set(dt, static_cast<T>(t - 1));
#pragma GCC unroll 16
      for (int k = 0; k < dc; k += nt) {
        const VT v = hn::Load(dt, s + k);
        below += hn::CountTrue(dt, hn::Eq(hn::Min(v, vt1), v));  // v <= t - 1
      }
    }
    // s[-1] and s[dc] are readable (scratch around the sums).
    const size_t near = static_cast<size_t>(static_cast<uint32_t>(s[bk]) < t) +
                        static_cast<size_t>(bk > 0 && static_cast<uint32_t>(s[bk - 1]) < t) +
                        static_cast<size_t>(bk + 1 < dc && static_cast<uint32_t>(s[bk + 1]) < t);
    unique = below == near;
  }
  a.best[x] = static_cast<int16_t>(unique ? bk : -1 - bk);
  a.offset[x] = static_cast<int16_t>(unique && a.subpixel && bk > 0 && bk < dc - 1
                                         ? SgmSubpixelOffset(s[bk - 1], s[bk], s[bk + 1])
                                         : 0);  // (not needed where the pixel is not unique)
  // The right-image minima over the diagonal of x.
  const int copy = kAscending ? 0 : 1;
  T* rmin = rm.min[copy] + (g.rev_base - x);
  T* rk = rm.k[copy] + (g.rev_base - x);
  VT kv = hn::Iota(dt, 0);
  const VT vn = hn::Set(dt, static_cast<T>(nt));
#pragma GCC unroll 16
  for (int k = 0; k < dc; k += nt) {
    const VT v = hn::Load(dt, s + k);
    const VT mo = hn::LoadU(dt, rmin + k);
    const VT nm = hn::Min(v, mo);
    // Takes v where v < mo (ascending) or v <= mo (descending).
    const auto take = kAscending ? hn::Not(hn::Eq(nm, mo)) : hn::Eq(nm, v);
    hn::StoreU(hn::IfThenElse(take, kv, hn::LoadU(dt, rk + k)), dt, rk + k);
    hn::StoreU(nm, dt, rmin + k);
    kv = hn::Add(kv, vn);
  }
  return MinAllU8(d, best_h);
}

// A whole row of the second half; both horizontal directions advance in one loop (two
// independent dependency chains, the per-pixel work of either fills the other's wait).
template <int kNV, int kPlanes, class SumT, class D>
void FinishRowImpl(D d, const RowArgs& args, uint8_t* scratch, int16_t* right_best) {
  // Local copies: byte stores may alias anything the compiler cannot see is local, which would
  // reload every field after every store.
  const SgmCostRow c_local = *args.c;
  const SgmRowGeometry g_local = *args.g;
  RowArgs a = args;
  a.c = &c_local;
  a.g = &g_local;
  using V = hn::Vec<D>;
  using T = std::conditional_t<sizeof(SumT) == 1, uint8_t, int16_t>;
  constexpr uint32_t kMaxT = sizeof(T) == 1 ? 0xFF : 0x7FFF;  // also "no candidate yet"
  const SgmRowGeometry& g = *a.g;
  const int dc = Disparities<kNV>(d, g), w = g.width;
  // scratch: 4 horizontal path blocks, 2 pixels of sums, then the right-image minima.
  uint8_t* a0 = scratch;
  uint8_t* b0 = scratch + dc;
  uint8_t* a1 = scratch + 2 * dc;
  uint8_t* b1 = scratch + 3 * dc;
  SumT* sums0 = reinterpret_cast<SumT*>(scratch + 4 * dc);
  SumT* sums1 = sums0 + dc;
  const int n_rev = g.rev_base + dc;
  const size_t stride = (static_cast<size_t>(n_rev) + 64 + 31) & ~size_t{31};
  T* minima = reinterpret_cast<T*>(scratch + 4 * dc + 2 * dc * sizeof(SumT) + 64);
  RightMinima<T> rm;
  for (int r = 0; r < 2; ++r) {
    rm.min[r] = minima + 2 * r * stride;
    rm.k[r] = rm.min[r] + stride;
    std::fill(rm.min[r], rm.min[r] + n_rev, static_cast<T>(kMaxT));
  }
  std::fill(a0, a0 + dc, uint8_t{0});  // paths enter the image from zero costs
  std::fill(a1, a1 + dc, uint8_t{0});
  V m0 = hn::Zero(d), m1 = hn::Zero(d);
  const auto p2 = [&](int x, int from) { return a.p2_table[std::abs(a.image_row[x] - a.image_row[from])]; };
  int i = 0;
  for (; i < w / 2; ++i) {
    const int x0 = i, x1 = w - 1 - i;
    m0 = FirstVisit<kNV, kPlanes, SumT>(d, a, x0, a0, b0, m0, p2(x0, i > 0 ? x0 - 1 : x0));
    m1 = FirstVisit<kNV, kPlanes, SumT>(d, a, x1, a1, b1, m1, p2(x1, i > 0 ? x1 + 1 : x1));
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
  if (w % 2 == 1) {  // the middle pixel: left-to-right arrives first
    const int x = i;
    m0 = FirstVisit<kNV, kPlanes, SumT>(d, a, x, a0, b0, m0, p2(x, i > 0 ? x - 1 : x));
    m1 = SecondVisit<kNV, kPlanes, SumT, false>(d, a, x, a1, b1, m1, p2(x, i > 0 ? x + 1 : x), sums1, rm);
    std::swap(a0, b0);
    std::swap(a1, b1);
    ++i;
  }
  for (; i < w; ++i) {
    const int x0 = i, x1 = w - 1 - i;
    m0 = SecondVisit<kNV, kPlanes, SumT, true>(d, a, x0, a0, b0, m0, p2(x0, x0 - 1), sums0, rm);
    m1 = SecondVisit<kNV, kPlanes, SumT, false>(d, a, x1, a1, b1, m1, p2(x1, x1 + 1), sums1, rm);
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
  // Merge the copies: the smaller sum wins, on a tie the smaller k (the golden model's first).
  for (int xr = 0; xr < w; ++xr) {
    const size_t i_rev = static_cast<size_t>(g.rev_base - g.min_disparity - xr);
    uint32_t bm = kMaxT;
    int bkk = -1;
    for (int r = 0; r < 2; ++r) {
      const uint32_t v = static_cast<uint32_t>(rm.min[r][i_rev]);
      if (v == kMaxT) continue;
      const int kk = static_cast<int>(static_cast<std::make_unsigned_t<T>>(rm.k[r][i_rev]));
      if (v < bm || (v == bm && kk < bkk)) {
        bm = v;
        bkk = kk;
      }
    }
    right_best[xr] = static_cast<int16_t>(bkk);
  }
}

#endif  // HWY_TARGET != HWY_SCALAR && !HWY_HAVE_SCALABLE

// Centre-symmetric census of one row (as CensusScalar) straight into nibble planes, 32 pixels
// per vector: plane b holds bits [4b, 4b + 4). In x order at out + b * plane_stride + x, or
// with `reversed` at index width - 1 + pad - x, zeros elsewhere below n_rev (SgmCostRow).
static void FourPathCensusSimd(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch,
                               uint8_t* out, int plane_stride, bool reversed, int pad,
                               int n_rev) {
  const int rx = cw / 2, ry = ch / 2;
  const int bits = (cw * ch - 1) / 2;
  const int planes = (bits + 3) / 4;
  if (reversed) {
    for (int b = 0; b < planes; ++b) {
      uint8_t* plane = out + static_cast<ptrdiff_t>(b) * plane_stride;
      std::fill(plane, plane + pad, uint8_t{0});
      std::fill(plane + pad + width, plane + n_rev, uint8_t{0});
    }
  }
  const auto at = [&](int b, int x) {
    return out + static_cast<ptrdiff_t>(b) * plane_stride + (reversed ? width - 1 + pad - x : x);
  };
  int x = 0;
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  const hn::CappedTag<uint8_t, 32> d;
  using V = hn::Vec<decltype(d)>;
  const int n = static_cast<int>(hn::Lanes(d));
  alignas(16) static constexpr uint8_t kReverse[16] = {15, 14, 13, 12, 11, 10, 9, 8,
                                                       7,  6,  5,  4,  3,  2,  1, 0};
  const auto reverse = [&](V v) {
    v = hn::TableLookupBytes(v, hn::LoadDup128(d, kReverse));
    if constexpr (hn::MaxLanes(decltype(d)()) == 32) v = hn::ConcatLowerUpper(d, v, v);
    return v;
  };
  for (; x + n <= width; x += n) {
    V nib[8];
    for (int b = 0; b < planes; ++b) nib[b] = hn::Zero(d);
    int bit = bits - 1;  // the first pair sets the most significant bit
    for (int dy = -ry; dy <= 0; ++dy) {
      for (int dx = -rx; dx <= rx; ++dx) {
        if (dy == 0 && dx == 0) break;
        const V a = hn::LoadU(d, center + dy * stride + x + dx);
        const V b = hn::LoadU(d, center - dy * stride + x - dx);
        // a > b: min(a, b) != a.
        const V set = hn::AndNot(hn::VecFromMask(d, hn::Eq(hn::Min(a, b), a)),
                                 hn::Set(d, static_cast<uint8_t>(1u << (bit & 3))));
        nib[bit >> 2] = hn::Or(nib[bit >> 2], set);
        --bit;
      }
    }
    for (int b = 0; b < planes; ++b) {
      hn::StoreU(reversed ? reverse(nib[b]) : nib[b], d, reversed ? at(b, x + n - 1) : at(b, x));
    }
  }
#endif
  for (; x < width; ++x) {
    uint32_t v = 0;
    for (int dy = -ry; dy <= 0; ++dy) {
      for (int dx = -rx; dx <= rx; ++dx) {
        if (dy == 0 && dx == 0) break;
        v = (v << 1) | (center[dy * stride + x + dx] > center[-dy * stride + x - dx] ? 1u : 0u);
      }
    }
    for (int b = 0; b < planes; ++b) *at(b, x) = static_cast<uint8_t>((v >> (4 * b)) & 15);
  }
}

// Compile-time vector counts pay only where vectors are real: on the emulated target the
// unrolled specialisations cost most of this file's compile time (half a minute under ASan)
// and buy nothing, so it runs the general kernels.
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
constexpr bool kSpecialise = HWY_TARGET != HWY_EMU128;
// 0 means "read at run time", so on the emulated target every call below is the general one.
constexpr int kFourVectors = kSpecialise ? 4 : 0;
constexpr int kThreePlanes = kSpecialise ? 3 : 0;
#endif

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
    const bool four = g.disparities == 4 * static_cast<int>(hn::Lanes(d));
    if (four && c.planes == 3) {
      VerticalImpl<kFourVectors, kThreePlanes>(d, c, g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out,
                         out_min, cost_out);
    } else if (four) {
      VerticalImpl<kFourVectors, 0>(d, c, g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out,
                         out_min, cost_out);
    } else {
      VerticalImpl<0, 0>(d, c, g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out,
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

static void FourPathFinishRowSimd(const SgmCostRow& c, const SgmRowGeometry& g,
                                  const uint8_t* image_row, const uint8_t* prev_image_row,
                                  const uint8_t* p2_table, uint8_t p1, const uint8_t* prev,
                                  const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
                                  const uint8_t* vb, int uniqueness_percent, bool subpixel,
                                  bool narrow, void* partial, uint8_t* cost,
                                  const uint32_t* threshold, uint8_t* scratch, int16_t* best,
                                  int16_t* offset, int16_t* right_best) {
#ifdef CAIRN_SGM_FOUR_PATH_KERNELS
  RowArgs a{&c, &g, image_row, prev_image_row, p2_table, p1, prev, prev_min, out, out_min, vb,
            partial, cost, threshold, uniqueness_percent, subpixel, best, offset};
  // Vectors per pixel and nibble planes as compile-time constants for the common case (128
  // disparities in 32-byte vectors or 64 in 16-byte ones, a 5x5 census).
  const auto run = [&](auto d) {
    const bool four = g.disparities == 4 * static_cast<int>(hn::Lanes(d));
    if (four && c.planes == 3) {
      if (narrow) {
        FinishRowImpl<kFourVectors, kThreePlanes, uint8_t>(d, a, scratch, right_best);
      } else {
        FinishRowImpl<kFourVectors, kThreePlanes, uint16_t>(d, a, scratch, right_best);
      }
    } else if (narrow) {
      FinishRowImpl<0, 0, uint8_t>(d, a, scratch, right_best);
    } else {
      FinishRowImpl<0, 0, uint16_t>(d, a, scratch, right_best);
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
  (void)prev_min, (void)out, (void)out_min, (void)vb, (void)uniqueness_percent, (void)subpixel;
  (void)narrow, (void)partial, (void)cost, (void)threshold, (void)scratch, (void)best;
  (void)offset, (void)right_best;
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
HWY_EXPORT(FourPathFinishRowSimd);
HWY_EXPORT(FourPathCensusSimd);

void Vertical(const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
              const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
              const uint8_t* prev, const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
              uint8_t* cost_out) {
  HWY_DYNAMIC_DISPATCH(FourPathVerticalSimd)(c, g, image_row, prev_image_row, p2_table, p1, prev,
                                             prev_min, out, out_min, cost_out);
}
void FinishRow(const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
               const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
               const uint8_t* prev, const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
               const uint8_t* vb,
               int uniqueness_percent, bool subpixel, bool narrow, void* partial,
               uint8_t* cost, const uint32_t* threshold, uint8_t* scratch, int16_t* best,
               int16_t* offset, int16_t* right_best) {
  HWY_DYNAMIC_DISPATCH(FourPathFinishRowSimd)(c, g, image_row, prev_image_row, p2_table, p1, prev,
                                              prev_min, out, out_min, vb, uniqueness_percent,
                                              subpixel, narrow, partial, cost, threshold,
                                              scratch, best, offset, right_best);
}

void Census(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch, uint8_t* out,
            int plane_stride, bool reversed, int pad, int n_rev) {
  HWY_DYNAMIC_DISPATCH(FourPathCensusSimd)(center, stride, width, cw, ch, out, plane_stride,
                                           reversed, pad, n_rev);
}

}  // namespace

const SgmFourPathKernels* SimdFourPathKernels() {
  static const SgmFourPathKernels kernels{Vertical, FinishRow, Census};
  return HWY_DYNAMIC_DISPATCH(HasFourPathSimd)() ? &kernels : nullptr;
}

}  // namespace cairn
#endif  // HWY_ONCE
