#include "mapping/submap_codec.h"

#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "mapping/testing/submap_test_util.h"

namespace cairn {
namespace {

// The same submap with other numbers of bits on the wire.
std::shared_ptr<const Submap> WithWireBits(const Submap& s, int offset_bits, int intensity_bits = 8) {
  SubmapMetadata m = s.metadata();
  m.options.wire_offset_bits = offset_bits;
  m.options.wire_intensity_bits = intensity_bits;
  return std::make_shared<const Submap>(m, s.points(), std::make_unique<octomap::OcTree>(s.tree()));
}

TEST(SubmapCodecTest, RoundTripKeepsMetadataQuantizedCloudAndOccupancy) {
  const auto original = testing::SyntheticSubmap(7);
  size_t previous_size = 0;
  for (const int bits : {1, 2, 3, 4}) {
    const auto submap = WithWireBits(*original, bits);
    for (Compression c : {Compression::kZstd, Compression::kLz4}) {
      SCOPED_TRACE(::testing::Message() << bits << " bits, " << Compressor::Name(c));
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
      EXPECT_EQ(s.metadata().options.wire_offset_bits, bits);
      // Every point is back in its voxel within resolution / 2^(bits+1) per axis, with its flags.
      ASSERT_EQ(s.points().size(), submap->points().size());
      std::map<std::tuple<int, int, int>, CloudPoint> by_voxel;
      const double res = s.metadata().options.cloud_resolution;
      const auto voxel = [&](const Eigen::Vector3f& p) {
        return std::make_tuple(static_cast<int>(std::floor(p.x() / res)),
                               static_cast<int>(std::floor(p.y() / res)),
                               static_cast<int>(std::floor(p.z() / res)));
      };
      for (const CloudPoint& p : s.points()) by_voxel[voxel(p.p)] = p;
      for (const CloudPoint& p : submap->points()) {
        auto it = by_voxel.find(voxel(p.p));
        ASSERT_NE(it, by_voxel.end());
        EXPECT_LE((it->second.p - p.p).cwiseAbs().maxCoeff(), res / (2 << bits) + 1e-5);
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
      // Decoded and encoded again, the submap is the same bytes: a relay changes nothing.
      auto again = SubmapCodec::Encode(s, c);
      ASSERT_TRUE(again.ok());
      EXPECT_EQ(*again, *bytes);
      if (c == Compression::kZstd) {
        // Fewer bits, fewer bytes.
        if (previous_size > 0) {
          EXPECT_GT(bytes->size(), previous_size);
        }
        previous_size = bytes->size();
      }
    }
  }
}

// Intensity quantized to fewer bits comes back within half a step, and takes fewer bytes.
TEST(SubmapCodecTest, IntensityBitsTradeBytesForSteps) {
  const auto original = testing::SyntheticSubmap(7);
  size_t previous_size = 0;
  for (const int bits : {8, 6, 3, 1}) {
    SCOPED_TRACE(::testing::Message() << bits << " intensity bits");
    auto bytes = SubmapCodec::Encode(*WithWireBits(*original, 2, bits));
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    auto back = SubmapCodec::Decode(*bytes);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ((*back)->metadata().options.wire_intensity_bits, bits);
    // Points come back in voxel order: compare the sorted intensities.
    std::vector<int> a, b;
    for (const CloudPoint& p : original->points()) a.push_back(p.r);
    for (const CloudPoint& p : (*back)->points()) b.push_back(p.r);
    ASSERT_EQ(a.size(), b.size());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    const int half_step = (1 << (8 - bits)) / 2;
    int worst = 0;
    for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    EXPECT_LE(worst, half_step);
    if (bits < 8) {
      EXPECT_GT(worst, 0);
    }
    if (previous_size > 0) {
      EXPECT_LT(bytes->size(), previous_size);
    }
    previous_size = bytes->size();
    auto again = SubmapCodec::Encode(**back);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(*again, *bytes);
  }
  for (const int bits : {0, 9}) {
    auto bytes = SubmapCodec::Encode(*WithWireBits(*original, 2, bits));
    ASSERT_FALSE(bytes.ok());
    EXPECT_NE(bytes.status().message().find("wire_intensity_bits"), std::string::npos)
        << bytes.status().ToString();
  }
}

TEST(SubmapCodecTest, RefusesOffsetBitsOutsideTheirRange) {
  const auto submap = testing::SyntheticSubmap(7, 1);
  for (const int bits : {0, 5}) {
    auto bytes = SubmapCodec::Encode(*WithWireBits(*submap, bits));
    ASSERT_FALSE(bytes.ok());
    EXPECT_NE(bytes.status().message().find("wire_offset_bits"), std::string::npos)
        << bytes.status().ToString();
  }
}

// Colour as residuals of a neighbour prediction, at 8 bits: exact. Two points in one voxel (a
// centroid rounded onto the next voxel's boundary) both come back.
TEST(SubmapCodecTest, ColourAndSharedVoxelsRoundTripExactly) {
  SubmapMetadata m;
  m.robot = "hexacopter";
  m.id = 2;
  m.options.wire_intensity_bits = 8;
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
    ASSERT_LE(best_d, res / 8 + 1e-5f);  // 2 offset bits per axis
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
  bad[8] = 2;  // the previous format (4 offset bits always) is not read as this one
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("version 2 is not supported"),
            std::string::npos);
  bad = good;
  bad.back() ^= 1;
  EXPECT_NE(SubmapCodec::Decode(bad).status().message().find("checksum"), std::string::npos);
}

std::shared_ptr<const Submap> WithStructure(const Submap& s, SubmapStructure structure) {
  return std::make_shared<const Submap>(s.metadata(), s.points(), std::make_unique<octomap::OcTree>(s.tree()),
                                        std::move(structure));
}

SubmapStructure SomeStructure() {
  SubmapStructure st;
  st.viewpoints = {{0.0f, 0.0f, 0.5f}, {0.3f, -0.1f, 0.52f}, {0.61f, -0.2f, 0.49f}};
  SubmapPlane floor;
  floor.offset = 0.01f;
  floor.centroid = {1.0f, 0.2f, -0.01f};
  floor.covariance << 1e-6f, 1e-8f, 2e-7f, 1e-8f, 2e-6f, -3e-7f, 2e-7f, -3e-7f, 4e-6f;
  floor.min = {-2.0f, -1.5f};
  floor.max = {2.5f, 1.25f};
  floor.area = 9.5f;
  floor.points = 3800;
  SubmapPlane wall = floor;
  wall.normal = Eigen::Vector3f(-0.8f, 0.6f, 0.0f);
  wall.offset = 3.25f;
  wall.points = 900;
  st.planes = {floor, wall};
  SubmapLine edge;
  edge.anchor = {0.3f, -0.1f, 0.52f};
  edge.direction = Eigen::Vector3f(0.6f, 0.0f, 0.8f);
  edge.moment = Eigen::Vector3f(1.0f, 2.0f, 0.5f).cross(edge.direction);
  edge.t_min = -0.4f;
  edge.t_max = 1.7f;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j)
      edge.covariance(i, j) = (i == j ? 1e-4f : 1e-6f) * static_cast<float>(1 + i + j);
  }
  edge.sightings = 12;
  st.lines = {edge};
  return st;
}

