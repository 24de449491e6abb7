#include "mapping/matching/hough_voting.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include <Eigen/Geometry>

namespace cairn {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Translation bins packed 16 bits per axis around an offset (+-16 km at 0.5 m bins); yaw 16 bits.
constexpr int kBinOffset = 1 << 15;

bool PackBin(int x, int y, int z, int yaw, uint64_t* key) {
  const int ux = x + kBinOffset, uy = y + kBinOffset, uz = z + kBinOffset;
  if (ux < 0 || uy < 0 || uz < 0 || ux > 0xFFFF || uy > 0xFFFF || uz > 0xFFFF) return false;
  *key = static_cast<uint64_t>(ux) | static_cast<uint64_t>(uy) << 16 | static_cast<uint64_t>(uz) << 32 |
         static_cast<uint64_t>(yaw) << 48;
  return true;
}

void UnpackBin(uint64_t key, int* x, int* y, int* z, int* yaw) {
  *x = static_cast<int>(key & 0xFFFF) - kBinOffset;
  *y = static_cast<int>((key >> 16) & 0xFFFF) - kBinOffset;
  *z = static_cast<int>((key >> 32) & 0xFFFF) - kBinOffset;
  *yaw = static_cast<int>(key >> 48);
}

double WrapTwoPi(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0.0 ? a + kTwoPi : a;
}

}  // namespace

void HoughVoting::VoteOneWay(const DescribedKeypoints& from, const DescribedKeypoints& to,
                             const std::vector<KeypointCorrespondence>& correspondences, bool a_in_b,
                             std::vector<HoughCluster>* clusters) const {
  if (from.points.empty() || to.points.empty() || correspondences.empty()) return;
  Eigen::Vector3d ref = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : from.points) ref += p.cast<double>();
  ref /= static_cast<double>(from.points.size());

  const double inv_bin = 1.0 / options_.translation_bin;
  // Full 3-D frames (the 6-DoF variant): the votes are the predicted reference points only, as in
  // Hough3D, since a yaw alone does not say the rotation.
  const bool gravity = from.gravity_frames && to.gravity_frames;
  const int yaw_bins = gravity ? std::max(1, static_cast<int>(std::lround(kTwoPi / options_.yaw_bin))) : 1;
  const double yaw_width = kTwoPi / yaw_bins;

  // Continuous bin coordinates of each vote: bin i spans [i - 0.5, i + 0.5).
  struct VotePos {
    std::array<double, 4> q;
    bool valid = false;
  };
  std::vector<VotePos> pos(correspondences.size());
  std::unordered_map<uint64_t, double> votes;
  votes.reserve(correspondences.size() * 16);
  for (size_t i = 0; i < correspondences.size(); ++i) {
    const KeypointCorrespondence& c = correspondences[i];
    const uint32_t f = a_in_b ? c.a : c.b, t = a_in_b ? c.b : c.a;
    if (f >= from.points.size() || t >= to.points.size()) continue;
    const double yaw =
        gravity ? static_cast<double>(to.frames[t].yaw) - static_cast<double>(from.frames[f].yaw) : 0.0;
    const double cy = std::cos(yaw), sy = std::sin(yaw);
    const Eigen::Vector3d e = ref - from.points[f].cast<double>();
    const Eigen::Vector3d turned =
        gravity ? Eigen::Vector3d(cy * e.x() - sy * e.y(), sy * e.x() + cy * e.y(), e.z())
                : Eigen::Vector3d((to.frames[t].axes * from.frames[f].axes.transpose()).cast<double>() * e);
    const Eigen::Vector3d pred = to.points[t].cast<double>() + turned;
    VotePos& v = pos[i];
    v.q = {pred.x() * inv_bin - 0.5, pred.y() * inv_bin - 0.5, pred.z() * inv_bin - 0.5,
           WrapTwoPi(yaw) / yaw_width - 0.5};
    // Far off (or non-finite) predictions cannot share a bin with anything sensible.
    bool near = true;
    for (double q : v.q) near = near && std::abs(q) < 1e6;
    if (!near) continue;
    std::array<int, 4> lo{};
    std::array<double, 4> up{};
    for (size_t d = 0; d < 4; ++d) {
      const double fl = std::floor(v.q[d]);
      lo[d] = static_cast<int>(fl);
      up[d] = v.q[d] - fl;
    }
    bool packed_all = true;
    for (int corner = 0; corner < 16; ++corner) {
      double w = 1.0;
      std::array<int, 4> bin{};
      for (size_t d = 0; d < 4; ++d) {
        const int bit = (corner >> d) & 1;
        bin[d] = lo[d] + bit;
        w *= bit ? up[d] : 1.0 - up[d];
      }
      bin[3] = ((bin[3] % yaw_bins) + yaw_bins) % yaw_bins;
      uint64_t key = 0;
      if (!PackBin(bin[0], bin[1], bin[2], bin[3], &key)) {
        packed_all = false;
        continue;
      }
      if (w > 0.0) votes[key] += w;
    }
    v.valid = packed_all;
  }

  // Peaks: bins at least as strong as their 80 neighbours (ties go to the smaller key).
  struct Peak {
    uint64_t key;
    double votes;
  };
  std::vector<Peak> peaks;
  for (const auto& [key, count] : votes) {
    if (count < options_.min_votes) continue;
    int x, y, z, yaw;
    UnpackBin(key, &x, &y, &z, &yaw);
    bool peak = true;
    for (int n = 0; n < 81 && peak; ++n) {
      const int dx = n % 3 - 1, dy = n / 3 % 3 - 1, dz = n / 9 % 3 - 1, dyaw = n / 27 - 1;
      if (dx == 0 && dy == 0 && dz == 0 && dyaw == 0) continue;
      uint64_t other = 0;
      if (!PackBin(x + dx, y + dy, z + dz, ((yaw + dyaw) % yaw_bins + yaw_bins) % yaw_bins, &other)) continue;
      if (other == key) continue;  // a single yaw bin wraps onto itself
      const auto it = votes.find(other);
      if (it == votes.end()) continue;
      if (it->second > count || (it->second == count && other < key)) peak = false;
    }
    if (peak) peaks.push_back({key, count});
  }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& p, const Peak& q) {
    return p.votes != q.votes ? p.votes > q.votes : p.key < q.key;
  });
  if (peaks.empty()) return;
  const double threshold = options_.min_relative_votes * peaks.front().votes;
  for (size_t k = 0; k < peaks.size() && static_cast<int64_t>(k) < options_.max_clusters; ++k) {
    if (peaks[k].votes < threshold) break;
    int x, y, z, yaw;
    UnpackBin(peaks[k].key, &x, &y, &z, &yaw);
    const std::array<double, 4> centre = {static_cast<double>(x), static_cast<double>(y),
                                          static_cast<double>(z), static_cast<double>(yaw)};
    HoughCluster cluster;
    cluster.a_in_b = a_in_b;
    cluster.votes = peaks[k].votes;
    // Members: the correspondences whose votes reached this bin.
    for (size_t i = 0; i < pos.size(); ++i) {
      if (!pos[i].valid) continue;
      bool inside = true;
      for (size_t d = 0; d < 3 && inside; ++d) inside = std::abs(pos[i].q[d] - centre[d]) < 1.0;
      if (!inside) continue;
      double dyaw = std::fmod(std::abs(pos[i].q[3] - centre[3]), static_cast<double>(yaw_bins));
      dyaw = std::min(dyaw, yaw_bins - dyaw);
      if (dyaw < 1.0) cluster.members.push_back(static_cast<uint32_t>(i));
    }
    if (cluster.members.empty()) continue;
    clusters->push_back(std::move(cluster));
  }
}

