#pragma once
// `detection:` in a cairnd profile: AprilTag sightings of teammates and landmarks (thesis 6.2) on
// the left rectified image, on the detection executor, becoming graph factors d (robot to robot)
// and o (robot to landmark) under the Cauchy loss.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"
#include "detection/tag_detector.h"

namespace cairn {

struct RobotDetectionOptions {
  bool enabled = false;
  int64_t every_nth_frame = 2;  // of the camera's frames: a whole-frame scan of each
  // Between whole-frame scans, every `roi_every_nth_frame`-th frame is searched only in regions
  // around the tags seen in the last `track_timeout` seconds, at `roi_decimate` (full resolution
  // by default: farther than the whole-frame scan reaches). Must divide every_nth_frame.
  int64_t roi_every_nth_frame = 1;
  double roi_decimate = 1.0;
  double roi_margin = 0.5;      // of the tag's extent in the image, added on every side
  double roi_margin_px = 32.0;  // px, added on every side as well (the robots' motion in a frame)
  double track_timeout = 1.0;   // s
  // Regions where the graph places teammates and landmarks, searched at `roi_decimate` on every
  // image handed to the stage for carriers with no tag tracked: farther than the whole-frame scan
  // reaches, and between its images. A carrier's place is trusted to `prediction_margin` plus
  // `prediction_speed` for every second of its estimate's age, this robot's heading to
  // `prediction_turn_rate` for every second of its own; regions larger than
  // `prediction_max_area` of the image, or from estimates older than `prediction_max_age`, are left
  // to the whole-frame scans. Live runs only: in a deterministic replay the graph's progress at a
  // given image would depend on thread timing.
  bool predicted_regions = true;
  double prediction_margin = 0.5;     // m
  double prediction_speed = 1.0;      // m/s
  double prediction_turn_rate = 0.5;  // rad/s
  double prediction_max_age = 10.0;   // s
  double prediction_max_area = 0.5;   // of the image
  // Which tag is on which robot or landmark (detection/tag_carrier_table.h); "" with `source: sim`
  // takes the simulated world's, and turns detection off in live runs and replays (said at start).
  std::string carriers_file;
  double corner_error = 0.5;  // px, eq. 6.9's corner perturbation
  // The covariance of a sighting (detection/tag_error_model.h): propagated, combined, thesis,
  // table, online, constant or quadratic. Every model but online, constant and quadratic needs `error_table`,
  // built for this robot's camera and the whole-frame scans' decimation by `cairn detect build-lut`
  // (a relative path is taken from the profile's folder). `region_error_table` is the same for the
  // region scans' `roi_decimate` ("": they use `error_table`, which is wider than their errors
  // where it was built at a coarser decimation).
  std::string error_model = "propagated";
  std::string error_table;
  std::string region_error_table;
  // Sightings beyond these are kept in detections.csv but not given to the graph (thesis 6.2.3:
  // far or edge-on tags flip between their two poses).
  double max_distance = 12.0;          // m, camera to tag
  double max_sigma_translation = 0.3;  // m, largest translation sigma of the tag's pose
  double max_sigma_rotation = 1.0;     // rad, largest rotation sigma
  // Corners this far from a square's projection (chi-square, 2 degrees of freedom, against the
  // error table's corner error; 13.8 is its 99.9 % point) give no pose to trust.
  double max_residual_chi2 = 13.8;
  bool write_csv = true;               // OUT/detections.csv
  TagDetectorOptions detector;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("every_nth_frame", every_nth_frame, 1, 1000, "frames");
    v.Integer("roi_every_nth_frame", roi_every_nth_frame, 1, 1000, "frames");
    v.Number("roi_decimate", roi_decimate, 1.0, 8.0, "");
    v.Number("roi_margin", roi_margin, 0.0, 10.0, "tag extents");
    v.Number("roi_margin_px", roi_margin_px, 0.0, 1000.0, "px");
    v.Number("track_timeout", track_timeout, 0.0, 60.0, "s");
    v.Flag("predicted_regions", predicted_regions);
    v.Number("prediction_margin", prediction_margin, 0.0, 100.0, "m");
    v.Number("prediction_speed", prediction_speed, 0.0, 100.0, "m/s");
    v.Number("prediction_turn_rate", prediction_turn_rate, 0.0, 100.0, "rad/s");
    v.Number("prediction_max_age", prediction_max_age, 0.0, 3600.0, "s");
    v.Number("prediction_max_area", prediction_max_area, 0.0, 1.0, "of the image");
    v.Text("carriers_file", carriers_file);
    v.Number("corner_error", corner_error, 0.0, 10.0, "px");
    v.Text("error_model", error_model);
    v.Text("error_table", error_table);
    v.Text("region_error_table", region_error_table);
    v.Number("max_distance", max_distance, 0.1, 1000.0, "m");
    v.Number("max_sigma_translation", max_sigma_translation, 1e-4, 100.0, "m");
    v.Number("max_sigma_rotation", max_sigma_rotation, 1e-4, 3.2, "rad");
    v.Number("max_residual_chi2", max_residual_chi2, 0.0, 1e9, "chi-square");
    v.Flag("write_csv", write_csv);
    v.Section("detector", detector);
  }
};

}  // namespace cairn