TEST(SubmapCodecTest, ViewpointsAndPlanesRoundTripExactly) {
  const auto submap = WithStructure(*testing::SyntheticSubmap(3), SomeStructure());
  auto bytes = SubmapCodec::Encode(*submap);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  auto back = SubmapCodec::Decode(*bytes);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  const SubmapStructure& a = submap->structure();
  const SubmapStructure& b = (*back)->structure();
  ASSERT_EQ(b.viewpoints.size(), a.viewpoints.size());
  for (size_t i = 0; i < a.viewpoints.size(); ++i) EXPECT_EQ(b.viewpoints[i], a.viewpoints[i]);
  ASSERT_EQ(b.planes.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(b.planes[k].normal, a.planes[k].normal);
    EXPECT_EQ(b.planes[k].offset, a.planes[k].offset);
    EXPECT_EQ(b.planes[k].centroid, a.planes[k].centroid);
    EXPECT_EQ(b.planes[k].covariance, a.planes[k].covariance);
    EXPECT_EQ(b.planes[k].min, a.planes[k].min);
    EXPECT_EQ(b.planes[k].max, a.planes[k].max);
    EXPECT_EQ(b.planes[k].area, a.planes[k].area);
    EXPECT_EQ(b.planes[k].points, a.planes[k].points);
  }
  ASSERT_EQ(b.lines.size(), 1u);
  EXPECT_EQ(b.lines[0].anchor, a.lines[0].anchor);
  EXPECT_EQ(b.lines[0].moment, a.lines[0].moment);
  EXPECT_EQ(b.lines[0].direction, a.lines[0].direction);
  EXPECT_EQ(b.lines[0].t_min, a.lines[0].t_min);
  EXPECT_EQ(b.lines[0].t_max, a.lines[0].t_max);
  EXPECT_EQ(b.lines[0].covariance, a.lines[0].covariance);
  EXPECT_EQ(b.lines[0].sightings, a.lines[0].sightings);
  EXPECT_EQ((*back)->points().size(), submap->points().size());
}

