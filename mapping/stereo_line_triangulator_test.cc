#include "mapping/stereo_line_triangulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "sim/surface_distance.h"
#include "sim/testing/structure_stereo_scene.h"
#include "sim/world_file.h"
#include "stereo/sgm_matcher.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

// A rectangular panel (bright) in front of a slanted background plane (darker, gently shaded),
// seen by the rover camera at half size: the intensity image (8 x 8 samples per pixel, sensor
// noise) and the disparity an SGM would give, with its artefacts: pixels of the background hidden
// from the right camera invalid, the panel's disparity spread 2 px over the background around it
// (a census window straddling the edge), Gaussian noise and the 1/16 px quantization.
struct LinePanelScene {
  StereoCamera cam = testing::RoverCamera(0.5);
  Eigen::Vector3d centre{0.1, -0.05, 2.5};
  Eigen::Vector3d axis_a, axis_b;  // half sides
  Eigen::Vector3d background_normal;
  double background_offset = 6.0;  // n . X = offset
  double panel_gray = 170.0, background_gray = 85.0;
  // A dark band painted across the panel (a marking: same depth on both sides of its edges).
  bool painted_band = false;

  LinePanelScene(double yaw_deg, double pitch_deg, double half_a, double half_b) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(pitch_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    axis_a = R * Eigen::Vector3d(half_a, 0.0, 0.0);
    axis_b = R * Eigen::Vector3d(0.0, half_b, 0.0);
    background_normal = Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
  }
  Eigen::Vector3d Corner(int k) const {
    const double sa = (k == 0 || k == 3) ? -1.0 : 1.0, sb = k < 2 ? -1.0 : 1.0;
    return centre + sa * axis_a + sb * axis_b;
  }
  // Distance along `dir` from `origin` to the panel (inf when missed); panel coordinates out.
  double PanelHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double* pa = nullptr,
                  double* pb = nullptr) const {
    const Eigen::Vector3d n = axis_a.cross(axis_b);
    const double t = n.dot(centre - origin) / n.dot(dir);
    if (!(t > 0.0)) return INFINITY;
    const Eigen::Vector3d l = origin + t * dir - centre;
    const double a = l.dot(axis_a) / axis_a.squaredNorm(), b = l.dot(axis_b) / axis_b.squaredNorm();
    if (std::abs(a) > 1.0 || std::abs(b) > 1.0) return INFINITY;
    if (pa != nullptr) *pa = a;
    if (pb != nullptr) *pb = b;
    return t;
  }
  double BackgroundHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const {
    return (background_offset - background_normal.dot(origin)) / background_normal.dot(dir);
  }
  Eigen::Vector3d Ray(double u, double v) const {
    const PinholeRadTan& k = cam.intrinsics;
    return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
  }
  double Gray(double u, double v) const {
    const Eigen::Vector3d dir = Ray(u, v);
    double a = 0.0, b = 0.0;
    if (std::isfinite(PanelHit(Eigen::Vector3d::Zero(), dir, &a, &b))) {
      return painted_band && std::abs(b) < 0.25 ? 0.5 * panel_gray : panel_gray;
    }
    const Eigen::Vector3d p = BackgroundHit(Eigen::Vector3d::Zero(), dir) * dir;
    return background_gray + 8.0 * std::sin(1.3 * p.x()) * std::cos(0.9 * p.y());
  }

  // The noise-free image.
  std::vector<double> Radiance() const {
    const PinholeRadTan& k = cam.intrinsics;
    std::vector<double> img(static_cast<size_t>(k.width) * static_cast<size_t>(k.height));
    constexpr int kSub = 8;
    for (int y = 0; y < k.height; ++y) {
      for (int x = 0; x < k.width; ++x) {
        double sum = 0.0;
        for (int sy = 0; sy < kSub; ++sy) {
          for (int sx = 0; sx < kSub; ++sx)
            sum += Gray(x - 0.5 + (sx + 0.5) / kSub, y - 0.5 + (sy + 0.5) / kSub);
        }
        img[static_cast<size_t>(y) * static_cast<size_t>(k.width) + static_cast<size_t>(x)] =
            sum / (kSub * kSub);
      }
    }
    return img;
  }
  static std::vector<uint8_t> Expose(const std::vector<double>& radiance, double noise_dn,
                                     std::mt19937* rng) {
    std::vector<uint8_t> img(radiance.size());
    std::normal_distribution<double> noise(0.0, noise_dn);
    for (size_t i = 0; i < img.size(); ++i) {
      img[i] = static_cast<uint8_t>(std::clamp(std::lround(radiance[i] + noise(*rng)), 0l, 255l));
    }
    return img;
  }

  // Noise-free disparity of every pixel (NaN: hidden from the right camera), and whether the
  // panel is what the pixel sees.
  void TrueDisparity(std::vector<double>* disparity, std::vector<uint8_t>* on_panel) const {
    const PinholeRadTan& k = cam.intrinsics;
    disparity->assign(static_cast<size_t>(k.width) * static_cast<size_t>(k.height), NAN);
    on_panel->assign(disparity->size(), 0);
    const Eigen::Vector3d right(cam.baseline, 0.0, 0.0);
    for (int y = 0; y < k.height; ++y) {
      for (int x = 0; x < k.width; ++x) {
        const size_t i = static_cast<size_t>(y) * static_cast<size_t>(k.width) + static_cast<size_t>(x);
        const Eigen::Vector3d dir = Ray(x, y);
        const double tp = PanelHit(Eigen::Vector3d::Zero(), dir);
        const double t = std::min(tp, BackgroundHit(Eigen::Vector3d::Zero(), dir));
        const Eigen::Vector3d p = t * dir;
        (*on_panel)[i] = std::isfinite(tp) ? 1 : 0;
        if (!(*on_panel)[i]) {
          const Eigen::Vector3d to = p - right;
          if (PanelHit(right, to.normalized()) < to.norm()) continue;  // occluded in the right image
        }
        (*disparity)[i] = k.fx * cam.baseline / p.z();
      }
    }
  }

  StereoMatcherOutput Disparity(const std::vector<double>& truth, const std::vector<uint8_t>& on_panel,
                                double sigma_px, std::mt19937* rng) const {
    const PinholeRadTan& k = cam.intrinsics;
    StereoMatcherOutput out;
    out.width = k.width;
    out.height = k.height;
    out.disparity.assign(truth.size(), kInvalidDisparity);
    std::normal_distribution<double> noise(0.0, sigma_px);
    constexpr int kFatten = 2;
    for (int y = 0; y < k.height; ++y) {
      for (int x = 0; x < k.width; ++x) {
        const size_t i = static_cast<size_t>(y) * static_cast<size_t>(k.width) + static_cast<size_t>(x);
        double d = truth[i];
        if (!on_panel[i]) {
          for (int dy = -kFatten; dy <= kFatten; ++dy) {
            for (int dx = -kFatten; dx <= kFatten; ++dx) {
              const int xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= k.width || yy >= k.height) continue;
              const size_t j =
                  static_cast<size_t>(yy) * static_cast<size_t>(k.width) + static_cast<size_t>(xx);
              if (on_panel[j] && std::isfinite(truth[j]) && !(d >= truth[j])) d = truth[j];
            }
          }
        }
        if (!std::isfinite(d)) continue;
        out.disparity[i] = static_cast<int16_t>(std::lround((d + noise(*rng)) * kDisparityScale));
      }
    }
    return out;
  }
};

