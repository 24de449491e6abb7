#pragma once
// CPU Semi-Global Matching (Hirschmueller 2008) behind the StereoMatcher interface, with either
// the scalar golden-model kernels or the Highway SIMD kernels; both give identical disparities.
//
// Schedule: the sum volume S (W x H x D uint16, the only full-size buffer) is filled by two row
// sweeps, a top-down one carrying the paths that arrive from the row above and a bottom-up one
// carrying those from the row below. Each sweep first covers its own half of the image (also
// adding the two horizontal paths there), then continues into the other half, where S already
// holds every other path, and finishes each row with winner-take-all. The two sweeps run on two
// threads without ever touching the same row at the same time; the sums are integers, so the
// result does not depend on the thread count. With raster_paths (the FPGA mode) a single top-down
// pass aggregates left-to-right, up-left, up and up-right and finishes each row at once.

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include <hwy/aligned_allocator.h>

#include "stereo/disparity_filter.h"
#include "stereo/sgm_kernels.h"
#include "stereo/sgm_options.h"
#include "stereo/stereo_matcher_interface.h"
#include "stereo/worker_pool.h"

namespace cairn {

class SgmMatcher final : public StereoMatcher {
 public:
  static Expected<std::unique_ptr<SgmMatcher>> Create(const SgmOptions& options);

  std::string_view name() const override;
  Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) override;

  const SgmOptions& options() const { return options_; }
  // Bytes held for the current image size.
  size_t buffer_bytes() const { return buffer_bytes_; }

  // Wall time of the stages of the last Match(), for benchmarks.
  struct StageTimes {
    double census_ms = 0, first_half_ms = 0, second_half_ms = 0, median_ms = 0, speckle_ms = 0,
           depth_ms = 0;
    // The SIMD four-path schedule's second half on the first thread: the fused row pass (cost,
    // own vertical and both horizontal paths, sum, winner-take-all, uniqueness, sub-pixel), then
    // the left-right check.
    double row_pass_ms = 0, lr_check_ms = 0;
  };
  const StageTimes& last_stage_times() const { return times_; }

 private:
  template <class T>
  using Buffer = hwy::AlignedFreeUniquePtr<T[]>;

  struct Sweep {
    Buffer<uint8_t> cost, horizontal_scratch;
    Buffer<uint16_t> row_sum, wta_scratch;
    Buffer<uint8_t> path[2][3];  // [prev/cur][path]
    Buffer<uint8_t> path_min[2][3];
    Buffer<uint8_t> right_planes, border;  // reversed right census row (sgm_kernels.h)
    Buffer<int16_t> best, right_best;
    int cur = 0;          // which of path[0], path[1] receives the next row
    bool has_prev = false;
    int prev_y = -1;
  };

  // The SIMD backend's schedule for paths == 4 (SgmFourPathKernels): a top-down and a bottom-up
  // sweep, each on its own thread, first run over their own half of the image computing only
  // their vertical path, which they leave in an 8-bit volume (W x H x D uint8, the only full-size
  // buffer). Then each continues into the other half, where the volume holds the opposite
  // vertical path, and finishes every row there: its own vertical path, both horizontal paths,
  // the sum (uint8 when four path costs cannot exceed 255), winner-take-all.
  struct FourPathLane {
    Buffer<uint8_t> state[2], mins[2], partial, cost, scratch;
    Buffer<int16_t> best, offset, right_best;
    const uint8_t* prev = nullptr;  // the path row of the previous row of the sweep
    const uint8_t* prev_min = nullptr;
    int prev_y = -1;
    int cur_min = 0, cur_state = 0;
  };
  void AllocateFourPath();
  void MatchFourPath();
  // The cost inputs of row y (SgmCostRow).
  SgmCostRow FourPathCostRow(int y) const;
  int nibble_planes() const { return (options_.census_bits() + 3) / 4; }
  int nibble_stride() const { return geometry_.rev_base + geometry_.disparities + 64; }
  // Continues the lane's sweep with row y: only the vertical path (first half), or the whole row.
  void FourPathVertical(FourPathLane& l, int y, uint8_t* out);
  void FourPathFinish(FourPathLane& l, int y, uint8_t* out);
  uint8_t* VolumeRow(int y) const {
    return volume_.get() + 64 + static_cast<size_t>(y) * width_ * geometry_.disparities;
  }

  explicit SgmMatcher(const SgmOptions& options);
  void Allocate(int width, int height);
  void PadImage(const uint8_t* src, int stride, uint8_t* dst, int y0, int y1) const;
  void ComputeCost(Sweep& s, int y);
  // Aggregates row y in a sweep; with `finish` the row is complete afterwards and gets its
  // disparities.
  void SweepRow(Sweep& s, int y, bool finish);
  // The paths arriving from the previous row of the sweep: dst = src + their costs.
  void VerticalPaths(Sweep& s, int y, int paths, const uint16_t* src, uint16_t* dst,
                     bool stream_dst);
  // raster_paths mode: the forward horizontal and the three upper paths of row y, then its
  // disparities.
  void RasterRow(Sweep& s, int y);
  void FinishRow(Sweep& s, int y);
  // Left-right check and sub-pixel offsets of row y from its winners and sums.
  template <class SumT>
  void FinishPixels(const SumT* sum, const int16_t* best, const int16_t* right_best, int y);
  // The same from sub-pixel offsets computed already (0 where none applies).
  void FinishPixels(const int16_t* best, const int16_t* offset, const int16_t* right_best, int y);
  const uint8_t* image_row(int y) const { return pad_left_.get() + (y + ry_) * pad_stride_ + rx_; }

  SgmOptions options_;
  const SgmKernels* kernels_;
  WorkerPool pool_;
  uint8_t p2_table_[256];
  int rx_ = 0, ry_ = 0;

  int width_ = 0, height_ = 0;
  SgmRowGeometry geometry_;
  ptrdiff_t pad_stride_ = 0;
  Buffer<uint8_t> pad_left_, pad_right_;
  Buffer<uint32_t> census_left_, census_right_;
  Buffer<uint16_t> sum_;
  Buffer<int16_t> raw_, filtered_;
  Sweep sweeps_[2];
  const SgmFourPathKernels* four_path_ = nullptr;  // set: MatchFourPath is used
  bool narrow_sums_ = false;
  std::vector<uint32_t> uniqueness_threshold_;  // SgmFourPathKernels::finish_row's threshold
  Buffer<uint8_t> volume_;
  // SgmCostRow's census nibble planes of every row (left, reversed right) and border costs.
  Buffer<uint8_t> left_nibbles_, nibbles_, border_;
  FourPathLane lanes_[2];
  DisparityFilter filter_;
  size_t buffer_bytes_ = 0;
  StageTimes times_;
};

}  // namespace cairn
