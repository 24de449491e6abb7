#include "mapping/obstacle_classifier.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/depth_projector.h"
#include "mapping/testing/mapping_test_scenes.h"

namespace cairn {
namespace {

using testing::ForwardCameraPose;
using testing::RenderDepth;
using testing::RoverCamera;

// Ground z = 0 up to x = edge, then a vertical drop to z = -drop (the face looks away from the
// camera, so it is never seen: a negative edge).
double CliffHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double edge, double drop) {
  if (d.z() >= 0.0) return -1.0;
  const double t0 = -o.z() / d.z();
  if (o.x() + t0 * d.x() < edge) return t0;
  return (-drop - o.z()) / d.z();
}

TEST(ObstacleClassifierTest, MinimalSlopeMatchesEquation51ByHand) {
  // Rise 1.5 over a run of hypot(3, 4) = 5: 0.3.
  EXPECT_DOUBLE_EQ(ObstacleClassifier::MinimalSlope({1, 2, 0.5}, {4, 6, -1.0}), 0.3);
  EXPECT_DOUBLE_EQ(ObstacleClassifier::MinimalSlope({0, 0, 0}, {0, 2, 0.4}), -0.2);
  EXPECT_TRUE(std::isinf(ObstacleClassifier::MinimalSlope({0, 0, 1}, {0, 0, 0})));
}

struct Scene {
  StereoCamera cam = RoverCamera(0.5);
  DepthPointOptions depth_options;
  ObstacleOptions options;
};

int CountObstacleCells(const ObstacleResult& r, double min_x, double max_x) {
  int n = 0;
  for (const ObstacleCell& c : r.cells) n += c.obstacle && c.x >= min_x && c.x < max_x;
  return n;
}

TEST(ObstacleClassifierTest, NegativeEdgeAtSyntheticCliff) {
  Scene s;
  const Eigen::Isometry3d T = ForwardCameraPose({0, 0, 1.3}, 0.0, 0.44);
  const DepthImage img = RenderDepth(s.cam, T, [](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    return CliffHit(o, d, 2.5, 3.0);
  });
  DepthProjector proj(s.depth_options, s.cam);
  ObstacleClassifier cls(s.options, s.cam, proj.error_model(), proj.range());
  CameraPoints pts;
  ObstacleResult r;
  ASSERT_TRUE(proj.Project(img, Eigen::Isometry3d(T), &pts).ok());
  ASSERT_TRUE(cls.Classify(img, &pts, &r).ok());
  // The far ground is 3 m lower and beyond the points' range: only the edge itself can tell. The
  // ray over the edge meets it 8.3 m out, so eq. 5.1 gives 3 / 5.8 = 0.52 > 0.4.
  EXPECT_GT(r.negative_edges, s.cam.intrinsics.width / 2);
  int edge_cells = 0, wrong = 0;
  for (const ObstacleCell& c : r.cells) {
    if (c.negative_edge) {
      ++edge_cells;
      EXPECT_NEAR(c.x, 2.5, 0.06) << "edge cell away from the cliff at y " << c.y;
      EXPECT_GT(c.traversability, 1.0f);
    }
    if (c.obstacle && c.x < 2.4) ++wrong;
  }
  EXPECT_GT(edge_cells, 20);
  EXPECT_EQ(wrong, 0);
  // Points on the edge are flagged, points on the flat ground before it are not.
  for (size_t i = 0; i < pts.size(); ++i) {
    if (pts.p_local[i].x() < 2.35) {
      ASSERT_EQ(pts.obstacle[i], 0) << i;
    }
  }

  // A robot that can drive any slope sees no negative edge although depth jumps.
  ObstacleOptions lenient = s.options;
  lenient.max_slope = 100.0;
  ObstacleClassifier cls2(lenient, s.cam, proj.error_model(), proj.range());
  ASSERT_TRUE(cls2.Classify(img, &pts, &r).ok());
  EXPECT_EQ(r.negative_edges, 0);
}

struct Box {
  double x0, x1, y0, y1, h;
};

// Flat ground z = 0 with boxes [x0,x1] x [y0,y1] x [0,h] standing on it.
double BoxesHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const std::vector<Box>& boxes) {
  double best = d.z() < 0 ? -o.z() / d.z() : -1.0;
  for (const Box& b : boxes) {
    // Slab test.
    double tmin = 0.0, tmax = 1e9;
    const double lo[3] = {b.x0, b.y0, 0.0}, hi[3] = {b.x1, b.y1, b.h};
    bool miss = false;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(d[a]) < 1e-12) {
        if (o[a] < lo[a] || o[a] > hi[a]) miss = true;
        continue;
      }
      double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      tmin = std::max(tmin, t0);
      tmax = std::min(tmax, t1);
    }
    if (!miss && tmin <= tmax && tmin > 0 && (best < 0 || tmin < best)) best = tmin;
  }
  return best;
}