// The triangulated segment whose image ends lie nearest the projection of panel side k.
const StereoLineSegment* LineForSide(const std::vector<StereoLineSegment>& lines, const LinePanelScene& scene,
                                     int k, bool* reversed) {
  const Eigen::Vector2d a = scene.cam.intrinsics.Project(scene.Corner(k));
  const Eigen::Vector2d b = scene.cam.intrinsics.Project(scene.Corner((k + 1) % 4));
  const StereoLineSegment* best = nullptr;
  double best_d = 10.0;  // px
  for (const StereoLineSegment& l : lines) {
    const double forward = (l.image_p0 - a).norm() + (l.image_p1 - b).norm();
    const double backward = (l.image_p0 - b).norm() + (l.image_p1 - a).norm();
    if (std::min(forward, backward) < best_d) {
      best_d = std::min(forward, backward);
      best = &l;
      *reversed = backward < forward;
    }
  }
  return best;
}

double LineNees(const Eigen::Vector3d& error, const Eigen::Matrix3d& cov) {
  return error.dot(cov.ldlt().solve(error));
}

TEST(StereoLineTriangulatorTest, PanelEdgesTakeThePanelsDepthNotTheBackgrounds) {
  const LinePanelScene scene(30.0, 10.0, 0.5, 0.3);
  std::mt19937 rng(11);
  std::vector<double> truth;
  std::vector<uint8_t> on_panel;
  scene.TrueDisparity(&truth, &on_panel);
  const std::vector<uint8_t> img = LinePanelScene::Expose(scene.Radiance(), 2.0, &rng);
  const StereoMatcherOutput disparity = scene.Disparity(truth, on_panel, 0.3, &rng);
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  const PinholeRadTan& k = scene.cam.intrinsics;
  ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
  // The error model of this disparity: independent samples of 0.3 px.
  StereoLineOptions options;
  options.pixel_error_px = 0.3 / std::sqrt(2.0);
  options.disparity_correlation_px = 0.0;
  StereoLineTriangulator triangulator(options, scene.cam);
  std::vector<StereoLineSegment> lines;
  StereoLineTriangulator::Stats stats;
  ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines, &stats));
  std::printf("%zu segments: %d triangulated, %d without depth, %d ambiguous, %d too far\n", segments.size(),
              stats.triangulated, stats.no_depth, stats.ambiguous, stats.too_far);
  for (int side = 0; side < 4; ++side) {
    bool reversed = false;
    const StereoLineSegment* l = LineForSide(lines, scene, side, &reversed);
    ASSERT_NE(l, nullptr) << "side " << side;
    // The panel is the bright side of all four edges, and the nearer one.
    EXPECT_EQ(l->side, LineDepthSide::kBright) << "side " << side;
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector3d truth_end = scene.Corner((side + ((e == 1) != reversed ? 1 : 0)) % 4);
      const Eigen::Vector3d est = e == 0 ? l->p0 : l->p1;
      const double nees = LineNees(est - truth_end, e == 0 ? l->cov0 : l->cov1);
      std::printf("side %d end %d: error %.1f mm (NEES %.2f), depth sigma %.1f mm, %d samples\n", side, e,
                  1e3 * (est - truth_end).norm(), nees, 1e3 * std::sqrt((e == 0 ? l->cov0 : l->cov1)(2, 2)),
                  l->support);
      // Chi-square with 3 degrees of freedom, 99.9 %.
      EXPECT_LT(nees, 16.27) << "side " << side << " end " << e;
    }
  }
}

