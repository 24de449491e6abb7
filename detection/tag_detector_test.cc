#include "detection/tag_detector.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <apriltag/tag25h9.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "detection/testing/rendered_tag.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

struct ReferenceTag {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners;
};

// `id, (x y), (x y), (x y), (x y)` per line.
std::vector<ReferenceTag> ReadReference(const std::string& path) {
  std::vector<ReferenceTag> out;
  std::ifstream in(path);
  std::string line;
  const std::regex number(R"([-+]?[0-9]*\.?[0-9]+)");
  while (std::getline(in, line)) {
    std::vector<double> v;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), number); it != std::sregex_iterator(); ++it)
      v.push_back(std::stod(it->str()));
    if (v.size() != 9) continue;
    ReferenceTag t;
    t.id = static_cast<int>(v[0]);
    // The reference uses libapriltag's pixel convention (centres at +0.5); ours has them at 0.
    for (size_t k = 0; k < 4; ++k) t.corners[k] = Eigen::Vector2d(v[1 + 2 * k] - 0.5, v[2 + 2 * k] - 0.5);
    out.push_back(t);
  }
  return out;
}

double CornerError(const std::array<Eigen::Vector2d, 4>& a, const std::array<Eigen::Vector2d, 4>& b) {
  double worst = 0.0;
  for (size_t k = 0; k < 4; ++k) worst = std::max(worst, (a[k] - b[k]).norm());
  return worst;
}

const char* const kPhotos[] = {"33369213973_9d9bb4cc96_c", "34085369442_304b6bafd9_c", "34139872896_defdb2f8d9_c"};

// 47 reference tags in 3 photos. Two are not met: a 12 px tag whose reference has two corners on
// one pixel column (696.0) is not found, and a tag seen nearly edge-on (6 px tall) is found 2.3 px
// from its reference. The test holds the rest to 1 px so that a regression shows.
TEST(TagDetectorTest, RealPhotosReferenceTagsWithinOnePixel) {
  size_t total = 0, within = 0;
  for (const char* name : kPhotos) {
    const std::string base = testing::DataDir() + "/apriltag/" + name;
    CAIRN_REQUIRE_PATH(base + ".jpg");
    const cv::Mat gray = cv::imread(base + ".jpg", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty()) << base;
    const std::vector<ReferenceTag> reference = ReadReference(base + ".txt");
    ASSERT_FALSE(reference.empty()) << base << ".txt";
    TagDetectorOptions o;
    o.decimate = 1.0;  // the photos' tags are 12-40 px wide
    TagDetector detector(o);
    const auto found = detector.Detect(testing::ImageOf(gray));
    ASSERT_TRUE(found.ok()) << found.status().ToString();
    size_t matched = 0;
    for (const ReferenceTag& r : reference) {
      double best = 1e9;
      for (const TagDetection& d : *found) {
        if (d.id == r.id) best = std::min(best, CornerError(d.corners, r.corners));
      }
      matched += best < 1.0;
      if (best >= 1.0) {
        std::printf("[ detect  ] %s: reference tag at (%.1f, %.1f): %s\n", name, r.corners[0].x(), r.corners[0].y(),
                    best > 50.0 ? "not found" : ("worst corner " + std::to_string(best) + " px").c_str());
      }
    }
    std::printf("[ detect  ] %s: %zu of %zu reference tags within 1 px, %zu detections\n", name, matched,
                reference.size(), found->size());
    total += reference.size();
    within += matched;
  }
  EXPECT_EQ(total, 47u);
  EXPECT_GE(within, 45u);
}

TEST(TagDetectorTest, IdsNotConfiguredAreDroppedAndCounted) {
  const cv::Mat tag = testing::RenderTag(7, 0.16, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 1.5)),
                                         PinholeRadTan{640, 480, 500.0, 500.0, 320.0, 240.0});
  TagDetectorOptions o;
  o.ids = {3.0, 11.0};
  TagDetector only_others(o);
  const auto none = only_others.Detect(testing::ImageOf(tag));
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  EXPECT_EQ(only_others.counts().unknown_ids, 1u);
  o.ids = {7.0};
  TagDetector seven(o);
  const auto one = seven.Detect(testing::ImageOf(tag));
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->size(), 1u);
  EXPECT_EQ((*one)[0].id, 7);
  EXPECT_EQ(seven.counts().detections, 1u);
}

