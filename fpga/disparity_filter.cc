#include "fpga/disparity_filter.h"

#include <algorithm>
#include <cstdlib>

#include "fpga/stereo_matcher_interface.h"

namespace cairn {

namespace {

// Median of the valid values among the 3x3 neighbours of (x, y); the centre is valid.
int16_t MedianOfValid(const int16_t* in, int width, int height, int x, int y) {
  int16_t v[9];
  int n = 0;
  for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy) {
    for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
      const int16_t d = in[static_cast<size_t>(yy) * width + xx];
      if (d != kInvalidDisparity) v[n++] = d;
    }
  }
  std::nth_element(v, v + (n - 1) / 2, v + n);
  return v[(n - 1) / 2];
}

inline void Sort2(int16_t& a, int16_t& b) {
  const int16_t lo = std::min(a, b);
  b = std::max(a, b);
  a = lo;
}

}  // namespace

void DisparityFilter::Median3x3(const int16_t* in, int16_t* out, int width, int height, int y0,
                                int y1) {
  for (int y = y0; y < y1; ++y) {
    int16_t* o = out + static_cast<size_t>(y) * width;
    const int16_t* c = in + static_cast<size_t>(y) * width;
    if (y == 0 || y == height - 1 || width < 3) {
      for (int x = 0; x < width; ++x) {
        o[x] = c[x] == kInvalidDisparity ? kInvalidDisparity : MedianOfValid(in, width, height, x, y);
      }
      continue;
    }
    const int16_t* u = c - width;
    const int16_t* d = c + width;
    // Interior: a branch-free odd-even transposition sort of the 9 values (9 rounds sort 9
    // inputs), vectorized by the compiler. kInvalidDisparity is the smallest int16, so the
    // invalid values come first and the median of the n valid ones sits at 9 - n + (n - 1) / 2.
    for (int x = 1; x < width - 1; ++x) {
      int16_t p0 = u[x - 1], p1 = u[x], p2 = u[x + 1], p3 = c[x - 1], p4 = c[x], p5 = c[x + 1],
              p6 = d[x - 1], p7 = d[x], p8 = d[x + 1];
      const int16_t centre = p4;
      Sort2(p0, p1); Sort2(p2, p3); Sort2(p4, p5); Sort2(p6, p7);
      Sort2(p1, p2); Sort2(p3, p4); Sort2(p5, p6); Sort2(p7, p8);
      Sort2(p0, p1); Sort2(p2, p3); Sort2(p4, p5); Sort2(p6, p7);
      Sort2(p1, p2); Sort2(p3, p4); Sort2(p5, p6); Sort2(p7, p8);
      Sort2(p0, p1); Sort2(p2, p3); Sort2(p4, p5); Sort2(p6, p7);
      Sort2(p1, p2); Sort2(p3, p4); Sort2(p5, p6); Sort2(p7, p8);
      Sort2(p0, p1); Sort2(p2, p3); Sort2(p4, p5); Sort2(p6, p7);
      Sort2(p1, p2); Sort2(p3, p4); Sort2(p5, p6); Sort2(p7, p8);
      Sort2(p0, p1); Sort2(p2, p3); Sort2(p4, p5); Sort2(p6, p7);
      const int invalid = (p0 == kInvalidDisparity) + (p1 == kInvalidDisparity) +
                          (p2 == kInvalidDisparity) + (p3 == kInvalidDisparity) +
                          (p4 == kInvalidDisparity) + (p5 == kInvalidDisparity) +
                          (p6 == kInvalidDisparity) + (p7 == kInvalidDisparity) +
                          (p8 == kInvalidDisparity);
      const int at = invalid + (8 - invalid) / 2;
      // Selections as bit masks keep the loop free of branches.
      const auto pick = [at](int j, int16_t v, int16_t m) {
        const int16_t mask = static_cast<int16_t>(-static_cast<int16_t>(at == j));
        return static_cast<int16_t>((v & mask) | (m & ~mask));
      };
      int16_t m = p0;
      m = pick(1, p1, m);
      m = pick(2, p2, m);
      m = pick(3, p3, m);
      m = pick(4, p4, m);
      m = pick(5, p5, m);
      m = pick(6, p6, m);
      m = pick(7, p7, m);
      m = pick(8, p8, m);
      const int16_t keep = static_cast<int16_t>(-static_cast<int16_t>(centre != kInvalidDisparity));
      o[x] = static_cast<int16_t>((m & keep) | (kInvalidDisparity & ~keep));
    }
    for (int x : {0, width - 1}) {
      o[x] = c[x] == kInvalidDisparity ? kInvalidDisparity : MedianOfValid(in, width, height, x, y);
    }
  }
}

void DisparityFilter::RemoveSpeckles(int16_t* disparity, int width, int height, int max_size,
                                     int max_diff) {
  if (max_size <= 0) return;
  const size_t n = static_cast<size_t>(width) * height;
  label_.assign(n, 0);  // no reallocation once the size was seen
  stack_.resize(2 * n);  // (x, y) pairs: no division per visited pixel
  region_.resize(n);
  for (int sy = 0; sy < height; ++sy) {
    for (int sx = 0; sx < width; ++sx) {
      const size_t start = static_cast<size_t>(sy) * width + sx;
      if (label_[start] != 0 || disparity[start] == kInvalidDisparity) continue;
      // Flood fill, remembering the members so that a small region can be cleared afterwards.
      int top = 0, count = 0;
      stack_[top++] = sx;
      stack_[top++] = sy;
      label_[start] = 1;
      while (top > 0) {
        const int py = stack_[--top];
        const int px = stack_[--top];
        const int32_t p = py * width + px;
        region_[count++] = p;
        const int16_t dp = disparity[p];
        const auto visit = [&](int qx, int qy) {
          const int32_t q = qy * width + qx;
          if (label_[q] != 0) return;
          const int16_t dq = disparity[q];
          if (dq == kInvalidDisparity || std::abs(dq - dp) > max_diff) return;
          label_[q] = 1;
          stack_[top++] = qx;
          stack_[top++] = qy;
        };
        if (px > 0) visit(px - 1, py);
        if (px + 1 < width) visit(px + 1, py);
        if (py > 0) visit(px, py - 1);
        if (py + 1 < height) visit(px, py + 1);
      }
      if (count < max_size) {
        for (int i = 0; i < count; ++i) disparity[region_[i]] = kInvalidDisparity;
      }
    }
  }
}

void DisparityFilter::FillHolesRow(int16_t* row, int width) {
  int x = 0;
  while (x < width) {
    if (row[x] != kInvalidDisparity) {
      ++x;
      continue;
    }
    int end = x;
    while (end < width && row[end] == kInvalidDisparity) ++end;
    const bool has_left = x > 0, has_right = end < width;
    if (has_left || has_right) {
      int16_t fill;
      if (has_left && has_right) {
        fill = std::min(row[x - 1], row[end]);
      } else {
        fill = has_left ? row[x - 1] : row[end];
      }
      std::fill(row + x, row + end, fill);
    }
    x = end;
  }
}

}  // namespace cairn
