#include "mapping/line_segment_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace cairn {
namespace {

// A gray image drawn with 8 x 8 samples per pixel (edges anti-aliased as a lens and sensor would),
// plus Gaussian read noise.
struct LineTestImage {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
};

// `inside(x, y)` tells whether a point (pixel centres at integers) is bright.
template <class Inside>
LineTestImage DrawLineTestImage(int width, int height, double dark, double bright, double noise_dn,
                                unsigned seed, const Inside& inside) {
  LineTestImage img;
  img.width = width;
  img.height = height;
  img.pixels.resize(static_cast<size_t>(width) * static_cast<size_t>(height));
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_dn);
  constexpr int kSub = 8;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      int in = 0;
      for (int sy = 0; sy < kSub; ++sy) {
        for (int sx = 0; sx < kSub; ++sx) {
          in += inside(x - 0.5 + (sx + 0.5) / kSub, y - 0.5 + (sy + 0.5) / kSub) ? 1 : 0;
        }
      }
      const double v = dark + (bright - dark) * in / (kSub * kSub) + noise(rng);
      img.pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] =
          static_cast<uint8_t>(std::clamp(std::lround(v), 0l, 255l));
    }
  }
  return img;
}

// A bright rectangle with the given centre, half sides and rotation; its four corners, in order.
struct LineTestRectangle {
  Eigen::Vector2d centre;
  double half_a, half_b, angle;
  Eigen::Vector2d Corner(int k) const {
    const double sa = (k == 0 || k == 3) ? -half_a : half_a, sb = k < 2 ? -half_b : half_b;
    const Eigen::Rotation2Dd R(angle);
    return centre + R * Eigen::Vector2d(sa, sb);
  }
  bool Inside(double x, double y) const {
    const Eigen::Vector2d l = Eigen::Rotation2Dd(-angle) * (Eigen::Vector2d(x, y) - centre);
    return std::abs(l.x()) <= half_a && std::abs(l.y()) <= half_b;
  }
};

// Distance of point p from the infinite line through a and b.
double LineTestDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = (b - a).normalized();
  const Eigen::Vector2d r = p - a;
  return std::abs(r.x() * d.y() - r.y() * d.x());
}

TEST(LineSegmentDetectorTest, FindsTheSidesOfRotatedRectangles) {
  LineSegmentOptions options;
  options.min_length_px = 40.0;
  LineSegmentDetector detector(options);
  std::vector<ImageLineSegment> segments;
  double worst_end = 0.0, worst_angle = 0.0, worst_offset = 0.0;
  int sides = 0;
  for (const double angle_deg : {0.0, 7.0, 30.0, 45.0, 62.0, 93.5}) {
    const LineTestRectangle rect{{160.0, 120.0}, 90.0, 60.0, angle_deg * M_PI / 180.0};
    const LineTestImage img = DrawLineTestImage(320, 240, 70.0, 150.0, 2.0, 5,
                                                [&](double x, double y) { return rect.Inside(x, y); });
    LineSegmentDetector::Stats stats;
    ASSERT_TRUE(detector.Detect(img.pixels.data(), img.width, img.height, img.width, &segments, &stats));
    SCOPED_TRACE(angle_deg);
    ASSERT_EQ(segments.size(), 4u) << stats.ridge_pixels << " ridge pixels, " << stats.regions << " regions";
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = rect.Corner(k), b = rect.Corner((k + 1) % 4);
      // The detected segment nearest this side.
      const ImageLineSegment* best = nullptr;
      double best_d = INFINITY;
      for (const ImageLineSegment& s : segments) {
        const double d =
            LineTestDistance(0.5 * (s.p0 + s.p1), a, b) + (0.5 * (s.p0 + s.p1) - 0.5 * (a + b)).norm();
        if (d < best_d) best_d = d, best = &s;
      }
      ASSERT_NE(best, nullptr);
      const ImageLineSegment& s = *best;
      // Ends: each detected end near one true corner.
      const double e0 = std::min((s.p0 - a).norm(), (s.p0 - b).norm());
      const double e1 = std::min((s.p1 - a).norm(), (s.p1 - b).norm());
      worst_end = std::max({worst_end, e0, e1});
      const double angle = std::acos(std::min(1.0, std::abs(s.direction().dot((b - a).normalized()))));
      worst_angle = std::max(worst_angle, angle * 180.0 / M_PI);
      // The side's midpoint from the fitted line, against the fit's own standard error.
      const double offset = LineTestDistance(0.5 * (a + b), s.p0, s.p1);
      worst_offset = std::max(worst_offset, offset);
      // The bright inside is on +normal.
      EXPECT_TRUE(rect.Inside(0.5 * (s.p0 + s.p1).x() + 3.0 * s.normal.x(),
                              0.5 * (s.p0 + s.p1).y() + 3.0 * s.normal.y()));
      ++sides;
    }
  }
  std::printf("%d sides: worst end %.2f px, angle %.3f deg, midpoint offset %.3f px\n", sides, worst_end,
              worst_angle, worst_offset);
  EXPECT_EQ(sides, 24);
  // Subpixel ends (the half-response point at a corner): well within a pixel.
  EXPECT_LT(worst_end, 0.5);
  // Two ends within 0.5 px on a 120 px side bound the angle by atan(1 / 120) = 0.48 deg; the
  // least-squares line over all its ridge pixels does much better.
  EXPECT_LT(worst_angle, 0.1);
  // The ridge's parabolic interpolation is biased by a few hundredths of a pixel at most.
  EXPECT_LT(worst_offset, 0.1);
}

