#include "daemon/pipeline/robot_detection_stage.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/bounded_errors.h"
#include "common/monotonic_clock.h"

namespace cairn {
namespace {

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

// The configured detector at `decimate`, for the table's ids unless others are configured (the
// rest are counted as unknown).
TagDetectorOptions DetectorOptions(TagDetectorOptions o, const TagCarrierTable& table, double decimate) {
  if (o.ids.empty()) o.ids = table.Ids();
  o.decimate = decimate;
  return o;
}

}  // namespace

Expected<TagErrorModel> RobotDetectionStage::MakeErrorModel(const RobotDetectionOptions& options,
                                                            const std::string& table_path, double decimate,
                                                            const RectifiedStereoCamera& camera,
                                                            const std::string& key) {
  auto kind = ParseTagErrorKind(options.error_model);
  if (!kind.ok()) return kind.status().WithContext("detection.error_model");
  std::shared_ptr<const TagErrorTable> table;
  double scale = 1.0;
  if (!table_path.empty()) {
    auto loaded = TagErrorTable::Load(table_path);
    if (!loaded.ok()) return loaded.status().WithContext(key);
    // Same field of view (within 2 %), at most the table's resolution.
    scale = camera.f / loaded->fx();
    const double fov = camera.width / camera.f, table_fov = loaded->width() / loaded->fx();
    if (std::abs(fov / table_fov - 1.0) > 0.02 || scale > 1.02)
      return InvalidArgumentError(key + ": " + table_path + " was built for a " +
                                  std::to_string(loaded->width()) + " px wide camera of f = " + Fixed(loaded->fx(), 1) +
                                  " px, this robot's rectified camera is " + std::to_string(camera.width) +
                                  " px wide with f = " + Fixed(camera.f, 1) + " px (build one: cairn detect build-lut)");
    if (loaded->decimate() != decimate)
      return InvalidArgumentError(key + ": " + table_path + " was built for detections at decimate " +
                                  Fixed(loaded->decimate(), 2) + ", these are made at " + Fixed(decimate, 2) +
                                  " (build one: cairn detect build-lut --decimate " + Fixed(decimate, 2) + ")");
    table = std::make_shared<const TagErrorTable>(std::move(*loaded));
  }
  auto model = TagErrorModel::Create(*kind, std::move(table), options.corner_error, std::min(scale, 1.0));
  if (!model.ok()) return model.status().WithContext("detection.error_model");
  return model;
}

RobotDetectionStage::RobotDetectionStage(const RobotDetectionOptions& options, TagCarrierTable table,
                                         TagErrorModel error_model, const RectifiedStereoCamera& camera,
                                         const Eigen::Isometry3d& T_body_cam, const std::string& robot, char letter,
                                         std::optional<TagErrorModel> region_error_model)
    : options_(options),
      table_(std::move(table)),
      error_model_(error_model),
      region_error_model_(region_error_model ? std::move(*region_error_model) : std::move(error_model)),
      T_body_cam_(T_body_cam),
      robot_(robot),
      letter_(letter),
      detector_(DetectorOptions(options.detector, table_, options.detector.decimate)),
      region_detector_(DetectorOptions(options.detector, table_, options.roi_decimate)),
      full_every_(std::max<int64_t>(1, options.every_nth_frame / std::max<int64_t>(1, options.roi_every_nth_frame))) {
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

PixelBox RobotDetectionStage::Region(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int width, int height,
                                     double margin, double margin_px) {
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const double m = margin * extent + margin_px;
  const int x0 = std::max(0, static_cast<int>(std::floor(lo.x() - m)));
  const int y0 = std::max(0, static_cast<int>(std::floor(lo.y() - m)));
  const int x1 = std::min(width - 1, static_cast<int>(std::ceil(hi.x() + m)));
  const int y1 = std::min(height - 1, static_cast<int>(std::ceil(hi.y() + m)));
  if (x0 > x1 || y0 > y1) return PixelBox{};
  return PixelBox{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

Expected<std::vector<TagDetection>> RobotDetectionStage::Find(const RectifiedPair& pair, bool full) {
  if (full) {
    ++report_.full_scans;
    return detector_.Detect(pair.left);
  }
  ++report_.region_scans;
  std::vector<TagDetection> all;
  for (const auto& [id, track] : tracks_) {
    const PixelBox box = Region(track.lo, track.hi, pair.left.width, pair.left.height, options_.roi_margin,
                                options_.roi_margin_px);
    if (box.width <= 0) continue;
    ++report_.regions;
    auto found = region_detector_.Detect(pair.left, &box);
    if (!found.ok()) return found.status();
    for (TagDetection& d : *found) {
      // Regions of tags close together overlap: each tag once.
      const bool seen = std::any_of(all.begin(), all.end(), [&](const TagDetection& a) { return a.id == d.id; });
      if (!seen) all.push_back(std::move(d));
    }
  }
  report_.tags_in_regions += all.size();
  return all;
}

bool RobotDetectionStage::Tracked(const std::string& carrier) const {
  for (const auto& [id, track] : tracks_) {
    const TagMount* mount = table_.Find(id);
    if (mount != nullptr && mount->carrier == carrier) return true;
  }
  return false;
}

void RobotDetectionStage::PredictRegions(const CarrierPredictions& predictions, Timestamp time,
                                         std::vector<PredictedRegion>* out) const {
  if (!predictions.valid) return;
  const double own_age = std::abs((time - predictions.time).seconds());
  if (own_age > options_.prediction_max_age) return;
  const Eigen::Isometry3d T_cam_global = (predictions.T_global_body * T_body_cam_).inverse();
  const double max_area = options_.prediction_max_area * camera_.width * camera_.height;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const CarrierPredictions::Carrier& c : predictions.carriers) {
    if ((!c.landmark && c.name == robot_) || Tracked(c.name)) continue;
    const double age = c.landmark ? 0.0 : std::abs((time - c.time).seconds());
    if (age > options_.prediction_max_age) continue;
    // The carrier lies within `radius` of its place; this robot's heading is off by up to `turn`.
    const double radius = options_.prediction_margin + options_.prediction_speed * (age + own_age);
    const double turn = std::min(options_.prediction_turn_rate * own_age, 1.0);
    const Eigen::Isometry3d T_cam_carrier = T_cam_global * c.T_global_carrier;
    Eigen::Vector2d lo(kInf, kInf), hi(-kInf, -kInf);
    double nearest = kInf;
    for (const auto& [id, mount] : table_.tags()) {
      if (mount.carrier != c.name || mount.landmark != c.landmark) continue;
      const Eigen::Isometry3d T_cam_tag = T_cam_carrier * mount.T_carrier_tag;
      // Only tags that face the camera can be decoded (AprilTag's z points into the tag).
      if (T_cam_tag.inverse().translation().z() >= 0.0) continue;
      if (T_cam_tag.translation().norm() - radius > options_.max_distance) continue;
      const double half = 0.5 * mount.size;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d p = T_cam_tag * Eigen::Vector3d(k & 1 ? half : -half, k & 2 ? half : -half, 0.0);
        nearest = std::min(nearest, p.z());
        if (p.z() <= 0.0) continue;
        const Eigen::Vector2d uv(camera_.fx * p.x() / p.z() + camera_.cx, camera_.fy * p.y() / p.z() + camera_.cy);
        lo = lo.cwiseMin(uv);
        hi = hi.cwiseMax(uv);
      }
    }
    // A carrier that may be within reach of the camera could be anywhere in the image: the
    // whole-frame scans find it.
    if (!(nearest - radius > 0.5) || !(lo.x() <= hi.x())) continue;
    const double margin_px =
        camera_.fx * (radius / (nearest - radius) + std::tan(turn)) + options_.roi_margin_px;
    const PixelBox box = Region(lo, hi, camera_.width, camera_.height, options_.roi_margin, margin_px);
    if (box.width <= 0 || static_cast<double>(box.width) * box.height > max_area) continue;
    out->push_back(PredictedRegion{c.name, box});
  }
}

Status RobotDetectionStage::FindPredicted(const RectifiedPair& pair, std::vector<TagDetection>* found) {
  for (const PredictedRegion& r : predicted_) {
    const bool seen = std::any_of(found->begin(), found->end(), [&](const TagDetection& d) {
      const TagMount* mount = table_.Find(d.id);
      return mount != nullptr && mount->carrier == r.carrier;
    });
    if (seen) continue;
    ++report_.predicted_regions;
    auto more = region_detector_.Detect(pair.left, &r.box);
    if (!more.ok()) return more.status();
    for (TagDetection& d : *more) {
      if (std::any_of(found->begin(), found->end(), [&](const TagDetection& a) { return a.id == d.id; })) continue;
      found->push_back(std::move(d));
      ++report_.tags_in_predicted_regions;
    }
  }
  return Status::Ok();
}

void RobotDetectionStage::Process(const RectifiedPair& pair, const CarrierPredictions* predictions,
                                  std::vector<TagSighting>* out) {
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  ++report_.images;
  const bool full = frames_++ % static_cast<uint64_t>(full_every_) == 0;
  // Tags not seen for a while are searched for by the whole-frame scans only (time going back:
  // another recording).
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    const double age = (pair.time - it->second.seen).seconds();
    it = (age > options_.track_timeout || age < 0.0) ? tracks_.erase(it) : std::next(it);
  }
  predicted_.clear();
  if (predictions != nullptr && predictions->valid && options_.predicted_regions) {
    ++report_.predictions;
    PredictRegions(*predictions, pair.time, &predicted_);
  }
  if (!full && tracks_.empty() && predicted_.empty()) {
    ++report_.idle;
    return;
  }
  const auto unknown = [&] { return detector_.counts().unknown_ids + region_detector_.counts().unknown_ids; };
  const uint64_t unknown_before = unknown();
  auto found = Find(pair, full);
  if (found.ok() && !predicted_.empty()) {
    if (Status s = FindPredicted(pair, &*found); !s.ok()) found = s;
  }
  report_.unknown_ids += unknown() - unknown_before;
  if (!found.ok()) {
    ++report_.bad_images;
    AppendBoundedError(report_.errors, found.status().ToString());
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
    Track& track = tracks_[d.id];
    track.lo = track.hi = d.corners[0];
    for (const Eigen::Vector2d& c : d.corners) {
      track.lo = track.lo.cwiseMin(c);
      track.hi = track.hi.cwiseMax(c);
    }
    track.seen = pair.time;
    TagPoseOptions po;
    po.tag_size = mount->size;
    po.corner_error = options_.corner_error;
    const auto pose = TagPoseEstimator(po).Estimate(d.corners, camera_);
    if (!pose.ok()) {
      ++report_.pose_failures;
      AppendBoundedError(report_.errors, "tag " + std::to_string(d.id) + ": " + pose.status().ToString());
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
    const TagErrorModel& model = d.decimate == options_.detector.decimate ? error_model_ : region_error_model_;
    const Matrix6d tag_covariance = model.Covariance(*pose, mount->size);
    t.covariance = CarrierCovariance(tag_covariance, T_tag_carrier);
    t.distance = pose->distance;
    t.view_angle = pose->view_angle;
    double sigma_t = 0.0, sigma_r = 0.0;
    for (int i = 0; i < 3; ++i) {
      sigma_t = std::max(sigma_t, std::sqrt(std::max(0.0, tag_covariance(i, i))));
      sigma_r = std::max(sigma_r, std::sqrt(std::max(0.0, tag_covariance(i + 3, i + 3))));
    }
    const double residual = model.ResidualChi2(*pose);
    if (pose->distance > options_.max_distance) {
      s.refused = "farther than " + Fixed(options_.max_distance, 1) + " m";
    } else if (residual > options_.max_residual_chi2) {
      s.refused = "corners off a square's projection (" + Fixed(pose->reprojection_error, 2) + " px, chi-square " +
                  Fixed(residual, 1) + " above the bound)";
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
  const auto took = clock.Now() - start;
  time_.Record(took);
  if (!full) region_time_.Record(took);
}

}  // namespace cairn
