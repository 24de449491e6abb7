// cairn detect build-lut / check-lut: the precomputed error table of thesis 6.2.3, built from tags
// rendered by the simulator's camera model at known poses (detection/tag_error_table.h), and its
// check on renderings it was not built from: per error model, the NEES of the poses against the
// truth, and the share of rendered tags found.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "common/angles.h"
#include "common/atomic_file.h"
#include "common/json_writer.h"
#include "detection/tag_detector.h"
#include "detection/tag_error_model.h"
#include "detection/tag_error_table.h"
#include "detection/tag_pose_estimator.h"
#include "sim/sim_robot.h"
#include "sim/tag_view_renderer.h"
#include "sim/terrain.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr int kTagId = 0;

constexpr const char* kBuildUsage =
    "usage: cairn detect build-lut --camera rover|hexacopter|NAME [--intrinsics W,H,FX,FY] --out FILE\n"
    "                              [--tag-size M (0.16)] [--distances FIRST,LAST,COUNT]\n"
    "                              [--angles FIRST,LAST,COUNT (deg)] [--samples N (16)] [--seed S (1)]\n"
    "                              [--decimate F (2)]\n"
    "  Renders a tag at every distance and viewing angle of the grid (N times, random in-plane turn,\n"
    "  tilt axis and place in the image) with the simulator's camera model, detects it as the daemon\n"
    "  does and writes the RMS pose error per cell (detection/tag_error_table.h). The camera is a\n"
    "  simulated robot's, or any rectified camera given by --intrinsics (image size and focal\n"
    "  lengths in px; the principal point at the image's centre).\n";

constexpr const char* kCheckUsage =
    "usage: cairn detect check-lut TABLE [--samples N (400)] [--seed S (2)] [--max-distance M (12)]\n"
    "                               [--max-angle DEG (60)] [--decimate F] [--max-residual-chi2 X (13.8)]\n"
    "                               [--sightings-csv FILE]\n"
    "  Renders N tags at random distances (up to 1.5x the table's last) and angles (0-80 deg) with\n"
    "  the table's camera, and prints per error model the NEES of the detected poses against the\n"
    "  truth, and how many tags were found, overall and within the distance and angle given.\n"
    "  --decimate: the detector's (default: the table's; 1 as the daemon's region scans, 2 as its\n"
    "  whole-frame scans). Detections whose corners are farther from a square's projection than the\n"
    "  chi-square bound are left out of the NEES, as the daemon refuses them. --sightings-csv writes each scored sighting (truth in\n"
    "  the estimate's tangent, and every model's covariance) for analysis of models not built in.\n";

struct Camera {
  std::string name;
  PinholeRadTan intrinsics;
};

// A simulated robot's rectified left camera, or one of the given size and focal lengths with its
// principal point at the centre (as the simulator's, so a table's header gives its camera back).
Expected<Camera> CameraOf(const std::string& name, const std::vector<double>& intrinsics, const sim::Terrain& terrain) {
  if (!intrinsics.empty()) {
    if (intrinsics.size() != 4 || !(intrinsics[0] >= 16 && intrinsics[1] >= 16 && intrinsics[2] > 0 && intrinsics[3] > 0) ||
        intrinsics[0] != std::floor(intrinsics[0]) || intrinsics[1] != std::floor(intrinsics[1]))
      return InvalidArgumentError("--intrinsics needs W,H,FX,FY: whole image sizes >= 16 px and focal lengths > 0");
    PinholeRadTan k;
    k.width = static_cast<int>(intrinsics[0]);
    k.height = static_cast<int>(intrinsics[1]);
    k.fx = intrinsics[2];
    k.fy = intrinsics[3];
    k.cx = (k.width - 1) / 2.0;
    k.cy = (k.height - 1) / 2.0;
    return Camera{name, k};
  }
  sim::SimRobot robot;
  if (name == "rover") {
    robot = sim::MakeRover(terrain, "rover", 0, 1, 10.0, 1.0, 0.16);
  } else if (name == "hexacopter") {
    robot = sim::MakeHexacopter(terrain, "hexacopter", 0, 1, 10.0, 1.0, 0.16);
  } else {
    return InvalidArgumentError("--camera must be rover or hexacopter, not '" + name + "' (or give --intrinsics)");
  }
  return Camera{name, robot.stereo.left.intrinsics};
}

