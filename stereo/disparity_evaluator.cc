#include "stereo/disparity_evaluator.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>

#include "io/image_codec.h"

namespace cairn {

Expected<DisparityMetric> ParseDisparityMetric(const std::string& name) {
  if (name == "bad0.5") return DisparityMetric::kBad05;
  if (name == "bad1") return DisparityMetric::kBad1;
  if (name == "bad2") return DisparityMetric::kBad2;
  if (name == "bad3") return DisparityMetric::kBad3;
  if (name == "bad4") return DisparityMetric::kBad4;
  if (name == "d1") return DisparityMetric::kD1;
  return InvalidArgumentError("unknown metric '" + name + "' (bad0.5, bad1, bad2, bad3, bad4, d1)");
}

const char* DisparityMetricName(DisparityMetric metric) {
  switch (metric) {
    case DisparityMetric::kBad05: return "bad0.5";
    case DisparityMetric::kBad1: return "bad1";
    case DisparityMetric::kBad2: return "bad2";
    case DisparityMetric::kBad3: return "bad3";
    case DisparityMetric::kBad4: return "bad4";
    case DisparityMetric::kD1: return "d1";
  }
  return "?";
}

Expected<FloatImage> LoadGroundTruth(const std::string& path, double scale) {
  if (path.size() > 4 && path.substr(path.size() - 4) == ".pfm") return ReadPfm(path);
  if (!std::filesystem::is_regular_file(path)) return NotFoundError("no such ground truth file " + path);
  const auto read = ImageCodec::Read(path, ImageReadMode::kGrayAnyDepth);
  if (!read.ok()) return read.status();
  const cv::Mat& m = *read;
  if (m.depth() != CV_8U && m.depth() != CV_16U) {
    return DataLossError(path + ": ground truth must be an 8- or 16-bit PNG or a PFM");
  }
  if (scale <= 0.0) scale = m.depth() == CV_16U ? 256.0 : 1.0;
  FloatImage img{m.cols, m.rows, {}};
  img.data.resize(static_cast<size_t>(m.cols) * m.rows);
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      const double v = m.depth() == CV_16U ? m.at<uint16_t>(y, x) : m.at<uint8_t>(y, x);
      img.data[static_cast<size_t>(y) * m.cols + x] =
          v == 0.0 ? std::numeric_limits<float>::infinity() : static_cast<float>(v / scale);
    }
  }
  return img;
}

Expected<FloatImage> LoadMask(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) return NotFoundError("no such mask file " + path);
  const auto read = ImageCodec::Read(path, ImageReadMode::kGray8);
  if (!read.ok()) return read.status();
  const cv::Mat& m = *read;
  FloatImage img{m.cols, m.rows, {}};
  img.data.resize(static_cast<size_t>(m.cols) * m.rows);
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) img.data[static_cast<size_t>(y) * m.cols + x] = m.at<uint8_t>(y, x);
  }
  return img;
}

FloatImage DisparityEvaluator::DeriveNonOccludedMask(const FloatImage& truth) {
  FloatImage mask{truth.width, truth.height, std::vector<float>(truth.data.size(), 0.0f)};
  std::vector<float> nearest(static_cast<size_t>(truth.width));
  for (int y = 0; y < truth.height; ++y) {
    // Z-buffer of the right view: the largest disparity landing on each right column.
    std::fill(nearest.begin(), nearest.end(), -1.0f);
    for (int x = 0; x < truth.width; ++x) {
      const float d = truth.at(x, y);
      if (!std::isfinite(d)) continue;
      const int xr = static_cast<int>(std::lround(x - d));
      if (xr >= 0 && xr < truth.width) nearest[xr] = std::max(nearest[xr], d);
    }
    for (int x = 0; x < truth.width; ++x) {
      const float d = truth.at(x, y);
      if (!std::isfinite(d)) continue;
      const int xr = static_cast<int>(std::lround(x - d));
      const bool visible = xr >= 0 && xr < truth.width && d >= nearest[xr] - 1.0f;
      mask.data[static_cast<size_t>(y) * truth.width + x] = visible ? 255.0f : 128.0f;
    }
  }
  return mask;
}

