#pragma once
// File helpers of the stereo tools: reading a pair as 8-bit gray, converting fixed-point
// disparities to PFM-ready floats, and a colour visualisation.

#include <string>

#include <opencv2/core.hpp>

#include "common/status.h"
#include "stereo/pfm_io.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {

struct GrayPair {
  cv::Mat left, right;  // CV_8UC1, equal sizes
};

// Reads two gray or colour PNG/JPEG files and converts them to gray; errors name the file.
Expected<GrayPair> LoadGrayPair(const std::string& left_path, const std::string& right_path);

// Pixels as float disparities, +inf where invalid.
FloatImage DisparityToFloat(const StereoMatcherOutput& output);

// Colour-mapped disparity (invalid black), scaled to [min_disparity, max_disparity].
Status WriteDisparityPng(const std::string& path, const StereoMatcherOutput& output,
                         int min_disparity, int max_disparity);

}  // namespace cairn
