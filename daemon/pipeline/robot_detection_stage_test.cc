#include "daemon/pipeline/robot_detection_stage.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "detection/testing/rendered_tag.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

RectifiedStereoCamera Camera() {
  RectifiedStereoCamera c;
  c.width = 1024;
  c.height = 508;
  c.f = 1080.0;
  c.cx = 512.0;
  c.cy = 254.0;
  c.baseline = 0.3;
  return c;
}

PinholeRadTan Pinhole() { return PinholeRadTan{1024, 508, 1080.0, 1080.0, 512.0, 254.0}; }

// Camera looking along the body's x axis (z forward, x right, y down), on a mast.
Eigen::Isometry3d BodyCam() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0.2, 0.0, 0.6);
  return T;
}

// A tag facing out of the carrier's back, raised 40 deg (as on the simulated rovers' masts).
Eigen::Isometry3d CarrierFace() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(std::numbers::pi / 2 - 40 * kDeg, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.08, 0.0, 0.8);
  return T;
}

TagCarrierTable Table() {
  TagCarrierTable t;
  EXPECT_TRUE(t.Add(0, "rover", false, 0.16, CarrierFace()).ok());
  EXPECT_TRUE(t.Add(10, "rover2", false, 0.16, CarrierFace()).ok());
  Eigen::Isometry3d lander_face = Eigen::Isometry3d::Identity();
  lander_face.linear() = (Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()) *
                          Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitZ()))
                             .toRotationMatrix();  // facing +x, printed upright
  lander_face.translation() = Eigen::Vector3d(0.81, 0.0, 0.2);
  EXPECT_TRUE(t.Add(200, "lander", true, 0.32, lander_face).ok());
  return t;
}

RobotDetectionOptions DetectionOptions() {
  RobotDetectionOptions o;
  o.enabled = true;
  o.detector.decimate = 1.0;
  o.max_sigma_rotation = 3.0;  // a small tag's tilt is poorly known (eq. 6.9): kept, with its sigma
  o.roi_every_nth_frame = o.every_nth_frame;  // every image scanned whole (regions: their own test)
  return o;
}

// The tag `id` of the table in view at T_cam_tag; returns the carrier's body in the observer's.
Eigen::Isometry3d Observed(const TagCarrierTable& table, int id, const Eigen::Isometry3d& T_cam_tag) {
  return BodyCam() * T_cam_tag * table.Find(id)->T_carrier_tag.inverse();
}

Eigen::Isometry3d TagInView(double distance, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.15, 0.05, distance);
  return T;
}

// The model the options name, with the rover's shipped table for the whole-frame scans' decimation
// (this camera is the rover's).
TagErrorModel ModelFor(const RobotDetectionOptions& o) {
  const std::string table = o.detector.decimate == 1.0 ? "rover_d1.lut" : "rover.lut";
  auto m = RobotDetectionStage::MakeErrorModel(o, testing::SourceDir() + "/configs/detection/" + table,
                                               o.detector.decimate, Camera());
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return *m;
}

RectifiedPair PairOf(const cv::Mat& left, int64_t time_ns) {
  RectifiedPair p;
  p.time = Timestamp::FromNanoseconds(time_ns);
  p.left = testing::ImageOf(left);
  p.right = p.left;
  return p;
}

TEST(RobotDetectionStageTest, ATeammatesTagGivesItsBodyInOursAtTheExposureTime) {
  const TagCarrierTable table = Table();
  RobotDetectionStage stage(DetectionOptions(), table, ModelFor(DetectionOptions()), Camera(), BodyCam(), "hexacopter", 'b');
  const Eigen::Isometry3d T_cam_tag = TagInView(3.0, 25 * kDeg);
  const cv::Mat image = testing::RenderTag(10, 0.16, T_cam_tag, Pinhole());
  std::vector<TagSighting> out;
  stage.Process(PairOf(image, 123456789), &out);
  ASSERT_EQ(out.size(), 1u);
  const TeamDetection& d = out[0].detection;
  EXPECT_TRUE(out[0].usable) << out[0].refused;
  EXPECT_EQ(d.observer, "hexacopter");
  EXPECT_EQ(d.observer_letter, 'b');
  EXPECT_EQ(d.observed, "rover2");
  EXPECT_FALSE(d.landmark);
  EXPECT_EQ(d.tag_id, 10);
  EXPECT_EQ(d.time.nanoseconds(), 123456789);
  const Eigen::Isometry3d truth = Observed(table, 10, T_cam_tag);
  const auto dev = TagPoseEstimator::Deviation(truth, d.T_observer_observed);
  EXPECT_LT(dev.head<3>().norm(), 0.03) << dev.transpose();
  EXPECT_LT(dev.tail<3>().norm(), 2 * kDeg) << dev.transpose();
  EXPECT_EQ(d.covariance.llt().info(), Eigen::Success);
  EXPECT_NEAR(d.distance, T_cam_tag.translation().norm(), 0.05);
  EXPECT_EQ(stage.report().usable, 1u);
}