// The ends' errors against their covariances over Monte Carlo runs of the image and disparity
// noise: the mean NEES of a consistent 3-D estimate is 3.
TEST(StereoLineTriangulatorTest, EndCovariancesMatchTheirErrorsOverMonteCarloRuns) {
  const LinePanelScene scene(30.0, 10.0, 0.5, 0.3);
  std::vector<double> truth;
  std::vector<uint8_t> on_panel;
  scene.TrueDisparity(&truth, &on_panel);
  const std::vector<double> radiance = scene.Radiance();
  constexpr double kDisparitySigma = 0.3;
  StereoLineOptions options;
  options.pixel_error_px = kDisparitySigma / std::sqrt(2.0);
  options.disparity_correlation_px = 0.0;
  // Where the detector puts this scene's corners along the edges (about 0.17 px RMS); the default
  // of 1 px is for ends where contrast fades or the disparity support stops.
  options.endpoint_sigma_px = 0.2;
  StereoLineTriangulator triangulator(options, scene.cam);
  LineSegmentDetector detector(LineSegmentOptions{});
  const PinholeRadTan& k = scene.cam.intrinsics;
  std::mt19937 rng(5);
  std::vector<ImageLineSegment> segments;
  std::vector<StereoLineSegment> lines;
  constexpr int kRuns = 100;
  double nees_sum = 0.0, along_sum = 0.0;
  int ends = 0, missing = 0;
  double eigen_sum[3] = {0.0, 0.0, 0.0};
  for (int run = 0; run < kRuns; ++run) {
    const std::vector<uint8_t> img = LinePanelScene::Expose(radiance, 2.0, &rng);
    const StereoMatcherOutput disparity = scene.Disparity(truth, on_panel, kDisparitySigma, &rng);
    ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
    ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines));
    for (int side = 0; side < 4; ++side) {
      bool reversed = false;
      const StereoLineSegment* l = LineForSide(lines, scene, side, &reversed);
      if (l == nullptr) {
        ++missing;
        continue;
      }
      const Eigen::Vector3d dir = (l->p1 - l->p0).normalized();
      for (int e = 0; e < 2; ++e) {
        const Eigen::Vector3d err =
            (e == 0 ? l->p0 : l->p1) - scene.Corner((side + ((e == 1) != reversed ? 1 : 0)) % 4);
        const Eigen::Matrix3d& cov = e == 0 ? l->cov0 : l->cov1;
        nees_sum += LineNees(err, cov);
        // Along the line and across it (the part a line landmark uses).
        const double along = err.dot(dir), along_var = dir.dot(cov * dir);
        along_sum += along * along / along_var;
        // Per direction of the covariance's eigenvectors: the largest is the depth, the others the
        // image position along and across the edge.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
        for (int q = 0; q < 3; ++q)
          eigen_sum[q] += std::pow(es.eigenvectors().col(q).dot(err), 2) / es.eigenvalues()[q];
        ++ends;
      }
    }
  }
  const double mean = nees_sum / ends;

  const double depth = eigen_sum[2] / ends;
  std::printf(
      "%d ends over %d runs (%d sides missed): mean NEES %.2f; per direction: depth %.2f, the others %.2f "
      "and %.2f; along the line %.2f\n",
      ends, kRuns, missing, mean, depth, eigen_sum[1] / ends, eigen_sum[0] / ends, along_sum / ends);
  EXPECT_LE(missing, kRuns * 4 / 100);
  // The mean of n independent chi-square(1) values has sigma sqrt(2 / n), 0.05 for 800 ends; the
  // two ends of a segment share one fit and a side's runs one scene, so the band is wider. The
  // depth is the disparity fit's: its error must match (neither over- nor underconfident).
  EXPECT_GT(depth, 0.75);
  EXPECT_LT(depth, 1.25);
  // Across the edge the image line fit is more precise than its (floored) residuals say: the
  // 3-D mean stays near but below 3; above 3 + 3 sigma would be overconfidence.
  EXPECT_GT(mean, 2.0);
  EXPECT_LT(mean, 3.5);
}