// The binomial smoothing and the Sobel kernel give a sharp edge of contrast C a peak gradient of
// about C / 3 per px: 20 DN clears the default 5 DN/px, 10 DN does not. Edges that clear it stay
// whole in 2 DN of noise.
TEST(LineSegmentDetectorTest, FindsEdgesAboveTheGradientThresholdWhole) {
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  for (const double angle_deg : {7.0, 30.0, 45.0}) {
    const LineTestRectangle rect{{160.0, 120.0}, 90.0, 60.0, angle_deg * M_PI / 180.0};
    SCOPED_TRACE(angle_deg);
    const LineTestImage strong = DrawLineTestImage(320, 240, 100.0, 120.0, 2.0, 7,
                                                   [&](double x, double y) { return rect.Inside(x, y); });
    ASSERT_TRUE(detector.Detect(strong.pixels.data(), strong.width, strong.height, strong.width, &segments));
    ASSERT_EQ(segments.size(), 4u);
    EXPECT_GT(segments[3].length, 0.95 * 120.0);
    EXPECT_GT(segments[1].length, 0.95 * 180.0);
    const LineTestImage faint = DrawLineTestImage(320, 240, 100.0, 110.0, 2.0, 7,
                                                  [&](double x, double y) { return rect.Inside(x, y); });
    ASSERT_TRUE(detector.Detect(faint.pixels.data(), faint.width, faint.height, faint.width, &segments));
    EXPECT_TRUE(segments.empty());
  }
}

// Bright bars of lengths 40, 80, 120 and 160 px (30 px high): each long enough gives its two long
// sides, longest first; max_segments keeps the longest.
TEST(LineSegmentDetectorTest, KeepsTheLongestAndDropsShortOnes) {
  const double lengths[] = {40.0, 80.0, 120.0, 160.0};
  const LineTestImage img = DrawLineTestImage(240, 240, 60.0, 160.0, 2.0, 3, [&](double x, double y) {
    for (int i = 0; i < 4; ++i) {
      if (x >= 40.0 && x <= 40.0 + lengths[i] && y >= 20.0 + 55.0 * i && y <= 50.0 + 55.0 * i) return true;
    }
    return false;
  });
  LineSegmentOptions options;  // 60 px minimum: the 40 px bar and every 30 px side are dropped
  LineSegmentDetector detector(options);
  std::vector<ImageLineSegment> segments;
  ASSERT_TRUE(detector.Detect(img.pixels.data(), img.width, img.height, img.width, &segments));
  ASSERT_EQ(segments.size(), 6u);
  for (size_t i = 0; i < segments.size(); ++i) {
    EXPECT_NEAR(segments[i].length, lengths[3 - i / 2], 1.0) << i;
  }
  options.max_segments = 3;
  LineSegmentDetector few(options);
  LineSegmentDetector::Stats stats;
  ASSERT_TRUE(few.Detect(img.pixels.data(), img.width, img.height, img.width, &segments, &stats));
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_EQ(stats.segments, 6);
  EXPECT_NEAR(segments[2].length, 120.0, 1.0);
}

