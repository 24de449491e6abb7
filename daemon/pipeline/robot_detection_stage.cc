#include "daemon/pipeline/robot_detection_stage.h"

#include <cmath>

#include "common/monotonic_clock.h"

namespace cairn {
namespace {

constexpr size_t kMaxErrors = 10;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

std::string Fixed(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

Expected<TagErrorModel> RobotDetectionStage::MakeErrorModel(const RobotDetectionOptions& options,
                                                            const std::string& table_path,
                                                            const RectifiedStereoCamera& camera) {
  auto kind = ParseTagErrorKind(options.error_model);
  if (!kind.ok()) return kind.status().WithContext("detection.error_model");
  std::shared_ptr<const TagErrorTable> table;
  double scale = 1.0;
  if (!table_path.empty()) {
    auto loaded = TagErrorTable::Load(table_path);
    if (!loaded.ok()) return loaded.status().WithContext("detection.error_table");
    // Same field of view (within 2 %), at most the table's resolution.
    scale = camera.f / loaded->fx();
    const double fov = camera.width / camera.f, table_fov = loaded->width() / loaded->fx();
    if (std::abs(fov / table_fov - 1.0) > 0.02 || scale > 1.02)
      return InvalidArgumentError("detection.error_table: " + table_path + " was built for a " +
                                  std::to_string(loaded->width()) + " px wide camera of f = " + Fixed(loaded->fx(), 1) +
                                  " px, this robot's rectified camera is " + std::to_string(camera.width) +
                                  " px wide with f = " + Fixed(camera.f, 1) + " px (build one: cairn detect build-lut)");
    table = std::make_shared<const TagErrorTable>(std::move(*loaded));
  }
  auto model = TagErrorModel::Create(*kind, std::move(table), options.corner_error, std::min(scale, 1.0));
  if (!model.ok()) return model.status().WithContext("detection.error_model");
  return model;
}

RobotDetectionStage::RobotDetectionStage(const RobotDetectionOptions& options, TagCarrierTable table,
                                         TagErrorModel error_model, const RectifiedStereoCamera& camera,
                                         const Eigen::Isometry3d& T_body_cam, const std::string& robot, char letter)
    : options_(options),
      table_(std::move(table)),
      error_model_(std::move(error_model)),
      T_body_cam_(T_body_cam),
      robot_(robot),
      letter_(letter),
      detector_([&] {
        TagDetectorOptions o = options.detector;
        if (o.ids.empty()) o.ids = table_.Ids();  // the rest are counted as unknown
        return o;
      }()) {
  camera_.width = camera.width;
  camera_.height = camera.height;
  camera_.fx = camera_.fy = camera.f;
  camera_.cx = camera.cx;
  camera_.cy = camera.cy;
}

Matrix6d RobotDetectionStage::CarrierCovariance(const Matrix6d& tag_covariance, const Eigen::Isometry3d& T_tag_carrier) {
  // T_cam_tag (Exp(rho), Exp(phi)) T_tag_carrier = T_cam_carrier (Exp(R^T (rho - [t]x phi)), Exp(R^T phi))
  // to first order, with (R, t) = T_tag_carrier.
  const Eigen::Matrix3d Rt = T_tag_carrier.linear().transpose();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = Rt;
  J.topRightCorner<3, 3>() = -Rt * Skew(T_tag_carrier.translation());
  J.bottomRightCorner<3, 3>() = Rt;
  const Matrix6d c = J * tag_covariance * J.transpose();
  return 0.5 * (c + c.transpose());
}

void RobotDetectionStage::Process(const RectifiedPair& pair, std::vector<TagSighting>* out) {
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  ++report_.images;
  const uint64_t unknown_before = detector_.counts().unknown_ids;
  auto found = detector_.Detect(pair.left);
  report_.unknown_ids += detector_.counts().unknown_ids - unknown_before;
  if (!found.ok()) {
    ++report_.bad_images;
    if (report_.errors.size() < kMaxErrors) report_.errors.push_back(found.status().ToString());
    time_.Record(clock.Now() - start);
    return;
  }
  for (const TagDetection& d : *found) {
    const TagMount* mount = table_.Find(d.id);
    if (mount == nullptr) {
      ++report_.unknown_ids;
      continue;
    }
    if (!mount->landmark && mount->carrier == robot_) {
      ++report_.own_tags;
      continue;
    }
    ++report_.tags;
    TagPoseOptions po;
    po.tag_size = mount->size;
    po.corner_error = options_.corner_error;
    const auto pose = TagPoseEstimator(po).Estimate(d.corners, camera_);
    if (!pose.ok()) {
      ++report_.pose_failures;
      if (report_.errors.size() < kMaxErrors) report_.errors.push_back("tag " + std::to_string(d.id) + ": " + pose.status().ToString());
      continue;
    }
    const Eigen::Isometry3d T_tag_carrier = mount->T_carrier_tag.inverse();
    TagSighting s;
    TeamDetection& t = s.detection;
    t.time = pair.time;
    t.observer = robot_;
    t.observer_letter = letter_;
    t.observed = mount->carrier;
    t.landmark = mount->landmark;
    t.tag_id = d.id;
    t.T_observer_observed = T_body_cam_ * pose->T_cam_tag * T_tag_carrier;
    t.has_alternative = pose->has_alternative;
    if (pose->has_alternative)
      t.T_observer_observed_alternative = T_body_cam_ * pose->T_cam_tag_alternative * T_tag_carrier;
    const Matrix6d tag_covariance = error_model_.Covariance(*pose, mount->size);
    t.covariance = CarrierCovariance(tag_covariance, T_tag_carrier);
    t.distance = pose->distance;
    t.view_angle = pose->view_angle;
    double sigma_t = 0.0, sigma_r = 0.0;
    for (int i = 0; i < 3; ++i) {
      sigma_t = std::max(sigma_t, std::sqrt(std::max(0.0, tag_covariance(i, i))));
      sigma_r = std::max(sigma_r, std::sqrt(std::max(0.0, tag_covariance(i + 3, i + 3))));
    }
    if (pose->distance > options_.max_distance) {
      s.refused = "farther than " + Fixed(options_.max_distance, 1) + " m";
    } else if (sigma_t > options_.max_sigma_translation) {
      s.refused = "translation sigma " + Fixed(sigma_t, 3) + " m above the bound";
    } else if (sigma_r > options_.max_sigma_rotation) {
      s.refused = "rotation sigma " + Fixed(sigma_r, 3) + " rad above the bound";
    } else if (!t.T_observer_observed.matrix().allFinite() || !t.covariance.allFinite()) {
      s.refused = "non-finite pose or covariance";
    }
    s.usable = s.refused.empty();
    ++(s.usable ? report_.usable : report_.refused);
    out->push_back(std::move(s));
  }
  time_.Record(clock.Now() - start);
}

}  // namespace cairn
