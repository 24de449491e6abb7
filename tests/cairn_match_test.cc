// `cairn match` on submap files as a user runs it: a matching pair prints the transform, and bad
// files (missing, truncated, empty submaps) end with a clear status naming the file, never a crash.

#include <cmath>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/submap_codec.h"
#include "mapping/testing/rock_field_scene.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

std::string Cairn() { return testing::BinaryDir() + "/tools/cairn"; }

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// The scene is built once: ray casting it is slow under the sanitizers.
class CairnMatchTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    temp_ = std::make_unique<testing::ScopedTempDir>("cairn_match");
    dir_ = temp_->path();
    const testing::ScenePair pair = testing::OverlappingSubmaps(7);
    T_a_b_ = pair.T_world_a.inverse() * pair.T_world_b;
    auto a = SubmapCodec::Encode(*pair.a), b = SubmapCodec::Encode(*pair.b);
    ASSERT_TRUE(a.ok() && b.ok());
    a_bytes_ = *a;
    WriteBytes(dir_ + "/a.submap", *a);
    WriteBytes(dir_ + "/b.submap", *b);
  }
  static void TearDownTestSuite() { temp_.reset(); }
  testing::ProcessResult Match(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {Cairn(), "match"};
    argv.insert(argv.end(), args.begin(), args.end());
    return testing::RunProcess(argv);
  }
  static inline std::unique_ptr<testing::ScopedTempDir> temp_;
  static inline std::string dir_;
  static inline Eigen::Isometry3d T_a_b_;
  static inline std::vector<uint8_t> a_bytes_;
};

TEST_F(CairnMatchTest, AMatchingPairPrintsTheTransform) {
  const auto r = Match({dir_ + "/a.submap", dir_ + "/b.submap"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue j = JsonValue::Parse(r.output);
  ASSERT_EQ(j["status"].string(), "matched") << r.output;
  const JsonValue& t = j["T_a_b"];
  EXPECT_NEAR(t["x"].number(), T_a_b_.translation().x(), 0.05);
  EXPECT_NEAR(t["y"].number(), T_a_b_.translation().y(), 0.05);
  EXPECT_NEAR(t["yaw"].number(), std::atan2(T_a_b_.linear()(1, 0), T_a_b_.linear()(0, 0)), 0.01);
  EXPECT_GT(j["counts"]["icp_inliers"].number(), 300);
}

TEST_F(CairnMatchTest, AMissingFileIsNamed) {
  const auto r = Match({dir_ + "/a.submap", dir_ + "/none.submap"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("none.submap"), std::string::npos) << r.output;
}

TEST_F(CairnMatchTest, ATruncatedFileIsNamedNotCrashedOn) {
  for (const size_t keep : {size_t{0}, size_t{7}, a_bytes_.size() / 2, a_bytes_.size() - 1}) {
    WriteBytes(dir_ + "/cut.submap", std::vector<uint8_t>(a_bytes_.begin(), a_bytes_.begin() + keep));
    const auto r = Match({dir_ + "/cut.submap", dir_ + "/b.submap"});
    EXPECT_EQ(r.exit_code, 1) << keep << " bytes: " << r.output;
    EXPECT_NE(r.output.find("cut.submap"), std::string::npos) << keep << " bytes: " << r.output;
  }
  // One flipped byte in the middle: the checksum names it.
  std::vector<uint8_t> flipped = a_bytes_;
  flipped[flipped.size() / 2] ^= 0x5a;
  WriteBytes(dir_ + "/flipped.submap", flipped);
  const auto r = Match({dir_ + "/flipped.submap", dir_ + "/b.submap"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("flipped.submap"), std::string::npos) << r.output;
}

TEST_F(CairnMatchTest, AnEmptySubmapIsUnsuitableWithTheReason) {
  SubmapMetadata metadata;
  const Submap empty(metadata, {}, MakeOccupancyTree(metadata.options));
  auto bytes = SubmapCodec::Encode(empty);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  WriteBytes(dir_ + "/empty.submap", *bytes);
  const auto r = Match({dir_ + "/empty.submap", dir_ + "/b.submap"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue j = JsonValue::Parse(r.output);
  EXPECT_EQ(j["status"].string(), "unsuitable");
  EXPECT_NE(j["reason"].string().find("submap A: 0 points"), std::string::npos) << r.output;
}

TEST_F(CairnMatchTest, BadOptionsAreRefusedWithUsage) {
  EXPECT_EQ(Match({dir_ + "/a.submap", dir_ + "/b.submap", "--guess", "1,2,nan,0"}).exit_code, 2);
  EXPECT_EQ(Match({dir_ + "/a.submap", dir_ + "/b.submap", "--sigma", "1,1,0,1"}).exit_code, 2);
  const auto r = Match({dir_ + "/a.submap", dir_ + "/b.submap", "--dof", "5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--dof 5: 4 or 6"), std::string::npos) << r.output;
}

TEST_F(CairnMatchTest, TheSixDofVariantPrintsTheFullTransform) {
  const auto r = Match({dir_ + "/a.submap", dir_ + "/b.submap", "--dof", "6"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue j = JsonValue::Parse(r.output);
  ASSERT_EQ(j["status"].string(), "matched") << r.output;
  EXPECT_EQ(j["dof"].number(), 6);
  const JsonValue& t = j["T_a_b"];
  EXPECT_NEAR(t["x"].number(), T_a_b_.translation().x(), 0.05);
  EXPECT_NEAR(t["yaw"].number(), std::atan2(T_a_b_.linear()(1, 0), T_a_b_.linear()(0, 0)), 0.01);
  EXPECT_LT(t["tilt"].number(), 0.01);
  // The matrix holds the estimated roll and pitch: its z column is within the tilt of z.
  EXPECT_NEAR(t["matrix"][size_t{2}][size_t{2}].number(), std::cos(t["tilt"].number()), 1e-9);
}

}  // namespace
}  // namespace cairn
