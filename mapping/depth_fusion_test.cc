#include "mapping/depth_fusion.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mapping/testing/mapping_test_scenes.h"

namespace cairn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Eq. 5.2c with 0.5 px per image coordinate is a disparity sigma of sqrt(2) 0.5 px.
const double kDisparitySigma = 0.5 * std::sqrt(2.0);

// A wall across the camera's view at x = `x` (the forward camera looks along +x).
double Wall(double x, const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return d.x() > 0.0 ? (x - o.x()) / d.x() : kInf; }
double Ground(const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return d.z() < 0.0 ? -o.z() / d.z() : kInf; }
auto WallAt(double x) {
  return [x](const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return Wall(x, o, d); };
}

// Root mean square of (depth - truth) over the pixels finite in both.
double RmsError(const std::vector<float>& depth, const DepthImage& truth) {
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < depth.size(); ++i) {
    if (!std::isfinite(depth[i]) || !std::isfinite(truth.depth[i])) continue;
    sum += (depth[i] - truth.depth[i]) * (depth[i] - truth.depth[i]);
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : kInf;
}

class DepthFusionTest : public ::testing::Test {
 protected:
  StereoCamera cam_ = testing::RoverCamera(0.25);
  StereoErrorModel model_{cam_.intrinsics.fx, cam_.baseline, 0.5};
  const Eigen::Isometry3d still_ = testing::ForwardCameraPose(Eigen::Vector3d::Zero(), 0.0, 0.0);

  static DepthFusionOptions Enabled(int64_t max_images = 10) {
    DepthFusionOptions o;
    o.enabled = true;
    o.max_images = max_images;
    return o;
  }
};

TEST_F(DepthFusionTest, StaticPlaneVarianceDropsAsOneOverN) {
  DepthFusion fusion(Enabled(100), cam_, model_);
  const Eigen::Isometry3d& T = still_;
  const auto wall = WallAt(2.0);
  const DepthImage truth = testing::RenderDepth(cam_, T, wall);
  constexpr int kImages = 9;
  double raw_rms = 0.0;
  for (int k = 0; k < kImages; ++k) {
    const DepthImage img = testing::RenderDepth(cam_, T, wall, kDisparitySigma, 10 + k);
    if (k == 0) raw_rms = RmsError(img.depth, truth);
    ASSERT_TRUE(fusion.Fuse(img, T).ok());
    if (k == 0) {
      EXPECT_EQ(fusion.stats().fused, 0);
    }
  }
  // Within 3 sigma nearly every pixel agrees with the fused image every time.
  EXPECT_GT(fusion.stats().fused, 0.97 * fusion.stats().measured);
  const double fused_rms = RmsError(fusion.fused().depth, truth);
  // 1 / sqrt(9) = 0.33 in theory; the pixels that restarted once add a little.
  EXPECT_LT(fused_rms, 0.42 * raw_rms) << fused_rms << " vs " << raw_rms;
  EXPECT_GT(fused_rms, 0.25 * raw_rms) << fused_rms << " vs " << raw_rms;
  // The reported sigma is about eq. 5.2c over sqrt(N) where all images agreed (each image's sigma
  // is eq. 5.2c at its own noisy depth).
  int near_bound = 0;
  for (size_t i = 0; i < fusion.depth_error().size(); ++i) {
    const double bound = model_.DepthError(truth.depth[i]) / 3.0;
    near_bound += std::abs(fusion.depth_error()[i] - bound) < 0.1 * bound;
  }
  EXPECT_GT(near_bound, 0.8 * static_cast<double>(fusion.stats().measured));
}

TEST_F(DepthFusionTest, MaxImagesBoundsTheWeightOfThePast) {
  DepthFusion fusion(Enabled(4), cam_, model_);
  for (int k = 0; k < 12; ++k) ASSERT_TRUE(fusion.Fuse(testing::RenderDepth(cam_, still_, WallAt(3.0)), still_).ok());
  for (size_t i = 0; i < fusion.depth_error().size(); i += 37) {
    EXPECT_NEAR(fusion.depth_error()[i], model_.DepthError(fusion.fused().depth[i]) / 2.0, 1e-4);
  }
}

TEST_F(DepthFusionTest, DepthEdgesAndMovingObjectsAreNotSmeared) {
  DepthFusion fusion(Enabled(), cam_, model_);
  const Eigen::Isometry3d& T = still_;
  // A box 2 m ahead covering the left half of the view (world +y) in front of a wall at 4 m.
  const auto box_and_wall = [](const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
    const double t = Wall(2.0, p, d);
    return (p + t * d).y() > 0.0 ? t : Wall(4.0, p, d);
  };
  const DepthImage truth = testing::RenderDepth(cam_, T, box_and_wall);
  for (int k = 0; k < 6; ++k) {
    ASSERT_TRUE(fusion.Fuse(testing::RenderDepth(cam_, T, box_and_wall, kDisparitySigma, 30 + k), T).ok());
  }
  // Every pixel stays on its own side of the edge: within 5 single-image sigmas (0.6 m at the box)
  // of its true depth, far from the 2 m gap between the surfaces.
  for (size_t i = 0; i < truth.depth.size(); ++i) {
    const double z = truth.depth[i];
    ASSERT_NEAR(fusion.fused().depth[i], z, 5.0 * model_.DepthError(z)) << "pixel " << i;
  }
  // The box leaves: where it was, the wall is taken as measured, not blended with the box.
  const DepthImage after = testing::RenderDepth(cam_, T, WallAt(4.0), kDisparitySigma, 99);
  ASSERT_TRUE(fusion.Fuse(after, T).ok());
  int box_pixels = 0;
  for (size_t i = 0; i < truth.depth.size(); ++i) {
    if (truth.depth[i] > 3.0f) continue;
    ++box_pixels;
    ASSERT_EQ(fusion.fused().depth[i], after.depth[i]) << "pixel " << i;
    ASSERT_FLOAT_EQ(fusion.depth_error()[i], static_cast<float>(model_.DepthError(after.depth[i])));
  }
  EXPECT_GT(box_pixels, truth.depth.size() / 3);
  EXPECT_LT(fusion.stats().fused, fusion.stats().measured - box_pixels + 1);
}

