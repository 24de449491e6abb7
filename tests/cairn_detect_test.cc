// `cairn detect` as a user runs it: real photos, a rendered tag at a known pose, and bad input.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "detection/testing/rendered_tag.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

testing::ProcessResult Detect(std::vector<std::string> args) {
  args.insert(args.begin(), {testing::BinaryDir() + "/tools/cairn", "detect"});
  return testing::RunProcess(args);
}

TEST(CairnDetectTest, ARenderedTagIsWhereItWasDrawn) {
  const std::string dir = testing::FreshTempDir("cairn_detect");
  const PinholeRadTan camera{1024, 508, 1080.0, 1080.0, 512.0, 254.0};
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(0.3, -0.1, 1.8);
  truth.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix();
  ASSERT_TRUE(cv::imwrite(dir + "/tag.png", testing::RenderTag(4, 0.16, truth, camera)));
  const auto r = Detect({dir + "/tag.png", "--intrinsics", "1080,1080,512,254", "--tag-size", "0.16"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue j = JsonValue::Parse(r.output);
  ASSERT_EQ(j["tags"].array().size(), 1u) << r.output;
  const JsonValue& tag = j["tags"][0];
  EXPECT_EQ(tag["id"].number(), 4);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(tag["T_cam_tag"][k][3].number(), truth.translation()[k], 0.01) << k;
  for (int k = 0; k < 6; ++k) EXPECT_GT(tag["covariance"][k][k].number(), 0.0) << k;
  // Only other ids wanted: nothing, and the drop is counted.
  const auto none = Detect({dir + "/tag.png", "--intrinsics", "1080,1080,512,254", "--ids", "1,2"});
  ASSERT_EQ(none.exit_code, 0) << none.output;
  const JsonValue n = JsonValue::Parse(none.output);
  EXPECT_EQ(n["tags"].array().size(), 0u);
  EXPECT_EQ(n["dropped_unknown_ids"].number(), 1);
}

TEST(CairnDetectTest, ARealPhotoHasItsTwelveTags) {
  const std::string photo = testing::DataDir() + "/apriltag/33369213973_9d9bb4cc96_c.jpg";
  CAIRN_REQUIRE_PATH(photo);
  const auto r = Detect({photo, "--intrinsics", "700,700,399.5,266", "--tag-size", "0.1"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(JsonValue::Parse(r.output)["tags"].array().size(), 12u);
}

TEST(CairnDetectTest, BadInputEndsWithAStatusNamingIt) {
  const std::string dir = testing::FreshTempDir("cairn_detect_bad");
  auto r = Detect({dir + "/none.png", "--intrinsics", "1,1,1,1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("none.png: no such file"), std::string::npos) << r.output;
  {
    std::FILE* f = std::fopen((dir + "/broken.png").c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs("\x89PNG not really", f);
    std::fclose(f);
  }
  r = Detect({dir + "/broken.png", "--intrinsics", "1,1,1,1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("broken.png: cannot read the image"), std::string::npos) << r.output;
  r = Detect({dir + "/broken.png", "--camera", dir + "/missing.yaml"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("missing.yaml"), std::string::npos) << r.output;
  EXPECT_EQ(Detect({dir + "/broken.png"}).exit_code, 2);  // no calibration
  EXPECT_EQ(Detect({dir + "/broken.png", "--intrinsics", "0,1,1,1"}).exit_code, 2);
  EXPECT_EQ(Detect({dir + "/broken.png", "--intrinsics", "1,1,1,1", "--ids", "2.5"}).exit_code, 2);
}

}  // namespace
}  // namespace cairn
