#include "mapping/matching/hough_voting.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/matching/correspondence_finder.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/gravity_shot_descriptor.h"
#include "mapping/matching/keypoint_extractor.h"
#include "mapping/testing/rock_field_scene.h"

namespace cairn {
namespace {

// Keypoints with frames in A, the same places in B under T_b_a, 40 true and 60 random pairs.
TEST(HoughVotingTest, StrongestClusterHoldsTheConsistentPairs) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::normal_distribution<float> yaw_noise(0.0f, 0.05f), pos_noise(0.0f, 0.03f);
  const double yaw = 2.2;
  const Eigen::Isometry3f T_b_a = testing::YawPose(yaw, Eigen::Vector3d(4.0, -1.0, 0.4)).cast<float>();
  DescribedKeypoints a, b;
  for (int i = 0; i < 100; ++i) {
    a.points.emplace_back(u(rng), u(rng), 0.1f * u(rng));
    GravityShotFrame f;
    f.yaw = u(rng);
    a.frames.push_back(f);
    b.points.push_back(T_b_a * a.points.back() +
                       Eigen::Vector3f(pos_noise(rng), pos_noise(rng), pos_noise(rng)));
    f.yaw = static_cast<float>(std::remainder(f.yaw + yaw + yaw_noise(rng), 2.0 * std::numbers::pi));
    b.frames.push_back(f);
  }
  std::vector<KeypointCorrespondence> c;
  std::uniform_int_distribution<uint32_t> pick(0, 99);
  for (uint32_t i = 0; i < 40; ++i) c.push_back({i, i, 0.2f, 0.8f});
  for (int i = 0; i < 60; ++i) {
    const uint32_t x = pick(rng), y = pick(rng);
    if (x != y) c.push_back({x, y, 0.3f, 0.7f});
  }
  const HoughResult r = HoughVoting().Vote(a, b, c);
  ASSERT_FALSE(r.clusters.empty());
  const HoughCluster& best = r.clusters.front();
  EXPECT_LT(std::abs(WrapAngle(best.yaw_b_a - yaw)), 0.05);
  EXPECT_LT((best.t_b_a - T_b_a.translation()).norm(), 0.2f);
  bool both_ways[2] = {false, false};
  for (const HoughCluster& cl : r.clusters) both_ways[cl.a_in_b ? 0 : 1] = true;
  EXPECT_TRUE(both_ways[0] && both_ways[1]);
  int true_kept = 0, false_kept = 0;
  for (const KeypointCorrespondence& k : r.candidates) {
    (k.a == k.b ? true_kept : false_kept) += 1;
    EXPECT_GT(k.score, 0.0f);
    EXPECT_LE(k.score, 0.8f);
  }
  EXPECT_GE(true_kept, 36);
  EXPECT_LE(false_kept, 10);
}

TEST(HoughVotingTest, NothingToVoteOn) {
  DescribedKeypoints a, b;
  EXPECT_TRUE(HoughVoting().Vote(a, b, {}).clusters.empty());
  a.points.emplace_back(0.0f, 0.0f, 0.0f);
  a.frames.emplace_back();
  b = a;
  // An index out of range is ignored; one vote is below min_votes.
  const HoughResult r = HoughVoting().Vote(a, b, {{0, 0, 0.1f, 0.9f}, {0, 7, 0.1f, 0.9f}});
  EXPECT_TRUE(r.clusters.empty());
  EXPECT_TRUE(r.candidates.empty());
}

// The whole feature side on two submaps of one rock field: keypoints, descriptors,
// correspondences, voting. A correspondence is true when its keypoints lie within `radius` of each
// other under the true transform.
TEST(HoughVotingTest, KeepsMostlyTruePairsOfTwoSubmaps) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7);
  const Eigen::Isometry3f T_b_a = pair.T_b_a().cast<float>();
  const KeypointExtractor extractor;
  const SubmapKeypoints ka = extractor.Extract(*pair.a), kb = extractor.Extract(*pair.b);
  GravityShotDescriptor describe_a(pair.a->points()), describe_b(pair.b->points());
  const DescribedKeypoints da = describe_a.ComputeAll(ka.points), db = describe_b.ComputeAll(kb.points);
  ASSERT_GT(da.size(), 50u);
  ASSERT_GT(db.size(), 50u);
  const std::vector<KeypointCorrespondence> c = CorrespondenceFinder().Find(da.descriptors, db.descriptors);
  const HoughResult r = HoughVoting().Vote(da, db, c);
  auto ratio = [&](const std::vector<KeypointCorrespondence>& list, float radius) {
    int ok = 0;
    for (const KeypointCorrespondence& k : list)
      ok += (T_b_a * da.points[k.a] - db.points[k.b]).norm() < radius;
    return list.empty() ? 0.0 : ok / static_cast<double>(list.size());
  };
  std::printf(
      "[ match   ] keypoints A %zu (of %lld), B %zu (of %lld); correspondences %zu: true within 0.1 m %.0f "
      "%%, "
      "0.2 m %.0f %%; after voting %zu in %zu clusters: %.0f %%, %.0f %%\n",
      da.size(), static_cast<long long>(ka.voxel_keypoints), db.size(),
      static_cast<long long>(kb.voxel_keypoints), c.size(), 100.0 * ratio(c, 0.1f), 100.0 * ratio(c, 0.2f),
      r.candidates.size(), r.clusters.size(), 100.0 * ratio(r.candidates, 0.1f),
      100.0 * ratio(r.candidates, 0.2f));
  ASSERT_FALSE(r.clusters.empty());
  const HoughCluster& best = r.clusters.front();
  const double true_yaw = std::atan2(T_b_a.linear()(1, 0), T_b_a.linear()(0, 0));
  std::printf(
      "[ match   ] strongest cluster: %zu pairs, %.1f votes, yaw error %.3f rad, translation error %.3f m\n",
      best.members.size(), best.votes, WrapAngle(best.yaw_b_a - true_yaw),
      (best.t_b_a - T_b_a.translation()).norm());
  EXPECT_LT(std::abs(WrapAngle(best.yaw_b_a - true_yaw)), 0.1);
  EXPECT_LT((best.t_b_a - T_b_a.translation()).norm(), 0.3f);
  EXPECT_GE(ratio(r.candidates, 0.2f), 0.5);

  // The stricter choice (a pair among the best three of both keypoints), for comparison.
  CorrespondenceFinderOptions mutual;
  mutual.mutual_only = true;
  const std::vector<KeypointCorrespondence> cm =
      CorrespondenceFinder(mutual).Find(da.descriptors, db.descriptors);
  const HoughResult rm = HoughVoting().Vote(da, db, cm);
  std::printf(
      "[ match   ] mutual only: %zu correspondences, true within 0.2 m %.0f %%; after voting %zu: %.0f %%\n",
      cm.size(), 100.0 * ratio(cm, 0.2f), rm.candidates.size(), 100.0 * ratio(rm.candidates, 0.2f));
  EXPECT_GT(ratio(r.candidates, 0.2f), ratio(c, 0.2f));
}

}  // namespace
}  // namespace cairn
