#pragma once
// The detection executor's work: tags on the left rectified image (a whole-frame scan of every
// `every_nth_frame`-th pair), each tag's pose by IPPE with the configured error model
// (detection/tag_error_model.h), and from the
// carrier table the observed robot's or landmark's body in this robot's body at the exposure time.
// Tags of this robot itself and ids not in the table are counted and dropped; sightings beyond
// the configured distance or uncertainty are handed on marked as refused, with the reason.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/robot_detection_options.h"
#include "daemon/pipeline/stereo_rectify_stage.h"
#include "daemon/pipeline/team_input.h"
#include "detection/tag_carrier_table.h"
#include "detection/tag_detector.h"
#include "detection/tag_error_model.h"
#include "detection/tag_pose_estimator.h"
#include "estimation/vo/vo_types.h"

namespace cairn {

struct TagSighting {
  TeamDetection detection;
  bool usable = false;  // within the distance and uncertainty bounds
  std::string refused;  // why not, when not usable
};

struct RobotDetectionReport {
  uint64_t images = 0;
  uint64_t bad_images = 0;
  uint64_t tags = 0;            // decoded tags of the table's ids
  uint64_t own_tags = 0;        // this robot's own (seen in a mirror or through a gap)
  uint64_t unknown_ids = 0;     // decoded ids not in the table
  uint64_t pose_failures = 0;
  uint64_t usable = 0;
  uint64_t refused = 0;         // beyond the distance or uncertainty bounds
  std::vector<std::string> errors;  // the first few, verbatim
};

class RobotDetectionStage {
 public:
  RobotDetectionStage(const RobotDetectionOptions& options, TagCarrierTable table, TagErrorModel error_model,
                      const RectifiedStereoCamera& camera, const Eigen::Isometry3d& T_body_cam, const std::string& robot,
                      char letter);

  // The error model `options` name, for `camera`: loads the table (`table_path`, already resolved)
  // and checks that it was built for a camera of this one's field of view.
  static Expected<TagErrorModel> MakeErrorModel(const RobotDetectionOptions& options, const std::string& table_path,
                                                const RectifiedStereoCamera& camera);

  // Appends a sighting for every tag of another carrier in the pair's left image.
  void Process(const RectifiedPair& pair, std::vector<TagSighting>* out);

  const RobotDetectionReport& report() const { return report_; }
  const LatencyHistogram& time() const { return time_; }

  // The covariance of a tag pose (the estimator's tangent at T_cam_tag) as the covariance of
  // T_cam_tag * T_tag_carrier in the same kind of tangent (translation in the carrier's axes).
  static Matrix6d CarrierCovariance(const Matrix6d& tag_covariance, const Eigen::Isometry3d& T_tag_carrier);

 private:
  RobotDetectionOptions options_;
  TagCarrierTable table_;
  TagErrorModel error_model_;
  PinholeRadTan camera_;
  Eigen::Isometry3d T_body_cam_;
  std::string robot_;
  char letter_ = 0;
  TagDetector detector_;
  RobotDetectionReport report_;
  LatencyHistogram time_;
};

}  // namespace cairn
