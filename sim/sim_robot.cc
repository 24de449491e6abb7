#include "sim/sim_robot.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <utility>
#include <numbers>

#include "sim/sim_random.h"
#include "sim/tag36h11_code.h"

namespace cairn::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kKnot = 0.5;  // s between spline control points

// Camera looking along body x, pitched down by `tilt` (camera: z forward, x right, y down).
Eigen::Matrix3d ForwardCamera(double tilt) {
  Eigen::Matrix3d base;
  base.col(0) = -Eigen::Vector3d::UnitY();
  base.col(1) = -Eigen::Vector3d::UnitZ();
  base.col(2) = Eigen::Vector3d::UnitX();
  return base * Eigen::AngleAxisd(-tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

StereoCalibration MakeStereo(int width, int height, double f, double baseline, double scale,
                             const Eigen::Vector3d& p_body_left, const Eigen::Matrix3d& R_body_cam) {
  StereoCalibration s;
  PinholeRadTan k;
  k.width = static_cast<int>(std::lround(width * scale));
  k.height = static_cast<int>(std::lround(height * scale));
  k.fx = k.fy = f * scale;
  k.cx = (k.width - 1) / 2.0;
  k.cy = (k.height - 1) / 2.0;
  s.left.name = "cam0";
  s.right.name = "cam1";
  s.left.intrinsics = s.right.intrinsics = k;
  s.left.T_body_cam.linear() = R_body_cam;
  s.left.T_body_cam.translation() = p_body_left;
  s.right.T_body_cam = s.left.T_body_cam * Eigen::Translation3d(baseline, 0, 0);
  return s;
}

// Xsens MTi-10 class figures: gyro 0.03 deg/s/sqrt(Hz), accel 60 ug/sqrt(Hz); bias random walks
// chosen for an in-run stability of roughly 18 deg/h and 15 ug.
ImuCalibration XsensMti10(double rate_hz) {
  ImuCalibration c;
  c.rate_hz = rate_hz;
  c.gyro_noise_density = 0.03 * kPi / 180.0;
  c.accel_noise_density = 60e-6 * 9.81;
  c.gyro_random_walk = 2.0e-5;
  c.accel_random_walk = 1.0e-4;
  return c;
}

// Angle difference wrapped into (-pi, pi].
double Wrap(double a) { return std::remainder(a, 2 * kPi); }

std::vector<Eigen::Vector3d> UnwrapYaw(std::vector<Eigen::Vector3d> e) {
  for (size_t i = 1; i < e.size(); ++i) e[i][0] = e[i - 1][0] + Wrap(e[i][0] - e[i - 1][0]);
  return e;
}

// A robot's path in the plane, by time from the moment it sets out on it.
using PlanarPath = std::function<Eigen::Vector2d(double t)>;

// Deployment from the lander: still in front of a tag until `still`, turning on the spot until
// `t_turn`, then a cubic Hermite curve from rest at p0 to the path's point p1 (velocity m1) at
// `t_join`, then the path from its time `t_entry` on.
struct DeployPlan {
  Eigen::Vector2d p0 = Eigen::Vector2d::Zero(), p1 = Eigen::Vector2d::Zero(), m1 = Eigen::Vector2d::Zero();
  double yaw0 = 0.0, yaw_go = 0.0;
  double still = 0.0, t_turn = 0.0, t_join = 0.0, t_entry = 0.0;
};

// `airborne`: a multicopter hovers above the ground robots, so it may share their face.
DeployPlan PlanDeployment(Deployment* d, const PlanarPath& path, double period, double standoff, double still,
                          double speed, bool airborne) {
  DeployPlan plan;
  plan.still = still;
  // Join the path where it passes at about the standoff distance from the lander: a short drive.
  double best = 1e300;
  for (int k = 0; k < 720; ++k) {
    const double t = period * k / 720.0;
    const double score = std::abs((path(t) - d->lander).norm() - standoff);
    if (score < best) {
      best = score;
      plan.t_entry = t;
    }
  }
  plan.p1 = path(plan.t_entry);
  plan.m1 = (path(plan.t_entry + 0.05) - path(plan.t_entry - 0.05)) / 0.1;
  // A sunlit face that no rover took, looking most nearly the way to the path.
  const Eigen::Vector2d to_path = plan.p1 - d->lander;
  const double towards = std::atan2(to_path.y(), to_path.x());
  int face = 0;
  double best_score = -1e9;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d normal(std::cos(kPi / 2 * k), std::sin(kPi / 2 * k));
    const bool taken = !airborne && ((d->taken_faces >> k) & 1u) != 0;
    const double score = std::cos(towards - kPi / 2 * k) + (normal.dot(d->sun) > 0.05 ? 4.0 : 0.0) - (taken ? 16.0 : 0.0);
    if (score > best_score) {
      best_score = score;
      face = k;
    }
  }
  if (!airborne) d->taken_faces |= 1u << face;
  const Eigen::Vector2d normal(std::cos(kPi / 2 * face), std::sin(kPi / 2 * face));
  plan.p0 = d->lander + standoff * normal;
  plan.yaw0 = std::atan2(-normal.y(), -normal.x());
  const double drive = std::max(4.0, 1.5 * (plan.p1 - plan.p0).norm() / speed);
  Eigen::Vector2d go = 3.0 * (plan.p1 - plan.p0) - drive * plan.m1;
  if (go.norm() < 1e-6) go = plan.p1 - plan.p0;
  plan.yaw_go = std::atan2(go.y(), go.x());
  plan.t_turn = still + 1.0 + std::abs(Wrap(plan.yaw_go - plan.yaw0)) / 0.4;  // turning at 0.4 rad/s
  plan.t_join = plan.t_turn + drive;
  return plan;
}

// Position and heading at time `t` from the robot's start.
std::pair<Eigen::Vector2d, double> DeployedPose(const DeployPlan& plan, const PlanarPath& path, double t) {
  const auto xy = [&](double u) -> Eigen::Vector2d {
    if (u <= plan.t_turn) return plan.p0;
    if (u >= plan.t_join) return path(plan.t_entry + (u - plan.t_join));
    const double T = plan.t_join - plan.t_turn, x = (u - plan.t_turn) / T;
    const double h00 = 2 * x * x * x - 3 * x * x + 1, h01 = -2 * x * x * x + 3 * x * x, h11 = x * x * x - x * x;
    return h00 * plan.p0 + h01 * plan.p1 + h11 * T * plan.m1;
  };
  if (t < plan.still) return {plan.p0, plan.yaw0};
  if (t < plan.t_turn) {
    const double x = (t - plan.still) / (plan.t_turn - plan.still), smooth = x * x * (3 - 2 * x);
    return {plan.p0, plan.yaw0 + Wrap(plan.yaw_go - plan.yaw0) * smooth};
  }
  const Eigen::Vector2d ahead = xy(t + 0.05) - xy(t - 0.05);
  return {xy(t), ahead.norm() > 1e-9 ? std::atan2(ahead.y(), ahead.x()) : plan.yaw_go};
}

}  // namespace