// A pose of a tag `d` m from the camera, its normal `angle` from the line of sight, turned
// randomly about its normal, the tilt about a random axis, the centre at a random pixel.
Eigen::Isometry3d RandomTagPose(const PinholeRadTan& k, double d, double angle, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double u = (0.15 + 0.7 * unit(rng)) * k.width, v = (0.15 + 0.7 * unit(rng)) * k.height;
  const Eigen::Vector3d ray = Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
  // The tag's z points into it, away from the camera: along the ray when seen face on.
  Eigen::Vector3d side = ray.unitOrthogonal();
  side = Eigen::AngleAxisd(2 * std::numbers::pi * unit(rng), ray) * side;
  const Eigen::Vector3d z = Eigen::AngleAxisd(angle, side) * ray;
  Eigen::Vector3d x = z.unitOrthogonal();
  x = Eigen::AngleAxisd(2 * std::numbers::pi * unit(rng), z) * x;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  T.translation() = d * ray;
  return T;
}

struct Sighting {
  bool rendered = false, detected = false;
  TagPose pose;
  // The truth in the tangent of the best solution, and of the one nearer the truth.
  Eigen::Matrix<double, 6, 1> error = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> nearest_error = Eigen::Matrix<double, 6, 1>::Zero();
  double corner_sq = 0.0;  // px^2, summed over the 8 coordinates
  std::array<Eigen::Vector2d, 4> corner_error{};  // px, detected minus true
  std::array<Eigen::Vector2d, 4> true_corners{};  // px
};

// Renders (retrying other places in the image when the tag does not fit) and detects one tag.
Sighting RenderAndDetect(const sim::TagViewRenderer& renderer, const PinholeRadTan& k, double tag_size, double d,
                         double angle, bool sample_corners, std::mt19937_64& rng, TagDetector& detector) {
  Sighting s;
  Eigen::Isometry3d truth;
  Expected<sim::TagView> view = OutOfRangeError("");
  for (int attempt = 0; attempt < 32 && !view.ok(); ++attempt) {
    truth = RandomTagPose(k, d, angle, rng);
    view = renderer.Render(kTagId, tag_size, truth, rng());
  }
  if (!view.ok()) return s;
  s.rendered = true;
  const auto found = detector.Detect(Image::GrayView(view->pixels.data(), view->width, view->height, view->width));
  if (!found.ok()) return s;
  for (const TagDetection& det : *found) {
    if (det.id != kTagId) continue;
    std::array<Eigen::Vector2d, 4> corners = det.corners;
    for (Eigen::Vector2d& c : corners) c += Eigen::Vector2d(view->x0, view->y0);
    TagPoseOptions po;
    po.tag_size = tag_size;
    po.sample_corners = sample_corners;
    const auto pose = TagPoseEstimator(po).Estimate(corners, k);
    if (!pose.ok()) return s;
    s.detected = true;
    s.pose = *pose;
    // The truth in the estimate's tangent: where the covariance is defined (T = T_est * Exp(e)).
    s.error = TagPoseEstimator::Deviation(pose->T_cam_tag, truth);
    s.nearest_error = s.error;
    if (pose->has_alternative) {
      const auto alt = TagPoseEstimator::Deviation(pose->T_cam_tag_alternative, truth);
      if (alt.tail<3>().norm() < s.error.tail<3>().norm()) s.nearest_error = alt;
    }
    for (int c = 0; c < 4; ++c) {
      s.corner_error[c] = corners[c] - view->corners[c];
      s.true_corners[c] = view->corners[c];
      s.corner_sq += s.corner_error[c].squaredNorm();
    }
    break;
  }
  return s;
}