TEST(ObstacleClassifierTest, StepAboveMaxStepIsObstacleAndBelowIsNot) {
  Scene s;
  const Eigen::Isometry3d T = ForwardCameraPose({0, 0, 1.3}, 0.0, 0.44);
  // A box 0.3 m high and another 0.08 m high (below h_max = 0.15 m) on flat ground.
  const std::vector<Box> boxes = {{2.5, 2.9, -0.6, -0.2, 0.3}, {2.5, 2.9, 0.2, 0.6, 0.08}};
  const auto scene = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return BoxesHit(o, d, boxes); };
  const DepthImage img = RenderDepth(s.cam, T, scene, 0.1, 3);
  DepthProjector proj(s.depth_options, s.cam);
  ObstacleClassifier cls(s.options, s.cam, proj.error_model(), proj.range());
  CameraPoints pts;
  ObstacleResult r;
  ASSERT_TRUE(proj.Project(img, T, &pts).ok());
  ASSERT_TRUE(cls.Classify(img, &pts, &r).ok());
  int high = 0, low = 0, elsewhere = 0;
  for (const ObstacleCell& c : r.cells) {
    if (!c.obstacle) continue;
    if (c.x > 2.3 && c.x < 3.1 && c.y > -0.8 && c.y < 0.0) ++high;
    else if (c.x > 2.3 && c.x < 3.1 && c.y > 0.0 && c.y < 0.8) ++low;
    else ++elsewhere;
  }
  EXPECT_GT(high, 20);
  EXPECT_EQ(low, 0);
  EXPECT_EQ(elsewhere, 0);
}

// Boxes a little higher than h_max, 3.5 m out, with stereo noise: their flat tops and the ground
// around them hold many cells within noise of the window's extremes, and delta_d of the two that
// come out extreme varies with where they lie. With step_tie_tolerance the steps are found in
// more cells, never in one whose window holds no step above h_max (all of them lie at the box),
// and a box below h_max stays traversable.
TEST(ObstacleClassifierTest, NearExtremeCellPairsDecideStepsTheExtremePairLeavesOpen) {
  Scene s;
  s.cam = RoverCamera(1.0);
  const Eigen::Isometry3d T = ForwardCameraPose({0, 0, 1.3}, 0.0, 0.3);
  DepthProjector proj(s.depth_options, s.cam);
  ObstacleOptions thesis = s.options;
  thesis.step_tie_tolerance = 0.0;
  ASSERT_GT(s.options.step_tie_tolerance, 0.0);
  ObstacleClassifier tied_cls(s.options, s.cam, proj.error_model(), proj.range());
  ObstacleClassifier thesis_cls(thesis, s.cam, proj.error_model(), proj.range());
  CameraPoints pts;
  ObstacleResult tied, extreme;
  int total_tied = 0, total_extreme = 0;
  unsigned seed = 11;
  for (const double rise : {-0.02, 0.02, 0.04, 0.06, 0.1}) {
    const double h = s.options.max_step + rise;
    const std::vector<Box> boxes = {{3.3, 3.7, -0.5, -0.1, h}, {3.3, 3.7, 0.3, 0.7, h}};
    const DepthImage img = RenderDepth(s.cam, T, [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
      return BoxesHit(o, d, boxes);
    }, 0.1, seed++);
    ASSERT_TRUE(proj.Project(img, T, &pts).ok());
    ASSERT_TRUE(tied_cls.Classify(img, &pts, &tied).ok());
    ASSERT_TRUE(thesis_cls.Classify(img, &pts, &extreme).ok());
    const int n_tied = CountObstacleCells(tied, 0.0, 10.0), n_extreme = CountObstacleCells(extreme, 0.0, 10.0);
    EXPECT_GE(n_tied, n_extreme) << "h " << h;
    if (h < s.options.max_step) {
      EXPECT_EQ(n_tied, 0) << "h " << h;
    }
    // Windows reach 2 cells (0.1 m) beyond a box; cells outside that hold no step.
    EXPECT_EQ(n_tied, CountObstacleCells(tied, 3.15, 3.85)) << "h " << h;
    total_tied += n_tied;
    total_extreme += n_extreme;
  }
  EXPECT_GT(total_tied, total_extreme + total_extreme / 4);
}

