#include "mapping/plane_extractor.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

// The rover's cameras: 1080 px, 0.3 m, half a pixel.
const StereoErrorModel kModel(1080.0, 0.3, 0.5);

// Points on the rectangle centre + s * u + t * v (|s| <= half_u, |t| <= half_v) every `step`, as a
// camera at `view` measures them: moved along the line of sight by the depth error of eq. 5.2 and
// across it by the pixel error.
void AddFace(const Eigen::Vector3d& centre, const Eigen::Vector3d& u, const Eigen::Vector3d& v, double half_u,
             double half_v, double step, const Eigen::Vector3d& view, std::mt19937* rng,
             std::vector<CloudPoint>* out) {
  std::normal_distribution<double> g(0.0, 1.0);
  for (double s = -half_u; s <= half_u + 1e-9; s += step) {
    for (double t = -half_v; t <= half_v + 1e-9; t += step) {
      const Eigen::Vector3d p = centre + s * u + t * v;
      const Eigen::Vector3d sight = (p - view).normalized();
      const double range = (p - view).norm();
      Eigen::Vector3d a = sight.unitOrthogonal(), b = sight.cross(a);
      const double along = kModel.DepthError(range), across = range * 0.5 / 1080.0;
      CloudPoint c;
      c.p = (p + g(*rng) * along * sight + g(*rng) * across * a + g(*rng) * across * b).cast<float>();
      out->push_back(c);
    }
  }
}

// Error of an estimated plane against the truth as the estimate's (a, b, d).
Eigen::Vector3d PlaneError(const SubmapPlane& est, const Eigen::Vector3d& n, double offset) {
  Eigen::Vector3f u, v;
  SubmapPlane::Axes(est.normal, &u, &v);
  const double c = n.dot(est.normal.cast<double>());
  return {u.cast<double>().dot(n) / c, v.cast<double>().dot(n) / c, offset - est.offset};
}

