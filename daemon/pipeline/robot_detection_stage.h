#pragma once
// The detection executor's work: tags on the left rectified image (a whole-frame scan of every
// `every_nth_frame`-th pair; on the pairs between, regions around the tags seen lately, the fast
// path of thesis 6.2.1), each tag's pose by IPPE with the configured error model
// (detection/tag_error_model.h), and from the
// carrier table the observed robot's or landmark's body in this robot's body at the exposure time.
// Where the graph places a teammate or a landmark whose tags are not tracked, the stage searches the
// region of the image where they should appear as well (on whole-frame scans too: they reach only
// so far at their decimation).
// Tags of this robot itself and ids not in the table are counted and dropped; sightings beyond
// the configured distance or uncertainty are handed on marked as refused, with the reason.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "daemon/pipeline/carrier_predictions.h"
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
  uint64_t images = 0;          // handed to the stage
  uint64_t full_scans = 0;      // whole-frame scans
  uint64_t region_scans = 0;    // images searched in regions only (tracked tags, predicted carriers)
  uint64_t regions = 0;         // regions searched
  uint64_t idle = 0;            // images between whole-frame scans with no tag to track
  uint64_t tags_in_regions = 0;  // tags found by region scans
  uint64_t predictions = 0;       // images handed in with the graph's place of this robot
  uint64_t predicted_regions = 0;  // regions searched where the graph places a carrier
  uint64_t tags_in_predicted_regions = 0;  // tags found there and not by the scan of the image
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
  // `error_model` covers the whole-frame scans' detections; `region_error_model` the region scans'
  // (none: `error_model` covers them too).
  RobotDetectionStage(const RobotDetectionOptions& options, TagCarrierTable table, TagErrorModel error_model,
                      const RectifiedStereoCamera& camera, const Eigen::Isometry3d& T_body_cam, const std::string& robot,
                      char letter, std::optional<TagErrorModel> region_error_model = std::nullopt);

  // The error model `options` name for detections at `decimate` on `camera`: loads the table
  // (`table_path`, already resolved; "" for none) and checks that it was built for a camera of this
  // one's field of view and for that decimation. Errors name the option `key`.
  static Expected<TagErrorModel> MakeErrorModel(const RobotDetectionOptions& options, const std::string& table_path,
                                                double decimate, const RectifiedStereoCamera& camera,
                                                const std::string& key = "detection.error_table");

  // Appends a sighting for every tag of another carrier in the pair's left image. Call with every
  // `roi_every_nth_frame`-th pair: each (every_nth_frame / roi_every_nth_frame)-th, starting with
  // the first, is scanned whole.
  void Process(const RectifiedPair& pair, std::vector<TagSighting>* out) { Process(pair, nullptr, out); }
  // The same, also searching where `predictions` (may be null) place the carriers with no tag
  // tracked.
  void Process(const RectifiedPair& pair, const CarrierPredictions* predictions, std::vector<TagSighting>* out);

  // The image regions where the tags of the carriers in `predictions` with no tag tracked should
  // appear in an image taken at `time`: one per carrier, around the tags that face the camera,
  // within max_distance and the prediction bounds of the options.
  struct PredictedRegion {
    std::string carrier;
    PixelBox box;
  };
  void PredictRegions(const CarrierPredictions& predictions, Timestamp time, std::vector<PredictedRegion>* out) const;

  // A tag's corners' bounding box grown by the configured margins and clipped to the image; empty
  // (width 0) when nothing of it is inside.
  static PixelBox Region(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int width, int height,
                         double margin, double margin_px);

  const RobotDetectionReport& report() const { return report_; }
  const LatencyHistogram& time() const { return time_; }
  const LatencyHistogram& region_time() const { return region_time_; }

  // The covariance of a tag pose (the estimator's tangent at T_cam_tag) as the covariance of
  // T_cam_tag * T_tag_carrier in the same kind of tangent (translation in the carrier's axes).
  static Matrix6d CarrierCovariance(const Matrix6d& tag_covariance, const Eigen::Isometry3d& T_tag_carrier);

 private:
  RobotDetectionOptions options_;
  TagCarrierTable table_;
  TagErrorModel error_model_;
  TagErrorModel region_error_model_;
  PinholeRadTan camera_;
  Eigen::Isometry3d T_body_cam_;
  std::string robot_;
  char letter_ = 0;
  // Where each tracked tag (an id of another carrier) was last seen.
  struct Track {
    Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
    Timestamp seen;
  };
  // Tags to search for in this image: a whole-frame scan, or regions around the tracks.
  Expected<std::vector<TagDetection>> Find(const RectifiedPair& pair, bool full);
  // Appends the tags found in the predicted regions that `found` does not hold yet.
  Status FindPredicted(const RectifiedPair& pair, std::vector<TagDetection>* found);
  bool Tracked(const std::string& carrier) const;

  TagDetector detector_;
  TagDetector region_detector_;
  std::map<int, Track> tracks_;
  std::vector<PredictedRegion> predicted_;  // this image's
  uint64_t frames_ = 0;
  int64_t full_every_ = 1;  // of the frames handed in
  RobotDetectionReport report_;
  LatencyHistogram time_;         // every image
  LatencyHistogram region_time_;  // images searched in regions only
};

}  // namespace cairn
