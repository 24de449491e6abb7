#include "mapping/matching/grey_level_search.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

// An aperiodic albedo pattern: random levels on a 0.3 m lattice, bilinearly interpolated, on
// gently rolling ground.
class AlbedoGround {
 public:
  explicit AlbedoGround(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> level(40.0f, 200.0f);
    for (float& v : lattice_) v = level(rng);
  }
  float Grey(double x, double y) const {
    const double u = (x + 20.0) / 0.3, v = (y + 20.0) / 0.3;
    const int i = static_cast<int>(std::floor(u)), j = static_cast<int>(std::floor(v));
    const double fu = u - i, fv = v - j;
    const auto at = [&](int a, int b) {
      return lattice_[static_cast<size_t>(((a % kN) + kN) % kN * kN + ((b % kN) + kN) % kN)];
    };
    return static_cast<float>((1 - fu) * (1 - fv) * at(i, j) + fu * (1 - fv) * at(i + 1, j) +
                              (1 - fu) * fv * at(i, j + 1) + fu * fv * at(i + 1, j + 1));
  }
  static double Height(double x, double y) { return 0.1 * std::sin(0.5 * x) + 0.05 * std::cos(0.7 * y); }

  // Points every 5 cm over a disc of `radius` around `centre` (world frame), expressed in the
  // frame T_world_frame, with their grey levels.
  void Sample(const Eigen::Vector2d& centre, double radius, const FourDofTransform& T_world_frame,
              std::vector<Eigen::Vector3d>* cloud, std::vector<float>* grey) const {
    const FourDofTransform T_frame_world = T_world_frame.inverse();
    for (double x = centre.x() - radius; x <= centre.x() + radius; x += 0.05) {
      for (double y = centre.y() - radius; y <= centre.y() + radius; y += 0.05) {
        if ((Eigen::Vector2d(x, y) - centre).norm() > radius) continue;
        cloud->push_back(T_frame_world * Eigen::Vector3d(x, y, Height(x, y)));
        grey->push_back(Grey(x, y));
      }
    }
  }

 private:
  static constexpr int kN = 140;
  std::vector<float> lattice_ = std::vector<float>(kN * kN);
};

TEST(GreyLevelSearchTest, FindsTheTurnAndShiftOfAnOverlappingPatch) {
  const AlbedoGround ground(7);
  const FourDofTransform T_world_a(1.0, -2.0, 0.3, 0.4);
  const FourDofTransform T_world_b(3.5, 0.5, -0.2, 2.1);
  std::vector<Eigen::Vector3d> a, b;
  std::vector<float> ga, gb;
  ground.Sample({1.0, -1.0}, 5.0, T_world_a, &a, &ga);
  ground.Sample({4.0, 1.0}, 5.0, T_world_b, &b, &gb);
  const Expected<GreyLevelSearchResult> r = GreyLevelSearch().Search(a, ga, b, gb);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_FALSE(r->candidates.empty());
  const FourDofTransform truth = T_world_a.inverse() * T_world_b;
  const FourDofTransform error = truth.inverse() * r->candidates.front().T_a_b;
  // Within the ICP's reach: a cell and half a yaw step.
  EXPECT_LT(error.translation().head<2>().norm(), 0.25);
  EXPECT_LT(std::abs(error.translation().z()), 0.05);
  EXPECT_LT(std::abs(error.yaw()), 0.03);
  EXPECT_GT(r->candidates.front().correlation, 0.8);
  EXPECT_GE(r->yaws, 120);
}

// Chance alignments of unrelated ground over a few square metres can pass the raster threshold;
// they stay well below a true one (above 0.8), and the matcher's checks at 5 cm refuse them.
TEST(GreyLevelSearchTest, PatchesOfDifferentGroundCorrelateWeakly) {
  const AlbedoGround one(7), other(8);
  std::vector<Eigen::Vector3d> a, b;
  std::vector<float> ga, gb;
  one.Sample({0.0, 0.0}, 5.0, FourDofTransform(), &a, &ga);
  other.Sample({0.0, 0.0}, 5.0, FourDofTransform(), &b, &gb);
  const Expected<GreyLevelSearchResult> r = GreyLevelSearch().Search(a, ga, b, gb);
  ASSERT_TRUE(r.ok());
  for (const GreyLevelCandidate& c : r->candidates) EXPECT_LT(c.correlation, 0.7);
}

