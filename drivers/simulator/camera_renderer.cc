#include "drivers/simulator/camera_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "drivers/simulator/sim_random.h"

namespace cairn::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Standard normal values drawn once; pixels index them with cheap random bits.
const std::array<float, 4096>& GaussTable() {
  static const std::array<float, 4096> table = [] {
    std::array<float, 4096> t{};
    SimRandom rng(0x5EED);
    for (float& v : t) v = static_cast<float>(rng.Normal());
    return t;
  }();
  return table;
}

// One scene object reduced to what the pixel loop needs.
struct Object {
  Eigen::Isometry3d T_obj_world;
  Eigen::Vector3d half_extent;   // box; for markers x = y = half edge, z = 0
  bool is_marker = false;
  const SimMarker* marker = nullptr;
  float albedo = 0.3f;
  int u0 = 0, u1 = -1, v0 = 0, v1 = -1;  // pixel rectangle that may see it
};

// Distance along the ray to a box in its own frame (slab test) and the hit face normal.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& h,
              Eigen::Vector3d* n_local) {
  double t0 = 0.0, t1 = kInf;
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (std::abs(o[i]) > h[i]) return kInf;
      continue;
    }
    double a = (-h[i] - o[i]) / d[i], b = (h[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    if (a > t0) { t0 = a; axis = i; }
    t1 = std::min(t1, b);
    if (t0 > t1) return kInf;
  }
  if (axis < 0) return kInf;  // origin inside the box
  *n_local = Eigen::Vector3d::Zero();
  (*n_local)[axis] = d[axis] > 0 ? -1.0 : 1.0;
  return t0;
}

// Albedo of a marker at local (x, y): quiet ring white, border black, 6 x 6 data bits.
float MarkerAlbedo(const SimMarker& m, double x, double y) {
  const double module = m.size / 8.0, half = 5 * module;
  const int c = static_cast<int>((x + half) / module), r = static_cast<int>((half - y) / module);
  if (r <= 0 || c <= 0 || r >= 9 || c >= 9) return 0.85f;
  if (r == 1 || c == 1 || r == 8 || c == 8) return 0.04f;
  const int bit = (r - 2) * 6 + (c - 2);
  return (m.bits >> (35 - bit)) & 1 ? 0.85f : 0.04f;
}

}  // namespace

void RenderScene::AddRobot(const SimRobot& robot, const Eigen::Isometry3d& T_world_body) {
  for (SimBox b : robot.boxes) {
    b.T_body_box = T_world_body * b.T_body_box;
    boxes.push_back(b);
  }
  for (SimMarker m : robot.markers) {
    m.T_body_marker = T_world_body * m.T_body_marker;
    markers.push_back(m);
  }
}

void CameraRenderer::Render(const RenderScene& scene, const PinholeRadTan& k,
                            const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                            uint64_t noise_seed, std::vector<uint8_t>* image,
                            std::vector<float>* depth) {
  std::vector<float> signal;
  RenderSignal(scene, k, T_world_cam, options, &signal, depth);
  ApplyNoise(signal, k.width, options, noise_seed, image);
}

void CameraRenderer::ApplyNoise(const std::vector<float>& signal, int width, const RenderOptions& options,
                                uint64_t noise_seed, std::vector<uint8_t>* image) {
  const auto& gauss = GaussTable();
  image->resize(signal.size());
  const size_t w = static_cast<size_t>(width);
  for (size_t row = 0; row * w < signal.size(); ++row) {
    SimRandom rng = SimRandom::Stream(noise_seed, row);
    uint64_t bits = 0;
    int bits_left = 0;
    for (size_t i = row * w; i < (row + 1) * w; ++i) {
      if (bits_left < 12) {
        bits = rng.Next();
        bits_left = 64;
      }
      const float g = gauss[bits & 4095];
      bits >>= 12;
      bits_left -= 12;
      const double sigma = std::sqrt(options.read_noise * options.read_noise + options.shot_noise * signal[i]);
      const double value = std::clamp(signal[i] + sigma * g, 0.0, 255.0);
      (*image)[i] = static_cast<uint8_t>(value + 0.5);
    }
  }
}