TEST(TagDetectorTest, ARegionOfInterestFindsTheSameCorners) {
  const PinholeRadTan camera{1024, 508, 1080.0, 1080.0, 512.0, 254.0};
  const cv::Mat tag = testing::RenderTag(2, 0.16, Eigen::Isometry3d(Eigen::Translation3d(0.4, 0.1, 3.0)), camera);
  TagDetectorOptions o;
  o.decimate = 1.0;  // decimated, the quads fall on another pixel grid in a region at an odd offset
  TagDetector detector(o);
  const auto full = detector.Detect(testing::ImageOf(tag));
  ASSERT_TRUE(full.ok());
  ASSERT_EQ(full->size(), 1u);
  const Eigen::Vector2d c = (*full)[0].center;
  const PixelBox roi{static_cast<int>(c.x()) - 60, static_cast<int>(c.y()) - 60, 120, 120};
  const auto part = detector.Detect(testing::ImageOf(tag), &roi);
  ASSERT_TRUE(part.ok()) << part.status().ToString();
  ASSERT_EQ(part->size(), 1u);
  EXPECT_LT(CornerError((*part)[0].corners, (*full)[0].corners), 0.1);
  // A region away from the tag sees nothing.
  const PixelBox empty_corner{0, 0, 100, 100};
  const auto nothing = detector.Detect(testing::ImageOf(tag), &empty_corner);
  ASSERT_TRUE(nothing.ok());
  EXPECT_TRUE(nothing->empty());
}

TEST(TagDetectorTest, BadImagesAndRegionsAreRefusedWithTheReason) {
  TagDetector detector;
  EXPECT_NE(detector.Detect(Image{}).status().message().find("empty image"), std::string::npos);
  cv::Mat gray(100, 120, CV_8UC1, cv::Scalar(90));
  Image colour = testing::ImageOf(gray);
  colour.format = PixelFormat::kRgb8;
  EXPECT_NE(detector.Detect(colour).status().message().find("gray"), std::string::npos);
  Image short_stride = testing::ImageOf(gray);
  short_stride.stride = 60;
  EXPECT_NE(detector.Detect(short_stride).status().message().find("stride"), std::string::npos);
  for (const PixelBox& bad : {PixelBox{-1, 0, 10, 10}, PixelBox{0, 0, 0, 10}, PixelBox{100, 0, 30, 10},
                              PixelBox{0, 95, 10, 10}}) {
    const auto r = detector.Detect(testing::ImageOf(gray), &bad);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("not inside"), std::string::npos) << r.status().message();
  }
  EXPECT_EQ(detector.counts().bad_images, 7u);
  // A plain image is fine and has no tags.
  const auto plain = detector.Detect(testing::ImageOf(gray));
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->empty());
}

// Tags of another family, and a tag seen almost edge-on, are simply not found: no crash, no
// false id.
TEST(TagDetectorTest, OtherFamiliesAndEdgeOnTagsAreNotReported) {
  const PinholeRadTan camera{640, 480, 500.0, 500.0, 320.0, 240.0};
  const Eigen::Isometry3d ahead(Eigen::Translation3d(0.0, 0.0, 1.0));
  cv::Mat other(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  apriltag_family_t* family = tag25h9_create();
  testing::DrawTag(other, 3, 0.16, ahead, camera, 0.6, family);
  tag25h9_destroy(family);
  TagDetectorOptions o;
  o.decimate = 1.0;
  TagDetector detector(o);
  const auto none = detector.Detect(testing::ImageOf(other));
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  Eigen::Isometry3d edge_on = ahead;
  edge_on.linear() = Eigen::AngleAxisd(89.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto edge = detector.Detect(testing::ImageOf(testing::RenderTag(3, 0.16, edge_on, camera)));
  ASSERT_TRUE(edge.ok());
  EXPECT_TRUE(edge->empty());
  // The same tag turned 60 deg is still found.
  edge_on.linear() = Eigen::AngleAxisd(60.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto turned = detector.Detect(testing::ImageOf(testing::RenderTag(3, 0.16, edge_on, camera)));
  ASSERT_TRUE(turned.ok());
  EXPECT_EQ(turned->size(), 1u);
}

TEST(TagDetectorTest, InvalidIdsFailEveryDetectionWithTheReason) {
  TagDetectorOptions o;
  o.ids = {2.5};
  TagDetector detector(o);
  cv::Mat gray(50, 50, CV_8UC1, cv::Scalar(90));
  const auto r = detector.Detect(testing::ImageOf(gray));
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("whole numbers"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace cairn