TEST(RobotDetectionStageTest, OwnTagsAreDroppedFarTagsRefusedLandmarksKept) {
  const TagCarrierTable table = Table();
  RobotDetectionOptions o = DetectionOptions();
  o.max_distance = 3.5;
  RobotDetectionStage stage(o, table, ModelFor(o), Camera(), BodyCam(), "rover", 'a');
  cv::Mat image(508, 1024, CV_8UC1, cv::Scalar(128));
  Eigen::Isometry3d own = TagInView(2.0, 0.0);
  own.translation().x() = -0.6;
  Eigen::Isometry3d lander = TagInView(3.0, -20 * kDeg);
  lander.translation().x() = 0.6;
  testing::DrawTag(image, 0, 0.16, own, Pinhole());
  testing::DrawTag(image, 200, 0.32, lander, Pinhole());
  std::vector<TagSighting> out;
  stage.Process(PairOf(image, 1), &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].detection.landmark);
  EXPECT_EQ(out[0].detection.observed, "lander");
  EXPECT_TRUE(out[0].usable) << out[0].refused;
  EXPECT_EQ(stage.report().own_tags, 1u);

  // The same landmark beyond the distance bound: handed on, refused with the reason.
  const cv::Mat far = testing::RenderTag(200, 0.32, TagInView(5.0, 0.0), Pinhole());
  out.clear();
  stage.Process(PairOf(far, 2), &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].usable);
  EXPECT_NE(out[0].refused.find("farther than 3.5 m"), std::string::npos) << out[0].refused;
  EXPECT_EQ(stage.report().refused, 1u);
}

TEST(RobotDetectionStageTest, AnErrorTableOfAnotherCameraOrAMissingOneIsRefusedAtStartUp) {
  RobotDetectionOptions o = DetectionOptions();
  const std::string dir = testing::SourceDir() + "/configs/detection/";
  // The hexacopter's table on the rover's camera: another field of view.
  auto m = RobotDetectionStage::MakeErrorModel(o, dir + "hexacopter.lut", 2.0, Camera());
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("detection.error_table: " + dir + "hexacopter.lut was built for a 666 px wide"),
            std::string::npos)
      << m.status().message();
  // The rover's table on the rover's camera at half resolution is fine (same field of view).
  RectifiedStereoCamera half = Camera();
  half.width /= 2;
  half.height /= 2;
  half.f /= 2;
  EXPECT_TRUE(RobotDetectionStage::MakeErrorModel(o, dir + "rover.lut", 2.0, half).ok());
  // A table holds for the decimation it was built at.
  m = RobotDetectionStage::MakeErrorModel(o, dir + "rover.lut", 1.0, Camera(), "detection.region_error_table");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("detection.region_error_table: " + dir +
                                      "rover.lut was built for detections at decimate 2.00, these are made at 1.00"),
            std::string::npos)
      << m.status().message();
  EXPECT_TRUE(RobotDetectionStage::MakeErrorModel(o, dir + "rover_d1.lut", 1.0, Camera()).ok());
  m = RobotDetectionStage::MakeErrorModel(o, dir + "nonexistent.lut", 2.0, Camera());
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("nonexistent.lut"), std::string::npos);
  m = RobotDetectionStage::MakeErrorModel(o, "", 2.0, Camera());  // combined needs a table
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("needs an error table"), std::string::npos) << m.status().message();
  o.error_model = "online";
  EXPECT_TRUE(RobotDetectionStage::MakeErrorModel(o, "", 2.0, Camera()).ok());
  o.error_model = "gaussian";
  m = RobotDetectionStage::MakeErrorModel(o, "", 2.0, Camera());
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("detection.error_model"), std::string::npos) << m.status().message();
}

