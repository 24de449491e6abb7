#pragma once
// An EuRoC/ASL dataset folder (mav0/cam0, cam1, imu0, optional state_groundtruth_estimate0),
// indexed and validated up front: a replay either starts with everything it needs present or
// fails before anything is written, naming the file and line at fault.

#include <string>
#include <vector>

#include "common/status.h"
#include "common/timestamp.h"
#include "hal/calibration.h"
#include "hal/imu_sample.h"

namespace cairn {

struct EurocStereoEntry {
  Timestamp time;
  std::string left_path;
  std::string right_path;
};

class EurocDataset {
 public:
  // `root` is the folder that holds mav0/ (or mav0 itself).
  static Expected<EurocDataset> Open(const std::string& root);
  // One camera's sensor.yaml (EuRoC/Kalibr form: resolution, intrinsics, radial-tangential).
  static Expected<CameraCalibration> ReadCameraFile(const std::string& sensor_yaml);

  const std::string& root() const { return root_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  // Left/right rows with the same timestamp, in file order of cam0.
  const std::vector<EurocStereoEntry>& stereo() const { return stereo_; }
  // Rows of one camera without a partner in the other (their image files are not required).
  int unpaired_left() const { return unpaired_left_; }
  int unpaired_right() const { return unpaired_right_; }
  const StereoCalibration& stereo_calibration() const { return stereo_calibration_; }
  const ImuCalibration& imu_calibration() const { return imu_calibration_; }
  double camera_rate_hz() const { return camera_rate_hz_; }
  // Empty when the dataset has no ground truth.
  const std::string& groundtruth_path() const { return groundtruth_path_; }

 private:
  std::string root_;
  std::vector<ImuSample> imu_;
  std::vector<EurocStereoEntry> stereo_;
  int unpaired_left_ = 0;
  int unpaired_right_ = 0;
  StereoCalibration stereo_calibration_;
  ImuCalibration imu_calibration_;
  double camera_rate_hz_ = 0.0;
  std::string groundtruth_path_;
};

}  // namespace cairn