// A dark band painted across the panel: its edges have the panel on both sides.
TEST(StereoLineTriangulatorTest, PaintedEdgesUseBothSidesAndLieOnTheirSurface) {
  LinePanelScene scene(30.0, 10.0, 0.5, 0.3);
  scene.painted_band = true;
  std::mt19937 rng(13);
  std::vector<double> truth;
  std::vector<uint8_t> on_panel;
  scene.TrueDisparity(&truth, &on_panel);
  const std::vector<uint8_t> img = LinePanelScene::Expose(scene.Radiance(), 2.0, &rng);
  const StereoMatcherOutput disparity = scene.Disparity(truth, on_panel, 0.3, &rng);
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  const PinholeRadTan& k = scene.cam.intrinsics;
  ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
  StereoLineOptions options;
  options.pixel_error_px = 0.3 / std::sqrt(2.0);
  options.disparity_correlation_px = 0.0;
  StereoLineTriangulator triangulator(options, scene.cam);
  std::vector<StereoLineSegment> lines;
  ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines));
  const Eigen::Vector3d normal = scene.axis_a.cross(scene.axis_b).normalized();
  int both = 0;
  for (const StereoLineSegment& l : lines) {
    // The panel's own sides are occluding edges, bright (panel) side nearer.
    if (l.side != LineDepthSide::kBoth) {
      EXPECT_EQ(l.side, LineDepthSide::kBright);
      continue;
    }
    ++both;
    for (int e = 0; e < 2; ++e) {
      const double off = normal.dot((e == 0 ? l.p0 : l.p1) - scene.centre);
      const double var = normal.dot((e == 0 ? l.cov0 : l.cov1) * normal);
      std::printf("painted edge end %d: %.1f mm off the panel, sigma %.1f mm\n", e, 1e3 * off,
                  1e3 * std::sqrt(var));
      EXPECT_LT(off * off / var, 10.83);  // chi-square(1), 99.9 %
    }
  }
  // The band's two edges (the band breaks the panel's left and right sides into short pieces).
  EXPECT_EQ(both, 2);
}