// One row per scored sighting: what a model can be computed from, and the truth it is judged by.
std::string SightingCsvHeader() {
  std::string h = "distance,view_angle,reprojection_error,alternative_reprojection_error,flipped_samples,corner_rms";
  const auto add = [&h](const char* prefix, int count) {
    for (int i = 0; i < count; ++i) h += "," + std::string(prefix) + std::to_string(i);
  };
  add("error", 6);
  add("nearest_error", 6);
  add("table_sigma", 6);
  add("alternative_delta", 6);
  add("sample_covariance", 36);
  add("corner_error", 8);
  add("true_corner", 8);
  add("corner_jacobian", 48);
  h += ",solved_samples";
  return h + "\n";
}

void AppendSightingRow(const Sighting& si, const TagErrorTable& table, double tag_size, std::string* out) {
  const TagPose& p = si.pose;
  char buf[64];
  const auto add = [&](double v) {
    std::snprintf(buf, sizeof(buf), ",%.9g", v);
    *out += buf;
  };
  std::snprintf(buf, sizeof(buf), "%.9g", p.distance);
  *out += buf;
  add(p.view_angle);
  add(p.reprojection_error);
  add(p.has_alternative ? p.alternative_reprojection_error : std::nan(""));
  add(p.flipped_samples);
  add(table.corner_rms());
  for (int i = 0; i < 6; ++i) add(si.error[i]);
  for (int i = 0; i < 6; ++i) add(si.nearest_error[i]);
  const Eigen::Matrix<double, 6, 1> sigma = table.Sigma(p.distance, p.view_angle, tag_size);
  for (int i = 0; i < 6; ++i) add(sigma[i]);
  const Eigen::Matrix<double, 6, 1> delta = p.has_alternative
                                                ? TagPoseEstimator::Deviation(p.T_cam_tag, p.T_cam_tag_alternative)
                                                : Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < 6; ++i) add(delta[i]);
  for (int i = 0; i < 36; ++i) add(p.sample_covariance(i / 6, i % 6));
  for (int i = 0; i < 8; ++i) add(si.corner_error[i / 2][i % 2]);
  for (int i = 0; i < 8; ++i) add(si.true_corners[i / 2][i % 2]);
  for (int i = 0; i < 48; ++i) add(p.corner_jacobian(i / 8, i % 8));
  add(p.solved_samples);
  *out += "\n";
}

bool ParseTriple(const std::string& s, double* first, double* last, int* count) {
  std::vector<double> v;
  if (!ParseNumberList(s, &v) || v.size() != 3 || !(v[1] > v[0]) || v[2] < 2 || v[2] > 1000 || v[2] != std::floor(v[2]))
    return false;
  *first = v[0];
  *last = v[1];
  *count = static_cast<int>(v[2]);
  return true;
}

bool ParseCount(const std::string& s, double lo, double hi, double* out) {
  std::vector<double> v;
  if (!ParseNumberList(s, &v) || v.size() != 1 || v[0] < lo || v[0] > hi) return false;
  *out = v[0];
  return true;
}

// The detector as the daemon runs it (detection.detector's defaults; region scans use decimate
// 1), for this one id.
TagDetectorOptions DaemonDetector(double decimate) {
  TagDetectorOptions o;
  o.ids = {static_cast<double>(kTagId)};
  o.decimate = decimate;
  return o;
}

}  // namespace

