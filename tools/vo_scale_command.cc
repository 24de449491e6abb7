// cairn bench vo-scale: where a robot's visual odometry gains or loses scale, stage by stage, on
// the simulator's renderings with their true depth and poses.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "estimation/testing/stereo_matches.h"
#include "estimation/vo/keyframe_visual_odometry.h"
#include "estimation/vo/stereo_feature_tracker.h"
#include "estimation/vo/stereo_pose_estimator.h"
#include "sim/mission_simulator.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kVoScaleUsage =
    "usage: cairn bench vo-scale [--robot rover|hexacopter] [--seed N] [--pairs N]\n"
    "  On the default world (seed N, default 2), renders the robot's stereo pairs with their true\n"
    "  depth and poses and measures, with the odometry's default options:\n"
    "  - stereo: the disparity of each corner's right-image match against the true one;\n"
    "  - tracking: each corner tracked into the pair 0.2 s later, against its true projection;\n"
    "  - pose: |t| and NEES against the truth from those pairs, by the 3-D alignment of their points alone\n"
    "    (vo.bundle_iterations 0) on the measured and on exact observations, and by the estimator\n"
    "    as configured (then a two-frame bundle adjustment) on the measured ones;\n"
    "  - chain: the odometry over 40 s at 10 Hz, its path against the truth's.\n"
    "  N pairs (default 30) for the first three.\n";

struct Rig {
  RectifiedStereoCamera camera;
  Eigen::Isometry3d T_body_left;
};

Rig RigOf(const sim::SimRobot& robot) {
  const auto& st = robot.stereo;
  Rig r;
  r.camera.width = st.left.intrinsics.width;
  r.camera.height = st.left.intrinsics.height;
  r.camera.f = st.left.intrinsics.fx;
  r.camera.cx = st.left.intrinsics.cx;
  r.camera.cy = st.left.intrinsics.cy;
  r.camera.baseline = st.baseline();
  r.T_body_left = st.left.T_body_cam;
  return r;
}

// A corner of the left image with its true point in that camera.
struct TrueCorner {
  StereoObservation observed;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

}  // namespace

