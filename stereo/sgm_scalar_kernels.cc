// The golden model: plain loops that define SGM's integer arithmetic exactly.

#include <algorithm>
#include <bit>
#include <cstdlib>

#include "stereo/sgm_kernels.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {
namespace {

void CensusScalar(const uint8_t* center, ptrdiff_t stride, int width, int cw, int ch,
                  uint32_t* out) {
  const int rx = cw / 2, ry = ch / 2;
  for (int x = 0; x < width; ++x) {
    uint32_t bits = 0;
    for (int dy = -ry; dy <= 0; ++dy) {
      for (int dx = -rx; dx <= rx; ++dx) {
        if (dy == 0 && dx == 0) break;
        const uint8_t a = center[dy * stride + x + dx];
        const uint8_t b = center[-dy * stride + x - dx];
        bits = (bits << 1) | (a > b ? 1u : 0u);
      }
    }
    out[x] = bits;
  }
}

void CostScalar(const uint32_t* left, const uint8_t* right_planes, int plane_stride, int planes,
                const uint8_t* border, const SgmRowGeometry& g, uint8_t* cost) {
  const int d_count = g.disparities;
  for (int x = 0; x < g.width; ++x) {
    const int base = g.rev_base - x;
    for (int k = 0; k < d_count; ++k) {
      uint32_t right = 0;
      for (int b = 0; b < planes; ++b) {
        right |= uint32_t{right_planes[b * plane_stride + base + k]} << (8 * b);
      }
      const int c = std::popcount(left[x] ^ right);
      cost[x * d_count + k] = static_cast<uint8_t>(std::max<int>(c, border[base + k]));
    }
  }
}

}  // namespace

uint8_t SgmPathStep(const uint8_t* c, const uint8_t* prev, uint8_t min_prev, uint8_t p1, uint8_t p2,
             int d_count, uint8_t* out) {
  const auto sat_add = [](uint8_t a, uint8_t b) {
    return static_cast<uint8_t>(std::min(a + b, 255));
  };
  const uint8_t jump = sat_add(min_prev, p2);
  uint8_t best = 0xFF;
  for (int k = 0; k < d_count; ++k) {
    uint8_t m = std::min(prev[k], std::min(sat_add(prev[k - 1], p1), sat_add(prev[k + 1], p1)));
    m = std::min(m, jump);
    out[k] = static_cast<uint8_t>(c[k] + (m - min_prev));
    best = std::min(best, out[k]);
  }
  return best;
}