TEST(SubmapCodecTest, VersionFourIsStillWrittenAndReadWithoutTheLines) {
  const auto submap = WithStructure(*testing::SyntheticSubmap(4), SomeStructure());
  auto v4 = SubmapCodec::Encode(*submap, Compression::kZstd, 4);
  ASSERT_TRUE(v4.ok()) << v4.status().ToString();
  EXPECT_EQ((*v4)[8], 4);
  auto back = SubmapCodec::Decode(*v4);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ((*back)->structure().planes.size(), 2u);
  EXPECT_EQ((*back)->structure().viewpoints.size(), 3u);
  EXPECT_TRUE((*back)->structure().lines.empty());
  auto v5 = SubmapCodec::Encode(*submap);
  ASSERT_TRUE(v5.ok());
  EXPECT_EQ((*v5)[8], 5);
  EXPECT_GT(v5->size(), v4->size());
}

TEST(SubmapCodecTest, RejectsALineThatIsNotOne) {
  SubmapStructure st = SomeStructure();
  st.lines[0].moment += 0.1f * st.lines[0].direction;
  auto bytes = SubmapCodec::Encode(*WithStructure(*testing::SyntheticSubmap(5), st));
  ASSERT_TRUE(bytes.ok());
  auto r = SubmapCodec::Decode(*bytes);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(r.status().message().find("submap line 0: moment is not perpendicular to the direction"),
            std::string::npos)
      << r.status().message();
  st = SomeStructure();
  std::swap(st.lines[0].t_min, st.lines[0].t_max);
  bytes = SubmapCodec::Encode(*WithStructure(*testing::SyntheticSubmap(5), st));
  ASSERT_TRUE(bytes.ok());
  EXPECT_NE(SubmapCodec::Decode(*bytes).status().message().find("submap line 0: ends are invalid"),
            std::string::npos);
}

TEST(SubmapCodecTest, VersionThreeIsStillWrittenAndReadWithoutTheStructure) {
  const auto submap = WithStructure(*testing::SyntheticSubmap(4), SomeStructure());
  auto v3 = SubmapCodec::Encode(*submap, Compression::kZstd, 3);
  ASSERT_TRUE(v3.ok()) << v3.status().ToString();
  EXPECT_EQ((*v3)[8], 3);
  auto back = SubmapCodec::Decode(*v3);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE((*back)->structure().viewpoints.empty());
  EXPECT_TRUE((*back)->structure().planes.empty());
  EXPECT_EQ((*back)->points().size(), submap->points().size());
  auto v4 = SubmapCodec::Encode(*submap);
  ASSERT_TRUE(v4.ok());
  EXPECT_GT(v4->size(), v3->size());
  const auto v2 = SubmapCodec::Encode(*submap, Compression::kZstd, 2);
  ASSERT_FALSE(v2.ok());
  EXPECT_NE(v2.status().message().find("version 2 cannot be written"), std::string::npos);
}

TEST(SubmapCodecTest, RejectsAPlaneThatIsNotOne) {
  SubmapStructure st = SomeStructure();
  st.planes[1].normal = Eigen::Vector3f(2.0f, 0.0f, 0.0f);
  auto bytes = SubmapCodec::Encode(*WithStructure(*testing::SyntheticSubmap(5), st));
  ASSERT_TRUE(bytes.ok());
  const auto r = SubmapCodec::Decode(*bytes);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(r.status().message().find("submap plane 1: normal is not a unit vector"), std::string::npos)
      << r.status().message();
  st = SomeStructure();
  st.planes[0].covariance(2, 2) = -1.0f;
  bytes = SubmapCodec::Encode(*WithStructure(*testing::SyntheticSubmap(5), st));
  ASSERT_TRUE(bytes.ok());
  EXPECT_NE(SubmapCodec::Decode(*bytes).status().message().find("submap plane 0: covariance"),
            std::string::npos);
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
