#pragma once
// A small synthetic submap for codec, composition and export tests.

#include <cmath>
#include <memory>
#include <random>

#include "mapping/submap.h"

namespace cairn::testing {

// Ground with a ridge seen from one viewpoint: `images` depth scans of random points.
inline std::shared_ptr<const Submap> SyntheticSubmap(uint64_t id, int images = 3, unsigned seed = 1) {
  OpenSubmap open(SubmapOptions{}, "rover1", id);
  OccupancyIntegrator integ(0.1, 8.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int k = 0; k < images; ++k) {
    CameraPoints pts;
    pts.time = Timestamp::FromSeconds(10.0 + k);
    pts.T_local_cam.translation() = Eigen::Vector3d(0.3 * k, 0.0, 1.3);
    for (int i = 0; i < 20000; ++i) {
      const float x = 1.0f + 4.0f * u(rng), y = -2.0f + 4.0f * u(rng);
      const bool ridge = x > 3.0f && x < 3.3f;
      const float z = (ridge ? 0.4f * u(rng) : 0.0f) + 0.01f * u(rng);
      pts.p_local.emplace_back(x, y, z);
      pts.p_cam.push_back(pts.p_local.back());
      pts.intensity.push_back(static_cast<uint8_t>(100 + 100 * u(rng)));
      pts.obstacle.push_back(ridge ? 1 : 0);
    }
    open.Integrate(pts, &integ);
    open.AddDistance(0.3);
  }
  return open.Finish();
}

}  // namespace cairn::testing
