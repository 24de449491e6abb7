#include "estimation/testing/vo_test_scene.h"

#include <algorithm>
#include <cmath>

namespace cairn::testing {
namespace {

uint64_t Hash(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

double Smooth(double t) { return t * t * t * (t * (6.0 * t - 15.0) + 10.0); }

}  // namespace

VoTestScene::VoTestScene(const RectifiedStereoCamera& camera, uint64_t seed, double hx, double hy, double z0,
                         double z1)
    : camera_(camera), seed_(seed), hx_(hx), hy_(hy), z0_(z0), z1_(z1) {}

RectifiedStereoCamera VoTestScene::EurocLikeCamera() {
  RectifiedStereoCamera c;
  c.width = 752;
  c.height = 480;
  c.f = 450.0;
  c.cx = 376.0;
  c.cy = 240.0;
  c.baseline = 0.11;
  return c;
}

double VoTestScene::Noise(int wall, int octave, double a, double b) const {
  const double fa = std::floor(a), fb = std::floor(b);
  const int64_t ia = static_cast<int64_t>(fa), ib = static_cast<int64_t>(fb);
  const auto v = [&](int64_t i, int64_t j) {
    const uint64_t h = Hash(seed_ ^ Hash(static_cast<uint64_t>(wall * 16 + octave) ^
                                         Hash(static_cast<uint64_t>(i) * 73856093ULL ^ static_cast<uint64_t>(j) * 19349663ULL)));
    return static_cast<double>(h >> 11) / 9007199254740992.0;
  };
  const double sa = Smooth(a - fa), sb = Smooth(b - fb);
  const double v0 = v(ia, ib) + sa * (v(ia + 1, ib) - v(ia, ib));
  const double v1 = v(ia, ib + 1) + sa * (v(ia + 1, ib + 1) - v(ia, ib + 1));
  return v0 + sb * (v1 - v0);
}

double VoTestScene::Texture(int wall, double a, double b) const {
  // Two octaves: 12 cm and 5 cm cells (several pixels at the room's distances).
  const double n = 0.6 * Noise(wall, 0, a / 0.12, b / 0.12) + 0.4 * Noise(wall, 1, a / 0.05, b / 0.05);
  return 30.0 + 200.0 * n;
}

void VoTestScene::RenderImage(const Eigen::Isometry3d& T_world_cam, std::vector<uint8_t>* out) const {
  out->assign(static_cast<size_t>(camera_.width) * static_cast<size_t>(camera_.height), 0);
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d o = T_world_cam.translation();
  const double lo[3] = {-hx_, -hy_, z0_}, hi[3] = {hx_, hy_, z1_};
  for (int y = 0; y < camera_.height; ++y) {
    for (int x = 0; x < camera_.width; ++x) {
      // A pixel integrates its area: 2x2 samples (box filter) keep the texture from aliasing.
      double g = 0.0;
      for (int sy = 0; sy < 2; ++sy) {
        for (int sx = 0; sx < 2; ++sx) {
          const double px = x - 0.25 + 0.5 * sx, py = y - 0.25 + 0.5 * sy;
          const Eigen::Vector3d d = R * Eigen::Vector3d((px - camera_.cx) / camera_.f, (py - camera_.cy) / camera_.f, 1.0);
          // Nearest wall hit from inside the box: the smallest positive exit distance per axis.
          double t_best = 1e300;
          int axis = -1, side = 0;
          for (int k = 0; k < 3; ++k) {
            if (std::abs(d[k]) < 1e-12) continue;
            const double bound = d[k] > 0.0 ? hi[k] : lo[k];
            const double t = (bound - o[k]) / d[k];
            if (t > 0.0 && t < t_best) {
              t_best = t;
              axis = k;
              side = d[k] > 0.0 ? 1 : 0;
            }
          }
          if (axis < 0) continue;
          const Eigen::Vector3d p = o + t_best * d;
          g += Texture(axis * 2 + side, p[(axis + 1) % 3], p[(axis + 2) % 3]);
        }
      }
      (*out)[static_cast<size_t>(y) * static_cast<size_t>(camera_.width) + static_cast<size_t>(x)] =
          static_cast<uint8_t>(std::clamp(std::lround(g / 4.0), 0L, 255L));
    }
  }
}

RenderedPair VoTestScene::Render(const Eigen::Isometry3d& T_world_cam) const {
  RenderedPair p;
  RenderImage(T_world_cam, &p.left);
  Eigen::Isometry3d T_cam_right = Eigen::Isometry3d::Identity();
  T_cam_right.translation().x() = camera_.baseline;
  RenderImage(T_world_cam * T_cam_right, &p.right);
  return p;
}

}  // namespace cairn::testing