int RunBenchVoScale(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kVoScaleUsage);
  std::string robot_name = "hexacopter";
  int64_t seed = 2, pairs = 30;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--robot" && has_value) {
      robot_name = args.args[++i];
    } else if (a == "--seed" && has_value) {
      seed = std::strtoll(args.args[++i], nullptr, 10);
    } else if (a == "--pairs" && has_value) {
      pairs = std::strtoll(args.args[++i], nullptr, 10);
    } else {
      std::fputs(kVoScaleUsage, stderr);
      return 2;
    }
  }
  if ((robot_name != "rover" && robot_name != "hexacopter") || pairs < 1 || pairs > 1000) {
    std::fputs(kVoScaleUsage, stderr);
    return 2;
  }
  sim::WorldOptions world;
  world.seed = seed;
  sim::MissionOptions mission;
  mission.robots = {robot_name};
  mission.duration = 45.0;
  auto created = sim::MissionSimulator::Create(world, mission);
  if (!created.ok()) {
    std::fprintf(stderr, "cairn bench vo-scale: %s\n", created.status().ToString().c_str());
    return 1;
  }
  const sim::MissionSimulator& sim = **created;
  const sim::SimRobot& robot = sim.robots()[0];
  const Rig rig = RigOf(robot);
  const RectifiedStereoCamera& cam = rig.camera;
  const VoOptions options;
  StereoFeatureTracker tracker(options, cam);
  VoOptions alignment_only = options;
  alignment_only.bundle_iterations = 0;
  StereoPoseEstimator aligner(alignment_only, cam), estimator(options, cam);
  const auto Wrap = [&](std::vector<uint8_t>& pixels) {
    return cv::Mat(cam.height, cam.width, CV_8UC1, pixels.data());
  };
  const auto T_world_left = [&](double t) {
    return robot.trajectory.Evaluate(t).T_world_body * rig.T_body_left;
  };

  double disparity_error = 0.0, along_flow = 0.0, flow = 0.0, measured = 0.0, exact = 0.0, bundle = 0.0;
  double track_sq = 0.0, nees_aligned = 0.0, nees_bundle = 0.0;
  int64_t tracked_all = 0;
  int64_t matches = 0, tracks = 0, estimates = 0;
  for (int64_t k = 0; k < pairs; ++k) {
    const double t0 = 2.0 + 40.0 * static_cast<double>(k) / static_cast<double>(pairs), t1 = t0 + 0.2;
    std::vector<uint8_t> l0, r0, l1, r1;
    std::vector<float> depth;
    sim.RenderStereo(0, t0, static_cast<uint64_t>(2 * k), &l0, &r0, &depth);
    sim.RenderStereo(0, t1, static_cast<uint64_t>(2 * k + 1), &l1, &r1, nullptr);
    StereoPyramids p0, p1;
    tracker.Prepare(Wrap(l0), Wrap(r0), &p0);
    tracker.Prepare(Wrap(l1), Wrap(r1), &p1);
    std::vector<StereoObservation> observed;
    tracker.DetectAndMatch(p0, &observed);
    std::vector<TrueCorner> corners;
    for (const StereoObservation& o : observed) {
      const long u = std::lround(o.u_left), v = std::lround(o.v);
      if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) continue;
      const float z = depth[static_cast<size_t>(v) * static_cast<size_t>(cam.width) + static_cast<size_t>(u)];
      if (!(z > 0.0f)) continue;
      const double d_true = cam.f * cam.baseline / z;
      disparity_error += (o.u_left - o.u_right) - d_true;
      ++matches;
      corners.push_back({o, Eigen::Vector3d((o.u_left - cam.cx) * z / cam.f, (o.v - cam.cy) * z / cam.f, z)});
    }
    // Tracked from a prediction 0.7 px off the truth, with the keyframe's disparity (as after a
    // keyframe with no motion model).
    const Eigen::Isometry3d T_1_0 = T_world_left(t1).inverse() * T_world_left(t0);
    std::vector<cv::Point2f> from, predicted;
    std::vector<float> predicted_disparity;
    std::vector<StereoObservation> truth;
    for (const TrueCorner& c : corners) {
      const StereoObservation t = testing::ObserveStereo(cam, T_1_0 * c.p);
      from.emplace_back(static_cast<float>(c.observed.u_left), static_cast<float>(c.observed.v));
      predicted.emplace_back(static_cast<float>(t.u_left + 0.7), static_cast<float>(t.v - 0.4));
      predicted_disparity.push_back(static_cast<float>(c.observed.u_left - c.observed.u_right));
      truth.push_back(t);
    }
    std::vector<StereoObservation> tracked;
    std::vector<uint8_t> found;
    tracker.Track(p0, from, predicted, predicted_disparity, p1, &tracked, &found);
    std::vector<StereoPoint> kf, cur, kf_exact, cur_exact;
    std::vector<StereoObservation> kf_seen, cur_seen, kf_seen_exact, cur_seen_exact;
    for (size_t i = 0; i < corners.size(); ++i) {
      if (!found[i]) continue;
      const Eigen::Vector2d f(truth[i].u_left - from[i].x, truth[i].v - from[i].y);
      const Eigen::Vector2d e(tracked[i].u_left - truth[i].u_left, tracked[i].v - truth[i].v);
      if (e.norm() > 2.0) continue;  // lost: not a bias
      track_sq += e.squaredNorm();
      ++tracked_all;
      if (f.norm() > 1.0) {
        along_flow += e.dot(f) / f.norm();
        flow += f.norm();
        ++tracks;
      }
      StereoPoint a, b, a_exact, b_exact;
      if (!TriangulateStereo(cam, corners[i].observed, options.pixel_sigma, options.min_disparity, &a) ||
          !TriangulateStereo(cam, tracked[i], options.pixel_sigma, options.min_disparity, &b) ||
          b.cov(2, 2) > options.max_depth_error * options.max_depth_error)
        continue;
      const StereoObservation exact_0 = testing::ObserveStereo(cam, corners[i].p);
      if (!TriangulateStereo(cam, exact_0, options.pixel_sigma, 0.0, &a_exact) ||
          !TriangulateStereo(cam, truth[i], options.pixel_sigma, 0.0, &b_exact))
        continue;
      kf.push_back(a);
      cur.push_back(b);
      kf_exact.push_back(a_exact);
      cur_exact.push_back(b_exact);
      kf_seen.push_back(corners[i].observed);
      cur_seen.push_back(tracked[i]);
      kf_seen_exact.push_back(exact_0);
      cur_seen_exact.push_back(truth[i]);
    }
    const Eigen::Isometry3d T_kf_cur_true = T_world_left(t0).inverse() * T_world_left(t1);
    const double true_length = T_kf_cur_true.translation().norm();
    const auto Nees = [&](const PoseEstimate& e) {
      Vector6d d;
      d.head<3>() = e.T_kf_cur.translation() - T_kf_cur_true.translation();
      const Eigen::AngleAxisd r(T_kf_cur_true.linear().transpose() * e.T_kf_cur.linear());
      d.tail<3>() = r.angle() * r.axis();
      return d.dot(e.covariance.ldlt().solve(d));
    };
    const auto ransac_seed = static_cast<uint64_t>(k);
    const PoseEstimate m = aligner.Estimate(kf_seen, cur_seen, kf, cur, ransac_seed);
    const PoseEstimate x = aligner.Estimate(kf_seen_exact, cur_seen_exact, kf_exact, cur_exact, ransac_seed);
    const PoseEstimate b = estimator.Estimate(kf_seen, cur_seen, kf, cur, ransac_seed);
    if (m.status == VoStatus::kOk && x.status == VoStatus::kOk && b.status == VoStatus::kOk &&
        true_length > 0.05) {
      measured += m.T_kf_cur.translation().norm() / true_length - 1.0;
      bundle += b.T_kf_cur.translation().norm() / true_length - 1.0;
      exact += x.T_kf_cur.translation().norm() / true_length - 1.0;
      nees_aligned += Nees(m);
      nees_bundle += Nees(b);
      ++estimates;
    }
  }

  // The odometry itself, chained over its frames.
  KeyframeVisualOdometry vo(options, cam, rig.T_body_left);
  double est_path = 0.0, true_path = 0.0;
  Eigen::Isometry3d last_odom = Eigen::Isometry3d::Identity(), last_true = Eigen::Isometry3d::Identity();
  bool chained = false;
  for (int k = 0; k <= 400; ++k) {
    const double t = 2.0 + 0.1 * k;
    std::vector<uint8_t> left, right;
    sim.RenderStereo(0, t, static_cast<uint64_t>(100000 + k), &left, &right, nullptr);
    const VoResult r = vo.Process(Timestamp::FromNanoseconds(static_cast<int64_t>(std::llround(t * 1e9))),
                                  Wrap(left), Wrap(right));
    const Eigen::Isometry3d T_true = robot.trajectory.Evaluate(t).T_world_body;
    if (r.status == VoStatus::kOk && chained) {
      est_path += (last_odom.inverse() * r.T_odom_body).translation().norm();
      true_path += (last_true.inverse() * T_true).translation().norm();
    }
    chained = r.status == VoStatus::kOk || r.status == VoStatus::kNoKeyframe;
    last_odom = r.T_odom_body;
    last_true = T_true;
  }

  std::printf("%s, default world seed %lld, focal length %.0f px, baseline %.3f m\n", robot_name.c_str(),
              static_cast<long long>(seed), cam.f, cam.baseline);
  std::printf("  stereo: %lld matches, disparity %+.4f px off the truth on average\n",
              static_cast<long long>(matches),
              matches > 0 ? disparity_error / static_cast<double>(matches) : 0.0);
  std::printf("  tracking: %lld tracks, %+.4f px along the flow on average (%+.3f %% of the flow)\n",
              static_cast<long long>(tracks), tracks > 0 ? along_flow / static_cast<double>(tracks) : 0.0,
              flow > 0.0 ? 100.0 * along_flow / flow : 0.0);
  std::printf("  tracking error: %.3f px rms per image axis (the odometry assumes %.3f)\n",
              tracked_all > 0 ? std::sqrt(track_sq / (2.0 * static_cast<double>(tracked_all))) : 0.0,
              options.pixel_sigma);
  const double per = estimates > 0 ? 100.0 / static_cast<double>(estimates) : 0.0;
  std::printf(
      "  pose: %lld pairs, |t| by the alignment alone %+.3f %% long on the measured observations, %+.3f %% "
      "on "
      "exact ones; by the estimator as configured %+.3f %% on the measured ones\n",
      static_cast<long long>(estimates), per * measured, per * exact, per * bundle);
  std::printf("  pose NEES mean (6 when consistent): alignment alone %.2f, estimator as configured %.2f\n",
              estimates > 0 ? nees_aligned / static_cast<double>(estimates) : 0.0,
              estimates > 0 ? nees_bundle / static_cast<double>(estimates) : 0.0);
  std::printf("  chain: path %.3f m against %.3f m, %+.3f %% long\n", est_path, true_path,
              true_path > 0.0 ? 100.0 * (est_path / true_path - 1.0) : 0.0);
  return 0;
}

}  // namespace cairn::tools