// The panel without texture (no disparity on it): its outline has depth on the background side
// only, which cannot tell the panel from a hole in it. No edge may take the background's depth.
TEST(StereoLineTriangulatorTest, AnEdgeOfASurfaceWithoutDisparityIsNotGivenTheBackgrounds) {
  const LinePanelScene scene(30.0, 10.0, 0.5, 0.3);
  std::mt19937 rng(23);
  std::vector<double> truth;
  std::vector<uint8_t> on_panel;
  scene.TrueDisparity(&truth, &on_panel);
  const std::vector<uint8_t> img = LinePanelScene::Expose(scene.Radiance(), 2.0, &rng);
  StereoMatcherOutput disparity = scene.Disparity(truth, on_panel, 0.3, &rng);
  for (size_t i = 0; i < on_panel.size(); ++i) {
    if (on_panel[i]) disparity.disparity[i] = kInvalidDisparity;
  }
  const PinholeRadTan& k = scene.cam.intrinsics;
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
  ASSERT_EQ(segments.size(), 4u);
  StereoLineTriangulator triangulator(StereoLineOptions{}, scene.cam);
  std::vector<StereoLineSegment> lines;
  StereoLineTriangulator::Stats stats;
  ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines, &stats));
  EXPECT_TRUE(lines.empty());
  // The left side's background is hidden from the right camera too: no depth on either side.
  EXPECT_EQ(stats.ambiguous + stats.no_depth, 4);
  EXPECT_GE(stats.ambiguous, 3);
}

// Disparities that jump between two surfaces everywhere: no side is consistent.
TEST(StereoLineTriangulatorTest, MixedDepthsOnBothSidesAreRejected) {
  const LinePanelScene scene(30.0, 10.0, 0.5, 0.3);
  std::mt19937 rng(17);
  const PinholeRadTan& k = scene.cam.intrinsics;
  const std::vector<uint8_t> img = LinePanelScene::Expose(scene.Radiance(), 2.0, &rng);
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
  ASSERT_EQ(segments.size(), 4u);
  StereoMatcherOutput disparity;
  disparity.width = k.width;
  disparity.height = k.height;
  disparity.disparity.resize(static_cast<size_t>(k.width) * static_cast<size_t>(k.height));
  std::bernoulli_distribution near(0.5);
  for (int16_t& d : disparity.disparity)
    d = static_cast<int16_t>(near(rng) ? 20 * kDisparityScale : 10 * kDisparityScale);
  StereoLineTriangulator triangulator(StereoLineOptions{}, scene.cam);
  std::vector<StereoLineSegment> lines;
  StereoLineTriangulator::Stats stats;
  ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines, &stats));
  EXPECT_TRUE(lines.empty());
  EXPECT_EQ(stats.no_depth, 4);
}

// A panel 25 m away: its ends' depth sigma exceeds the limit.
TEST(StereoLineTriangulatorTest, FarSegmentsAreDropped) {
  LinePanelScene scene(30.0, 10.0, 4.0, 2.5);
  scene.centre = Eigen::Vector3d(0.5, -0.3, 25.0);
  scene.background_offset = 60.0;
  std::mt19937 rng(19);
  std::vector<double> truth;
  std::vector<uint8_t> on_panel;
  scene.TrueDisparity(&truth, &on_panel);
  const std::vector<uint8_t> img = LinePanelScene::Expose(scene.Radiance(), 2.0, &rng);
  const StereoMatcherOutput disparity = scene.Disparity(truth, on_panel, 0.3, &rng);
  const PinholeRadTan& k = scene.cam.intrinsics;
  LineSegmentDetector detector(LineSegmentOptions{});
  std::vector<ImageLineSegment> segments;
  ASSERT_TRUE(detector.Detect(img.data(), k.width, k.height, k.width, &segments));
  ASSERT_EQ(segments.size(), 4u);
  StereoLineTriangulator triangulator(StereoLineOptions{}, scene.cam);
  std::vector<StereoLineSegment> lines;
  StereoLineTriangulator::Stats stats;
  ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines, &stats));
  EXPECT_TRUE(lines.empty());
  EXPECT_EQ(stats.too_far, 4);
  // The limit is what drops them: with a looser one they come back.
  StereoLineOptions loose;
  loose.max_depth_sigma = 100.0;
  StereoLineTriangulator accepting(loose, scene.cam);
  ASSERT_TRUE(accepting.Triangulate(segments, disparity, &lines, &stats));
  EXPECT_EQ(lines.size(), 4u);
}

