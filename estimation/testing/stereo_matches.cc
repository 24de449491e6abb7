#include "estimation/testing/stereo_matches.h"

#include <cmath>

namespace cairn::testing {

StereoObservation ObserveStereo(const RectifiedStereoCamera& c, const Eigen::Vector3d& p) {
  return {c.f * p.x() / p.z() + c.cx, c.f * (p.x() - c.baseline) / p.z() + c.cx, c.f * p.y() / p.z() + c.cy};
}

StereoMatches MakeStereoMatches(const RectifiedStereoCamera& cam, const Eigen::Isometry3d& T_kf_cur, int n,
                                double noise_px, double sigma_px, std::mt19937_64& rng, double z_min,
                                double z_max, double min_current_depth) {
  std::uniform_real_distribution<double> ux(0.0, cam.width), uy(0.0, cam.height), uz(z_min, z_max);
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto noise = [&](std::mt19937_64& g) { return noise_px * normal(g); };
  StereoMatches out;
  const Eigen::Isometry3d T_cur_kf = T_kf_cur.inverse();
  while (static_cast<int>(out.kf.size()) < n) {
    const double z = uz(rng);
    const double v = uy(rng), u = ux(rng);  // GCC's argument order, on every compiler
    const Eigen::Vector3d p_kf((u - cam.cx) * z / cam.f, (v - cam.cy) * z / cam.f, z);
    const Eigen::Vector3d p_cur = T_cur_kf * p_kf;
    if (p_cur.z() < min_current_depth) continue;
    StereoObservation a = ObserveStereo(cam, p_kf), b = ObserveStereo(cam, p_cur);
    for (StereoObservation* o : {&a, &b}) {
      o->u_left += noise(rng);
      o->u_right += noise(rng);
      o->v += noise(rng) / std::sqrt(2.0);  // the mean of two rows
    }
    StereoPoint pa, pb;
    if (!TriangulateStereo(cam, a, sigma_px, 0.5, &pa) || !TriangulateStereo(cam, b, sigma_px, 0.5, &pb))
      continue;
    out.kf_seen.push_back(a);
    out.cur_seen.push_back(b);
    out.kf.push_back(pa);
    out.cur.push_back(pb);
  }
  return out;
}

}  // namespace cairn::testing