// A patch of flat ground and, beside it, one cell seen through a single pixel on top of a box
// 0.3 m high (the rest of the box and of the ground is invalid): with min_cell_points 1 that one
// point makes a step for the patch's cells next to it; with 2 its cell is left out and the patch
// stays clear.
TEST(ObstacleClassifierTest, CellsOfOnePointAreLeftOutOfTheHeightGrid) {
  Scene s;
  const Eigen::Isometry3d T = ForwardCameraPose({0, 0, 1.3}, 0.0, 0.44);
  const std::vector<Box> boxes = {{2.42, 2.48, 0.02, 0.08, 0.3}};
  DepthImage img = RenderDepth(s.cam, T, [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    return BoxesHit(o, d, boxes);
  });
  const PinholeRadTan& k = s.cam.intrinsics;
  bool top_kept = false;
  for (int v = 0; v < img.height; ++v) {
    for (int u = 0; u < img.width; ++u) {
      float& z = img.depth[static_cast<size_t>(v * img.width + u)];
      const Eigen::Vector3d p = T * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      const bool patch = p.z() < 0.01 && p.x() > 2.05 && p.x() < 2.4 && std::abs(p.y()) < 0.2;
      const bool top = p.z() > 0.29 && !top_kept;
      top_kept = top_kept || top;
      if (!patch && !top) z = std::numeric_limits<float>::quiet_NaN();
    }
  }
  ASSERT_TRUE(top_kept);
  DepthProjector proj(s.depth_options, s.cam);
  CameraPoints pts;
  ObstacleResult r;
  ASSERT_TRUE(proj.Project(img, T, &pts).ok());
  ObstacleOptions every_cell = s.options;
  every_cell.min_cell_points = 1;
  ObstacleClassifier every_cls(every_cell, s.cam, proj.error_model(), proj.range());
  ASSERT_TRUE(every_cls.Classify(img, &pts, &r).ok());
  EXPECT_GT(CountObstacleCells(r, 2.0, 2.5), 0);
  const size_t cells_with_lone = r.cells.size();
  ASSERT_EQ(s.options.min_cell_points, 2);
  ObstacleClassifier cls(s.options, s.cam, proj.error_model(), proj.range());
  ASSERT_TRUE(cls.Classify(img, &pts, &r).ok());
  EXPECT_EQ(CountObstacleCells(r, 0.0, 10.0), 0);
  EXPECT_EQ(r.cells.size(), cells_with_lone - 1);
  for (size_t i = 0; i < pts.size(); ++i) ASSERT_EQ(pts.obstacle[i], 0) << i;
}

// Flat ground seen to 9 m with stereo noise (0.25 px per pixel, independent: sub-pixel SGM noise
// without its spatial smoothing): the far cells' height differences are noise. A fixed threshold
// h_max reports many of them; h_max + delta_d (eq. 5.4) suppresses them (not all: delta_d is the
// error of the cells' distance, which underrates height noise for cells side by side), and near
// cells are unaffected.
TEST(ObstacleClassifierTest, ErrorAdaptiveThresholdSuppressesFarFalseObstacles) {
  Scene s;
  s.depth_options.max_depth_error = 1.0;  // keep points out to max_depth
  s.depth_options.max_depth = 9.0;
  const Eigen::Isometry3d T = ForwardCameraPose({0, 0, 1.3}, 0.0, 0.25);
  const DepthImage img = RenderDepth(s.cam, T, [](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    return d.z() < 0 ? -o.z() / d.z() : -1.0;
  }, 0.25, 7);
  DepthProjector proj(s.depth_options, s.cam);
  CameraPoints pts;
  ASSERT_TRUE(proj.Project(img, T, &pts).ok());
  ObstacleOptions fixed = s.options;
  fixed.error_adaptive = false;
  ObstacleClassifier adaptive_cls(s.options, s.cam, proj.error_model(), proj.range());
  ObstacleClassifier fixed_cls(fixed, s.cam, proj.error_model(), proj.range());
  ObstacleResult a, f;
  ASSERT_TRUE(fixed_cls.Classify(img, &pts, &f).ok());
  ASSERT_TRUE(adaptive_cls.Classify(img, &pts, &a).ok());
  const int fixed_far = CountObstacleCells(f, 5.0, 10.0);
  const int adaptive_far = CountObstacleCells(a, 5.0, 10.0);
  EXPECT_GT(fixed_far, 50);
  EXPECT_LE(adaptive_far, fixed_far / 20);
  EXPECT_EQ(CountObstacleCells(a, 0.0, 3.0), 0);
}

TEST(ObstacleClassifierTest, RejectsImageOfWrongSize) {
  Scene s;
  DepthProjector proj(s.depth_options, s.cam);
  ObstacleClassifier cls(s.options, s.cam, proj.error_model(), proj.range());
  DepthImage img;
  img.width = 10;
  img.height = 10;
  img.depth.assign(100, 1.0f);
  CameraPoints pts;
  ObstacleResult r;
  EXPECT_FALSE(proj.Project(img, Eigen::Isometry3d::Identity(), &pts).ok());
  EXPECT_EQ(cls.Classify(img, &pts, &r).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace cairn
