#include "mapping/matching/grey_level_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/elapsed.h"

namespace cairn {
namespace {

// Rasters wider than this (cells per side) are refused: 205 m at the default cell, far beyond a
// submap; the FFTs' memory grows with its square.
constexpr int kMaxRasterCells = 2048;

// Grey levels (and heights) of points turned by `yaw`, in cells of `cell` m from `origin`: the
// local deviation of each textured cell's mean grey level (0 elsewhere) and the mask of those
// cells.
struct Raster {
  cv::Mat deviation;  // CV_32F
  cv::Mat mask;       // CV_32F, 1 where textured
  cv::Mat height;     // CV_32F mean z, valid where mask
};

Raster Rasterize(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey, double yaw,
                 const Eigen::Vector2d& origin, int rows, int cols, double cell, int mean_half_width) {
  cv::Mat sum = cv::Mat::zeros(rows, cols, CV_32F), count = cv::Mat::zeros(rows, cols, CV_32F);
  cv::Mat z = cv::Mat::zeros(rows, cols, CV_32F);
  const double c = std::cos(yaw), s = std::sin(yaw), inv = 1.0 / cell;
  const size_t n = std::min(cloud.size(), grey.size());
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = cloud[i];
    if (!p.allFinite() || !std::isfinite(grey[i])) continue;
    const double x = c * p.x() - s * p.y() - origin.x(), y = s * p.x() + c * p.y() - origin.y();
    const double fc = std::floor(x * inv), fr = std::floor(y * inv);
    if (!(fc >= 0.0 && fr >= 0.0 && fc < cols && fr < rows)) continue;
    const int col = static_cast<int>(fc), row = static_cast<int>(fr);
    sum.at<float>(row, col) += grey[i];
    count.at<float>(row, col) += 1.0f;
    z.at<float>(row, col) += static_cast<float>(p.z());
  }
  Raster r;
  r.mask = cv::Mat::zeros(rows, cols, CV_32F);
  cv::Mat mean = cv::Mat::zeros(rows, cols, CV_32F);
  r.height = cv::Mat::zeros(rows, cols, CV_32F);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const float k = count.at<float>(row, col);
      if (k <= 0.0f) continue;
      r.mask.at<float>(row, col) = 1.0f;
      mean.at<float>(row, col) = sum.at<float>(row, col) / k;
      r.height.at<float>(row, col) = z.at<float>(row, col) / k;
    }
  }
  // Local mean over the textured cells of a (2w+1)^2 window.
  cv::Mat local_sum, local_count;
  const cv::Size window(2 * mean_half_width + 1, 2 * mean_half_width + 1);
  cv::boxFilter(mean, local_sum, CV_32F, window, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(r.mask, local_count, CV_32F, window, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  r.deviation = cv::Mat::zeros(rows, cols, CV_32F);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (r.mask.at<float>(row, col) == 0.0f) continue;
      r.deviation.at<float>(row, col) =
          mean.at<float>(row, col) - local_sum.at<float>(row, col) / local_count.at<float>(row, col);
    }
  }
  return r;
}

// The forward DFT (packed) of `m` placed at the top left of a zero `rows` x `cols` matrix.
cv::Mat PaddedSpectrum(const cv::Mat& m, int rows, int cols) {
  cv::Mat padded = cv::Mat::zeros(rows, cols, CV_32F);
  m.copyTo(padded(cv::Rect(0, 0, m.cols, m.rows)));
  cv::Mat spectrum;
  cv::dft(padded, spectrum, 0, m.rows);
  return spectrum;
}

// sum_x a(x + s) b(x) for every circular shift s.
cv::Mat Correlate(const cv::Mat& spectrum_a, const cv::Mat& spectrum_b) {
  cv::Mat product, out;
  cv::mulSpectrums(spectrum_a, spectrum_b, product, 0, true);
  cv::idft(product, out, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  return out;
}

struct SearchPeak {
  int yaw_index = 0;
  double yaw = 0.0;
  Eigen::Vector2d shift;  // cells, sub-cell refined
  double correlation = 0.0;
  int64_t overlap = 0;
  Eigen::Vector2d t_xy;
};

}  // namespace

