#pragma once
// The row kernels of Semi-Global Matching. SgmMatcher owns the buffers, the threading and the
// per-pixel decisions; a backend only supplies these loops. The scalar set is the golden model;
// the Highway set must give the same result for every input (all arithmetic is integer).
//
// Layouts: a cost row is width * D uint8 and a sum row width * D uint16 (disparity index k
// fastest, k = d - d_min). A path row is kPathLead sentinel bytes followed by one block of
// `block` = D + kPathTail uint8 per pixel: lanes [0, D) are the path costs, the rest hold
// kPathSentinel, so lane D and lane -1 (the previous block's tail, or the lead) never win as
// +-1 neighbours. Pointers to path rows point at the first block. Path costs fit 8 bits because SgmOptions::Validate demands
// census_bits + 2 * p2 <= 255: a path cost is at most C + P2 and the jump term min + P2 at most
// census_bits + 2 * P2, so no addition overflows and none saturates.

#include <cstddef>
#include <cstdint>

#include "stereo/stereo_matcher_interface.h"

namespace cairn {

inline constexpr uint8_t kPathSentinel = 0xFF;
inline constexpr int kPathLead = 64;
inline constexpr int kPathTail = 16;  // small blocks: the path rows are the working set

struct SgmRowGeometry {
  int width = 0;
  int disparities = 0;  // D, a multiple of 16
  int block = 0;        // D + kPathTail
  int min_disparity = 0;
  // Reversed right-census index of (x, k): rev_base - x + k (see SgmKernels::cost).
  int rev_base = 0;
};

struct SgmKernels {
  // Center-symmetric census of one row. `center` points at pixel (0, y) inside an image padded by
  // (cw/2, ch/2) replicated pixels on every side; bit order: pairs in raster order, first pair
  // in the most significant used bit.
  void (*census)(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch,
                 uint32_t* out);
  // cost[x*D + k] = max(popcount(left[x] ^ right(i)), border[i]), i = rev_base - x + k, where
  // right(i) is the reversed right census stored as `planes` byte planes: byte b of right(i) is
  // right_planes[b * plane_stride + i] (planes = ceil(census bits / 8); the other bytes are 0).
  void (*cost)(const uint32_t* left, const uint8_t* right_planes, int plane_stride, int planes,
               const uint8_t* border, const SgmRowGeometry& g, uint8_t* cost);
  // The left-to-right and right-to-left paths; sum = their sum. scratch: a path row of 4 blocks.
  void (*horizontal)(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                     const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum);
  // Only the left-to-right path (raster_paths mode); sum = its costs.
  void (*horizontal_forward)(const uint8_t* cost, const uint8_t* image_row,
                             const SgmRowGeometry& g, const uint8_t* p2_table, uint8_t p1,
                             uint8_t* scratch, uint16_t* sum);
  // `paths` (1 or 3) paths arriving from the previous row at x, x-1, x+1. prev == nullptr on the
  // first row of a sweep. dst[x*D + k] = src[...] + sum of the new path costs (dst may be src).
  // stream_dst hints that dst is not read again soon (a backend may bypass the cache).
  void (*vertical)(const uint8_t* cost, const uint8_t* image_row, const uint8_t* prev_image_row,
                   const SgmRowGeometry& g, int paths, const uint8_t* p2_table, uint8_t p1,
                   uint8_t* const* prev, const uint8_t* const* prev_min, uint8_t* const* cur,
                   uint8_t* const* cur_min, const uint16_t* src, uint16_t* dst, bool stream_dst);
  // Winner-take-all of one sum row. best[x] = argmin_k (smallest k on ties), or -1 - best when
  // the uniqueness test fails. right_best[xr] = argmin_k sum(xr + d_min + k, k) over the row, -1
  // where no candidate exists. scratch: 2 * (rev_base + D + 1) uint16.
  void (*wta)(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent,
              uint16_t* scratch, int16_t* best, int16_t* right_best);
};

const SgmKernels& ScalarSgmKernels();

// Golden-model pieces that the RTL unit benches check the hardware against.
// One recursion step over d_count disparities: out[k] = c[k] + min(prev[k], prev[k-1] + p1,
// prev[k+1] + p1, min_prev + p2) - min_prev (sums saturate at 255, which only the sentinels
// reach; prev[-1] and prev[d_count] must be readable). Returns min_k out[k].
uint8_t SgmPathStep(const uint8_t* c, const uint8_t* prev, uint8_t min_prev, uint8_t p1,
                    uint8_t p2, int d_count, uint8_t* out);
// Equiangular sub-pixel offset in 1/kDisparityScale px from the sums at the winner (`at`) and its
// neighbours, rounded half away from zero; 0 when the denominator is 0.
inline int SgmSubpixelOffset(int below, int at, int above) {
  const int den = (below > above ? below : above) - at;
  if (den <= 0) return 0;
  const int num = (below - above) * (kDisparityScale / 2);
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}
// The left-right check of a left winner k against the right image's winner at the match (-1 when
// that right pixel had no candidate).
inline bool SgmLeftRightConsistent(int k, int right_k, int max_diff) {
  return right_k >= 0 && (k > right_k ? k - right_k : right_k - k) <= max_diff;
}
// The SIMD backend's own schedule for the four horizontal and vertical paths
// (SgmMatcher::MatchFourPath): fewer, fused passes, the same arithmetic as the kernels above.
//
// Cost inputs of one row. Both census rows are stored as `planes` = ceil(census bits / 4) nibble
// planes: nibble b of the left census at x is left[b * left_stride + x], nibble b of the reversed
// right census right(i) (see SgmKernels::cost) is nibbles[b * stride + i]. cost(x, k) is as in
// SgmKernels::cost; pixels x in [safe_begin, safe_end) have no border lanes.
struct SgmCostRow {
  const uint8_t* left = nullptr;
  int left_stride = 0;
  const uint8_t* nibbles = nullptr;
  int stride = 0;
  int planes = 0;
  const uint8_t* border = nullptr;
  int safe_begin = 0, safe_end = 0;
};

// Path rows here are plain: width * D uint8, no sentinel blocks; every pointer is aligned to 64
// bytes and has 64 readable bytes before and after.
struct SgmFourPathKernels {
  // One vertical path over a row, the cost computed on the fly: out = step(prev) as in
  // SgmKernels::vertical with one path, out = cost where prev == nullptr (first row of the
  // sweep); out_min[x] = min_k out(x, k); cost_out (may be null) receives the cost row.
  void (*vertical)(const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
                   const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
                   const uint8_t* prev, const uint8_t* prev_min, uint8_t* out, uint8_t* out_min,
                   uint8_t* cost_out);
  // A row of the second half, complete: its cost, the own vertical path (as `vertical`, prev ->
  // out), both horizontal paths (as SgmKernels::horizontal), their sum with the opposite
  // vertical path vb, and winner-take-all as SgmKernels::wta (best, right_best); offset[x] is the
  // sub-pixel offset at best (SgmSubpixelOffset) with `subpixel` and 0 < best < D - 1, else 0.
  // Sums are uint8 when `narrow` (the caller guarantees that four path costs stay <= 255), else
  // uint16. threshold[m] = ceil(100 m / (100 - uniqueness_percent)) for every sum m. partial:
  // width * D sums and cost: width * D bytes of scratch space; scratch: 4 D + 4 D + 64 bytes
  // plus 8 (rev_base + D + 96) sums.
  void (*finish_row)(const SgmCostRow& c, const SgmRowGeometry& g, const uint8_t* image_row,
                     const uint8_t* prev_image_row, const uint8_t* p2_table, uint8_t p1,
                     const uint8_t* prev, const uint8_t* prev_min, uint8_t* out,
                     uint8_t* out_min, const uint8_t* vb, int uniqueness_percent, bool subpixel,
                     bool narrow, void* partial, uint8_t* cost, const uint32_t* threshold,
                     uint8_t* scratch, int16_t* best, int16_t* offset, int16_t* right_best);
  // SgmKernels::census of one row, as SgmCostRow's nibble planes: plane b at out + b * stride,
  // index x, or with `reversed` index width - 1 + pad - x (pad = max(0, -d_min)) and 0 elsewhere
  // below n_rev = rev_base + D.
  void (*census)(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch, uint8_t* out,
                 int plane_stride, bool reversed, int pad, int n_rev);
};
// nullptr where the dispatched target has no such kernels (HWY_SCALAR).
const SgmFourPathKernels* SimdFourPathKernels();

// Highway implementation for the best target of this CPU (AVX2, SSE4, NEON, ...).
const SgmKernels& SimdSgmKernels();
// Name of the Highway target SimdSgmKernels() dispatches to, for reports.
const char* SimdTargetName();

}  // namespace cairn