// Between whole-frame scans (decimate 2, every 4th frame) the stage searches only around the tags
// it saw lately, at full resolution: it follows a teammate's tag to where the whole-frame scan
// no longer finds it, and stops looking once the tag has been gone for the track timeout.
TEST(RobotDetectionStageTest, RegionScansFollowATagBetweenWholeFrameScans) {
  RobotDetectionOptions o = DetectionOptions();
  o.detector.decimate = 2.0;
  o.every_nth_frame = 4;
  o.roi_every_nth_frame = 1;  // every 4th frame whole, the 3 between in regions
  o.track_timeout = 1.0;
  o.max_distance = 20.0;
  RobotDetectionStage stage(o, Table(), ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  std::vector<TagSighting> out;
  const auto at = [&](double distance) {
    Eigen::Isometry3d T = TagInView(distance, 10 * kDeg);
    T.translation().head<2>() *= distance / 3.0;  // the same place in the image
    return T;
  };
  stage.Process(PairOf(testing::RenderTag(10, 0.16, at(4.0), Pinhole()), 0), &out);  // whole
  ASSERT_EQ(out.size(), 1u);
  const cv::Mat far = testing::RenderTag(10, 0.16, at(11.0), Pinhole());
  out.clear();
  stage.Process(PairOf(testing::RenderTag(10, 0.16, at(6.0), Pinhole()), 100'000'000), &out);  // region
  stage.Process(PairOf(far, 200'000'000), &out);                                                // region
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[1].detection.distance, 11.0, 0.5);
  // The whole-frame scan at decimate 2 does not find the tag at 11 m.
  TagDetectorOptions whole = o.detector;
  EXPECT_TRUE(TagDetector(whole).Detect(testing::ImageOf(far))->empty());
  EXPECT_EQ(stage.report().full_scans, 1u);
  EXPECT_EQ(stage.report().region_scans, 2u);
  EXPECT_EQ(stage.report().tags_in_regions, 2u);
  // Gone: region scans find nothing until the track times out, then the frames between whole
  // scans cost nothing.
  const cv::Mat empty(508, 1024, CV_8UC1, cv::Scalar(128));
  out.clear();
  stage.Process(PairOf(empty, 300'000'000), &out);    // region, nothing
  stage.Process(PairOf(empty, 400'000'000), &out);    // whole, nothing
  stage.Process(PairOf(empty, 1'500'000'000), &out);  // region: the track has timed out
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(stage.report().full_scans, 2u);
  EXPECT_EQ(stage.report().region_scans, 3u);
  EXPECT_EQ(stage.report().idle, 1u);
  EXPECT_GT(stage.region_time().count(), 0u);
}

// The region scans' sightings take the error model of their decimation, the whole-frame scans'
// that of theirs (quads found at full resolution have better corners).
TEST(RobotDetectionStageTest, RegionScansTakeTheErrorModelOfTheirDecimation) {
  RobotDetectionOptions o = DetectionOptions();
  o.detector.decimate = 2.0;
  o.every_nth_frame = 2;
  o.roi_every_nth_frame = 1;
  // A region model that cannot be mistaken: eq. 8.1's constant sigmas.
  RobotDetectionOptions constant = o;
  constant.error_model = "constant";
  auto region = RobotDetectionStage::MakeErrorModel(constant, "", 1.0, Camera(), "detection.region_error_table");
  ASSERT_TRUE(region.ok()) << region.status().ToString();
  const TagCarrierTable table = Table();
  RobotDetectionStage own(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b', *region);
  RobotDetectionStage shared(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  const cv::Mat image = testing::RenderTag(10, 0.16, TagInView(4.0, 20 * kDeg), Pinhole());
  std::vector<TagSighting> a, b;
  for (int64_t t : {0, 100'000'000}) {  // whole, then region
    own.Process(PairOf(image, t), &a);
    shared.Process(PairOf(image, t), &b);
  }
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(own.report().region_scans, 1u);
  EXPECT_TRUE(a[0].detection.covariance.isApprox(b[0].detection.covariance));
  EXPECT_TRUE(b[1].detection.covariance.isApprox(b[0].detection.covariance, 0.05));  // the same quad, the same model
  Eigen::Matrix<double, 6, 1> sigma2;
  sigma2 << 1e-4, 1e-4, 1e-4, 5e-4, 5e-4, 5e-4;
  const Matrix6d expected =
      RobotDetectionStage::CarrierCovariance(sigma2.asDiagonal(), table.Find(10)->T_carrier_tag.inverse());
  EXPECT_TRUE(a[1].detection.covariance.isApprox(expected, 1e-9)) << a[1].detection.covariance;
}

// Where the graph would place a carrier whose tag `id` the camera sees at T_cam_tag, its place
// moved by `offset` (global axes), with this robot at the global origin at time 0.
CarrierPredictions PredictionOf(const TagCarrierTable& table, int id, const Eigen::Isometry3d& T_cam_tag,
                                const Eigen::Vector3d& offset, double carrier_time) {
  CarrierPredictions p;
  p.valid = true;
  p.time = Timestamp::FromNanoseconds(0);
  const TagMount* mount = table.Find(id);
  CarrierPredictions::Carrier c;
  c.name = mount->carrier;
  c.landmark = mount->landmark;
  c.time = Timestamp::FromNanoseconds(static_cast<int64_t>(carrier_time * 1e9));
  c.T_global_carrier = p.T_global_body * BodyCam() * T_cam_tag * mount->T_carrier_tag.inverse();
  c.T_global_carrier.translation() += offset;
  p.carriers.push_back(c);
  return p;
}

// A teammate 11 m away is beyond the reach of the whole-frame scans at decimate 2; where the
// graph places it (0.3 m off, within its margin), the stage searches at full resolution and finds
// it, on the whole-frame scan's image and on the images between, where nothing is tracked.
TEST(RobotDetectionStageTest, PredictedRegionsFindATeammateBeyondTheWholeFrameScansReach) {
  RobotDetectionOptions o = DetectionOptions();
  o.detector.decimate = 2.0;
  o.every_nth_frame = 2;
  o.roi_every_nth_frame = 1;
  o.max_distance = 20.0;
  o.track_timeout = 0.05;  // the next image searches the prediction, not the track
  const TagCarrierTable table = Table();
  Eigen::Isometry3d T_cam_tag = TagInView(11.0, 10 * kDeg);
  T_cam_tag.translation().head<2>() *= 11.0 / 3.0;
  const cv::Mat far = testing::RenderTag(10, 0.16, T_cam_tag, Pinhole());
  ASSERT_TRUE(TagDetector(o.detector).Detect(testing::ImageOf(far))->empty());
  const CarrierPredictions predicted = PredictionOf(table, 10, T_cam_tag, {0.2, -0.2, 0.1}, 0.0);

  RobotDetectionStage blind(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  std::vector<TagSighting> out;
  blind.Process(PairOf(far, 0), &out);            // whole
  blind.Process(PairOf(far, 100'000'000), &out);  // between: nothing tracked, idle
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(blind.report().idle, 1u);

  RobotDetectionStage stage(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  stage.Process(PairOf(far, 0), &predicted, &out);            // whole, then the prediction
  stage.Process(PairOf(far, 100'000'000), &predicted, &out);  // between
  ASSERT_EQ(out.size(), 2u);
  for (const TagSighting& s : out) {
    EXPECT_EQ(s.detection.observed, "rover2");
    EXPECT_NEAR(s.detection.distance, T_cam_tag.translation().norm(), 0.5);
  }
  EXPECT_EQ(stage.report().predictions, 2u);
  EXPECT_EQ(stage.report().predicted_regions, 2u);
  EXPECT_EQ(stage.report().tags_in_predicted_regions, 2u);
  EXPECT_EQ(stage.report().idle, 0u);
  // With the tag tracked, its region is searched instead of the prediction.
  o.track_timeout = 1.0;
  RobotDetectionStage tracking(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  out.clear();
  tracking.Process(PairOf(far, 0), &predicted, &out);
  tracking.Process(PairOf(far, 100'000'000), &predicted, &out);
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(tracking.report().predicted_regions, 1u);
  EXPECT_EQ(tracking.report().tags_in_regions, 1u);
}

TEST(RobotDetectionStageTest, PredictedRegionsCoverTheCarrierAndGrowWithTheEstimatesAge) {
  RobotDetectionOptions o = DetectionOptions();
  o.max_distance = 20.0;
  const TagCarrierTable table = Table();
  RobotDetectionStage stage(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  Eigen::Isometry3d T_cam_tag = TagInView(15.0, 0.0);
  const Eigen::Vector2d centre(1080.0 * T_cam_tag.translation().x() / 15.0 + 512.0,
                               1080.0 * T_cam_tag.translation().y() / 15.0 + 254.0);
  const auto region = [&](const CarrierPredictions& p, double at) {
    std::vector<RobotDetectionStage::PredictedRegion> r;
    stage.PredictRegions(p, Timestamp::FromNanoseconds(static_cast<int64_t>(at * 1e9)), &r);
    return r;
  };
  // Off by the margin: the tag's true place is inside.
  const auto fresh = region(PredictionOf(table, 10, T_cam_tag, {0.0, 0.5, 0.0}, 0.0), 0.0);
  ASSERT_EQ(fresh.size(), 1u);
  EXPECT_EQ(fresh[0].carrier, "rover2");
  const PixelBox& b = fresh[0].box;
  EXPECT_TRUE(centre.x() > b.x && centre.x() < b.x + b.width && centre.y() > b.y && centre.y() < b.y + b.height);
  // The teammate's estimate a second old: a larger region; this robot's 50 ms old: larger still.
  const auto old = region(PredictionOf(table, 10, T_cam_tag, Eigen::Vector3d::Zero(), -1.0), 0.0);
  const auto both = region(PredictionOf(table, 10, T_cam_tag, Eigen::Vector3d::Zero(), -1.0), 0.05);
  ASSERT_EQ(old.size(), 1u);
  ASSERT_EQ(both.size(), 1u);
  EXPECT_GT(old[0].box.width, fresh[0].box.width);
  EXPECT_GT(both[0].box.width * both[0].box.height, old[0].box.width * old[0].box.height);
  // The lander does not move: its age is this robot's only.
  Eigen::Isometry3d T_cam_lander_tag = TagInView(10.0, 0.0);
  const auto lander = region(PredictionOf(table, 200, T_cam_lander_tag, Eigen::Vector3d::Zero(), -100.0), 0.0);
  ASSERT_EQ(lander.size(), 1u);
  EXPECT_EQ(lander[0].carrier, "lander");
}

TEST(RobotDetectionStageTest, PredictionsThatCannotHelpMakeNoRegion) {
  RobotDetectionOptions o = DetectionOptions();
  o.max_distance = 20.0;
  const TagCarrierTable table = Table();
  RobotDetectionStage stage(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  const auto count = [&](const CarrierPredictions& p, double at = 0.0) {
    std::vector<RobotDetectionStage::PredictedRegion> r;
    stage.PredictRegions(p, Timestamp::FromNanoseconds(static_cast<int64_t>(at * 1e9)), &r);
    return r.size();
  };
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  ASSERT_EQ(count(PredictionOf(table, 10, TagInView(8.0, 0.0), zero, 0.0)), 1u);
  CarrierPredictions unplaced = PredictionOf(table, 10, TagInView(8.0, 0.0), zero, 0.0);
  unplaced.valid = false;  // this robot not placed
  EXPECT_EQ(count(unplaced), 0u);
  Eigen::Isometry3d behind = TagInView(8.0, 0.0);
  behind.translation().z() = -8.0;
  EXPECT_EQ(count(PredictionOf(table, 10, behind, zero, 0.0)), 0u);
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(8.0, 100 * kDeg), zero, 0.0)), 0u);  // facing away
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(30.0, 0.0), zero, 0.0)), 0u);        // beyond max_distance
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(0.8, 0.0), zero, 0.0)), 0u);         // within reach: anywhere
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(8.0, 0.0), zero, -11.0)), 0u);       // older than max_age
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(8.0, 0.0), zero, 0.0), 11.0), 0u);   // so is this robot's
  EXPECT_EQ(count(PredictionOf(table, 10, TagInView(8.0, 0.0), zero, -5.0)), 0u);        // larger than max_area
  EXPECT_EQ(count(PredictionOf(table, 0, TagInView(8.0, 0.0), zero, 0.0)), 1u);          // the rover: a teammate
  RobotDetectionStage rover(o, table, ModelFor(o), Camera(), BodyCam(), "rover", 'a');
  std::vector<RobotDetectionStage::PredictedRegion> own;
  rover.PredictRegions(PredictionOf(table, 0, TagInView(8.0, 0.0), zero, 0.0), Timestamp::FromNanoseconds(0), &own);
  EXPECT_TRUE(own.empty());  // its own tags
  o.predicted_regions = false;
  RobotDetectionStage off(o, table, ModelFor(o), Camera(), BodyCam(), "hexacopter", 'b');
  const CarrierPredictions p = PredictionOf(table, 10, TagInView(8.0, 0.0), zero, 0.0);
  std::vector<TagSighting> out;
  off.Process(PairOf(cv::Mat(508, 1024, CV_8UC1, cv::Scalar(128)), 0), &p, &out);
  EXPECT_EQ(off.report().predictions, 0u);
  EXPECT_EQ(off.report().predicted_regions, 0u);
}

