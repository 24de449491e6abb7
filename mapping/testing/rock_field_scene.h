#pragma once
// A coloured, gravity-aligned test world for submap matching: gently undulating ground with
// half-ellipsoid rocks and boxes, sampled densely, and submaps of it seen from different origins
// (x, y, z, yaw) with position noise and their own 0.05 m voxel grid.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/occupancy_integrator.h"
#include "mapping/submap.h"
#include "mapping/voxel_cloud.h"

namespace cairn::testing {

struct ScenePoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // world
  uint8_t r = 0, g = 0, b = 0;
  bool obstacle = false;
};

struct RockFieldOptions {
  double x_min = -5.0, x_max = 5.0, y_min = -4.0, y_max = 4.0;  // m
  int rocks = 30;
  int boxes = 8;
  double density = 1600.0;  // surface samples per m^2 (about 4 per 0.05 m voxel)
  unsigned seed = 7;
};

inline double RockFieldGround(double x, double y) { return 0.05 * std::sin(0.7 * x) * std::cos(0.5 * y); }

inline uint8_t ClampColour(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

inline std::vector<ScenePoint> RockField(const RockFieldOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto uni = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  std::vector<ScenePoint> out;

  struct Footprint {
    Eigen::Vector2d c;
    double yaw, a, b;
    bool box;
  };
  std::vector<Footprint> footprints;
  const double margin = 0.6;
  // Rocks: half-ellipsoids sunk a little into the ground, each with its own colour and shading.
  for (int i = 0; i < o.rocks; ++i) {
    Footprint f{{uni(o.x_min + margin, o.x_max - margin), uni(o.y_min + margin, o.y_max - margin)},
                uni(0.0, std::numbers::pi),
                uni(0.15, 0.5),
                uni(0.15, 0.5),
                false};
    const double h = uni(0.15, 0.45);
    const double base[3] = {uni(70, 200), uni(60, 170), uni(50, 150)};
    const double p = 1.6;
    const double area =
        2.0 * std::numbers::pi *
        std::pow((std::pow(f.a * f.b, p) + std::pow(f.a * h, p) + std::pow(f.b * h, p)) / 3.0, 1.0 / p);
    const int n = static_cast<int>(area * o.density);
    const double cy = std::cos(f.yaw), sy = std::sin(f.yaw);
    const double z0 = RockFieldGround(f.c.x(), f.c.y()) - 0.05;
    for (int k = 0; k < n; ++k) {
      Eigen::Vector3d s(gauss(rng), gauss(rng), gauss(rng));
      s.normalize();
      if (s.z() < 0.0) s.z() = -s.z();
      const Eigen::Vector3d e(f.a * s.x(), f.b * s.y(), h * s.z());
      ScenePoint sp;
      sp.p =
          Eigen::Vector3d(f.c.x() + cy * e.x() - sy * e.y(), f.c.y() + sy * e.x() + cy * e.y(), z0 + e.z());
      const double above = sp.p.z() - RockFieldGround(sp.p.x(), sp.p.y());
      if (above < 0.0) continue;
      const double shade =
          0.75 + 0.25 * s.z() + 0.1 * std::sin(9.0 * e.x()) * std::sin(11.0 * e.y() + 3.0 * e.z());
      sp.r = ClampColour(base[0] * shade + 8.0 * gauss(rng));
      sp.g = ClampColour(base[1] * shade + 8.0 * gauss(rng));
      sp.b = ClampColour(base[2] * shade + 8.0 * gauss(rng));
      sp.obstacle = above > 0.05;
      out.push_back(sp);
    }
    footprints.push_back(f);
  }
  // Boxes: five faces each, one saturated colour per face.
  for (int i = 0; i < o.boxes; ++i) {
    Footprint f{{uni(o.x_min + margin, o.x_max - margin), uni(o.y_min + margin, o.y_max - margin)},
                uni(0.0, std::numbers::pi),
                uni(0.12, 0.35),
                uni(0.12, 0.35),
                true};
    const double h = uni(0.2, 0.6);
    const double cy = std::cos(f.yaw), sy = std::sin(f.yaw);
    const double z0 = RockFieldGround(f.c.x(), f.c.y()) - 0.03;
    for (int face = 0; face < 5; ++face) {
      const double colour[3] = {uni(40, 230), uni(40, 230), uni(40, 230)};
      const double w = face < 4 ? (face % 2 == 0 ? 2.0 * f.a : 2.0 * f.b) : 2.0 * f.a;
      const double d = face < 4 ? h : 2.0 * f.b;
      const int n = static_cast<int>(w * d * o.density);
      for (int k = 0; k < n; ++k) {
        const double s = uni(-0.5, 0.5), t = uni(0.0, 1.0);
        Eigen::Vector3d e;
        switch (face) {
          case 0:
            e = {f.a, 2.0 * f.b * s, h * t};
            break;
          case 1:
            e = {2.0 * f.a * s, f.b, h * t};
            break;
          case 2:
            e = {-f.a, 2.0 * f.b * s, h * t};
            break;
          case 3:
            e = {2.0 * f.a * s, -f.b, h * t};
            break;
          default:
            e = {2.0 * f.a * s, 2.0 * f.b * (t - 0.5), h};
            break;
        }
        ScenePoint sp;
        sp.p =
            Eigen::Vector3d(f.c.x() + cy * e.x() - sy * e.y(), f.c.y() + sy * e.x() + cy * e.y(), z0 + e.z());
        const double above = sp.p.z() - RockFieldGround(sp.p.x(), sp.p.y());
        if (above < 0.0) continue;
        sp.r = ClampColour(colour[0] + 6.0 * gauss(rng));
        sp.g = ClampColour(colour[1] + 6.0 * gauss(rng));
        sp.b = ClampColour(colour[2] + 6.0 * gauss(rng));
        sp.obstacle = above > 0.05;
        out.push_back(sp);
      }
    }
    footprints.push_back(f);
  }
  // Ground outside the footprints, sandy with large darker and lighter patches.
  const int n = static_cast<int>((o.x_max - o.x_min) * (o.y_max - o.y_min) * o.density);
  for (int k = 0; k < n; ++k) {
    const double x = uni(o.x_min, o.x_max), y = uni(o.y_min, o.y_max);
    bool covered = false;
    for (const Footprint& f : footprints) {
      const double dx = x - f.c.x(), dy = y - f.c.y();
      const double lx = std::cos(f.yaw) * dx + std::sin(f.yaw) * dy;
      const double ly = -std::sin(f.yaw) * dx + std::cos(f.yaw) * dy;
      covered = f.box ? (std::abs(lx) < f.a && std::abs(ly) < f.b)
                      : (lx * lx / (f.a * f.a) + ly * ly / (f.b * f.b) < 1.0);
      if (covered) break;
    }
    if (covered) continue;
    ScenePoint sp;
    sp.p = Eigen::Vector3d(x, y, RockFieldGround(x, y));
    const double patch = 25.0 * std::sin(1.3 * x + 0.4) * std::cos(1.1 * y) + 10.0 * std::sin(4.0 * x * y);
    sp.r = ClampColour(170.0 + patch + 8.0 * gauss(rng));
    sp.g = ClampColour(140.0 + patch + 8.0 * gauss(rng));
    sp.b = ClampColour(100.0 + 0.6 * patch + 8.0 * gauss(rng));
    out.push_back(sp);
  }
  return out;
}

// T_world_submap with roll = pitch = 0.
inline Eigen::Isometry3d YawPose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A submap of `points` (submap frame) whose occupancy tree is cast from each of `viewpoints`
// (submap frame) to every point; no viewpoints: an empty tree.
inline std::shared_ptr<const Submap> RayCastSubmap(std::vector<CloudPoint> points,
                                                   const std::vector<Eigen::Vector3d>& viewpoints,
                                                   const SubmapOptions& options, double max_range) {
  std::unique_ptr<octomap::OcTree> tree = MakeOccupancyTree(options);
  if (!viewpoints.empty()) {
    OccupancyIntegrator integrator(options.octree_resolution, max_range);
    CameraPoints cam;
    cam.p_local.reserve(points.size());
    for (const CloudPoint& c : points) cam.p_local.push_back(c.p);
    cam.p_cam = cam.p_local;
    for (const Eigen::Vector3d& v : viewpoints) {
      cam.T_local_cam.translation() = v;
      integrator.Integrate(cam, tree.get());
    }
    tree->updateInnerOccupancy();
    tree->prune();
  }
  SubmapMetadata metadata;
  metadata.options = options;
  return std::make_shared<const Submap>(metadata, std::move(points), std::move(tree));
}

struct SceneSubmapOptions {
  double x_min = -1e9, x_max = 1e9;  // world x range the submap saw
  double noise = 0.01;               // m, Gaussian per sample and axis
  unsigned seed = 11;
  // Camera positions (world) whose rays to every point build the occupancy tree; none: an empty tree.
  std::vector<Eigen::Vector3d> viewpoints;
};

// The part of the scene a submap with origin T_world_submap saw, voxel-filtered at 0.05 m in the
// submap frame (so each submap has its own grid), with an OctoMap at 0.1 m cast from the viewpoints.
inline std::shared_ptr<const Submap> SceneSubmap(const std::vector<ScenePoint>& scene,
                                                 const Eigen::Isometry3d& T_world_submap,
                                                 const SceneSubmapOptions& o) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, o.noise);
  const Eigen::Isometry3d T_submap_world = T_world_submap.inverse();
  SubmapOptions options;
  VoxelCloud cloud(options.cloud_resolution, scene.size() / 2 + 16);
  for (const ScenePoint& sp : scene) {
    if (sp.p.x() < o.x_min || sp.p.x() > o.x_max) continue;
    const Eigen::Vector3d noisy = sp.p + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    cloud.Add((T_submap_world * noisy).cast<float>(), sp.r, sp.g, sp.b, sp.obstacle);
  }
  std::vector<Eigen::Vector3d> viewpoints;
  for (const Eigen::Vector3d& v : o.viewpoints) viewpoints.push_back(T_submap_world * v);
  return RayCastSubmap(cloud.Points(), viewpoints, options, 8.0);
}