SimRobot MakeRover(const Terrain& terrain, const std::string& name, int index, uint64_t seed,
                   double duration, double image_scale, double tag_size, Deployment* deployment) {
  SimRobot r;
  r.name = name;
  r.kind = SimRobotKind::kRover;
  r.stereo = MakeStereo(1024, 508, 1080.0, 0.09, image_scale, {0.2, 0.045, 1.0}, ForwardCamera(25 * kPi / 180));
  r.imu = XsensMti10(200.0);
  r.wheels = {{0.35, 0.33, -0.3}, {0.35, -0.33, -0.3}, {-0.35, 0.33, -0.3}, {-0.35, -0.33, -0.3}};
  // Seeded loop: a wobbly circle, driven at 0.4 m/s.
  SimRandom rng = SimRandom::Stream(seed, 100 + static_cast<uint64_t>(index));
  const double limit = terrain.half_size() - 3.0;
  const double R0 = std::min(7.0, limit / 2), phase = rng.Uniform(0, 2 * kPi);
  // y before x: a seed names one world whatever order a compiler evaluates arguments in (this is
  // the order GCC's builds always drew, so earlier missions keep their paths).
  const double center_y = rng.Uniform(-3, 3);
  const double center_x = rng.Uniform(-3, 3);
  const Eigen::Vector2d drawn(center_x + 4.0 * index, center_y);
  const double speed = 0.4, wobble = 0.15;
  const int n = static_cast<int>(std::ceil(duration / kKnot)) + 4;
  // It stands still before it drives off, as a rover does until its estimator has initialized
  // (wheels turning hold the filter's static initialization back).
  const double still = 2.0;  // s
  // The rover's poses (control points) around a loop centred at `c`, and the steepest tilt of the
  // ground under its wheels along them.
  struct Drive {
    std::vector<Eigen::Vector3d> pos, euler;
    double max_tilt = 0.0;
    Deployment deployment;
  };
  const auto drive_around = [&](const Eigen::Vector2d& c) {
    Drive d;
    const Eigen::Vector2d center(std::clamp(c.x(), -limit + R0, limit - R0),
                                 std::clamp(c.y(), -limit + R0, limit - R0));
    const auto xy_at = [&](double s) {
      const double th = phase + s / R0;
      const double rad = R0 * (1 + wobble * std::sin(2 * th + phase));
      return Eigen::Vector2d(center + rad * Eigen::Vector2d(std::cos(th), std::sin(th)));
    };
    const PlanarPath loop = [&](double t) { return xy_at(speed * t); };
    std::optional<DeployPlan> plan;
    // In front of a lander tag: the camera (1.3 m up, 25 deg down) sees the tag, 0.7 m up, from 1.6 m.
    if (deployment != nullptr && deployment->enabled) {
      d.deployment = *deployment;
      plan = PlanDeployment(&d.deployment, loop, 2 * kPi * R0 / speed, 2.6, still, speed, false);
    }
    for (int i = 0; i < n; ++i) {
      Eigen::Vector2d p;
      double yaw = 0.0;
      if (plan) {
        std::tie(p, yaw) = DeployedPose(*plan, loop, kKnot * (i - 1));
      } else {
        const double s = speed * std::max(0.0, kKnot * (i - 1) - still);
        const Eigen::Vector2d ahead = xy_at(s + 0.05) - xy_at(s - 0.05);
        p = xy_at(s);
        yaw = std::atan2(ahead.y(), ahead.x());
      }
      const Eigen::Rotation2Dd R(yaw);
      double hw[4];
      for (size_t w = 0; w < 4; ++w) {
        const Eigen::Vector2d pw = p + R * r.wheels[w].head<2>();
        hw[w] = terrain.Height(pw.x(), pw.y());
      }
      // Wheels: 0 front-left, 1 front-right, 2 rear-left, 3 rear-right.
      const double pitch = std::atan2((hw[2] + hw[3]) - (hw[0] + hw[1]), 2 * 0.7);
      const double roll = std::atan2((hw[0] + hw[2]) - (hw[1] + hw[3]), 2 * 0.66);
      d.pos.emplace_back(p.x(), p.y(), (hw[0] + hw[1] + hw[2] + hw[3]) / 4 + 0.3);
      d.euler.emplace_back(yaw, pitch, roll);
      d.max_tilt = std::max(d.max_tilt, std::acos(std::cos(pitch) * std::cos(roll)));
    }
    return d;
  };
  // A rover's planner keeps it off ground that tilts it more than this (the big crater's walls
  // reach 70 deg, and a rover driven down them faces its unlit inside, blind). The drawn loop is
  // kept when it is drivable; else the nearest drivable one, its centre moved in 0.5 m steps in 16
  // directions; else the least steep of those.
  constexpr double kMaxTilt = 25 * kPi / 180;
  Drive chosen = drive_around(drawn);
  for (int step = 1; step <= 40 && chosen.max_tilt > kMaxTilt; ++step) {
    for (int k = 0; k < 16 && chosen.max_tilt > kMaxTilt; ++k) {
      const double a = 2 * kPi * k / 16;
      Drive d = drive_around(drawn + 0.5 * step * Eigen::Vector2d(std::cos(a), std::sin(a)));
      if (d.max_tilt < chosen.max_tilt) chosen = std::move(d);
    }
  }
  if (deployment != nullptr && deployment->enabled) *deployment = chosen.deployment;
  std::vector<Eigen::Vector3d> pos = std::move(chosen.pos), euler = std::move(chosen.euler);
  r.trajectory = BSplineTrajectory(kKnot, std::move(pos), UnwrapYaw(std::move(euler)));
  // Body and camera mast, and three tags tilted 40 deg upwards around the mast.
  r.boxes.push_back({Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.0)), {0.45, 0.35, 0.15}, 0.35f});
  r.boxes.push_back({Eigen::Isometry3d(Eigen::Translation3d(0.2, 0, 0.55)), {0.05, 0.05, 0.4}, 0.3f});
  for (int k = 0; k < 3; ++k) {
    SimMarker m;
    m.id = 10 * index + k;
    m.size = tag_size;
    m.bits = *Tag36h11MarkerBits(m.id);
    const double az = kPi + 2 * kPi * k / 3;  // first tag faces backwards
    const Eigen::Matrix3d R_face =
        (Eigen::AngleAxisd(az, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(kPi / 2 - 40 * kPi / 180, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();  // marker z = outward normal, raised 40 deg
    m.T_body_marker.linear() = R_face;
    m.T_body_marker.translation() = Eigen::Vector3d(0.2, 0, 0.75) + 0.12 * (R_face * Eigen::Vector3d::UnitZ());
    r.markers.push_back(m);
  }
  return r;
}

void AddRoofTag(int index, double size, SimRobot* rover) {
  SimMarker m;
  m.id = 10 * index + 3;
  m.size = size;
  m.bits = *Tag36h11MarkerBits(m.id);
  // Behind the mast, so that the rover's own camera does not see it; 1 mm above the deck.
  m.T_body_marker.translation() = Eigen::Vector3d(-0.2, 0.0, 0.151);
  rover->markers.push_back(m);
}

SimRobot MakeHexacopter(const Terrain& terrain, const std::string& name, int index, uint64_t seed,
                        double duration, double image_scale, double tag_size, Deployment* deployment) {
  SimRobot r;
  r.name = name;
  r.kind = SimRobotKind::kHexacopter;
  r.stereo = MakeStereo(666, 506, 350.0, 0.12, image_scale, {0.15, 0.06, -0.05}, ForwardCamera(60 * kPi / 180));
  r.imu = XsensMti10(400.0);
  SimRandom rng = SimRandom::Stream(seed, 200 + static_cast<uint64_t>(index));
  const double limit = terrain.half_size() - 3.0;
  const double R0 = std::min(9.0, limit / 2), phase = rng.Uniform(0, 2 * kPi);
  const double speed = 1.0, altitude = rng.Uniform(3.5, 5.0);
  const int n = static_cast<int>(std::ceil(duration / kKnot)) + 4;
  std::vector<Eigen::Vector3d> pos, euler;
  // It hovers after take-off before it sets out, as a survey flight does (and as the filter's static
  // initialization needs: a multicopter in flight is never still).
  const double hover = 2.0;  // s
  const auto th_at = [&](int i) { return phase + speed * std::max(0.0, kKnot * (i - 1) - hover) / R0; };
  const auto figure8 = [&](double th) {
    return Eigen::Vector2d(R0 * Eigen::Vector2d(std::cos(th), 0.6 * std::sin(2 * th) + std::sin(th) * 0.4));
  };
  const auto height = [&](const Eigen::Vector2d& p, double th) {
    return terrain.Height(p.x(), p.y()) + altitude + 0.5 * std::sin(3 * th);
  };
  std::optional<DeployPlan> plan;
  std::vector<double> deployed_yaw;
  const PlanarPath path = [&](double t) { return figure8(phase + speed * t / R0); };
  // 2 m out from a lander tag and 2 m above it: the camera, 60 deg down, sees it 45 deg down.
  if (deployment != nullptr && deployment->enabled) {
    plan = PlanDeployment(deployment, path, 2 * kPi * R0 / speed, 3.0, hover, speed, true);
  }
  for (int i = 0; i < n; ++i) {
    const double t = kKnot * (i - 1);
    if (!plan) {
      const double th = th_at(i);
      const Eigen::Vector2d p = figure8(th);
      pos.emplace_back(p.x(), p.y(), height(p, th));
      continue;
    }
    const auto [p, yaw] = DeployedPose(*plan, path, t);
    deployed_yaw.push_back(yaw);
    const double z0 = deployment->lander_ground + 0.7 + 2.0;
    const double th_entry = phase + speed * plan->t_entry / R0;
    double z = z0;
    if (t >= plan->t_join) {
      z = height(p, phase + speed * (plan->t_entry + t - plan->t_join) / R0);
    } else if (t > plan->t_turn) {
      const double x = (t - plan->t_turn) / (plan->t_join - plan->t_turn);
      z = z0 + (height(plan->p1, th_entry) - z0) * x * x * (3 - 2 * x);
    }
    pos.emplace_back(p.x(), p.y(), z);
  }
  // Heading along the path; roll and pitch lean into the horizontal acceleration as a multirotor.
  for (int i = 0; i < n; ++i) {
    const size_t a = static_cast<size_t>(std::max(i - 1, 0)), b = static_cast<size_t>(std::min(i + 1, n - 1));
    const Eigen::Vector3d vel = (pos[b] - pos[a]) / (kKnot * static_cast<double>(b - a));
    const Eigen::Vector3d acc = i > 0 && i < n - 1
                                    ? Eigen::Vector3d((pos[b] - 2 * pos[static_cast<size_t>(i)] + pos[a]) / (kKnot * kKnot))
                                    : Eigen::Vector3d::Zero();
    // Hovering, it already faces along the path (its tangent at the start).
    const double th = th_at(i);
    const Eigen::Vector2d tangent(-std::sin(th), 1.2 * std::cos(2 * th) + 0.4 * std::cos(th));
    const double yaw = plan ? deployed_yaw[static_cast<size_t>(i)]
                       : vel.head<2>().norm() > 1e-6 ? std::atan2(vel.y(), vel.x())
                                                      : std::atan2(tangent.y(), tangent.x());
    const Eigen::Vector2d acc_body = Eigen::Rotation2Dd(-yaw) * acc.head<2>();
    euler.emplace_back(yaw, std::atan2(acc_body.x(), 9.81), -std::atan2(acc_body.y(), 9.81));
  }
  r.trajectory = BSplineTrajectory(kKnot, std::move(pos), UnwrapYaw(std::move(euler)));
  r.boxes.push_back({Eigen::Isometry3d::Identity(), {0.3, 0.3, 0.06}, 0.25f});
  SimMarker m;
  m.id = 100 + index;
  m.size = tag_size;
  m.bits = *Tag36h11MarkerBits(m.id);
  m.T_body_marker.linear() = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();  // faces down
  m.T_body_marker.translation() = Eigen::Vector3d(0, 0, -0.065);
  r.markers.push_back(m);
  return r;
}

}  // namespace cairn::sim
