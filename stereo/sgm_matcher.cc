#include "stereo/sgm_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "stereo/stereo_depth.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace cairn {
namespace {

constexpr int kMaxSide = 16384;

// Asks for transparent huge pages on the whole-frame sum volume: it is written and read once per
// frame in long streams, and 2 MB pages save most of the TLB misses. Only a hint.
void AdviseHugePages(void* p, size_t bytes) {
#ifdef __linux__
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

template <class T>
hwy::AlignedFreeUniquePtr<T[]> AllocateBuffer(size_t n, size_t* bytes) {
  *bytes += n * sizeof(T);
  return hwy::AllocateAligned<T>(n);
}

}  // namespace

Expected<std::unique_ptr<SgmMatcher>> SgmMatcher::Create(const SgmOptions& options) {
  CAIRN_RETURN_IF_ERROR(options.Validate());
  return std::unique_ptr<SgmMatcher>(new SgmMatcher(options));
}

SgmMatcher::SgmMatcher(const SgmOptions& options)
    : options_(options),
      kernels_(options.backend == SgmBackend::kScalar ? &ScalarSgmKernels() : &SimdSgmKernels()),
      pool_(static_cast<int>(options.threads)),
      rx_(static_cast<int>(options.census_width / 2)),
      ry_(static_cast<int>(options.census_height / 2)) {
  options.FillP2Table(p2_table_);
  if (options.backend == SgmBackend::kSimd && options.paths == 4 && !options.raster_paths) {
    four_path_ = SimdFourPathKernels();
  }
  // Four path costs of at most census_bits + p2 each (sgm_kernels.h) fit uint8 sums; the winner's
  // index k has to fit them too.
  narrow_sums_ = 4 * (options.census_bits() + options.p2) <= 255 && options.num_disparities <= 256;
  // The uniqueness test "s (100 - u) < m 100" as "s < t(m)" for every possible sum m <= 4 * 255.
  const uint32_t keep = static_cast<uint32_t>(100 - options.uniqueness_percent);
  uniqueness_threshold_.resize(4 * 255 + 1);
  for (uint32_t m = 0; m < uniqueness_threshold_.size(); ++m) {
    uniqueness_threshold_[m] = (m * 100u + keep - 1) / keep;
  }
}

std::string_view SgmMatcher::name() const {
  if (options_.raster_paths) {
    return options_.backend == SgmBackend::kScalar ? "sgm-scalar-raster" : "sgm-simd-raster";
  }
  return options_.backend == SgmBackend::kScalar ? "sgm-scalar" : "sgm-simd";
}

void SgmMatcher::Allocate(int width, int height) {
  width_ = width;
  height_ = height;
  buffer_bytes_ = 0;
  const int d = static_cast<int>(options_.num_disparities);
  const int dmin = static_cast<int>(options_.min_disparity);
  geometry_.width = width;
  geometry_.disparities = d;
  geometry_.block = d + kPathTail;
  geometry_.min_disparity = dmin;
  geometry_.rev_base = width - 1 + dmin + std::max(0, -dmin);
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  // 64 spare bytes per row let SIMD census loads run past the right border.
  pad_stride_ = static_cast<ptrdiff_t>(w + 2 * rx_ + 64);
  const size_t pad_bytes = static_cast<size_t>(pad_stride_) * (h + 2 * ry_);
  pad_left_ = AllocateBuffer<uint8_t>(pad_bytes, &buffer_bytes_);
  pad_right_ = AllocateBuffer<uint8_t>(pad_bytes, &buffer_bytes_);
  std::memset(pad_left_.get(), 0, pad_bytes);
  std::memset(pad_right_.get(), 0, pad_bytes);
  if (four_path_ == nullptr) {  // the four-path schedule keeps its census as nibble planes
    census_left_ = AllocateBuffer<uint32_t>(w * h, &buffer_bytes_);
    census_right_ = AllocateBuffer<uint32_t>(w * h, &buffer_bytes_);
  }
  if (four_path_ != nullptr) {
    AllocateFourPath();
  } else if (!options_.raster_paths) {  // the raster pass needs no sum volume
    sum_ = AllocateBuffer<uint16_t>(w * h * d, &buffer_bytes_);
    AdviseHugePages(sum_.get(), w * h * d * sizeof(uint16_t));
  }
  raw_ = AllocateBuffer<int16_t>(w * h, &buffer_bytes_);
  filtered_ = AllocateBuffer<int16_t>(w * h, &buffer_bytes_);
  const size_t n_rev = static_cast<size_t>(geometry_.rev_base) + d + 64;
  for (Sweep& s : sweeps_) {
    if (four_path_ != nullptr) break;
    s.cost = AllocateBuffer<uint8_t>(w * d, &buffer_bytes_);
    s.row_sum = AllocateBuffer<uint16_t>(w * d, &buffer_bytes_);
    s.horizontal_scratch = AllocateBuffer<uint8_t>(kPathLead + 4 * geometry_.block, &buffer_bytes_);
    s.wta_scratch = AllocateBuffer<uint16_t>(2 * n_rev, &buffer_bytes_);
    std::fill_n(s.horizontal_scratch.get(), kPathLead + 4 * geometry_.block, kPathSentinel);
    for (int b = 0; b < 2; ++b) {
      for (int p = 0; p < 3; ++p) {
        // Sentinels fill the block pads once; the kernels only ever write lanes [0, D).
        s.path[b][p] = AllocateBuffer<uint8_t>(kPathLead + w * geometry_.block, &buffer_bytes_);
        std::fill_n(s.path[b][p].get(), kPathLead + w * geometry_.block, kPathSentinel);
        s.path_min[b][p] = AllocateBuffer<uint8_t>(w, &buffer_bytes_);
      }
    }
    s.right_planes = AllocateBuffer<uint8_t>(4 * n_rev, &buffer_bytes_);
    s.border = AllocateBuffer<uint8_t>(n_rev, &buffer_bytes_);
    s.best = AllocateBuffer<int16_t>(w, &buffer_bytes_);
    s.right_best = AllocateBuffer<int16_t>(w, &buffer_bytes_);
  }
}

void SgmMatcher::AllocateFourPath() {
  const size_t w = static_cast<size_t>(width_), h = static_cast<size_t>(height_);
  const size_t d = static_cast<size_t>(geometry_.disparities);
  const size_t row = w * d;
  // 64 readable bytes before and after every path row (sgm_kernels.h).
  volume_ = AllocateBuffer<uint8_t>(row * h + 128, &buffer_bytes_);
  AdviseHugePages(volume_.get(), row * h + 128);
  const size_t n_rev = static_cast<size_t>(geometry_.rev_base) + d + 64;
  const size_t planes = static_cast<size_t>(nibble_planes());
  nibbles_ = AllocateBuffer<uint8_t>(h * planes * static_cast<size_t>(nibble_stride()) + 64,
                                     &buffer_bytes_);
  left_nibbles_ = AllocateBuffer<uint8_t>(h * planes * w + 64, &buffer_bytes_);
  // The right image sits at i in [pad, pad + width) (pad = max(0, -d_min)), the border cost
  // around it.
  border_ = AllocateBuffer<uint8_t>(n_rev, &buffer_bytes_);
  const int pad = geometry_.rev_base - (width_ - 1) - geometry_.min_disparity;
  std::fill_n(border_.get(), n_rev, static_cast<uint8_t>(options_.census_bits()));
  std::fill_n(border_.get() + pad, w, uint8_t{0});
  for (FourPathLane& l : lanes_) {
    for (int b = 0; b < 2; ++b) {
      l.state[b] = AllocateBuffer<uint8_t>(row + 128, &buffer_bytes_);
      l.mins[b] = AllocateBuffer<uint8_t>(w, &buffer_bytes_);
    }
    l.partial = AllocateBuffer<uint8_t>(row * 2, &buffer_bytes_);
    l.cost = AllocateBuffer<uint8_t>(row, &buffer_bytes_);
    l.scratch = AllocateBuffer<uint8_t>(8 * d + 64 + 16 * (n_rev + 96), &buffer_bytes_);
    l.best = AllocateBuffer<int16_t>(w, &buffer_bytes_);
    l.offset = AllocateBuffer<int16_t>(w, &buffer_bytes_);
    l.right_best = AllocateBuffer<int16_t>(w, &buffer_bytes_);
  }
}

SgmCostRow SgmMatcher::FourPathCostRow(int y) const {
  const SgmRowGeometry& g = geometry_;
  SgmCostRow c;
  c.stride = nibble_stride();
  c.planes = nibble_planes();
  c.left_stride = width_;
  c.left = left_nibbles_.get() + static_cast<size_t>(y) * c.planes * width_;
  c.nibbles = nibbles_.get() + static_cast<size_t>(y) * c.planes * c.stride;
  c.border = border_.get();
  // x - d_min - k is inside the right image for every k.
  c.safe_begin = std::max(0, g.min_disparity + g.disparities - 1);
  c.safe_end = std::min(width_, width_ + g.min_disparity);
  return c;
}

void SgmMatcher::FourPathVertical(FourPathLane& l, int y, uint8_t* out) {
  const SgmCostRow c = FourPathCostRow(y);
  uint8_t* out_min = l.mins[l.cur_min].get();
  four_path_->vertical(c, geometry_, image_row(y),
                       l.prev != nullptr ? image_row(l.prev_y) : nullptr, p2_table_,
                       static_cast<uint8_t>(options_.p1), l.prev, l.prev_min, out, out_min,
                       nullptr);
  l.prev = out;
  l.prev_min = out_min;
  l.prev_y = y;
  l.cur_min ^= 1;
}

void SgmMatcher::FourPathFinish(FourPathLane& l, int y, uint8_t* out) {
  const SgmCostRow c = FourPathCostRow(y);
  uint8_t* out_min = l.mins[l.cur_min].get();
  four_path_->finish_row(c, geometry_, image_row(y),
                         l.prev != nullptr ? image_row(l.prev_y) : nullptr, p2_table_,
                         static_cast<uint8_t>(options_.p1), l.prev, l.prev_min, out, out_min,
                         VolumeRow(y), static_cast<int>(options_.uniqueness_percent),
                         options_.subpixel, narrow_sums_, l.partial.get(), l.cost.get(),
                         uniqueness_threshold_.data(), l.scratch.get(),
                         l.best.get(), l.offset.get(), l.right_best.get());
  l.prev = out;
  l.prev_min = out_min;
  l.prev_y = y;
  l.cur_min ^= 1;
}

void SgmMatcher::MatchFourPath() {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const int h = height_, half = h / 2;
  for (FourPathLane& l : lanes_) {
    l.prev = nullptr;
    l.prev_min = nullptr;
    l.prev_y = -1;
  }
  // Each sweep's own half: only its vertical path, straight into the volume.
  pool_.ForEach(2, [&](int t) {
    FourPathLane& l = lanes_[t];
    if (t == 0) {
      for (int y = 0; y < half; ++y) FourPathVertical(l, y, VolumeRow(y));
    } else {
      for (int y = h - 1; y >= half; --y) FourPathVertical(l, y, VolumeRow(y));
    }
  });
  times_.first_half_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const auto t1 = Clock::now();
  // The other half, where the volume holds the opposite vertical path: every row finishes.
  double split[2] = {0, 0};
  pool_.ForEach(2, [&](int t) {
    FourPathLane& l = lanes_[t];
    auto mark = Clock::now();
    const auto lap = [&](int i) {
      if (t != 0) return;
      const auto now = Clock::now();
      split[i] += std::chrono::duration<double, std::milli>(now - mark).count();
      mark = now;
    };
    const auto finish = [&](int y) {
      uint8_t* own = l.state[l.cur_state].get() + 64;
      l.cur_state ^= 1;
      FourPathFinish(l, y, own);
      lap(0);
      FinishPixels(l.best.get(), l.offset.get(), l.right_best.get(), y);
      lap(1);
    };
    if (t == 0) {
      for (int y = half; y < h; ++y) finish(y);
    } else {
      for (int y = half - 1; y >= 0; --y) finish(y);
    }
  });
  times_.second_half_ms = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
  times_.row_pass_ms = split[0];
  times_.lr_check_ms = split[1];
}

void SgmMatcher::PadImage(const uint8_t* src, int stride, uint8_t* dst, int y0, int y1) const {
  // Rows y0..y1 of the padded image (in padded coordinates), borders replicated.
  const int w = width_;
  for (int py = y0; py < y1; ++py) {
    const int sy = std::clamp(py - ry_, 0, height_ - 1);
    const uint8_t* s = src + static_cast<ptrdiff_t>(sy) * stride;
    uint8_t* t = dst + py * pad_stride_;
    std::memset(t, s[0], static_cast<size_t>(rx_));
    std::memcpy(t + rx_, s, static_cast<size_t>(w));
    std::memset(t + rx_ + w, s[w - 1], static_cast<size_t>(rx_));
  }
}

void SgmMatcher::ComputeCost(Sweep& s, int y) {
  const SgmRowGeometry& g = geometry_;
  const int n_rev = g.rev_base + g.disparities;
  const int plane_stride = n_rev + 64;  // as allocated: 4 planes of n_rev + 64 bytes
  const int planes = (options_.census_bits() + 7) / 8;
  const int pad = g.rev_base - (width_ - 1) - g.min_disparity;  // = max(0, -d_min)
  const uint32_t* cr = census_right_.get() + static_cast<size_t>(y) * width_;
  const uint8_t border_cost = static_cast<uint8_t>(options_.census_bits());
  uint8_t* rp = s.right_planes.get();
  for (int i = 0; i < n_rev; ++i) {
    const int xr = width_ - 1 + pad - i;
    const bool inside = xr >= 0 && xr < width_;
    const uint32_t c = inside ? cr[xr] : 0u;
    for (int b = 0; b < planes; ++b) rp[b * plane_stride + i] = static_cast<uint8_t>(c >> (8 * b));
    s.border[i] = inside ? 0 : border_cost;
  }
  kernels_->cost(census_left_.get() + static_cast<size_t>(y) * width_, rp, plane_stride, planes,
                 s.border.get(), g, s.cost.get());
}

void SgmMatcher::SweepRow(Sweep& s, int y, bool finish) {
  const SgmRowGeometry& g = geometry_;
  const uint8_t p1 = static_cast<uint8_t>(options_.p1);
  const int paths = options_.paths == 8 ? 3 : 1;
  ComputeCost(s, y);
  uint16_t* sum_row = sum_.get() + static_cast<size_t>(y) * width_ * g.disparities;
  // First visit: the horizontal paths go to the row buffer, and the volume row is written once
  // (streamed past the cache: the other sweep reads it much later). Second visit: the volume row
  // plus this sweep's paths land in the row buffer for winner-take-all.
  if (!finish) {
    kernels_->horizontal(s.cost.get(), image_row(y), g, p2_table_, p1,
                         s.horizontal_scratch.get() + kPathLead, s.row_sum.get());
  }
  VerticalPaths(s, y, paths, finish ? sum_row : s.row_sum.get(),
                finish ? s.row_sum.get() : sum_row, /*stream_dst=*/!finish);
  if (finish) FinishRow(s, y);
}

void SgmMatcher::VerticalPaths(Sweep& s, int y, int paths, const uint16_t* src, uint16_t* dst,
                               bool stream_dst) {
  const int prev = 1 - s.cur;
  uint8_t* prev_paths[3];
  const uint8_t* prev_min[3];
  uint8_t* cur_paths[3];
  uint8_t* cur_min[3];
  for (int p = 0; p < 3; ++p) {
    prev_paths[p] = s.path[prev][p].get() + kPathLead;
    prev_min[p] = s.path_min[prev][p].get();
    cur_paths[p] = s.path[s.cur][p].get() + kPathLead;
    cur_min[p] = s.path_min[s.cur][p].get();
  }
  kernels_->vertical(s.cost.get(), image_row(y), s.has_prev ? image_row(s.prev_y) : nullptr,
                     geometry_, paths, p2_table_, static_cast<uint8_t>(options_.p1),
                     s.has_prev ? prev_paths : nullptr, prev_min, cur_paths, cur_min, src, dst,
                     stream_dst);
  s.cur = prev;
  s.has_prev = true;
  s.prev_y = y;
}

void SgmMatcher::RasterRow(Sweep& s, int y) {
  const SgmRowGeometry& g = geometry_;
  const uint8_t p1 = static_cast<uint8_t>(options_.p1);
  ComputeCost(s, y);
  kernels_->horizontal_forward(s.cost.get(), image_row(y), g, p2_table_, p1,
                               s.horizontal_scratch.get() + kPathLead, s.row_sum.get());
  // Up, up-left and up-right (the three paths arriving from the row above), added in place.
  VerticalPaths(s, y, 3, s.row_sum.get(), s.row_sum.get(), /*stream_dst=*/false);
  FinishRow(s, y);
}

void SgmMatcher::FinishRow(Sweep& s, int y) {
  kernels_->wta(s.row_sum.get(), geometry_, static_cast<int>(options_.uniqueness_percent),
                s.wta_scratch.get(), s.best.get(), s.right_best.get());
  FinishPixels(s.row_sum.get(), s.best.get(), s.right_best.get(), y);
}

void SgmMatcher::FinishPixels(const int16_t* best, const int16_t* offset,
                              const int16_t* right_best, int y) {
  const SgmRowGeometry& g = geometry_;
  int16_t* out = raw_.get() + static_cast<size_t>(y) * width_;
  const int max_diff = static_cast<int>(options_.lr_max_diff);
  for (int x = 0; x < width_; ++x) {
    out[x] = kInvalidDisparity;
    const int k = best[x];
    if (k < 0) continue;  // not unique
    const int d = g.min_disparity + k;
    const int xr = x - d;
    if (xr < 0 || xr >= width_) continue;  // matched outside the right image
    if (options_.lr_check && !SgmLeftRightConsistent(k, right_best[xr], max_diff)) continue;
    out[x] = static_cast<int16_t>(d * kDisparityScale + offset[x]);
  }
}

template <class SumT>
void SgmMatcher::FinishPixels(const SumT* sum, const int16_t* best, const int16_t* right_best,
                              int y) {
  const SgmRowGeometry& g = geometry_;
  const int d_count = g.disparities;
  int16_t* out = raw_.get() + static_cast<size_t>(y) * width_;
  const int max_diff = static_cast<int>(options_.lr_max_diff);
  for (int x = 0; x < width_; ++x) {
    out[x] = kInvalidDisparity;
    const int k = best[x];
    if (k < 0) continue;  // not unique
    const int d = g.min_disparity + k;
    const int xr = x - d;
    if (xr < 0 || xr >= width_) continue;  // matched outside the right image
    if (options_.lr_check) {
      if (!SgmLeftRightConsistent(k, right_best[xr], max_diff)) continue;
    }
    int value = d * kDisparityScale;
    if (options_.subpixel && k > 0 && k < d_count - 1) {
      const SumT* sr = sum + static_cast<size_t>(x) * d_count;
      value += SgmSubpixelOffset(sr[k - 1], sr[k], sr[k + 1]);
    }
    out[x] = static_cast<int16_t>(value);
  }
}

Status SgmMatcher::Match(const StereoMatcherInput& input, StereoMatcherOutput* output) {
  if (output == nullptr) return InvalidArgumentError("SgmMatcher::Match: output is null");
  if (input.left == nullptr || input.right == nullptr) {
    return InvalidArgumentError("SgmMatcher::Match: left or right image is null");
  }
  if (input.width < 1 || input.height < 1 || input.width > kMaxSide || input.height > kMaxSide) {
    return InvalidArgumentError("SgmMatcher::Match: image size " + std::to_string(input.width) +
                                "x" + std::to_string(input.height) + " outside 1.." +
                                std::to_string(kMaxSide));
  }
  if (input.stride < input.width) {
    return InvalidArgumentError("SgmMatcher::Match: stride " + std::to_string(input.stride) +
                                " is smaller than the width " + std::to_string(input.width));
  }
  if (input.width != width_ || input.height != height_) Allocate(input.width, input.height);
  const int w = width_, h = height_;
  const size_t n = static_cast<size_t>(w) * h;
  ResizeStereoOutput(w, h, output);
  using Clock = std::chrono::steady_clock;
  auto mark = Clock::now();
  const auto lap = [&mark](double* ms) {
    const auto now = Clock::now();
    *ms = std::chrono::duration<double, std::milli>(now - mark).count();
    mark = now;
  };
  const int tasks = pool_.threads();
  const auto band = [&](int t, int count, int* y0, int* y1) {
    *y0 = static_cast<int>(static_cast<int64_t>(count) * t / tasks);
    *y1 = static_cast<int>(static_cast<int64_t>(count) * (t + 1) / tasks);
  };

  // Pad and census, row bands in parallel.
  const int pad_rows = h + 2 * ry_;
  pool_.ForEach(tasks, [&](int t) {
    int y0, y1;
    band(t, pad_rows, &y0, &y1);
    PadImage(input.left, input.stride, pad_left_.get(), y0, y1);
    PadImage(input.right, input.stride, pad_right_.get(), y0, y1);
  });
  pool_.ForEach(tasks, [&](int t) {
    int y0, y1;
    band(t, h, &y0, &y1);
    for (int y = y0; y < y1; ++y) {
      const ptrdiff_t off = (y + ry_) * pad_stride_ + rx_;
      if (four_path_ != nullptr) {  // the census as the four-path kernels read it
        const int cw = static_cast<int>(options_.census_width);
        const int ch = static_cast<int>(options_.census_height);
        const int planes = nibble_planes(), stride = nibble_stride();
        four_path_->census(pad_left_.get() + off, pad_stride_, w, cw, ch,
                           left_nibbles_.get() + static_cast<size_t>(y) * planes * w, w, false, 0,
                           w);
        four_path_->census(pad_right_.get() + off, pad_stride_, w, cw, ch,
                           nibbles_.get() + static_cast<size_t>(y) * planes * stride, stride, true,
                           geometry_.rev_base - (w - 1) - geometry_.min_disparity,
                           geometry_.rev_base + geometry_.disparities);
        continue;
      }
      kernels_->census(pad_left_.get() + off, pad_stride_, w, static_cast<int>(options_.census_width),
                       static_cast<int>(options_.census_height), census_left_.get() + static_cast<size_t>(y) * w);
      kernels_->census(pad_right_.get() + off, pad_stride_, w, static_cast<int>(options_.census_width),
                       static_cast<int>(options_.census_height), census_right_.get() + static_cast<size_t>(y) * w);
    }
  });

  lap(&times_.census_ms);
  for (Sweep& s : sweeps_) s.has_prev = false;
  if (four_path_ != nullptr) {
    MatchFourPath();  // times both halves
    mark = Clock::now();
  } else if (options_.raster_paths) {
    // FPGA mode: one top-down pass finishes every row as soon as it is reached (no sum volume).
    for (int y = 0; y < h; ++y) RasterRow(sweeps_[0], y);
    lap(&times_.first_half_ms);
    times_.second_half_ms = 0.0;
  } else {
    // The two sweeps (see the header): sweep 0 top-down, sweep 1 bottom-up.
    const int half = h / 2;
    pool_.ForEach(2, [&](int t) {
      if (t == 0) {
        for (int y = 0; y < half; ++y) SweepRow(sweeps_[0], y, false);
      } else {
        for (int y = h - 1; y >= half; --y) SweepRow(sweeps_[1], y, false);
      }
    });
    lap(&times_.first_half_ms);
    pool_.ForEach(2, [&](int t) {
      if (t == 0) {
        for (int y = half; y < h; ++y) SweepRow(sweeps_[0], y, true);
      } else {
        for (int y = half - 1; y >= 0; --y) SweepRow(sweeps_[1], y, true);
      }
    });
    lap(&times_.second_half_ms);
  }

  // Post-filters, shared by every backend.
  int16_t* disp = raw_.get();
  if (options_.median) {
    pool_.ForEach(tasks, [&](int t) {
      int y0, y1;
      band(t, h, &y0, &y1);
      DisparityFilter::Median3x3(raw_.get(), filtered_.get(), w, h, y0, y1);
    });
    disp = filtered_.get();
  }
  lap(&times_.median_ms);
  filter_.RemoveSpeckles(disp, w, h, static_cast<int>(options_.speckle_max_size),
                         static_cast<int>(options_.speckle_max_diff), &pool_);
  if (options_.fill_holes) {
    for (int y = 0; y < h; ++y) DisparityFilter::FillHolesRow(disp + static_cast<size_t>(y) * w, w);
  }
  lap(&times_.speckle_ms);
  std::copy(disp, disp + n, output->disparity.begin());
  pool_.ForEach(tasks, [&](int t) {
    int y0, y1;
    band(t, h, &y0, &y1);
    ComputeStereoDepth(input, options_.pixel_error_px, output, y0, y1);
  });
  lap(&times_.depth_ms);
  return Status::Ok();
}

}  // namespace cairn
