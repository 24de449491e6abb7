#pragma once
// Integer post-filters on a fixed-point disparity image (1/16 px, kInvalidDisparity = invalid).
// Shared by every backend, so they are part of the bit-exact contract.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cairn {

class WorkerPool;

class DisparityFilter {
 public:
  // 3x3 median of the valid pixels around each valid pixel (lower middle for an even count);
  // invalid pixels stay invalid. Rows [y0, y1) of `out` are written; in and out must differ.
  static void Median3x3(const int16_t* in, int16_t* out, int width, int height, int y0, int y1);

  // Invalidates 4-connected regions of fewer than max_size pixels whose neighbours differ by at
  // most max_diff. Buffers are kept between calls (no allocation for a repeated size). With a
  // pool, row bands are filled on its threads and the regions crossing band borders are joined
  // afterwards; a region is a connected component, so the result is the same.
  void RemoveSpeckles(int16_t* disparity, int width, int height, int max_size, int max_diff,
                      WorkerPool* pool = nullptr);

  // Fills each invalid run of a row with the smaller (farther) of its valid end values, or the one
  // valid end at an image border.
  static void FillHolesRow(int16_t* row, int width);

 private:
  // A region of one band that reaches a band border: it may continue in the next band.
  struct Open {
    int32_t id, size;
    size_t first_pixel;  // its pixels in Band::open_pixels (kept only while size < max_size)
  };
  // One band of rows [y0, y1) in a padded copy: (width + 2) x (rows + 2) cells, the frame
  // marked visited, so that a flood fill needs no bounds checks; invalid pixels start visited.
  struct Band {
    std::vector<uint8_t> visited;
    std::vector<int16_t> disparity;
    std::vector<int32_t> stack, region, open_pixels;  // padded cell indices
    std::vector<int32_t> top_id, bottom_id;            // region ids along the first, last row
    std::vector<Open> open;
  };
  void FillBand(int16_t* disparity, int width, int height, int y0, int y1, int max_size,
                int max_diff, Band& band);

  std::vector<Band> bands_;
  std::vector<int32_t> parent_;
  // The open regions of all bands by id, and their joined sizes: members so that their
  // capacity stays from one image to the next.
  std::vector<Open*> open_;
  std::vector<int64_t> open_size_;
};

}  // namespace cairn