FloatImage DisparityEvaluator::InterpolateBackground(const FloatImage& estimate) {
  FloatImage out = estimate;
  const int w = out.width, h = out.height;
  const auto at = [&](int x, int y) -> float& { return out.data[static_cast<size_t>(y) * w + x]; };
  std::vector<bool> row_has(static_cast<size_t>(h), false);
  for (int y = 0; y < h; ++y) {
    int last = -1;  // the last column with an estimate
    for (int x = 0; x < w; ++x) {
      if (!std::isfinite(at(x, y))) continue;
      if (last < 0) {
        for (int k = 0; k < x; ++k) at(k, y) = at(x, y);  // the row's start
      } else if (x > last + 1) {
        const float fill = std::min(at(last, y), at(x, y));  // the background side of the gap
        for (int k = last + 1; k < x; ++k) at(k, y) = fill;
      }
      last = x;
    }
    if (last < 0) continue;
    for (int k = last + 1; k < w; ++k) at(k, y) = at(last, y);  // the row's end
    row_has[static_cast<size_t>(y)] = true;
  }
  // Rows above the first row with an estimate take that row, rows below the last take the last
  // (rows without any estimate between two that have some stay missing, as in KITTI's devkit).
  const auto first = std::find(row_has.begin(), row_has.end(), true);
  if (first == row_has.end()) return out;
  const int top = static_cast<int>(first - row_has.begin());
  const int bottom = h - 1 - static_cast<int>(std::find(row_has.rbegin(), row_has.rend(), true) - row_has.rbegin());
  for (int y = 0; y < h; ++y) {
    if (y >= top && y <= bottom) continue;
    const int from = y < top ? top : bottom;
    std::copy_n(out.data.begin() + static_cast<ptrdiff_t>(from) * w, w, out.data.begin() + static_cast<ptrdiff_t>(y) * w);
  }
  return out;
}

Expected<DisparityScore> DisparityEvaluator::Score(const FloatImage& estimate,
                                                   const FloatImage& truth, const FloatImage& mask,
                                                   DisparityMetric metric) {
  if (estimate.width != truth.width || estimate.height != truth.height) {
    return InvalidArgumentError("estimate is " + std::to_string(estimate.width) + "x" +
                                std::to_string(estimate.height) + " but ground truth is " +
                                std::to_string(truth.width) + "x" + std::to_string(truth.height));
  }
  DisparityScore score;
  FloatImage derived;
  const FloatImage* m = &mask;
  if (mask.data.empty()) {
    derived = DeriveNonOccludedMask(truth);
    m = &derived;
    score.mask_derived = true;
  } else if (mask.width != truth.width || mask.height != truth.height) {
    return InvalidArgumentError("mask size differs from the ground truth size");
  }
  double threshold = 1.0;
  switch (metric) {
    case DisparityMetric::kBad05: threshold = 0.5; break;
    case DisparityMetric::kBad1: threshold = 1.0; break;
    case DisparityMetric::kBad2: threshold = 2.0; break;
    case DisparityMetric::kBad3: threshold = 3.0; break;
    case DisparityMetric::kBad4: threshold = 4.0; break;
    case DisparityMetric::kD1: threshold = 3.0; break;
  }
  long bad_nonocc = 0, bad_all = 0, valid = 0, bad_estimated = 0;
  for (size_t i = 0; i < truth.data.size(); ++i) {
    const float e = estimate.data[i];
    if (std::isfinite(e)) ++valid;
    const float t = truth.data[i];
    const float mv = m->data[i];
    if (!std::isfinite(t) || mv == 0.0f) continue;
    bool bad = !std::isfinite(e);
    if (!bad) {
      const double err = std::abs(static_cast<double>(e) - t);
      bad = metric == DisparityMetric::kD1 ? (err > threshold && err > 0.05 * t) : err > threshold;
    }
    ++score.scored_all;
    bad_all += bad;
    if (mv == 255.0f) {
      ++score.scored_nonocc;
      bad_nonocc += bad;
      if (std::isfinite(e)) {
        ++score.estimated_nonocc;
        bad_estimated += bad;
      }
    }
  }
  score.bad_all = score.scored_all > 0 ? static_cast<double>(bad_all) / score.scored_all : 0.0;
  score.bad_nonocc =
      score.scored_nonocc > 0 ? static_cast<double>(bad_nonocc) / score.scored_nonocc : 0.0;
  score.bad_estimated = score.estimated_nonocc > 0
                            ? static_cast<double>(bad_estimated) / score.estimated_nonocc
                            : 0.0;
  score.density = truth.data.empty() ? 0.0 : static_cast<double>(valid) / truth.data.size();
  return score;
}

}  // namespace cairn