TEST(PlaneExtractorTest, FindsTheFloorAndTwoWallsOfARoomCorner) {
  std::mt19937 rng(3);
  std::vector<CloudPoint> pts;
  const Eigen::Vector3d view(0.0, 0.0, 1.2);
  AddFace({0.5, 0.5, 0.0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.5, 1.5, 0.05, view, &rng,
          &pts);
  AddFace({2.0, 0.5, 1.0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 1.5, 0.95, 0.05, view, &rng,
          &pts);
  AddFace({0.5, 2.0, 1.0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(), 1.45, 0.95, 0.05, view, &rng,
          &pts);
  PlaneExtractor extractor(PlaneOptions{}, kModel);
  const std::vector<Eigen::Vector3f> views = {view.cast<float>()};
  PlaneExtractor::Stats stats;
  const std::vector<SubmapPlane> planes = extractor.Extract(pts, views, &stats);
  ASSERT_EQ(planes.size(), 3u);
  EXPECT_GT(stats.planar_cubes, 50u);
  // Normals towards the camera: the floor's up, the walls' towards the origin.
  const Eigen::Vector3d normals[3] = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitX(),
                                      -Eigen::Vector3d::UnitY()};
  const double offsets[3] = {0.0, 2.0, 2.0};
  for (int k = 0; k < 3; ++k) {
    const SubmapPlane* found = nullptr;
    for (const SubmapPlane& p : planes) {
      if (p.normal.cast<double>().dot(normals[k]) > 0.99) found = &p;
    }
    ASSERT_NE(found, nullptr) << "plane " << k;
    EXPECT_GT(found->normal.cast<double>().dot(normals[k]), std::cos(0.5 * M_PI / 180.0));
    EXPECT_NEAR(found->offset, offsets[k], 0.01);
    // The faces reach within a cube of their true edges.
    EXPECT_GT(found->max.x() - found->min.x(), 2.5) << k;
    EXPECT_GT(found->max.y() - found->min.y(), 1.5) << k;
    EXPECT_GT(found->points, 800u);
  }
  EXPECT_GE(planes[0].points, planes[1].points);
  EXPECT_GE(planes[1].points, planes[2].points);
}

// The covariance describes the error: over many draws of the stereo noise the normalized
// estimation error squared of (a, b, d) averages the 3 of a chi-square with 3 degrees of freedom.
TEST(PlaneExtractorTest, CovarianceIsConsistentWithTheStereoNoise) {
  std::mt19937 rng(11);
  PlaneExtractor extractor(PlaneOptions{}, kModel);
  const Eigen::Vector3d view(0.0, 0.0, 1.0);
  const Eigen::Vector3d n = Eigen::Vector3d(-1.0, 0.2, 0.3).normalized();
  const Eigen::Vector3d centre(4.0, 0.5, 0.8);
  const Eigen::Vector3d u = Eigen::Vector3d::UnitZ().cross(n).normalized(), v = n.cross(u);
  const double offset = -n.dot(centre);
  const std::vector<Eigen::Vector3f> views = {view.cast<float>()};
  double nees = 0.0;
  int trials = 0;
  for (int i = 0; i < 200; ++i) {
    std::vector<CloudPoint> pts;
    AddFace(centre, u, v, 1.0, 0.8, 0.04, view, &rng, &pts);
    const std::vector<SubmapPlane> planes = extractor.Extract(pts, views);
    ASSERT_EQ(planes.size(), 1u) << "draw " << i;
    ASSERT_GT(planes[0].normal.cast<double>().dot(n), 0.99);
    const Eigen::Vector3d e = PlaneError(planes[0], n, offset);
    nees += e.dot(planes[0].covariance.cast<double>().inverse() * e);
    ++trials;
  }
  nees /= trials;
  // The mean of 200 draws has a standard deviation of 0.17.
  EXPECT_GT(nees, 2.4);
  EXPECT_LT(nees, 3.6);
}

TEST(PlaneExtractorTest, ScatteredPointsMakeNoPlane) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(-1.5f, 1.5f);
  std::vector<CloudPoint> pts(40000);
  for (CloudPoint& p : pts) p.p = Eigen::Vector3f(x(rng), x(rng), x(rng));
  PlaneExtractor extractor(PlaneOptions{}, kModel);
  EXPECT_TRUE(extractor.Extract(pts, {}).empty());
}

TEST(PlaneExtractorTest, SkipsPointsThatAreNotFiniteAndCountsThem) {
  std::mt19937 rng(7);
  std::vector<CloudPoint> pts;
  const Eigen::Vector3d view(0.0, 0.0, 1.0);
  AddFace({1.0, 0.0, 0.0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0, 1.0, 0.05, view, &rng,
          &pts);
  CloudPoint bad;
  bad.p = Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  pts.insert(pts.begin() + 10, bad);
  bad.p = Eigen::Vector3f(1e30f, 0.0f, 0.0f);
  pts.push_back(bad);
  PlaneExtractor extractor(PlaneOptions{}, kModel);
  PlaneExtractor::Stats stats;
  const std::vector<Eigen::Vector3f> views = {view.cast<float>()};
  const std::vector<SubmapPlane> planes = extractor.Extract(pts, views, &stats);
  EXPECT_EQ(stats.skipped_points, 2u);
  ASSERT_EQ(planes.size(), 1u);
  EXPECT_GT(planes[0].normal.z(), 0.999f);
  EXPECT_TRUE(extractor.Extract({}, views).empty());
}

TEST(PlaneExtractorTest, SmallFacesAreNotPlanes) {
  std::mt19937 rng(9);
  std::vector<CloudPoint> pts;
  const Eigen::Vector3d view(0.0, 0.0, 1.0);
  // 0.8 m x 0.8 m: under the default 1 m^2.
  AddFace({1.0, 0.0, 0.0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 0.4, 0.4, 0.05, view, &rng,
          &pts);
  PlaneExtractor extractor(PlaneOptions{}, kModel);
  const std::vector<Eigen::Vector3f> views = {view.cast<float>()};
  EXPECT_TRUE(extractor.Extract(pts, views).empty());
  PlaneOptions small;
  small.min_area = 0.3;
  PlaneExtractor lenient(small, kModel);
  EXPECT_EQ(lenient.Extract(pts, views).size(), 1u);
}

TEST(SubmapPlaneTest, AxesAreOrthonormalWithUAlwaysLevelOnSteepPlanes) {
  for (const Eigen::Vector3f& n :
       {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(1, 0, 0),
        Eigen::Vector3f(0.3f, -0.2f, 0.9f).normalized(), Eigen::Vector3f(0.01f, 0.02f, 1.0f).normalized()}) {
    Eigen::Vector3f u, v;
    SubmapPlane::Axes(n, &u, &v);
    EXPECT_NEAR(u.norm(), 1.0f, 1e-6f);
    EXPECT_NEAR(v.norm(), 1.0f, 1e-6f);
    EXPECT_NEAR(u.dot(n), 0.0f, 1e-6f);
    EXPECT_NEAR(v.dot(n), 0.0f, 1e-6f);
    EXPECT_NEAR(n.cross(u).dot(v), 1.0f, 1e-5f);
    if (std::abs(n.z()) < 0.99f) {
      EXPECT_NEAR(u.z(), 0.0f, 1e-6f);
    }
  }
}

}  // namespace
}  // namespace cairn