// Rendered stereo pairs of the structures world along the drive past the lander, matched by SGM:
// the triangulated ends against the world's true surfaces (terrain with the structures' blocks,
// lander). An end counts as on the surface when the nearest one lies within 3 sigma of its
// covariance's largest axis (the depth; the error along the line of sight).
TEST(StereoLineTriangulatorTest, StructuresWorldEndsLieOnTheTrueSurfaces) {
  auto world = sim::LoadWorldFile(testing::SourceDir() + "/configs/worlds/structures.yaml");
  ASSERT_TRUE(world.ok()) << world.status().ToString();
  sim::MissionOptions mission;
  mission.duration = 1.0;
  auto sim = sim::MissionSimulator::Create(*world, mission);
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  const sim::SurfaceDistance surface(**sim, 1.0);
  const StereoCamera cam = testing::RoverCamera(1.0);
  auto matcher = SgmMatcher::Create(SgmOptions{});
  ASSERT_TRUE(matcher.ok()) << matcher.status().ToString();
  LineSegmentDetector detector(LineSegmentOptions{});
  StereoLineTriangulator triangulator(StereoLineOptions{}, cam);
  const PinholeRadTan& k = cam.intrinsics;
  int ends = 0, on_surface = 0, segments_found = 0;
  std::vector<ImageLineSegment> segments;
  std::vector<StereoLineSegment> lines;
  constexpr int kFrames = 6;
  for (int i = 0; i < kFrames; ++i) {
    testing::StructureStereoFrame frame;
    testing::RenderStructureFrame(**sim, cam, testing::StructureDrivePose((*sim)->terrain(), i, kFrames),
                                  static_cast<uint64_t>(i), &frame);
    const StereoMatcherInput in{
        frame.left.data(), frame.right.data(), k.width, k.height, k.width, k.fx, cam.baseline, 0.0};
    StereoMatcherOutput disparity;
    ASSERT_TRUE((*matcher)->Match(in, &disparity).ok());
    ASSERT_TRUE(detector.Detect(frame.left.data(), k.width, k.height, k.width, &segments));
    StereoLineTriangulator::Stats stats;
    ASSERT_TRUE(triangulator.Triangulate(segments, disparity, &lines, &stats));
    segments_found += static_cast<int>(segments.size());
    for (const StereoLineSegment& l : lines) {
      for (int e = 0; e < 2; ++e) {
        const Eigen::Matrix3d& cov = e == 0 ? l.cov0 : l.cov1;
        const double sigma =
            std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues().maxCoeff());
        // 1 cm for the surface search's own resolution.
        const double radius = 3.0 * sigma + 0.01;
        const double distance = surface.Distance(frame.T_world_cam * (e == 0 ? l.p0 : l.p1), radius);
        ++ends;
        on_surface += distance <= radius ? 1 : 0;
      }
    }
    std::printf("frame %d: %zu segments, %d triangulated, %d without depth, %d ambiguous, %d too far\n", i,
                segments.size(), stats.triangulated, stats.no_depth, stats.ambiguous, stats.too_far);
  }
  const double fraction = ends > 0 ? static_cast<double>(on_surface) / ends : 0.0;
  std::printf("%d segments, %d triangulated ends, %d of them within 3 sigma of the true surfaces (%.1f %%)\n",
              segments_found, ends, on_surface, 100.0 * fraction);
  EXPECT_GE(ends, 20);
  EXPECT_GE(fraction, 0.9);
}

}  // namespace
}  // namespace cairn