HoughResult HoughVoting::Vote(const DescribedKeypoints& a, const DescribedKeypoints& b,
                              const std::vector<KeypointCorrespondence>& correspondences) const {
  HoughResult result;
  VoteOneWay(a, b, correspondences, /*a_in_b=*/true, &result.clusters);
  VoteOneWay(b, a, correspondences, /*a_in_b=*/false, &result.clusters);
  std::stable_sort(result.clusters.begin(), result.clusters.end(),
                   [](const HoughCluster& p, const HoughCluster& q) { return p.votes > q.votes; });
  if (result.clusters.empty()) return result;

  // Each cluster's transform T_b_a: circular mean of the members' yaws (with full frames, the
  // yaw of their mean rotation matrix), then the mean offset.
  const bool gravity = a.gravity_frames && b.gravity_frames;
  for (HoughCluster& cluster : result.clusters) {
    double s = 0.0, c = 0.0;
    for (uint32_t m : cluster.members) {
      const KeypointCorrespondence& k = correspondences[m];
      if (gravity) {
        const double yaw = static_cast<double>(b.frames[k.b].yaw) - static_cast<double>(a.frames[k.a].yaw);
        s += std::sin(yaw);
        c += std::cos(yaw);
      } else {
        const Eigen::Matrix3f R = b.frames[k.b].axes * a.frames[k.a].axes.transpose();
        s += R(1, 0);
        c += R(0, 0);
      }
    }
    const double yaw = std::atan2(s, c);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (uint32_t m : cluster.members) {
      const KeypointCorrespondence& k = correspondences[m];
      t += b.points[k.b].cast<double>() - R * a.points[k.a].cast<double>();
    }
    cluster.yaw_b_a = static_cast<float>(yaw);
    cluster.t_b_a = (t / static_cast<double>(cluster.members.size())).cast<float>();
  }

  const double strongest = result.clusters.front().votes;
  std::vector<float> weight(correspondences.size(), -1.0f);
  for (const HoughCluster& cluster : result.clusters) {
    const float w = static_cast<float>(cluster.votes / strongest);
    for (uint32_t m : cluster.members) weight[m] = std::max(weight[m], w);
  }
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (weight[i] < 0.0f) continue;
    KeypointCorrespondence c = correspondences[i];
    c.score *= weight[i];
    result.candidates.push_back(c);
  }
  std::sort(result.candidates.begin(), result.candidates.end(),
            [](const KeypointCorrespondence& p, const KeypointCorrespondence& q) {
              return p.a != q.a ? p.a < q.a : p.b < q.b;
            });
  return result;
}

}  // namespace cairn