int RunDetectBuildLut(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBuildUsage);
  std::string camera_name, out;
  std::vector<double> intrinsics;
  double tag_size = 0.16, samples = 16, seed = 1, decimate = 2.0;
  double d0 = 0.5, d1 = 24.0, a0 = 0.0, a1 = 80.0;
  int nd = 48, na = 17;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has = i + 1 < args.args.size();
    bool ok = true;
    if (a == "--camera" && has) {
      camera_name = args.args[++i];
    } else if (a == "--out" && has) {
      out = args.args[++i];
    } else if (a == "--intrinsics" && has) {
      ok = ParseNumberList(args.args[++i], &intrinsics);
    } else if (a == "--tag-size" && has) {
      ok = ParseCount(args.args[++i], 0.01, 10.0, &tag_size);
    } else if (a == "--samples" && has) {
      ok = ParseCount(args.args[++i], 1, 10000, &samples);
    } else if (a == "--seed" && has) {
      ok = ParseCount(args.args[++i], 0, 1e15, &seed);
    } else if (a == "--decimate" && has) {
      ok = ParseCount(args.args[++i], 1.0, 8.0, &decimate);
    } else if (a == "--distances" && has) {
      ok = ParseTriple(args.args[++i], &d0, &d1, &nd) && d0 > 0.0;
    } else if (a == "--angles" && has) {
      ok = ParseTriple(args.args[++i], &a0, &a1, &na) && a0 >= 0.0 && a1 < 90.0;
    } else {
      std::fprintf(stderr, "cairn detect build-lut: unknown or incomplete option '%s'\n%s", a.c_str(), kBuildUsage);
      return 2;
    }
    if (!ok) {
      std::fprintf(stderr, "cairn detect build-lut: %s: bad value\n%s", a.c_str(), kBuildUsage);
      return 2;
    }
  }
  if (camera_name.empty() || out.empty()) {
    std::fprintf(stderr, "cairn detect build-lut: --camera and --out are needed\n%s", kBuildUsage);
    return 2;
  }
  if (camera_name.find_first_of(" \t\n#") != std::string::npos) {
    std::fprintf(stderr, "cairn detect build-lut: --camera '%s': a name without spaces or '#'\n", camera_name.c_str());
    return 2;
  }
  const sim::Terrain terrain = sim::Terrain::Generate(sim::WorldOptions{});
  const auto camera = CameraOf(camera_name, intrinsics, terrain);
  if (!camera.ok()) {
    std::fprintf(stderr, "cairn detect build-lut: %s\n", camera.status().message().c_str());
    return 2;
  }
  const PinholeRadTan& k = camera->intrinsics;
  const sim::TagViewRenderer renderer(terrain, k);
  TagDetector detector(DaemonDetector(decimate));
  TagErrorTable table(camera_name, k.width, k.height, k.fx, k.fy, tag_size, d0, d1, nd, a0 * kDegree, a1 * kDegree, na);
  std::mt19937_64 rng(static_cast<uint64_t>(seed));
  double corner_sq = 0.0;
  int corner_n = 0, rendered = 0, detected = 0;
  for (int i = 0; i < nd; ++i) {
    for (int j = 0; j < na; ++j) {
      TagErrorCell& cell = table.cell(i, j);
      Eigen::Matrix<double, 6, 1> sq = Eigen::Matrix<double, 6, 1>::Zero();
      for (int s = 0; s < static_cast<int>(samples); ++s) {
        const Sighting si = RenderAndDetect(renderer, k, tag_size, table.distance_at(i), table.angle_at(j), false, rng, detector);
        cell.rendered += si.rendered;
        if (!si.detected) continue;
        ++cell.detected;
        sq += si.nearest_error.cwiseAbs2();
        corner_sq += si.corner_sq;
        corner_n += 8;
      }
      if (cell.detected > 0) cell.sigma = (sq / cell.detected).cwiseSqrt().cwiseMax(1e-6);
      rendered += cell.rendered;
      detected += cell.detected;
    }
    std::fprintf(stderr, "\r  %4.1f m done", table.distance_at(i));
  }
  std::fprintf(stderr, "\n");
  if (detected == 0) {
    std::fprintf(stderr, "cairn detect build-lut: no rendered tag was detected; no table written\n");
    return 1;
  }
  table.set_corner_rms(std::sqrt(corner_sq / std::max(corner_n, 1)));
  table.set_decimate(decimate);
  table.FillAndSmooth();
  if (Status s = WriteFileAtomically(out, table.Serialize()); !s.ok()) {
    std::fprintf(stderr, "cairn detect build-lut: %s\n", s.ToString().c_str());
    return 1;
  }
  std::printf("{\"table\": \"%s\", \"camera\": \"%s\", \"rendered\": %d, \"detected\": %d, \"corner_rms_px\": %.4f}\n",
              out.c_str(), camera_name.c_str(), rendered, detected, table.corner_rms());
  return 0;
}