namespace {

constexpr auto Step = SgmPathStep;

// passes = 1: left to right only; 2: also right to left.
void HorizontalPasses(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                      const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum,
                      int passes) {
  const int d_count = g.disparities;
  uint8_t* a = scratch;
  uint8_t* b = scratch + g.block;
  for (int pass = 0; pass < passes; ++pass) {
    std::fill(a, a + d_count, uint8_t{0});
    uint8_t min_prev = 0;
    int prev_x = pass == 0 ? 0 : g.width - 1;
    for (int i = 0; i < g.width; ++i) {
      const int x = pass == 0 ? i : g.width - 1 - i;
      const uint8_t p2 = p2_table[std::abs(image_row[x] - image_row[prev_x])];
      min_prev = Step(cost + x * d_count, a, min_prev, p1, p2, d_count, b);
      uint16_t* s = sum + x * d_count;
      for (int k = 0; k < d_count; ++k) s[k] = static_cast<uint16_t>(pass == 0 ? b[k] : s[k] + b[k]);
      std::swap(a, b);
      prev_x = x;
    }
  }
}

void HorizontalScalar(const uint8_t* cost, const uint8_t* image_row, const SgmRowGeometry& g,
                      const uint8_t* p2_table, uint8_t p1, uint8_t* scratch, uint16_t* sum) {
  HorizontalPasses(cost, image_row, g, p2_table, p1, scratch, sum, 2);
}

void HorizontalForwardScalar(const uint8_t* cost, const uint8_t* image_row,
                             const SgmRowGeometry& g, const uint8_t* p2_table, uint8_t p1,
                             uint8_t* scratch, uint16_t* sum) {
  HorizontalPasses(cost, image_row, g, p2_table, p1, scratch, sum, 1);
}

void VerticalScalar(const uint8_t* cost, const uint8_t* image_row, const uint8_t* prev_image_row,
                    const SgmRowGeometry& g, int paths, const uint8_t* p2_table, uint8_t p1,
                    uint8_t* const* prev, const uint8_t* const* prev_min, uint8_t* const* cur,
                    uint8_t* const* cur_min, const uint16_t* src, uint16_t* dst,
                    bool /*stream_dst*/) {
  const int d_count = g.disparities;
  static constexpr int kOffsets[3] = {0, -1, 1};
  // A path entering the image starts from zero costs, which makes its first step return C.
  uint8_t zero_block[kPathLead + 512 + kPathTail];
  std::fill(zero_block, zero_block + kPathLead + g.block, kPathSentinel);
  std::fill(zero_block + kPathLead, zero_block + kPathLead + d_count, uint8_t{0});
  const uint8_t* zero = zero_block + kPathLead;
  for (int x = 0; x < g.width; ++x) {
    for (int k = 0; k < d_count; ++k) dst[x * d_count + k] = src[x * d_count + k];
    for (int p = 0; p < paths; ++p) {
      const int px = x + kOffsets[p];
      const bool inside = prev != nullptr && px >= 0 && px < g.width;
      const uint8_t* lp = inside ? prev[p] + px * g.block : zero;
      const uint8_t mp = inside ? prev_min[p][px] : 0;
      const uint8_t p2 = inside ? p2_table[std::abs(image_row[x] - prev_image_row[px])] : p2_table[0];
      uint8_t* out = cur[p] + x * g.block;
      cur_min[p][x] = Step(cost + x * d_count, lp, mp, p1, p2, d_count, out);
      for (int k = 0; k < d_count; ++k) {
        dst[x * d_count + k] = static_cast<uint16_t>(dst[x * d_count + k] + out[k]);
      }
    }
  }
}

void WtaScalar(const uint16_t* sum, const SgmRowGeometry& g, int uniqueness_percent,
               uint16_t* scratch, int16_t* best, int16_t* right_best) {
  const int d_count = g.disparities;
  const int n_rev = g.rev_base + d_count;
  uint16_t* rmin = scratch;
  uint16_t* rk = scratch + n_rev;
  std::fill(rmin, rmin + n_rev, uint16_t{0x7FFF});
  std::fill(rk, rk + n_rev, uint16_t{0xFFFF});
  for (int x = 0; x < g.width; ++x) {
    const uint16_t* s = sum + x * d_count;
    int bk = 0;
    for (int k = 1; k < d_count; ++k) {
      if (s[k] < s[bk]) bk = k;
    }
    uint32_t second = 0xFFFF;
    for (int k = 0; k < d_count; ++k) {
      if (k < bk - 1 || k > bk + 1) second = std::min<uint32_t>(second, s[k]);
    }
    const bool unique = second * static_cast<uint32_t>(100 - uniqueness_percent) >=
                        uint32_t{s[bk]} * 100u;
    best[x] = static_cast<int16_t>(unique ? bk : -1 - bk);
    const int base = g.rev_base - x;
    for (int k = 0; k < d_count; ++k) {
      if (s[k] < rmin[base + k]) {
        rmin[base + k] = s[k];
        rk[base + k] = static_cast<uint16_t>(k);
      }
    }
  }
  for (int xr = 0; xr < g.width; ++xr) {
    const uint16_t k = rk[g.rev_base - g.min_disparity - xr];
    right_best[xr] = k == 0xFFFF ? int16_t{-1} : static_cast<int16_t>(k);
  }
}

}  // namespace

const SgmKernels& ScalarSgmKernels() {
  static const SgmKernels kernels{CensusScalar,   CostScalar,     HorizontalScalar,
                                  HorizontalForwardScalar, VerticalScalar, WtaScalar};
  return kernels;
}

}  // namespace cairn