void CameraRenderer::RenderSignal(const RenderScene& scene, const PinholeRadTan& k,
                                  const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                                  std::vector<float>* out, std::vector<float>* depth) {
  const int w = k.width, h = k.height;
  out->assign(static_cast<size_t>(w) * static_cast<size_t>(h), 0.0f);
  if (depth != nullptr) depth->assign(out->size(), 0.0f);
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();

  // Objects with the pixel rectangle their bounding sphere can cover.
  std::vector<Object> objects;
  auto add = [&](const Eigen::Isometry3d& T_world_obj, const Eigen::Vector3d& half, bool marker,
                 const SimMarker* m, float albedo) {
    Object ob{T_world_obj.inverse(), half, marker, m, albedo};
    const Eigen::Vector3d c = T_cam_world * T_world_obj.translation();
    const double r = half.norm() + 1e-3;
    if (c.z() + r <= 0.0) return;  // behind the camera
    if (c.z() - r <= 0.01) {
      ob.u0 = 0; ob.u1 = w - 1; ob.v0 = 0; ob.v1 = h - 1;
    } else {
      double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d p = c + r * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
        const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
        umin = std::min(umin, u); umax = std::max(umax, u);
        vmin = std::min(vmin, v); vmax = std::max(vmax, v);
      }
      ob.u0 = std::max(0, static_cast<int>(std::floor(umin)));
      ob.u1 = std::min(w - 1, static_cast<int>(std::ceil(umax)));
      ob.v0 = std::max(0, static_cast<int>(std::floor(vmin)));
      ob.v1 = std::min(h - 1, static_cast<int>(std::ceil(vmax)));
    }
    if (ob.u0 <= ob.u1 && ob.v0 <= ob.v1) objects.push_back(ob);
  };
  for (const SimBox& b : scene.boxes) add(b.T_body_box, b.half_extent, false, nullptr, b.albedo);
  for (const SimMarker& m : scene.markers) {
    add(m.T_body_marker, Eigen::Vector3d(m.size * 0.625, m.size * 0.625, 0.0), true, &m, 0.0f);
  }

  const double scale = options.gain * options.exposure * 255.0;
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d origin = T_world_cam.translation();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d ray_cam = Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
      const Eigen::Vector3d dir = R * ray_cam;
      double t_best = options.max_range;
      double albedo = 0.0;
      Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
      bool hit = false;
      for (const Object& ob : objects) {
        if (u < ob.u0 || u > ob.u1 || v < ob.v0 || v > ob.v1) continue;
        const Eigen::Vector3d o = ob.T_obj_world * origin, d = ob.T_obj_world.linear() * dir;
        if (ob.is_marker) {
          if (d.z() >= 0.0 || o.z() <= 0.0) continue;  // seen from behind or edge-on
          const double t = -o.z() / d.z();
          const Eigen::Vector3d p = o + t * d;
          if (t >= t_best || std::abs(p.x()) > ob.half_extent.x() || std::abs(p.y()) > ob.half_extent.y()) continue;
          t_best = t;
          albedo = MarkerAlbedo(*ob.marker, p.x(), p.y());
          normal = ob.T_obj_world.linear().transpose() * Eigen::Vector3d::UnitZ();
          hit = true;
        } else {
          Eigen::Vector3d n_local;
          const double t = HitBox(o, d, ob.half_extent, &n_local);
          if (t >= t_best) continue;
          t_best = t;
          albedo = ob.albedo;
          normal = ob.T_obj_world.linear().transpose() * n_local;
          hit = true;
        }
      }
      const TerrainHit th = scene.terrain->Raycast(origin, dir, t_best);
      if (th.t > 0.0) {
        t_best = th.t;
        const Eigen::Vector3d p = origin + th.t * dir;
        albedo = scene.terrain->Albedo(p.x(), p.y());
        normal = th.normal;
        hit = true;
      }
      double signal = 0.0;
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      if (hit) {
        signal = scale * albedo * (options.ambient + std::max(0.0, normal.dot(scene.sun_direction)));
        if (depth != nullptr) (*depth)[i] = static_cast<float>(t_best * ray_cam.z());
      }
      (*out)[i] = static_cast<float>(signal);
    }
  }
}

}  // namespace cairn::sim
