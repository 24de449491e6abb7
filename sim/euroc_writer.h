#pragma once
// Writes one robot's simulated streams as an EuRoC/ASL folder (mav0/cam0, cam1, imu0,
// state_groundtruth_estimate0, each with data.csv and sensor.yaml holding the true calibration),
// in the exact form drivers/replay/euroc_dataset.h reads.

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "hal/calibration.h"
#include "sim/imu_synthesizer.h"

namespace cairn::sim {

class EurocWriter {
 public:
  // Creates `root`/mav0 and its sensor folders and writes the sensor.yaml files.
  static Expected<std::unique_ptr<EurocWriter>> Create(const std::string& root,
                                                       const StereoCalibration& stereo,
                                                       double camera_rate_hz,
                                                       const ImuCalibration& imu);
  ~EurocWriter();
  EurocWriter(const EurocWriter&) = delete;
  EurocWriter& operator=(const EurocWriter&) = delete;

  // One IMU reading and the ground truth (body pose, velocity, biases) at its time.
  Status AddImu(const ImuTruth& truth);
  // One synchronized pair of 8-bit images, written as PNG.
  Status AddStereo(Timestamp time, const std::vector<uint8_t>& left, const std::vector<uint8_t>& right,
                   int width, int height);
  // Flushes and closes every file; reports the first write error.
  Status Close();

 private:
  EurocWriter() = default;
  std::string mav0_;
  FILE* imu_ = nullptr;
  FILE* gt_ = nullptr;
  FILE* cam_[2] = {nullptr, nullptr};
};

}  // namespace cairn::sim
