#include "sim/euroc_writer.h"

#include <cinttypes>
#include <filesystem>

#include <opencv2/core.hpp>

#include "io/image_codec.h"

namespace cairn::sim {
namespace {

namespace fs = std::filesystem;

std::string Matrix4Yaml(const Eigen::Isometry3d& T) {
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  const Eigen::Matrix4d m = T.matrix();
  char buf[40];
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      std::snprintf(buf, sizeof(buf), "%.17g%s", m(r, c), r == 3 && c == 3 ? "]\n" : ", ");
      s += buf;
    }
  }
  return s;
}

Status WriteText(const std::string& path, const std::string& text) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return IoError(path + ": cannot create");
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) return IoError(path + ": write failed");
  return Status::Ok();
}

std::string CameraYaml(const CameraCalibration& cam, double rate_hz) {
  const PinholeRadTan& k = cam.intrinsics;
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "rate_hz: %.17g\nresolution: [%d, %d]\ncamera_model: pinhole\n"
                "intrinsics: [%.17g, %.17g, %.17g, %.17g]\ndistortion_model: radial-tangential\n"
                "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n",
                rate_hz, k.width, k.height, k.fx, k.fy, k.cx, k.cy);
  return "%YAML:1.0\nsensor_type: camera\ncomment: cairn simulator, rectified " + cam.name + "\n" +
         Matrix4Yaml(cam.T_body_cam) + buf;
}

std::string ImuYaml(const ImuCalibration& imu) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "rate_hz: %.17g\ngyroscope_noise_density: %.17g\ngyroscope_random_walk: %.17g\n"
                "accelerometer_noise_density: %.17g\naccelerometer_random_walk: %.17g\n",
                imu.rate_hz, imu.gyro_noise_density, imu.gyro_random_walk, imu.accel_noise_density,
                imu.accel_random_walk);
  return "%YAML:1.0\nsensor_type: imu\ncomment: cairn simulator, Xsens MTi-10 class noise\n" +
         Matrix4Yaml(imu.T_body_imu) + buf;
}

}  // namespace

Expected<std::unique_ptr<EurocWriter>> EurocWriter::Create(const std::string& root,
                                                           const StereoCalibration& stereo,
                                                           double camera_rate_hz,
                                                           const ImuCalibration& imu) {
  std::unique_ptr<EurocWriter> w(new EurocWriter());
  w->mav0_ = root + "/mav0";
  std::error_code ec;
  for (const char* sub : {"cam0/data", "cam1/data", "imu0", "state_groundtruth_estimate0"}) {
    fs::create_directories(w->mav0_ + "/" + sub, ec);
    if (ec) return IoError(w->mav0_ + "/" + sub + ": cannot create: " + ec.message());
  }
  CAIRN_RETURN_IF_ERROR(WriteText(w->mav0_ + "/cam0/sensor.yaml", CameraYaml(stereo.left, camera_rate_hz)));
  CAIRN_RETURN_IF_ERROR(WriteText(w->mav0_ + "/cam1/sensor.yaml", CameraYaml(stereo.right, camera_rate_hz)));
  CAIRN_RETURN_IF_ERROR(WriteText(w->mav0_ + "/imu0/sensor.yaml", ImuYaml(imu)));
  CAIRN_RETURN_IF_ERROR(WriteText(w->mav0_ + "/state_groundtruth_estimate0/sensor.yaml",
                                  "%YAML:1.0\nsensor_type: visual-inertial\ncomment: exact simulated body (IMU) "
                                  "pose, velocity and biases\n" + Matrix4Yaml(Eigen::Isometry3d::Identity())));
  struct Open { FILE** f; std::string path; const char* header; } files[] = {
      {&w->imu_, w->mav0_ + "/imu0/data.csv",
       "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
       "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"},
      {&w->gt_, w->mav0_ + "/state_groundtruth_estimate0/data.csv",
       "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
       "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
       "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
       "b_a_RS_S_z [m s^-2]\n"},
      {&w->cam_[0], w->mav0_ + "/cam0/data.csv", "#timestamp [ns],filename\n"},
      {&w->cam_[1], w->mav0_ + "/cam1/data.csv", "#timestamp [ns],filename\n"},
  };
  for (Open& o : files) {
    *o.f = std::fopen(o.path.c_str(), "w");
    if (*o.f == nullptr) return IoError(o.path + ": cannot create");
    std::fputs(o.header, *o.f);
  }
  return w;
}

EurocWriter::~EurocWriter() { (void)Close(); }

Status EurocWriter::AddImu(const ImuTruth& r) {
  const ImuSample& s = r.sample;
  std::fprintf(imu_, "%" PRId64 ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", s.time.nanoseconds(),
               s.gyro.x(), s.gyro.y(), s.gyro.z(), s.accel.x(), s.accel.y(), s.accel.z());
  const Eigen::Vector3d p = r.state.T_world_body.translation();
  const Eigen::Quaterniond q(r.state.T_world_body.linear());
  const Eigen::Vector3d& v = r.state.velocity;
  std::fprintf(gt_,
               "%" PRId64 ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.9g,%.9g,%.9g,"
               "%.9g,%.9g,%.9g\n",
               s.time.nanoseconds(), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(),
               v.z(), r.gyro_bias.x(), r.gyro_bias.y(), r.gyro_bias.z(), r.accel_bias.x(),
               r.accel_bias.y(), r.accel_bias.z());
  return std::ferror(imu_) || std::ferror(gt_) ? IoError(mav0_ + ": IMU or ground-truth write failed")
                                               : Status::Ok();
}

Status EurocWriter::AddStereo(Timestamp time, const std::vector<uint8_t>& left,
                              const std::vector<uint8_t>& right, int width, int height) {
  const std::string name = std::to_string(time.nanoseconds()) + ".png";
  const std::vector<uint8_t>* images[2] = {&left, &right};
  for (int c = 0; c < 2; ++c) {
    const std::string path = mav0_ + "/cam" + std::to_string(c) + "/data/" + name;
    const cv::Mat m(height, width, CV_8UC1, const_cast<uint8_t*>(images[c]->data()));
    CAIRN_RETURN_IF_ERROR(ImageCodec::Write(path, m));
    std::fprintf(cam_[c], "%" PRId64 ",%s\n", time.nanoseconds(), name.c_str());
  }
  return Status::Ok();
}

Status EurocWriter::Close() {
  bool ok = true;
  for (FILE** f : {&imu_, &gt_, &cam_[0], &cam_[1]}) {
    if (*f != nullptr) {
      ok = !std::ferror(*f) && ok;
      ok = std::fclose(*f) == 0 && ok;
      *f = nullptr;
    }
  }
  return ok ? Status::Ok() : IoError(mav0_ + ": closing the CSV files failed");
}

}  // namespace cairn::sim