// A camera flying over the ground, moving and turning between images.
Eigen::Isometry3d FlightPose(int k) {
  return testing::ForwardCameraPose(Eigen::Vector3d(0.15 * k, 0.05 * k, 1.5 + 0.02 * k), 0.02 * k, 0.5);
}

TEST_F(DepthFusionTest, MovingCameraWarpsThePreviousImage) {
  const DepthFusionOptions o = Enabled();
  DepthFusion exact(o, cam_, model_), noisy(o, cam_, model_);
  constexpr int kImages = 8;
  double raw_rms = 0.0;
  DepthImage truth;
  for (int k = 0; k < kImages; ++k) {
    truth = testing::RenderDepth(cam_, FlightPose(k), Ground);
    ASSERT_TRUE(exact.Fuse(truth, FlightPose(k)).ok());
    const DepthImage img = testing::RenderDepth(cam_, FlightPose(k), Ground, kDisparitySigma, 50 + k);
    raw_rms = RmsError(img.depth, truth);
    ASSERT_TRUE(noisy.Fuse(img, FlightPose(k)).ok());
  }
  // Noise-free images agree after the warp: almost all pixels fuse (the rest came into view) and
  // the fused depth stays on the ground (interpolation and the 1/16 px quantization, 0.6 % at 5 m).
  EXPECT_GT(exact.stats().fused, 0.85 * exact.stats().measured);
  for (size_t i = 0; i < truth.depth.size(); ++i) {
    if (!std::isfinite(truth.depth[i])) continue;
    ASSERT_NEAR(exact.fused().depth[i], truth.depth[i], 0.015 * truth.depth[i]) << "pixel " << i;
  }
  const double fused_rms = RmsError(noisy.fused().depth, truth);
  EXPECT_LT(fused_rms, 0.6 * raw_rms) << fused_rms << " vs " << raw_rms;
  // Without the relative pose (the same pose passed for every image), the noise-free images still
  // pass the wide gate, but the fused ground lags behind: the warp is what keeps it in place.
  DepthFusion unmoved(o, cam_, model_);
  for (int k = 0; k < kImages; ++k) {
    ASSERT_TRUE(unmoved.Fuse(testing::RenderDepth(cam_, FlightPose(k), Ground), FlightPose(0)).ok());
  }
  const double exact_rms = RmsError(exact.fused().depth, truth), unmoved_rms = RmsError(unmoved.fused().depth, truth);
  EXPECT_GT(unmoved_rms, 5.0 * exact_rms) << unmoved_rms << " vs " << exact_rms;
}

TEST_F(DepthFusionTest, FrameSwitchKeepsTheFusedImage) {
  DepthFusion one_frame(Enabled(), cam_, model_), switched(Enabled(), cam_, model_);
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
  T_old_new.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.1, 1.0).normalized()).toRotationMatrix();
  T_old_new.translation() = Eigen::Vector3d(3.0, -1.0, 0.5);
  for (int k = 0; k < 6; ++k) {
    const DepthImage img = testing::RenderDepth(cam_, FlightPose(k), Ground, kDisparitySigma, 70 + k);
    ASSERT_TRUE(one_frame.Fuse(img, FlightPose(k)).ok());
    if (k == 3) switched.Rebase(T_old_new);
    ASSERT_TRUE(switched.Fuse(img, k < 3 ? FlightPose(k) : T_old_new.inverse() * FlightPose(k)).ok());
  }
  // The same relative poses in other coordinates: the same result up to float rounding (a pixel
  // right at the agreement gate may fall on the other side of it).
  ASSERT_EQ(switched.fused().depth.size(), one_frame.fused().depth.size());
  int differ = 0;
  for (size_t i = 0; i < one_frame.fused().depth.size(); ++i) {
    const float a = one_frame.fused().depth[i], b = switched.fused().depth[i];
    differ += std::isfinite(a) ? !(std::abs(a - b) <= 1e-4f * a) : std::isnan(a) != std::isnan(b);
  }
  EXPECT_LE(differ, 5);
  EXPECT_NEAR(switched.stats().fused, one_frame.stats().fused, 5);
  EXPECT_GT(switched.stats().fused, 0.8 * switched.stats().measured);
}

}  // namespace
}  // namespace cairn
