#include "drivers/replay/euroc_dataset.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "drivers/replay/csv_reader.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

// EuRoC's sensor.yaml files start with OpenCV's "%YAML:1.0", which is not a YAML directive.
Expected<YAML::Node> LoadSensorYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot open");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (first && line.rfind("%YAML:", 0) == 0) line = "# " + line;
    first = false;
    text << line << "\n";
  }
  try {
    YAML::Node n = YAML::Load(text.str());
    if (!n.IsMap()) return DataLossError(path + ": not a mapping of keys");
    return n;
  } catch (const YAML::Exception& e) {
    return DataLossError(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

Expected<std::vector<double>> NumberList(const YAML::Node& root, const std::string& path,
                                         const std::string& key, size_t count) {
  const YAML::Node n = root[key];
  if (!n.IsDefined() || !n.IsSequence()) return DataLossError(path + ": missing list '" + key + "'");
  if (n.size() != count) {
    return DataLossError(path + ":" + std::to_string(n.Mark().line + 1) + ": '" + key + "' has " +
                         std::to_string(n.size()) + " values, expected " + std::to_string(count));
  }
  std::vector<double> v;
  for (size_t i = 0; i < count; ++i) {
    double x = 0.0;
    if (!YAML::convert<double>::decode(n[i], x)) {
      return DataLossError(path + ":" + std::to_string(n[i].Mark().line + 1) + ": '" + key +
                           "' item " + std::to_string(i) + " is not a number");
    }
    v.push_back(x);
  }
  return v;
}

Expected<double> Scalar(const YAML::Node& root, const std::string& path, const std::string& key) {
  const YAML::Node n = root[key];
  double x = 0.0;
  if (!n.IsDefined() || !n.IsScalar() || !YAML::convert<double>::decode(n, x)) {
    return DataLossError(path + ": missing or non-numeric '" + key + "'");
  }
  return x;
}

Expected<Eigen::Isometry3d> ReadTBS(const YAML::Node& root, const std::string& path) {
  const YAML::Node t = root["T_BS"];
  if (!t.IsDefined() || !t.IsMap()) return DataLossError(path + ": missing 'T_BS'");
  auto data = NumberList(t, path, "data", 16);
  if (!data.ok()) return data.status();
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = (*data)[static_cast<size_t>(r * 4 + c)];
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0.0) {
    return DataLossError(path + ": T_BS rotation is not orthonormal");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Re-orthonormalize: the files carry about 12 significant digits.
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

Expected<CameraCalibration> ReadCamera(const std::string& path, const std::string& name,
                                       double* rate_hz) {
  auto y = LoadSensorYaml(path);
  if (!y.ok()) return y.status();
  CameraCalibration cam;
  cam.name = name;
  auto T = ReadTBS(*y, path);
  if (!T.ok()) return T.status();
  cam.T_body_cam = *T;
  auto res = NumberList(*y, path, "resolution", 2);
  auto intr = NumberList(*y, path, "intrinsics", 4);
  auto dist = NumberList(*y, path, "distortion_coefficients", 4);
  auto rate = Scalar(*y, path, "rate_hz");
  for (const Status& s : {res.status(), intr.status(), dist.status(), rate.status()}) {
    if (!s.ok()) return s;
  }
  const YAML::Node model = (*y)["distortion_model"];
  if (model.IsDefined() && model.as<std::string>("") != "radial-tangential") {
    return DataLossError(path + ": distortion_model '" + model.as<std::string>("") +
                         "' is not supported (radial-tangential only)");
  }
  PinholeRadTan& k = cam.intrinsics;
  k.width = static_cast<int>((*res)[0]);
  k.height = static_cast<int>((*res)[1]);
  k.fx = (*intr)[0]; k.fy = (*intr)[1]; k.cx = (*intr)[2]; k.cy = (*intr)[3];
  k.k1 = (*dist)[0]; k.k2 = (*dist)[1]; k.p1 = (*dist)[2]; k.p2 = (*dist)[3];
  if (k.width <= 0 || k.height <= 0 || k.fx <= 0.0 || k.fy <= 0.0) {
    return DataLossError(path + ": resolution and focal lengths must be positive");
  }
  *rate_hz = *rate;
  return cam;
}

Expected<ImuCalibration> ReadImu(const std::string& dir) {
  const std::string path = dir + "/sensor.yaml";
  auto y = LoadSensorYaml(path);
  if (!y.ok()) return y.status();
  ImuCalibration imu;
  auto T = ReadTBS(*y, path);
  if (!T.ok()) return T.status();
  imu.T_body_imu = *T;
  struct Field { const char* key; double* out; } fields[] = {
      {"rate_hz", &imu.rate_hz},
      {"gyroscope_noise_density", &imu.gyro_noise_density},
      {"gyroscope_random_walk", &imu.gyro_random_walk},
      {"accelerometer_noise_density", &imu.accel_noise_density},
      {"accelerometer_random_walk", &imu.accel_random_walk},
  };
  for (const Field& f : fields) {
    auto v = Scalar(*y, path, f.key);
    if (!v.ok()) return v.status();
    if (*v <= 0.0) return DataLossError(path + ": '" + f.key + "' must be positive");
    *f.out = *v;
  }
  return imu;
}

struct CameraRows {
  std::vector<std::pair<Timestamp, std::string>> rows;  // time, image file name
};

Expected<CameraRows> ReadCameraCsv(const std::string& dir) {
  const std::string path = dir + "/data.csv";
  auto rows = CsvReader::ReadAll(path, 2);
  if (!rows.ok()) return rows.status();
  CameraRows out;
  for (const CsvRow& r : *rows) {
    auto t = CsvReader::Int(path, r, 0);
    if (!t.ok()) return t.status();
    if (r.fields[1].empty()) {
      return DataLossError(path + ":" + std::to_string(r.line) + ": empty image file name");
    }
    out.rows.emplace_back(Timestamp::FromNanoseconds(*t), r.fields[1]);
  }
  return out;
}

}  // namespace

Expected<EurocDataset> EurocDataset::Open(const std::string& root_in) {
  std::string root = root_in;
  while (root.size() > 1 && root.back() == '/') root.pop_back();
  std::string mav0 = root + "/mav0";
  if (!fs::is_directory(mav0)) {
    if (fs::path(root).filename() == "mav0" && fs::is_directory(root)) {
      mav0 = root;
    } else {
      return NotFoundError(root + ": not an EuRoC/ASL dataset (no mav0/ folder)");
    }
  }
  EurocDataset ds;
  ds.root_ = root;

  // IMU: timestamp, gyro xyz, accel xyz.
  {
    const std::string path = mav0 + "/imu0/data.csv";
    auto rows = CsvReader::ReadAll(path, 7);
    if (!rows.ok()) return rows.status();
    ds.imu_.reserve(rows->size());
    for (const CsvRow& r : *rows) {
      ImuSample s;
      auto t = CsvReader::Int(path, r, 0);
      if (!t.ok()) return t.status();
      s.time = Timestamp::FromNanoseconds(*t);
      double v[6];
      for (size_t c = 0; c < 6; ++c) {
        auto d = CsvReader::Double(path, r, c + 1);
        if (!d.ok()) return d.status();
        v[c] = *d;
      }
      s.gyro = Eigen::Vector3d(v[0], v[1], v[2]);
      s.accel = Eigen::Vector3d(v[3], v[4], v[5]);
      ds.imu_.push_back(s);
    }
    auto imu = ReadImu(mav0 + "/imu0");
    if (!imu.ok()) return imu.status();
    ds.imu_calibration_ = *imu;
  }

  // Cameras: pair rows by identical timestamps.
  double rate0 = 0.0, rate1 = 0.0;
  auto cam0 = ReadCamera(mav0 + "/cam0/sensor.yaml", "cam0", &rate0);
  if (!cam0.ok()) return cam0.status();
  auto cam1 = ReadCamera(mav0 + "/cam1/sensor.yaml", "cam1", &rate1);
  if (!cam1.ok()) return cam1.status();
  ds.stereo_calibration_.left = *cam0;
  ds.stereo_calibration_.right = *cam1;
  ds.camera_rate_hz_ = rate0;
  auto rows0 = ReadCameraCsv(mav0 + "/cam0");
  if (!rows0.ok()) return rows0.status();
  auto rows1 = ReadCameraCsv(mav0 + "/cam1");
  if (!rows1.ok()) return rows1.status();
  std::map<int64_t, std::string> right;
  for (const auto& [t, file] : rows1->rows) right.emplace(t.nanoseconds(), file);
  size_t matched_right = 0;
  for (const auto& [t, file] : rows0->rows) {
    const auto it = right.find(t.nanoseconds());
    if (it == right.end()) {
      ++ds.unpaired_left_;
      continue;
    }
    ++matched_right;
    EurocStereoEntry e{t, mav0 + "/cam0/data/" + file, mav0 + "/cam1/data/" + it->second};
    for (const std::string* p : {&e.left_path, &e.right_path}) {
      if (!fs::is_regular_file(*p)) {
        return NotFoundError(*p + ": image listed in " +
                             (p == &e.left_path ? mav0 + "/cam0" : mav0 + "/cam1") +
                             "/data.csv is missing");
      }
    }
    ds.stereo_.push_back(std::move(e));
  }
  ds.unpaired_right_ = static_cast<int>(rows1->rows.size() - matched_right);

  const std::string gt = mav0 + "/state_groundtruth_estimate0/data.csv";
  if (fs::is_regular_file(gt)) ds.groundtruth_path_ = gt;
  return ds;
}

Expected<CameraCalibration> EurocDataset::ReadCameraFile(const std::string& sensor_yaml) {
  double rate = 0.0;
  return ReadCamera(sensor_yaml, "camera", &rate);
}

}  // namespace cairn
