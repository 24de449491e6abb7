#include "stereo/disparity_filter.h"

#include <algorithm>
#include <cstdlib>

#include "stereo/stereo_matcher_interface.h"
#include "stereo/worker_pool.h"

namespace cairn {

// The interior pixels [x0, x1) of a row in SIMD vectors (disparity_filter_simd.cc); returns
// where the scalar loop has to continue.
int MedianInteriorRow(const int16_t* u, const int16_t* c, const int16_t* d, int16_t* o, int x0,
                      int x1);

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
    const int x_simd = MedianInteriorRow(u, c, d, o, 1, width - 1);
    // Interior: a branch-free odd-even transposition sort of the 9 values (9 rounds sort 9
    // inputs), vectorized by the compiler. kInvalidDisparity is the smallest int16, so the
    // invalid values come first and the median of the n valid ones sits at 9 - n + (n - 1) / 2.
    for (int x = x_simd; x < width - 1; ++x) {
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

void DisparityFilter::FillBand(int16_t* disparity, int width, int height, int y0, int y1,
                               int max_size, int max_diff, Band& band) {
  const int rows = y1 - y0;
  const int pw = width + 2;
  const size_t cells = static_cast<size_t>(pw) * (rows + 2);
  band.visited.resize(cells);
  band.disparity.resize(cells);
  band.stack.resize(static_cast<size_t>(rows) * width);
  band.region.resize(static_cast<size_t>(rows) * width);
  band.top_id.assign(static_cast<size_t>(width), 0);
  band.bottom_id.assign(static_cast<size_t>(width), 0);
  band.open.clear();
  band.open_pixels.clear();
  uint8_t* visited = band.visited.data();
  int16_t* disp = band.disparity.data();
  std::fill_n(visited, pw, uint8_t{1});
  std::fill_n(visited + static_cast<size_t>(rows + 1) * pw, pw, uint8_t{1});
  for (int r = 0; r < rows; ++r) {
    const int16_t* src = disparity + static_cast<size_t>(y0 + r) * width;
    uint8_t* v = visited + static_cast<size_t>(r + 1) * pw;
    int16_t* d = disp + static_cast<size_t>(r + 1) * pw;
    v[0] = v[width + 1] = 1;
    d[0] = d[width + 1] = kInvalidDisparity;
    for (int x = 0; x < width; ++x) {
      d[x + 1] = src[x];
      v[x + 1] = src[x] == kInvalidDisparity ? 1 : 0;
    }
  }
  int32_t* stack = band.stack.data();
  int32_t* region = band.region.data();
  // Cells of the first and the last row of the band; they matter where another band follows.
  const int32_t first_end = pw + width + 1, last_begin = rows * pw + 1;
  const bool open_top = y0 > 0, open_bottom = y1 < height;
  for (int r = 0; r < rows; ++r) {
    for (int x = 0; x < width; ++x) {
      const int32_t start = (r + 1) * pw + x + 1;
      if (visited[start] != 0) continue;
      // Flood fill, remembering the members so that a small region can be cleared afterwards.
      const int32_t id = (y0 + r) * width + x + 1;
      int top = 0, count = 0;
      bool open = false;
      stack[top++] = start;
      visited[start] = 1;
      while (top > 0) {
        const int32_t p = stack[--top];
        region[count++] = p;
        if (p < first_end) {
          band.top_id[static_cast<size_t>(p - pw - 1)] = id;
          open |= open_top;
        }
        if (p >= last_begin) {
          band.bottom_id[static_cast<size_t>(p - last_begin)] = id;
          open |= open_bottom;
        }
        const int dp = disp[p];
        for (const int32_t q : {p - 1, p + 1, p - pw, p + pw}) {
          if (visited[q] != 0 || std::abs(disp[q] - dp) > max_diff) continue;
          visited[q] = 1;
          stack[top++] = q;
        }
      }
      if (open) {
        band.open.push_back({id, count, band.open_pixels.size()});
        if (count < max_size) band.open_pixels.insert(band.open_pixels.end(), region, region + count);
      } else if (count < max_size) {
        for (int i = 0; i < count; ++i) {
          const int32_t p = region[i];
          const int py = p / pw - 1, px = p % pw - 1;  // only for the few cleared pixels
          disparity[static_cast<size_t>(y0 + py) * width + px] = kInvalidDisparity;
        }
      }
    }
  }
}

void DisparityFilter::RemoveSpeckles(int16_t* disparity, int width, int height, int max_size,
                                     int max_diff, WorkerPool* pool) {
  if (max_size <= 0) return;
  // Bands of at least 32 rows, one per thread.
  const int bands = std::max(1, std::min(pool != nullptr ? pool->threads() : 1, height / 32));
  bands_.resize(static_cast<size_t>(bands));
  const auto band_rows = [&](int b, int* y0, int* y1) {
    *y0 = static_cast<int>(static_cast<int64_t>(height) * b / bands);
    *y1 = static_cast<int>(static_cast<int64_t>(height) * (b + 1) / bands);
  };
  auto fill = [&](int b) {
    int y0, y1;
    band_rows(b, &y0, &y1);
    FillBand(disparity, width, height, y0, y1, max_size, max_diff, bands_[static_cast<size_t>(b)]);
  };
  if (bands == 1) {
    fill(0);
    return;
  }
  pool->ForEach(bands, fill);
  // Join the open regions across the band borders (union-find over their ids), then clear the
  // joined regions that stay small.
  std::vector<Open*>& open = open_;  // by index
  open.clear();
  for (Band& band : bands_) {
    for (Open& o : band.open) open.push_back(&o);
  }
  std::sort(open.begin(), open.end(), [](const Open* a, const Open* b) { return a->id < b->id; });
  const auto index_of = [&](int32_t id) {
    const auto it = std::lower_bound(open.begin(), open.end(), id,
                                     [](const Open* o, int32_t v) { return o->id < v; });
    return static_cast<int32_t>(it - open.begin());
  };
  parent_.resize(open.size());
  for (size_t i = 0; i < open.size(); ++i) parent_[i] = static_cast<int32_t>(i);
  const auto find = [&](int32_t i) {
    while (parent_[static_cast<size_t>(i)] != i) {
      parent_[static_cast<size_t>(i)] = parent_[static_cast<size_t>(parent_[static_cast<size_t>(i)])];
      i = parent_[static_cast<size_t>(i)];
    }
    return i;
  };
  std::vector<int64_t>& size = open_size_;
  size.resize(open.size());
  for (size_t i = 0; i < open.size(); ++i) size[i] = open[i]->size;
  for (int b = 1; b < bands; ++b) {
    int y0, y1;
    band_rows(b, &y0, &y1);
    const int32_t* above = bands_[static_cast<size_t>(b - 1)].bottom_id.data();
    const int32_t* below = bands_[static_cast<size_t>(b)].top_id.data();
    const int16_t* da = disparity + static_cast<size_t>(y0 - 1) * width;
    const int16_t* db = disparity + static_cast<size_t>(y0) * width;
    for (int x = 0; x < width; ++x) {
      if (da[x] == kInvalidDisparity || db[x] == kInvalidDisparity) continue;
      if (std::abs(da[x] - db[x]) > max_diff) continue;
      const int32_t ra = find(index_of(above[x])), rb = find(index_of(below[x]));
      if (ra == rb) continue;
      parent_[static_cast<size_t>(rb)] = ra;
      size[static_cast<size_t>(ra)] += size[static_cast<size_t>(rb)];
    }
  }
  const int pw = width + 2;
  for (int b = 0; b < bands; ++b) {
    int y0, y1;
    band_rows(b, &y0, &y1);
    const Band& band = bands_[static_cast<size_t>(b)];
    for (const Open& o : band.open) {
      if (o.size >= max_size || size[static_cast<size_t>(find(index_of(o.id)))] >= max_size) continue;
      for (int32_t i = 0; i < o.size; ++i) {
        const int32_t p = band.open_pixels[o.first_pixel + i];
        disparity[static_cast<size_t>(y0 + p / pw - 1) * width + p % pw - 1] = kInvalidDisparity;
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