Expected<GreyLevelSearchResult> GreyLevelSearch::Search(const std::vector<Eigen::Vector3d>& cloud_a,
                                                        const std::vector<float>& grey_a,
                                                        const std::vector<Eigen::Vector3d>& cloud_b,
                                                        const std::vector<float>& grey_b,
                                                        Eigen::Vector2d yaw_window) const {
  const auto start = std::chrono::steady_clock::now();
  const GreyLevelSearchOptions& o = options_;
  if (!(o.cell > 0.0) || !(o.yaw_step > 0.0) || o.max_candidates < 1)
    return InvalidArgumentError("grey-level search: cell and yaw_step must be > 0, max_candidates >= 1");
  GreyLevelSearchResult out;

  // A's raster over its points' xy box; B's turned about its box centre within a square that
  // holds it at every yaw.
  Eigen::AlignedBox2d box_a, box_b;
  for (size_t i = 0; i < std::min(cloud_a.size(), grey_a.size()); ++i)
    if (cloud_a[i].allFinite() && std::isfinite(grey_a[i])) box_a.extend(cloud_a[i].head<2>());
  for (size_t i = 0; i < std::min(cloud_b.size(), grey_b.size()); ++i)
    if (cloud_b[i].allFinite() && std::isfinite(grey_b[i])) box_b.extend(cloud_b[i].head<2>());
  if (box_a.isEmpty() || box_b.isEmpty()) {
    out.ms = MillisecondsSince(start);
    return out;
  }
  const Eigen::Vector2d centre_b = box_b.center();
  double radius_b = 0.0;
  for (size_t i = 0; i < std::min(cloud_b.size(), grey_b.size()); ++i)
    if (cloud_b[i].allFinite()) radius_b = std::max(radius_b, (cloud_b[i].head<2>() - centre_b).norm());
  const int cols_a = static_cast<int>(std::ceil(box_a.sizes().x() / o.cell)) + 1;
  const int rows_a = static_cast<int>(std::ceil(box_a.sizes().y() / o.cell)) + 1;
  const int side_b = static_cast<int>(std::ceil(2.0 * radius_b / o.cell)) + 1;
  if (std::max({cols_a, rows_a, side_b}) > kMaxRasterCells)
    return InvalidArgumentError("grey-level search: a raster of " + std::to_string(std::max({cols_a, rows_a, side_b})) +
                                " cells per side, more than " + std::to_string(kMaxRasterCells));
  const int half_width = static_cast<int>(std::lround(o.local_mean_radius / o.cell));
  const Eigen::Vector2d origin_a = box_a.min();
  const Raster ra = Rasterize(cloud_a, grey_a, 0.0, origin_a, rows_a, cols_a, o.cell, half_width);

  // Linear (not circular) correlation: every shift from -(side_b - 1) to size_a - 1.
  const int rows = cv::getOptimalDFTSize(rows_a + side_b - 1), cols = cv::getOptimalDFTSize(cols_a + side_b - 1);
  cv::Mat a_dev_sq;
  cv::multiply(ra.deviation, ra.deviation, a_dev_sq);
  const cv::Mat fa = PaddedSpectrum(ra.deviation, rows, cols);
  const cv::Mat fa_sq = PaddedSpectrum(a_dev_sq, rows, cols);
  const cv::Mat fa_mask = PaddedSpectrum(ra.mask, rows, cols);

  const int yaws = static_cast<int>(std::ceil(2.0 * std::numbers::pi / o.yaw_step));
  const double step = 2.0 * std::numbers::pi / yaws;
  const int suppress = std::max(1, static_cast<int>(std::ceil(o.separation_translation / o.cell)));
  std::vector<SearchPeak> peaks;
  cv::Mat score(rows, cols, CV_32F);
  for (int k = 0; k < yaws; ++k) {
    const double yaw = -std::numbers::pi + step * k;
    if (std::abs(WrapAngle(yaw - yaw_window.x())) > yaw_window.y() + 0.5 * step) continue;
    ++out.yaws;
    const Eigen::Vector2d turned_centre = Eigen::Rotation2Dd(yaw) * centre_b;
    const Eigen::Vector2d origin_b = turned_centre - Eigen::Vector2d::Constant(radius_b);
    const Raster rb = Rasterize(cloud_b, grey_b, yaw, origin_b, side_b, side_b, o.cell, half_width);
    cv::Mat b_dev_sq;
    cv::multiply(rb.deviation, rb.deviation, b_dev_sq);
    const cv::Mat fb = PaddedSpectrum(rb.deviation, rows, cols);
    const cv::Mat fb_sq = PaddedSpectrum(b_dev_sq, rows, cols);
    const cv::Mat fb_mask = PaddedSpectrum(rb.mask, rows, cols);
    const cv::Mat overlap = Correlate(fa_mask, fb_mask);
    const cv::Mat ab = Correlate(fa, fb);
    const cv::Mat aa = Correlate(fa_sq, fb_mask);
    const cv::Mat bb = Correlate(fa_mask, fb_sq);
    score.setTo(-2.0f);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (overlap.at<float>(r, c) < static_cast<float>(o.min_overlap_cells) - 0.5f) continue;
        const double d = static_cast<double>(aa.at<float>(r, c)) * bb.at<float>(r, c);
        if (!(d > 1e-12)) continue;
        score.at<float>(r, c) = static_cast<float>(ab.at<float>(r, c) / std::sqrt(d));
      }
    }
    // The best few peaks of this yaw, each suppressing its neighbourhood.
    for (int64_t taken = 0; taken < o.max_candidates; ++taken) {
      double best = 0.0;
      cv::Point at;
      cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
      if (best < o.min_correlation) break;
      SearchPeak p;
      p.yaw_index = k;
      p.yaw = yaw;
      p.correlation = best;
      p.overlap = static_cast<int64_t>(std::lround(overlap.at<float>(at)));
      // Sub-cell position by a parabola through the neighbours (circular indices).
      const auto value = [&](int r, int c) {
        return static_cast<double>(score.at<float>((r + rows) % rows, (c + cols) % cols));
      };
      const auto vertex = [](double left, double mid, double right) {
        const double den = left - 2.0 * mid + right;
        return left > -1.5 && right > -1.5 && den < 0.0 ? std::clamp(0.5 * (left - right) / den, -0.5, 0.5) : 0.0;
      };
      const double dc = vertex(value(at.y, at.x - 1), best, value(at.y, at.x + 1));
      const double dr = vertex(value(at.y - 1, at.x), best, value(at.y + 1, at.x));
      const int sr = at.y <= rows_a - 1 ? at.y : at.y - rows;
      const int sc = at.x <= cols_a - 1 ? at.x : at.x - cols;
      p.shift = Eigen::Vector2d(sc + dc, sr + dr);
      p.t_xy = origin_a + o.cell * p.shift - origin_b;
      peaks.push_back(p);
      for (int r = at.y - suppress; r <= at.y + suppress; ++r)
        for (int c = at.x - suppress; c <= at.x + suppress; ++c) score.at<float>((r + rows) % rows, (c + cols) % cols) = -2.0f;
    }
  }

  std::stable_sort(peaks.begin(), peaks.end(), [](const SearchPeak& x, const SearchPeak& y) { return x.correlation > y.correlation; });
  std::vector<SearchPeak> kept;
  for (const SearchPeak& p : peaks) {
    if (static_cast<int64_t>(kept.size()) >= o.max_candidates) break;
    bool same = false;
    for (const SearchPeak& q : kept) {
      same = same || ((p.t_xy - q.t_xy).norm() < o.separation_translation &&
                      std::abs(WrapAngle(p.yaw - q.yaw)) < o.separation_yaw);
    }
    if (!same) kept.push_back(p);
  }

  // z: the median height difference over the cells both rasters hold.
  std::vector<float> dz;
  for (const SearchPeak& p : kept) {
    const Eigen::Vector2d turned_centre = Eigen::Rotation2Dd(p.yaw) * centre_b;
    const Eigen::Vector2d origin_b = turned_centre - Eigen::Vector2d::Constant(radius_b);
    const Raster rb = Rasterize(cloud_b, grey_b, p.yaw, origin_b, side_b, side_b, o.cell, half_width);
    const int sr = static_cast<int>(std::lround(p.shift.y())), sc = static_cast<int>(std::lround(p.shift.x()));
    dz.clear();
    for (int r = 0; r < side_b; ++r) {
      for (int c = 0; c < side_b; ++c) {
        const int ar = r + sr, ac = c + sc;
        if (rb.mask.at<float>(r, c) == 0.0f || ar < 0 || ac < 0 || ar >= rows_a || ac >= cols_a ||
            ra.mask.at<float>(ar, ac) == 0.0f)
          continue;
        dz.push_back(ra.height.at<float>(ar, ac) - rb.height.at<float>(r, c));
      }
    }
    if (dz.empty()) continue;
    std::nth_element(dz.begin(), dz.begin() + static_cast<ptrdiff_t>(dz.size() / 2), dz.end());
    GreyLevelCandidate candidate;
    candidate.T_a_b = FourDofTransform(p.t_xy.x(), p.t_xy.y(), dz[dz.size() / 2], p.yaw);
    candidate.correlation = p.correlation;
    candidate.overlap_cells = p.overlap;
    out.candidates.push_back(candidate);
  }
  out.ms = MillisecondsSince(start);
  return out;
}

}  // namespace cairn