TEST(GreyLevelSearchTest, AYawWindowSearchesOnlyItsYaws) {
  const AlbedoGround ground(7);
  std::vector<Eigen::Vector3d> a, b;
  std::vector<float> ga, gb;
  ground.Sample({0.0, 0.0}, 4.0, FourDofTransform(), &a, &ga);
  ground.Sample({1.0, 0.0}, 4.0, FourDofTransform(0.0, 0.0, 0.0, 1.0), &b, &gb);
  const Expected<GreyLevelSearchResult> r = GreyLevelSearch().Search(a, ga, b, gb, {1.0, 0.1});
  ASSERT_TRUE(r.ok());
  EXPECT_LE(r->yaws, 5);
  ASSERT_FALSE(r->candidates.empty());
  EXPECT_NEAR(r->candidates.front().T_a_b.yaw(), 1.0, 0.03);
  // The true yaw outside the window: nothing there correlates.
  const Expected<GreyLevelSearchResult> elsewhere = GreyLevelSearch().Search(a, ga, b, gb, {-1.0, 0.1});
  ASSERT_TRUE(elsewhere.ok());
  EXPECT_TRUE(elsewhere->candidates.empty());
}

// A window narrower than a step searches its centre's yaw itself, not the nearest of the full
// search's steps (up to 1.5 deg off), so a gate that narrow can admit the candidate.
TEST(GreyLevelSearchTest, ANarrowWindowSearchesItsCentre) {
  const AlbedoGround ground(7);
  std::vector<Eigen::Vector3d> a, b;
  std::vector<float> ga, gb;
  const double yaw = 1.0 + 0.5 * GreyLevelSearchOptions().yaw_step;
  ground.Sample({0.0, 0.0}, 4.0, FourDofTransform(), &a, &ga);
  ground.Sample({1.0, 0.0}, 4.0, FourDofTransform(0.0, 0.0, 0.0, yaw), &b, &gb);
  const Expected<GreyLevelSearchResult> r = GreyLevelSearch().Search(a, ga, b, gb, {yaw, 0.0});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->yaws, 1);
  ASSERT_FALSE(r->candidates.empty());
  EXPECT_NEAR(r->candidates.front().T_a_b.yaw(), yaw, 1e-9);
}

// What a candidate may be off by the steps alone: half a cell's diagonal, and half a yaw step,
// which at B's centroid 10 m from its origin is another 0.26 m.
TEST(GreyLevelSearchTest, TheSlackGrowsWithTheDistanceOfBsCloud) {
  const GreyLevelSearch search;
  const double half_step =
      std::numbers::pi / std::ceil(2.0 * std::numbers::pi / GreyLevelSearchOptions().yaw_step);
  const std::vector<Eigen::Vector3d> near{{-1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  const std::vector<Eigen::Vector3d> far{
      {5.0, 8.0, 0.0}, {7.0, 8.0, 3.0}, {std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0}};
  const double cell = 0.5 * std::numbers::sqrt2 * GreyLevelSearchOptions().cell;
  EXPECT_NEAR(search.SearchSlack(near).x(), cell, 1e-12);
  EXPECT_NEAR(search.SearchSlack(near).y(), half_step, 1e-12);
  EXPECT_NEAR(search.SearchSlack(far).x(), cell + 10.0 * half_step, 1e-9);
  EXPECT_NEAR(search.SearchSlack({}).x(), cell, 1e-12);
}

TEST(GreyLevelSearchTest, EmptyNonFiniteAndHugeInputsAreHandled) {
  const GreyLevelSearch search;
  std::vector<Eigen::Vector3d> a, b;
  std::vector<float> ga, gb;
  Expected<GreyLevelSearchResult> r = search.Search(a, ga, b, gb);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->candidates.empty());

  const double nan = std::numeric_limits<double>::quiet_NaN();
  a = {Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d(1, 1, 0)};
  ga = {100.0f, std::numeric_limits<float>::quiet_NaN()};
  b = a;
  gb = ga;
  r = search.Search(a, ga, b, gb);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->candidates.empty());

  a = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1000, 0, 0)};
  ga = {100.0f, 120.0f};
  r = search.Search(a, ga, a, ga);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("cells per side"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace cairn
