#pragma once
// Portable float maps as used by Middlebury: "Pf" (one channel), width height, scale (< 0 means
// little-endian), then rows from the bottom of the image up. Invalid disparities are +inf.

#include <string>
#include <vector>

#include "common/status.h"

namespace cairn {

struct FloatImage {
  int width = 0;
  int height = 0;
  std::vector<float> data;  // row-major, top row first

  float at(int x, int y) const { return data[static_cast<size_t>(y) * width + x]; }
};

Status WritePfm(const std::string& path, const FloatImage& image);
Expected<FloatImage> ReadPfm(const std::string& path);

}  // namespace cairn
