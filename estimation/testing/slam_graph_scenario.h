#pragma once
// Test scenario shared by the SLAM graph tests: two robots with known trajectories, the factors of
// either topology, a detection and a later submap match.

#include <random>
#include <utility>
#include <vector>

#include "estimation/graph/slam_graph.h"
#include "estimation/graph/topology_builder.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"

namespace cairn::testing_scenario {

inline Pose3 P(double x, double y, double z, double yaw, double roll = 0.0) {
  return {Eigen::Vector3d(x, y, z), so3::ExpQuaternion(Eigen::Vector3d(roll, 0.0, yaw))};
}

inline Matrix6d Cov(double sigma_t, double sigma_r) {
  Vector6d d;
  d << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  return d.cwiseAbs2().asDiagonal();
}

// Two robots driving known trajectories; each keeps submaps every 4 poses. Produces the factors of
// either topology plus a detection (robot b seen from robot a) and a later submap match.
struct Scenario {
  std::vector<SlamFactor> factors;
  std::vector<std::pair<uint64_t, Pose3>> truth;  // variable -> true world pose
  uint64_t detection_index = 0;                    // position of the first inter-robot factor
};

inline Scenario MakeScenario(TopologyBuilder::Topology topology, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  auto perturb = [&](const Pose3& p, double s) {
    const Eigen::Vector3d dt = s * DrawVector3(n, rng);
    return p * Pose3{dt, so3::ExpQuaternion(0.1 * s * DrawVector3(n, rng))};
  };
  Scenario sc;
  const Pose3 start[2] = {P(0, 0, 0, 0), P(3, -2, 0.5, 1.0, 0.05)};
  std::vector<uint64_t> submaps[2];
  std::vector<Pose3> submap_truth[2];
  uint64_t x_key[2][12] = {};
  Pose3 x_truth[2][12];
  for (int r = 0; r < 2; ++r) {
    TopologyBuilder b(topology, static_cast<char>('a' + r));
    for (auto& f : b.Start(r == 0, Matrix6d::Identity() * 1e6)) sc.factors.push_back(f);
    Pose3 origin = start[r];
    submaps[r].push_back(b.SubmapKey(0));
    submap_truth[r].push_back(origin);
    for (int k = 0; k < 12; ++k) {
      const Pose3 x = start[r] * P(0.5 * k, 0.2 * k * (r ? -1 : 1), 0.01 * k, 0.15 * k);
      if (k > 0 && k % 4 == 0) {  // frame switch at the current pose, gravity-aligned origin
        const Pose3 new_origin = x;
        for (auto& f : b.FrameSwitch(perturb(origin.Inverse() * new_origin, noise), Cov(0.05, 0.01))) {
          sc.factors.push_back(f);
        }
        origin = new_origin;
        submaps[r].push_back(b.SubmapKey(b.current_submap()));
        submap_truth[r].push_back(origin);
      }
      uint64_t key = 0;
      for (auto& f : b.PoseEstimate(perturb(origin.Inverse() * x, noise), Cov(0.02 * (k % 4 + 1), 0.005), &key)) {
        sc.factors.push_back(f);
      }
      x_key[r][k] = key;
      x_truth[r][k] = x;
      sc.truth.emplace_back(key, x);
    }
    for (size_t i = 0; i < submaps[r].size(); ++i) sc.truth.emplace_back(submaps[r][i], submap_truth[r][i]);
  }
  sc.detection_index = sc.factors.size();
  SlamFactor d;  // eq. 4.7 already applied: pose of robot b in robot a at the same time
  d.kind = FactorKind::kDetection;
  d.a = x_key[0][5];
  d.b = x_key[1][5];
  d.z = perturb(x_truth[0][5].Inverse() * x_truth[1][5], noise);
  d.information = Cov(0.05, 0.02).inverse();
  sc.factors.push_back(d);
  SlamFactor c;
  c.kind = FactorKind::kMatch;
  c.a = submaps[0][2];
  c.b = submaps[1][1];
  c.z = perturb(submap_truth[0][2].Inverse() * submap_truth[1][1], noise);
  c.information = Cov(0.03, 0.01).inverse();
  sc.factors.push_back(c);
  return sc;
}

}  // namespace cairn::testing_scenario
