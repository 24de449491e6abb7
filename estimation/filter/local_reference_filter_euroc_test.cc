// The filter on real IMU data: EuRoC V1_01 with ground-truth positions fed as noisy 20 Hz
// position updates. Needs CAIRN_DATA_DIR (skips, naming the path, without it).

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/replay/euroc_dataset.h"
#include "estimation/filter/local_reference_filter.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

struct GroundTruth {
  Timestamp time;
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
  Eigen::Vector3d gyro_bias, accel_bias;
};

std::vector<GroundTruth> ReadGroundTruth(const std::string& path) {
  std::vector<GroundTruth> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    std::getline(ss, cell, ',');
    const int64_t ns = std::stoll(cell);
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    if (v.size() < 16) continue;
    GroundTruth g;
    g.time = Timestamp::FromNanoseconds(ns);
    g.p = Eigen::Vector3d(v[0], v[1], v[2]);
    g.q = Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized();
    g.gyro_bias = Eigen::Vector3d(v[10], v[11], v[12]);
    g.accel_bias = Eigen::Vector3d(v[13], v[14], v[15]);
    rows.push_back(g);
  }
  return rows;
}

TEST(LocalReferenceFilterEurocTest, BiasesConvergeAndAttitudeStaysAccurate) {
  const char* dir = std::getenv("CAIRN_DATA_DIR");
  const std::string root = std::string(dir ? dir : "") + "/euroc-v1_01-micro";
  const std::string gt_path = root + "/mav0/state_groundtruth_estimate0/data.csv";
  if (dir == nullptr || !std::ifstream(gt_path)) GTEST_SKIP() << "missing " << gt_path;
  Expected<EurocDataset> data = EurocDataset::Open(root);
  ASSERT_TRUE(data.ok()) << data.status().ToString();
  const std::vector<GroundTruth> gt = ReadGroundTruth(gt_path);
  ASSERT_GT(gt.size(), 2000u);

  FilterOptions o;
  LocalReferenceFilter filter(o, data->imu_calibration());
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);
  constexpr double kSigmaPosition = 0.01;  // m, added to the ground truth

  size_t next_gt = 0;
  size_t check_gt = 0;
  Eigen::Isometry3d T_world_frame = Eigen::Isometry3d::Identity();
  double max_attitude_error_deg = 0.0;
  double max_tilt_error_deg = 0.0;
  int attitude_samples = 0;
  Eigen::Vector3d sum_bg_err = Eigen::Vector3d::Zero(), sum_ba_err = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_bg = Eigen::Vector3d::Zero(), sum_ba = Eigen::Vector3d::Zero();
  int bias_samples = 0;
  const double t_end = data->imu().back().time.seconds();
  // The MAV rests (motors idling) for the first seconds: static initialization gives roll, pitch
  // and the gyro bias. Its frame is the ground-truth world moved to the initial position and
  // turned by the initial yaw.
  const std::vector<ImuSample>& imu = data->imu();
  size_t i = 0;
  while (i < imu.size() && !filter.initialized()) filter.Propagate(imu[i++]);
  ASSERT_TRUE(filter.initialized());
  while (next_gt < gt.size() && gt[next_gt].time < filter.state().time) ++next_gt;
  {
    const Eigen::Matrix3d R = gt[next_gt].q.toRotationMatrix();
    T_world_frame.linear() =
        Eigen::AngleAxisd(std::atan2(R(1, 0), R(0, 0)), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_world_frame.translation() = gt[next_gt].p;
    check_gt = next_gt;
    const Eigen::Vector3d up_gt = gt[next_gt].q.conjugate() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_est = filter.state().q.conjugate() * Eigen::Vector3d::UnitZ();
    const double tilt_deg = std::acos(std::min(1.0, up_gt.dot(up_est))) * 180.0 / M_PI;
    std::printf("static initialization after %.2f s: gravity direction off by %.3f deg, gyro bias error %.5f rad/s\n",
                (filter.state().time - imu.front().time).seconds(), tilt_deg,
                (filter.state().bg - gt[next_gt].gyro_bias).norm());
    // Accelerometer bias (about 0.07 m/s^2 here) is not separable from tilt at rest: 0.4 deg.
    EXPECT_LT(tilt_deg, 1.0);
    EXPECT_LT((filter.state().bg - gt[next_gt].gyro_bias).norm(), 0.003);
  }
  for (; i < imu.size(); ++i) {
    const ImuSample& s = imu[i];
    filter.Propagate(s);
    // Position updates at the ground-truth (camera) times, announced just before the IMU data
    // reaches them.
    while (next_gt < gt.size() && gt[next_gt].time <= s.time + Duration::Milliseconds(5)) {
      const GroundTruth& g = gt[next_gt++];
      const Eigen::Vector3d p_frame = T_world_frame.inverse() * g.p +
                                      kSigmaPosition * DrawVector3(noise, rng);
      filter.ApplyPosition(g.time, p_frame, Eigen::Matrix3d::Identity() * kSigmaPosition * kSigmaPosition);
    }
    // Compare with the ground truth at its own times through the pose history.
    while (check_gt < next_gt && gt[check_gt].time <= filter.state().time) {
      const GroundTruth& g = gt[check_gt++];
      PoseSample pose;
      if (!filter.PoseAt(g.time, &pose)) continue;
      const Eigen::Quaterniond q_frame_gt(T_world_frame.linear().transpose() * g.q.toRotationMatrix());
      const Eigen::Quaterniond q_est(pose.T_frame_body.linear());
      // Attitude error in the frame: horizontal part (tilt, observable) and vertical (yaw).
      const Eigen::Vector3d e_world = q_frame_gt * so3::Log(q_est.conjugate() * q_frame_gt);
      const double err = e_world.norm() * 180.0 / M_PI;
      const double tilt = e_world.head<2>().norm() * 180.0 / M_PI;
      max_attitude_error_deg = std::max(max_attitude_error_deg, err);
      // Tilt is judged once the flight has excited the filter (take-off is at about 5.5 s).
      if ((g.time - gt.front().time).seconds() > 15.0) max_tilt_error_deg = std::max(max_tilt_error_deg, tilt);
      ++attitude_samples;
      if (g.time.seconds() > t_end - 60.0) {
        sum_bg_err += (filter.state().bg - g.gyro_bias).cwiseAbs();
        sum_ba_err += (filter.state().ba - g.accel_bias).cwiseAbs();
        sum_bg += filter.state().bg;
        sum_ba += filter.state().ba;
        ++bias_samples;
      }
    }
  }
  ASSERT_GT(attitude_samples, 2000);
  ASSERT_GT(bias_samples, 1000);
  const Eigen::Vector3d bg_err = sum_bg_err / bias_samples, ba_err = sum_ba_err / bias_samples;
  std::printf("max attitude error %.3f deg over %d ground-truth poses\n", max_attitude_error_deg,
              attitude_samples);
  std::printf("gyro bias error %.5f %.5f %.5f; accel bias error %.4f %.4f %.4f\n", bg_err.x(), bg_err.y(),
              bg_err.z(), ba_err.x(), ba_err.y(), ba_err.z());
  std::printf("mean gyro bias %.5f %.5f %.5f; mean accel bias %.4f %.4f %.4f; gt %.5f %.5f %.5f / %.4f %.4f %.4f\n",
              sum_bg.x() / bias_samples, sum_bg.y() / bias_samples, sum_bg.z() / bias_samples,
              sum_ba.x() / bias_samples, sum_ba.y() / bias_samples, sum_ba.z() / bias_samples,
              gt.back().gyro_bias.x(), gt.back().gyro_bias.y(), gt.back().gyro_bias.z(),
              gt.back().accel_bias.x(), gt.back().accel_bias.y(), gt.back().accel_bias.z());
  std::printf("max tilt error after 15 s %.3f deg\n", max_tilt_error_deg);
  // Roll and pitch (observable) stay within 1 degree. Yaw is only weakly observable from position
  // updates and is not bounded by this test (it reaches a few degrees here).
  EXPECT_LT(max_tilt_error_deg, 1.0);
  // Tolerances: the reference biases are themselves a batch estimate; the gyro bias is observed
  // tightly (0.003 rad/s is 7x the measured error), the accelerometer bias trades off against
  // tilt (0.3 deg of tilt is 0.05 m/s^2), hence 0.05 m/s^2 on the mean absolute error.
  EXPECT_LT(bg_err.maxCoeff(), 0.003);
  EXPECT_LT(ba_err.maxCoeff(), 0.05);
  EXPECT_EQ(filter.counters().updates_rejected, 0u);
}

}  // namespace
}  // namespace cairn