TEST(RobotDetectionStageTest, RegionsGrowByTheMarginsAndStayInsideTheImage) {
  PixelBox b = RobotDetectionStage::Region({100, 50}, {140, 70}, 1024, 508, 0.5, 10);  // extent 40: 30 px
  EXPECT_EQ(b.x, 70);
  EXPECT_EQ(b.y, 20);
  EXPECT_EQ(b.width, 101);
  EXPECT_EQ(b.height, 81);
  b = RobotDetectionStage::Region({-50, -50}, {10, 10}, 1024, 508, 0.0, 5);
  EXPECT_EQ(b.x, 0);
  EXPECT_EQ(b.y, 0);
  EXPECT_EQ(b.width, 16);
  b = RobotDetectionStage::Region({2000, 10}, {2100, 20}, 1024, 508, 0.0, 5);
  EXPECT_EQ(b.width, 0);
}

TEST(RobotDetectionStageTest, BadImagesAreCountedNotFatal) {
  RobotDetectionStage stage(DetectionOptions(), Table(), ModelFor(DetectionOptions()), Camera(), BodyCam(), "rover", 'a');
  std::vector<TagSighting> out;
  stage.Process(RectifiedPair{}, &out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(stage.report().bad_images, 1u);
  ASSERT_EQ(stage.report().errors.size(), 1u);
}

TEST(RobotDetectionStageTest, CarrierCovarianceIsTheFirstOrderPropagation) {
  const Eigen::Isometry3d T_cam_tag = TagInView(2.0, 0.3);
  const Eigen::Isometry3d T_tag_carrier = Table().Find(0)->T_carrier_tag.inverse();
  // Columns of the Jacobian by finite differences of the decoupled right perturbation.
  Matrix6d J;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    delta[k] = h;
    Eigen::Isometry3d P = T_cam_tag;
    P.translation() += T_cam_tag.linear() * delta.head<3>();
    P.linear() = T_cam_tag.linear() * Eigen::AngleAxisd(delta.tail<3>().norm(), k >= 3 ? delta.tail<3>().normalized()
                                                                                        : Eigen::Vector3d::UnitX())
                                          .toRotationMatrix();
    J.col(k) = TagPoseEstimator::Deviation(T_cam_tag * T_tag_carrier, P * T_tag_carrier) / h;
  }
  Matrix6d tag_cov = Matrix6d::Zero();
  tag_cov.diagonal() << 1e-4, 2e-4, 9e-4, 1e-3, 4e-4, 2e-5;
  const Matrix6d expected = J * tag_cov * J.transpose();
  const Matrix6d got = RobotDetectionStage::CarrierCovariance(tag_cov, T_tag_carrier);
  EXPECT_LT((got - expected).norm(), 1e-6 * expected.norm()) << got << "\n\n" << expected;
}

}  // namespace
}  // namespace cairn
