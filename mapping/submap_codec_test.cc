#include "mapping/submap_codec.h"

#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "mapping/testing/submap_test_util.h"

namespace cairn {
namespace {

TEST(SubmapCodecTest, RoundTripKeepsMetadataQuantizedCloudAndOccupancy) {
  const auto submap = testing::SyntheticSubmap(7);
  for (Compression c : {Compression::kZstd, Compression::kLz4}) {
    auto bytes = SubmapCodec::Encode(*submap, c);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    auto back = SubmapCodec::Decode(*bytes);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    const Submap& s = **back;
    EXPECT_EQ(s.metadata().robot, "rover1");
    EXPECT_EQ(s.metadata().id, 7u);
    EXPECT_EQ(s.metadata().images, 3u);
    EXPECT_EQ(s.metadata().start, Timestamp::FromSeconds(10.0));
    EXPECT_EQ(s.metadata().end, Timestamp::FromSeconds(12.0));
    EXPECT_DOUBLE_EQ(s.metadata().distance, submap->metadata().distance);
    EXPECT_DOUBLE_EQ(s.metadata().options.octree_resolution, 0.1);
    // Every point is back in its voxel within resolution / 32 per axis, with its flags.
    ASSERT_EQ(s.points().size(), submap->points().size());
    std::map<std::tuple<int, int, int>, CloudPoint> by_voxel;
    const double res = s.metadata().options.cloud_resolution;
    const auto voxel = [&](const Eigen::Vector3f& p) {
      return std::make_tuple(static_cast<int>(std::floor(p.x() / res)), static_cast<int>(std::floor(p.y() / res)),
                             static_cast<int>(std::floor(p.z() / res)));
    };
    for (const CloudPoint& p : s.points()) by_voxel[voxel(p.p)] = p;
    for (const CloudPoint& p : submap->points()) {
      auto it = by_voxel.find(voxel(p.p));
      ASSERT_NE(it, by_voxel.end());
      EXPECT_LE((it->second.p - p.p).cwiseAbs().maxCoeff(), res / 32 + 1e-5);
      EXPECT_EQ(it->second.obstacle, p.obstacle);
      EXPECT_EQ(it->second.r, p.r);
    }
    // Same free/occupied state for every leaf of the original.
    int64_t leaves = 0;
    for (auto it = submap->tree().begin_leafs(); it != submap->tree().end_leafs(); ++it) {
      const octomap::OcTreeNode* n = s.tree().search(it.getKey());
      ASSERT_NE(n, nullptr);
      EXPECT_EQ(s.tree().isNodeOccupied(n), submap->tree().isNodeOccupied(*it));
      ++leaves;
    }
    EXPECT_GT(leaves, 100);
  }
}

// Version 2 codes colour as residuals of a neighbour prediction: still exact. Two points in one
// voxel (a centroid rounded onto the next voxel's boundary) both come back.
TEST(SubmapCodecTest, ColourAndSharedVoxelsRoundTripExactly) {
  SubmapMetadata m;
  m.robot = "hexacopter";
  m.id = 2;
  std::vector<CloudPoint> pts;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> u8(0, 255);
  const float res = 0.05f;
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 30; ++y) {
      for (int z = 0; z < 3; ++z) {
        if ((x * 7 + y * 3 + z) % 5 == 0) continue;  // holes: not every neighbour exists
        CloudPoint p;
        p.p = Eigen::Vector3f((x + 0.3f) * res, (y - 20 + 0.7f) * res, (z + 0.5f) * res);
        p.r = static_cast<uint8_t>(u8(rng));
        p.g = static_cast<uint8_t>(x * 6);
        p.b = static_cast<uint8_t>(255 - y * 8);
        p.obstacle = z == 2;
        pts.push_back(p);
      }
    }
  }
  CloudPoint twin = pts[10];
  twin.p.z() += 0.2f * res;
  twin.r ^= 0x55;
  pts.push_back(twin);
  const Submap submap(m, pts, MakeOccupancyTree(m.options));
  auto bytes = SubmapCodec::Encode(submap);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  auto back = SubmapCodec::Decode(*bytes);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ((*back)->points().size(), pts.size());
  // Decoded in index order: match each original to the decoded point nearest to it.
  std::vector<bool> used((*back)->points().size(), false);
  for (const CloudPoint& p : pts) {
    size_t best = 0;
    float best_d = 1e9f;
    for (size_t j = 0; j < (*back)->points().size(); ++j) {
      const CloudPoint& q = (*back)->points()[j];
      const float d = (q.p - p.p).cwiseAbs().maxCoeff();
      if (!used[j] && d < best_d && q.r == p.r) {
        best_d = d;
        best = j;
      }
    }
    ASSERT_LE(best_d, res / 32 + 1e-5f);
    const CloudPoint& q = (*back)->points()[best];
    used[best] = true;
    EXPECT_EQ(q.g, p.g);
    EXPECT_EQ(q.b, p.b);
    EXPECT_EQ(q.obstacle, p.obstacle);
  }
}

TEST(SubmapCodecTest, RejectsCorruptInputWithAClearError) {
  const auto submap = testing::SyntheticSubmap(3, 1);
  auto bytes = SubmapCodec::Encode(*submap);
  ASSERT_TRUE(bytes.ok());
  const std::vector<uint8_t>& good = *bytes;
  // Truncation anywhere.
  for (size_t n : {size_t{0}, size_t{5}, size_t{20}, good.size() / 2, good.size() - 1}) {
    auto r = SubmapCodec::Decode(std::span(good.data(), n));
    ASSERT_FALSE(r.ok()) << n;
    EXPECT_EQ(r.status().code(), StatusCode::kDataLoss);
  }
  // A flipped bit in every byte of the header and in a spread of body bytes.
  for (size_t i = 0; i < good.size(); i += (i < 40 ? 1 : 97)) {
    std::vector<uint8_t> bad = good;
    bad[i] ^= 0x10;
    auto r = SubmapCodec::Decode(bad);
    ASSERT_FALSE(r.ok()) << "byte " << i;
    EXPECT_FALSE(r.status().message().empty());
  }
  std::vector<uint8_t> bad = good;
  bad[0] = 'X';
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("magic"), std::string::npos);
  bad = good;
  bad[8] = 9;  // version
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("version"), std::string::npos);
  bad[8] = 1;  // the previous format (raw channels) is not read as this one
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("version 1 is not supported"), std::string::npos);
  bad = good;
  bad.back() ^= 1;
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("checksum"), std::string::npos);
}

TEST(SubmapCodecTest, OctreeStreamValidation) {
  // Root with child 0 an inner node whose children are all occupied leaves: valid.
  std::vector<uint8_t> ok = {0x03, 0x00, 0x55, 0x55};
  EXPECT_TRUE(SubmapCodec::ValidateOctreeBinary(ok).ok());
  EXPECT_FALSE(SubmapCodec::ValidateOctreeBinary(std::vector<uint8_t>{0x03, 0x00, 0x55}).ok());
  EXPECT_FALSE(SubmapCodec::ValidateOctreeBinary(std::vector<uint8_t>{0x03, 0x00, 0x55, 0x55, 0x00}).ok());
  // A chain of inner nodes deeper than 16 levels.
  std::vector<uint8_t> deep;
  for (int i = 0; i < 17; ++i) {
    deep.push_back(0x03);
    deep.push_back(0x00);
  }
  deep.push_back(0x55);
  deep.push_back(0x55);
  EXPECT_NE(SubmapCodec::ValidateOctreeBinary(deep).message().find("finest level"), std::string::npos);
}

}  // namespace
}  // namespace cairn
