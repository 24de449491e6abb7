// `cairn detect` as a user runs it: real photos, a rendered tag at a known pose, and bad input.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "detection/testing/rendered_tag.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

testing::ProcessResult Detect(std::vector<std::string> args) {
  args.insert(args.begin(), {testing::BinaryDir() + "/tools/cairn", "detect"});
  return testing::RunProcess(args);
}

TEST(CairnDetectTest, ARenderedTagIsWhereItWasDrawn) {
  const testing::ScopedTempDir temp("cairn_detect");
  const std::string dir = temp.path();
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

TEST(CairnDetectTest, BuildLutWritesATableThatCheckLutScoresEveryModelOn) {
  const testing::ScopedTempDir temp("cairn_detect_lut");
  const std::string dir = temp.path();
  const std::string table = dir + "/rover.lut";
  auto r = Detect({"build-lut", "--camera", "rover", "--out", table, "--distances", "1,4,2", "--angles", "0,40,2",
                   "--samples", "3", "--seed", "5", "--decimate", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue built = JsonValue::Parse(r.output.substr(r.output.find('{')));
  EXPECT_GE(built["rendered"].number(), 10);  // of 12: a near tag may not fit in 32 random places
  EXPECT_GT(built["detected"].number(), 6);
  EXPECT_GT(built["corner_rms_px"].number(), 0.0);
  EXPECT_LT(built["corner_rms_px"].number(), 1.0);
  const std::string csv = dir + "/sightings.csv";
  r = Detect({"check-lut", table, "--samples", "12", "--seed", "6", "--sightings-csv", csv});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue checked = JsonValue::Parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(checked["camera"].string(), "rover");
  EXPECT_EQ(checked["decimate"].number(), 1.0);  // the table's, unless told otherwise
  ASSERT_EQ(checked["models"].array().size(), 7u);
  EXPECT_EQ(checked["models"][0]["model"].string(), "combined");
  EXPECT_GT(checked["detected"].number(), 0);
  for (const JsonValue& m : checked["models"].array()) EXPECT_GT(m["mean_nees"].number(), 0.0) << m["model"].string();
  // One row per sighting scored, every row as wide as the header.
  std::ifstream rows(csv);
  std::string line;
  ASSERT_TRUE(std::getline(rows, line));
  const auto columns = std::count(line.begin(), line.end(), ',');
  EXPECT_NE(line.find("corner_jacobian47"), std::string::npos);
  int scored = 0;
  while (std::getline(rows, line)) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), columns);
    ++scored;
  }
  EXPECT_EQ(scored, checked["detected"].number() - checked["refused_residual"].number());
  // Bad input: an unknown camera, a grid backwards, a table that is not one.
  r = Detect({"build-lut", "--camera", "drone", "--out", table});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--camera must be rover or hexacopter, not 'drone'"), std::string::npos) << r.output;
  r = Detect({"build-lut", "--camera", "mine", "--intrinsics", "640,480,0,500", "--out", table});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--intrinsics needs W,H,FX,FY"), std::string::npos) << r.output;
  r = Detect({"build-lut", "--camera", "rover", "--out", table, "--distances", "4,1,3"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--distances: bad value"), std::string::npos) << r.output;
  r = Detect({"check-lut", testing::SourceDir() + "/configs/rover.yaml"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("rover.yaml:"), std::string::npos) << r.output;
}

TEST(CairnDetectTest, BadInputEndsWithAStatusNamingIt) {
  const testing::ScopedTempDir temp("cairn_detect_bad");
  const std::string dir = temp.path();
  auto r = Detect({dir + "/none.png", "--intrinsics", "1,1,1,1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no such image file " + dir + "/none.png"), std::string::npos) << r.output;
  {
    std::FILE* f = std::fopen((dir + "/broken.png").c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs("\x89PNG not really", f);
    std::fclose(f);
  }
  r = Detect({dir + "/broken.png", "--intrinsics", "1,1,1,1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("broken.png: not a PNG, JPEG or binary PGM/PPM image"), std::string::npos) << r.output;
  r = Detect({dir + "/broken.png", "--camera", dir + "/missing.yaml"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("missing.yaml"), std::string::npos) << r.output;
  EXPECT_EQ(Detect({dir + "/broken.png"}).exit_code, 2);  // no calibration
  EXPECT_EQ(Detect({dir + "/broken.png", "--intrinsics", "0,1,1,1"}).exit_code, 2);
  EXPECT_EQ(Detect({dir + "/broken.png", "--intrinsics", "1,1,1,1", "--ids", "2.5"}).exit_code, 2);
}

}  // namespace
}  // namespace cairn