// Two submaps of one rock field from origins 1.1 rad and a few metres apart, each seeing a part of
// it (A: world x <= 2 m, B: world x >= -2 m), with independent noise and voxel grids.
struct ScenePair {
  std::vector<ScenePoint> scene;
  Eigen::Isometry3d T_world_a = YawPose(0.3, Eigen::Vector3d(-1.0, 0.5, 0.1));
  Eigen::Isometry3d T_world_b = YawPose(1.4, Eigen::Vector3d(1.2, -0.7, 0.3));
  std::shared_ptr<const Submap> a, b;

  Eigen::Isometry3d T_b_a() const { return T_world_b.inverse() * T_world_a; }
};

inline ScenePair OverlappingSubmaps(unsigned seed = 7, bool cast_rays = true) {
  ScenePair pair;
  RockFieldOptions o;
  o.seed = seed;
  pair.scene = RockField(o);
  SceneSubmapOptions sa, sb;
  sa.x_max = 2.0;
  sa.seed = seed + 1;
  sb.x_min = -2.0;
  sb.seed = seed + 2;
  if (cast_rays) {
    sa.viewpoints = {{-4.0, -2.0, 1.5}, {-2.0, 2.0, 1.5}, {0.0, -2.0, 1.5}, {1.5, 2.0, 1.5}};
    sb.viewpoints = {{-1.5, -2.0, 1.5}, {0.0, 2.0, 1.5}, {2.0, -2.0, 1.5}, {4.0, 2.0, 1.5}};
  }
  pair.a = SceneSubmap(pair.scene, pair.T_world_a, sa);
  pair.b = SceneSubmap(pair.scene, pair.T_world_b, sb);
  return pair;
}

}  // namespace cairn::testing