// Noise alone, and a circle. An arc of length L on radius R strays s = L^2 / (8 R) from its chord
// and 2 s / 3 from its least-squares line, so with 1 px allowed a piece spans at most
// sqrt(8 R * 1.5) = 35 px of a 100 px circle, or 43 px before a fifth of its pixels (its ends) were
// dropped as strays: below the 60 px minimum.
TEST(LineSegmentDetectorTest, NoiseAndCurvesGiveNoSegments) {
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  const LineTestImage noise =
      DrawLineTestImage(320, 240, 100.0, 100.0, 5.0, 9, [](double, double) { return false; });
  ASSERT_TRUE(detector.Detect(noise.pixels.data(), noise.width, noise.height, noise.width, &segments));
  EXPECT_TRUE(segments.empty()) << segments.size();
  const LineTestImage circle = DrawLineTestImage(320, 240, 60.0, 160.0, 2.0, 9, [](double x, double y) {
    return std::hypot(x - 160.0, y - 120.0) <= 100.0;
  });
  LineSegmentOptions short_ones;
  short_ones.min_length_px = 20.0;
  LineSegmentDetector short_detector(short_ones);
  ASSERT_TRUE(
      short_detector.Detect(circle.pixels.data(), circle.width, circle.height, circle.width, &segments));
  ASSERT_FALSE(segments.empty());
  EXPECT_LT(segments[0].length, std::sqrt(8.0 * 100.0 * 1.5) / 0.8);
  ASSERT_TRUE(detector.Detect(circle.pixels.data(), circle.width, circle.height, circle.width, &segments));
  EXPECT_TRUE(segments.empty()) << segments.size();
}

// An occluding contour in front of bands darker and brighter than the object: its polarity flips
// every 40 px and vanishes where the brightness matches; its pieces still join into one segment.
TEST(LineSegmentDetectorTest, JoinsAContourWhosePolarityFlips) {
  const double angle = 12.0 * M_PI / 180.0;
  const Eigen::Vector2d origin(60.0, 40.0), dir(std::sin(angle), std::cos(angle));
  const LineTestImage img =
      DrawLineTestImage(240, 240, 0.0, 255.0, 2.0, 5, [](double, double) { return false; });
  // Redraw by hand: the object (128) left of the line, bands of 96 and 160 right of it.
  LineTestImage scene = img;
  std::mt19937 rng(21);
  std::normal_distribution<double> noise(0.0, 2.0);
  constexpr int kSub = 8;
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      double sum = 0.0;
      for (int sy = 0; sy < kSub; ++sy) {
        for (int sx = 0; sx < kSub; ++sx) {
          const Eigen::Vector2d p(x - 0.5 + (sx + 0.5) / kSub, y - 0.5 + (sy + 0.5) / kSub);
          const Eigen::Vector2d r = p - origin;
          const double across = r.x() * dir.y() - r.y() * dir.x(), along = r.dot(dir);
          sum += across < 0.0 ? 128.0 : (static_cast<int>(std::floor(along / 40.0)) % 2 == 0 ? 96.0 : 160.0);
        }
      }
      scene.pixels[static_cast<size_t>(y) * static_cast<size_t>(scene.width) + static_cast<size_t>(x)] =
          static_cast<uint8_t>(std::clamp(std::lround(sum / (kSub * kSub) + noise(rng)), 0l, 255l));
    }
  }
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  ASSERT_TRUE(detector.Detect(scene.pixels.data(), scene.width, scene.height, scene.width, &segments));
  // The contour runs from the top border to the bottom one: about 200 px inside the image.
  const ImageLineSegment* contour = nullptr;
  for (const ImageLineSegment& s : segments) {
    if (std::abs(s.direction().dot(dir)) > std::cos(1.0 * M_PI / 180.0)) {
      contour = &s;
      break;
    }
  }
  ASSERT_NE(contour, nullptr);
  std::printf("contour: %.1f px long, %zu segments in all\n", contour->length, segments.size());
  EXPECT_GT(contour->length, 180.0);
  EXPECT_LT(LineTestDistance(contour->p0, origin, origin + dir), 0.5);
  EXPECT_LT(LineTestDistance(contour->p1, origin, origin + dir), 0.5);
}

}  // namespace
}  // namespace cairn
