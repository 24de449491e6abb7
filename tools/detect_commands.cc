// cairn detect: AprilTag 36h11 tags in a photo (detection/tag_detector.h) and their 6-D poses with
// the uncertainty of thesis 6.2.3's online step (detection/tag_pose_estimator.h), printed as JSON.

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <string>
#include <vector>

#include "common/elapsed.h"
#include "common/json_writer.h"
#include "detection/tag_detector.h"
#include "detection/tag_pose_estimator.h"
#include "drivers/replay/euroc_dataset.h"
#include "io/image_codec.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kDetectUsage =
    "usage: cairn detect IMAGE (--camera SENSOR_YAML | --intrinsics fx,fy,cx,cy[,k1,k2,p1,p2])\n"
    "                    [--tag-size M (0.16)] [--ids LIST] [--decimate F (1)] [--corner-error PX (0.5)]\n"
    "  Finds tag36h11 tags in IMAGE and prints, per tag, its id, corners (px, pixel centres at whole\n"
    "  numbers), T_cam_tag and its 6x6 covariance as JSON.\n"
    "  --camera      a EuRoC/Kalibr sensor.yaml of the camera that took IMAGE\n"
    "  --intrinsics  pinhole focal lengths and centre in px, optionally radial-tangential distortion\n"
    "  --ids         comma-separated ids to keep (default: every id)\n";

void WriteMatrix(JsonWriter& j, const char* key, const Eigen::MatrixXd& m) {
  j.Key(key).BeginArray();
  for (int r = 0; r < m.rows(); ++r) {
    j.BeginArray();
    for (int c = 0; c < m.cols(); ++c) j.Number(m(r, c));
    j.EndArray();
  }
  j.EndArray();
}

// A view of a continuous 8-bit gray cv::Mat (which must outlive it).
Image GrayView(const cv::Mat& m) { return Image::GrayView(m.data, m.cols, m.rows, static_cast<int>(m.step[0])); }

}  // namespace