int RunDetectCheckLut(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kCheckUsage);
  std::string path, sightings_csv;
  double samples = 400, seed = 2, max_distance = 12.0, max_angle = 60.0, decimate = 0.0, max_residual_chi2 = 13.8;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has = i + 1 < args.args.size();
    bool ok = true;
    if (a == "--samples" && has) {
      ok = ParseCount(args.args[++i], 1, 1e6, &samples);
    } else if (a == "--seed" && has) {
      ok = ParseCount(args.args[++i], 0, 1e15, &seed);
    } else if (a == "--max-distance" && has) {
      ok = ParseCount(args.args[++i], 0.01, 1000, &max_distance);
    } else if (a == "--max-angle" && has) {
      ok = ParseCount(args.args[++i], 0, 89.9, &max_angle);
    } else if (a == "--decimate" && has) {
      ok = ParseCount(args.args[++i], 1.0, 8.0, &decimate);
    } else if (a == "--max-residual-chi2" && has) {
      ok = ParseCount(args.args[++i], 0.0, 1e9, &max_residual_chi2);
    } else if (a == "--sightings-csv" && has) {
      sightings_csv = args.args[++i];
    } else if (!a.empty() && a[0] != '-' && path.empty()) {
      path = a;
    } else {
      std::fprintf(stderr, "cairn detect check-lut: unknown or incomplete option '%s'\n%s", a.c_str(), kCheckUsage);
      return 2;
    }
    if (!ok) {
      std::fprintf(stderr, "cairn detect check-lut: %s: bad value\n%s", a.c_str(), kCheckUsage);
      return 2;
    }
  }
  if (path.empty()) {
    std::fprintf(stderr, "cairn detect check-lut: name a table\n%s", kCheckUsage);
    return 2;
  }
  auto loaded = TagErrorTable::Load(path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "cairn detect check-lut: %s\n", loaded.status().message().c_str());
    return 1;
  }
  // By default the detections are made as the table's were; another decimation judges the table
  // where the daemon would refuse it (robot_detection_stage.h).
  if (decimate == 0.0) decimate = loaded->decimate();
  const auto table = std::make_shared<const TagErrorTable>(std::move(*loaded));
  const sim::Terrain terrain = sim::Terrain::Generate(sim::WorldOptions{});
  // The table's camera, from its header.
  const auto camera = CameraOf(table->camera(), {static_cast<double>(table->width()), static_cast<double>(table->height()),
                                                 table->fx(), table->fy()}, terrain);
  if (!camera.ok()) {
    std::fprintf(stderr, "cairn detect check-lut: %s: %s\n", path.c_str(), camera.status().message().c_str());
    return 1;
  }
  const PinholeRadTan& k = camera->intrinsics;
  const sim::TagViewRenderer renderer(terrain, k);
  TagDetector detector(DaemonDetector(decimate));
  const double last = table->distance_at(table->distance_count() - 1);
  const double tag_size = table->tag_size();

  const TagErrorKind kinds[] = {TagErrorKind::kCombined, TagErrorKind::kPropagated, TagErrorKind::kThesis,
                                TagErrorKind::kTable,    TagErrorKind::kOnline,     TagErrorKind::kConstant,
                                TagErrorKind::kQuadratic};
  struct Score {
    std::vector<double> nees;
  };
  std::vector<Score> scores(std::size(kinds));
  std::vector<TagErrorModel> models;
  for (const TagErrorKind kind : kinds) models.push_back(*TagErrorModel::Create(kind, table, TagPoseOptions{}.corner_error));
  std::mt19937_64 rng(static_cast<uint64_t>(seed));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::string csv = SightingCsvHeader();
  int rendered = 0, detected = 0, in_range = 0, in_range_detected = 0, flips = 0, refused_residual = 0;
  for (int s = 0; s < static_cast<int>(samples); ++s) {
    const double d = table->distance_at(0) + unit(rng) * (1.5 * last - table->distance_at(0));
    const double angle = unit(rng) * 80.0 * kDegree;
    const Sighting si = RenderAndDetect(renderer, k, tag_size, d, angle, true, rng, detector);
    if (!si.rendered) continue;
    ++rendered;
    const bool inside = d <= max_distance && angle <= max_angle * kDegree;
    in_range += inside;
    if (!si.detected) continue;
    ++detected;
    in_range_detected += inside;
    // The daemon refuses these (detection.max_residual_chi2).
    if (models[0].ResidualChi2(si.pose) > max_residual_chi2) {
      ++refused_residual;
      continue;
    }
    flips += si.error.tail<3>().norm() > si.nearest_error.tail<3>().norm() + 1e-9;
    if (!sightings_csv.empty()) AppendSightingRow(si, *table, tag_size, &csv);
    for (size_t m = 0; m < models.size(); ++m) {
      const Matrix6d P = models[m].Covariance(si.pose, tag_size);
      scores[m].nees.push_back(si.error.dot(P.ldlt().solve(si.error)));
    }
  }
  if (!sightings_csv.empty()) {
    if (Status st = WriteFileAtomically(sightings_csv, csv); !st.ok()) {
      std::fprintf(stderr, "cairn detect check-lut: %s\n", st.message().c_str());
      return 1;
    }
  }
  JsonWriter j;
  j.BeginObject();
  j.Field("table", path).Field("camera", table->camera()).Field("seed", static_cast<int64_t>(seed));
  j.Field("rendered", rendered).Field("detected", detected).Field("flipped_best_solutions", flips);
  j.Field("refused_residual", refused_residual).Field("max_residual_chi2", max_residual_chi2);
  j.Field("max_distance_m", max_distance).Field("max_angle_deg", max_angle).Field("decimate", decimate);
  j.Field("in_range", in_range).Field("in_range_detected", in_range_detected);
  j.Field("recall_in_range", in_range > 0 ? static_cast<double>(in_range_detected) / in_range : 0.0);
  // 95 % band of the mean of n chi-square(6) values, by the Wilson-Hilferty approximation.
  const double n = std::max(detected, 1);
  const auto chi2_quantile = [](double dof, double z) {
    const double c = 2.0 / (9.0 * dof);
    return dof * std::pow(1.0 - c + z * std::sqrt(c), 3);
  };
  j.Field("nees_band_low", chi2_quantile(6.0 * n, -1.959964) / n);
  j.Field("nees_band_high", chi2_quantile(6.0 * n, 1.959964) / n);
  j.Key("models").BeginArray();
  for (size_t m = 0; m < models.size(); ++m) {
    std::vector<double> v = scores[m].nees;
    double mean = 0.0;
    int inside95 = 0;
    for (const double x : v) {
      mean += x;
      inside95 += x <= 12.592;  // chi-square(6) 95 %
    }
    mean /= std::max<size_t>(v.size(), 1);
    std::sort(v.begin(), v.end());
    j.BeginObject();
    j.Field("model", TagErrorKindName(kinds[m]));
    j.Field("mean_nees", mean).Field("median_nees", v.empty() ? 0.0 : v[v.size() / 2]);
    j.Field("share_within_chi2_95", v.empty() ? 0.0 : static_cast<double>(inside95) / v.size());
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  std::printf("%s\n", j.str().c_str());
  return 0;
}

}  // namespace cairn::tools