int RunDetect(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kDetectUsage);
  std::string image_path, camera_path;
  std::vector<double> intrinsics;
  TagDetectorOptions detector_options;
  detector_options.decimate = 1.0;
  TagPoseOptions pose_options;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    std::vector<double> v;
    if (a == "--camera" && has_value) {
      camera_path = args.args[++i];
    } else if (a == "--intrinsics" && has_value) {
      if (!ParseNumberList(args.args[++i], &intrinsics) || (intrinsics.size() != 4 && intrinsics.size() != 8) ||
          intrinsics[0] <= 0 || intrinsics[1] <= 0) {
        std::fprintf(stderr, "cairn detect: --intrinsics needs fx,fy,cx,cy (fx, fy > 0), optionally ,k1,k2,p1,p2\n");
        return 2;
      }
    } else if (a == "--tag-size" && has_value) {
      if (!ParseNumberList(args.args[++i], &v) || v.size() != 1 || !(v[0] > 0)) {
        std::fprintf(stderr, "cairn detect: --tag-size needs one positive number (m)\n");
        return 2;
      }
      pose_options.tag_size = v[0];
    } else if (a == "--ids" && has_value) {
      if (!ParseNumberList(args.args[++i], &detector_options.ids)) {
        std::fprintf(stderr, "cairn detect: --ids needs comma-separated ids\n");
        return 2;
      }
    } else if (a == "--decimate" && has_value) {
      if (!ParseNumberList(args.args[++i], &v) || v.size() != 1 || !(v[0] >= 1.0)) {
        std::fprintf(stderr, "cairn detect: --decimate needs one number >= 1\n");
        return 2;
      }
      detector_options.decimate = v[0];
    } else if (a == "--corner-error" && has_value) {
      if (!ParseNumberList(args.args[++i], &v) || v.size() != 1 || !(v[0] >= 0.0)) {
        std::fprintf(stderr, "cairn detect: --corner-error needs one number >= 0 (px)\n");
        return 2;
      }
      pose_options.corner_error = v[0];
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "cairn detect: unknown or incomplete option '%s'\n%s", a.c_str(), kDetectUsage);
      return 2;
    } else if (image_path.empty()) {
      image_path = a;
    } else {
      std::fprintf(stderr, "cairn detect: one image only ('%s' is extra)\n", a.c_str());
      return 2;
    }
  }
  if (image_path.empty() || camera_path.empty() == intrinsics.empty()) {
    std::fprintf(stderr, "cairn detect: name an image and exactly one of --camera and --intrinsics\n%s",
                 kDetectUsage);
    return 2;
  }
  if (Status s = detector_options.Validate(); !s.ok()) {
    std::fprintf(stderr, "cairn detect: --ids: %s\n", s.message().c_str());
    return 2;
  }
  PinholeRadTan camera;
  if (!camera_path.empty()) {
    auto c = EurocDataset::ReadCameraFile(camera_path);
    if (!c.ok()) {
      std::fprintf(stderr, "cairn detect: %s\n", c.status().ToString().c_str());
      return 1;
    }
    camera = c->intrinsics;
  } else {
    camera.fx = intrinsics[0], camera.fy = intrinsics[1], camera.cx = intrinsics[2], camera.cy = intrinsics[3];
    if (intrinsics.size() == 8) {
      camera.k1 = intrinsics[4], camera.k2 = intrinsics[5], camera.p1 = intrinsics[6], camera.p2 = intrinsics[7];
    }
  }
  const auto read = ImageCodec::Read(image_path, ImageReadMode::kGray8);
  if (!read.ok()) {
    std::fprintf(stderr, "cairn detect: %s\n", read.status().message().c_str());
    return 1;
  }
  const cv::Mat& gray = *read;
  if (camera.width > 0 && (camera.width != gray.cols || camera.height != gray.rows)) {
    std::fprintf(stderr, "cairn detect: %s is %dx%d, the camera in %s is %dx%d\n", image_path.c_str(), gray.cols,
                 gray.rows, camera_path.c_str(), camera.width, camera.height);
    return 1;
  }
  camera.width = gray.cols;
  camera.height = gray.rows;

  TagDetector detector(detector_options);
  const auto start = std::chrono::steady_clock::now();
  const auto found = detector.Detect(GrayView(gray));
  const double detect_ms = MillisecondsSince(start);
  if (!found.ok()) {
    std::fprintf(stderr, "cairn detect: %s: %s\n", image_path.c_str(), found.status().ToString().c_str());
    return 1;
  }
  const TagPoseEstimator estimator(pose_options);
  JsonWriter j;
  j.BeginObject();
  j.Field("image", image_path);
  j.Field("width", gray.cols).Field("height", gray.rows);
  j.Field("tag_frame", "AprilTag: origin at the tag centre, x right, y down as printed, z into the tag");
  j.Field("covariance_order", "rho_x rho_y rho_z phi_x phi_y phi_z: T = T_cam_tag * Exp(rho, phi), tag frame");
  j.Field("detect_ms", detect_ms);
  j.Field("dropped_unknown_ids", detector.counts().unknown_ids);
  j.Field("dropped_low_margin", detector.counts().low_margin);
  j.Key("tags").BeginArray();
  for (const TagDetection& d : *found) {
    j.BeginObject();
    j.Field("id", d.id).Field("hamming", d.hamming).Field("decision_margin", d.decision_margin);
    j.Key("corners").BeginArray();
    for (const Eigen::Vector2d& c : d.corners) j.BeginArray().Number(c.x()).Number(c.y()).EndArray();
    j.EndArray();
    const auto pose = estimator.Estimate(d.corners, camera);
    if (pose.ok()) {
      WriteMatrix(j, "T_cam_tag", pose->T_cam_tag.matrix());
      WriteMatrix(j, "covariance", pose->covariance);
      j.Field("reprojection_error_px", pose->reprojection_error);
      j.Field("distance_m", pose->distance).Field("view_angle_deg", pose->view_angle * 180.0 / M_PI);
      j.Field("flipped_samples", pose->flipped_samples);
      if (pose->has_alternative) {
        WriteMatrix(j, "T_cam_tag_alternative", pose->T_cam_tag_alternative.matrix());
        j.Field("alternative_reprojection_error_px", pose->alternative_reprojection_error);
      }
    } else {
      j.Field("pose_error", pose.status().ToString());
    }
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  std::printf("%s\n", j.str().c_str());
  return 0;
}

}  // namespace cairn::tools
