#include "mapping/matching/submap_pairing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cairn {
namespace {

// The world-axis box around a submap-frame box moved by the origin's pose.
Eigen::AlignedBox2d WorldBox(const Eigen::AlignedBox2d& box, const FourDofTransform& T_world_submap) {
  Eigen::AlignedBox2d out;
  for (const auto corner : {Eigen::AlignedBox2d::BottomLeft, Eigen::AlignedBox2d::BottomRight,
                            Eigen::AlignedBox2d::TopLeft, Eigen::AlignedBox2d::TopRight}) {
    const Eigen::Vector2d c = box.corner(corner);
    out.extend((T_world_submap * Eigen::Vector3d(c.x(), c.y(), 0.0)).head<2>());
  }
  return out;
}

}  // namespace

std::string_view PairSkipName(PairSkip skip) {
  switch (skip) {
    case PairSkip::kNone:
      return "candidate";
    case PairSkip::kUnsuitable:
      return "unsuitable submap";
    case PairSkip::kNotPlaced:
      return "origin not in the graph";
    case PairSkip::kOtherComponent:
      return "origins not connected in the graph";
    case PairSkip::kConsecutive:
      return "consecutive submaps of one robot";
    case PairSkip::kNoOverlap:
      return "too little overlap";
    case PairSkip::kKnownBetter:
      return "relative pose known better than the matcher measures";
    case PairSkip::kAttempted:
      return "attempted already";
    case PairSkip::kTeammate:
      return "a teammate's to try";
  }
  return "?";
}

double SubmapPairing::StereoPrecision(double pixel_error, double distance, double focal_px, double baseline) {
  return pixel_error * distance * distance / (focal_px * baseline) * std::sqrt(2.0);
}

SubmapPairing::PairKey SubmapPairing::Ordered(const SubmapKey& a, const SubmapKey& b) {
  return a < b ? PairKey{a, b} : PairKey{b, a};
}

void SubmapPairing::Update(const PairingSubmap& submap) { submaps_[submap.key] = submap; }

PairSkip SubmapPairing::EvaluateOrdered(const PairingSubmap& a, const PairingSubmap& b, SubmapPair* pair) const {
  if (!a.matchable || !b.matchable) return PairSkip::kUnsuitable;
  if (owned_ && !owned_(a.key, b.key)) return PairSkip::kTeammate;
  // A match ties graph variables: both submaps' frames must be in the graph.
  if (!a.placed || !b.placed) return PairSkip::kNotPlaced;
  if (a.component != b.component) {
    if (!options_.match_unconnected) return PairSkip::kOtherComponent;
    // Nothing ties the two origins: a global search, after every pair the graph can predict.
    if (pair != nullptr) {
      pair->a = a.key;
      pair->b = b.key;
      pair->overlap_area = 0.0;
      pair->relative_sigma = Eigen::Vector4d::Constant(std::numeric_limits<double>::infinity());
      pair->score = -1.0;
      pair->has_prior = false;
    }
    return PairSkip::kNone;
  }
  if (options_.skip_consecutive && a.key.robot == b.key.robot &&
      (a.key.id + 1 == b.key.id || b.key.id + 1 == a.key.id))
    return PairSkip::kConsecutive;
  if (a.box_xy.isEmpty() || b.box_xy.isEmpty()) return PairSkip::kNoOverlap;

  Eigen::Vector4d sigma;
  for (int t = 0; t < 4; ++t) {
    const double d = std::abs(a.covariance(t, t) - b.covariance(t, t));
    sigma[t] = std::max(std::isfinite(d) ? std::sqrt(d) : 0.0, options_.min_relative_sigma);
  }
  const Eigen::AlignedBox2d box_a = WorldBox(a.box_xy, a.T_world_submap);
  const Eigen::AlignedBox2d box_b = WorldBox(b.box_xy, b.T_world_submap);
  double area = 1.0;
  for (int t = 0; t < 2; ++t) {
    const double overlap = std::min(box_a.max()[t], box_b.max()[t]) - std::max(box_a.min()[t], box_b.min()[t]);
    area *= std::max(0.0, overlap + options_.sigma_widening * sigma[t]);
  }
  if (!(area > options_.min_overlap_area)) return PairSkip::kNoOverlap;
  const bool young_tie = a.key.robot != b.key.robot && std::min(a.robot_ties, b.robot_ties) <
                                                           static_cast<uint64_t>(options_.min_robot_ties);
  if (sigma.head<3>().mean() < options_.matcher_precision && !young_tie) return PairSkip::kKnownBetter;
  if (pair != nullptr) {
    pair->a = a.key;
    pair->b = b.key;
    pair->overlap_area = area;
    pair->relative_sigma = sigma;
    pair->score = options_.alpha * area + sigma.head<3>().sum();
    pair->prior.T_a_b = a.T_world_submap.inverse() * b.T_world_submap;
    // World-axis variances turned into A's axes (the yaw and z axes are shared).
    Eigen::Matrix4d world = sigma.cwiseAbs2().asDiagonal();
    Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
    R.topLeftCorner<3, 3>() = a.T_world_submap.rotation();
    pair->prior.covariance = R.transpose() * world * R;
  }
  return PairSkip::kNone;
}

PairSkip SubmapPairing::Evaluate(const SubmapKey& a, const SubmapKey& b, SubmapPair* pair) const {
  const PairKey key = Ordered(a, b);
  const auto ia = submaps_.find(key.first), ib = submaps_.find(key.second);
  if (ia == submaps_.end() || ib == submaps_.end() || key.first == key.second) return PairSkip::kNotPlaced;
  if (attempts_.count(key) != 0) return PairSkip::kAttempted;
  return EvaluateOrdered(ia->second, ib->second, pair);
}

std::map<PairSkip, size_t> SubmapPairing::Census() const {
  std::map<PairSkip, size_t> out;
  for (auto i = submaps_.begin(); i != submaps_.end(); ++i) {
    for (auto j = std::next(i); j != submaps_.end(); ++j) {
      ++out[attempts_.count({i->first, j->first}) != 0 ? PairSkip::kAttempted
                                                       : EvaluateOrdered(i->second, j->second, nullptr)];
    }
  }
  return out;
}

std::vector<SubmapPair> SubmapPairing::Candidates() const {
  std::vector<SubmapPair> out;
  for (auto i = submaps_.begin(); i != submaps_.end(); ++i) {
    for (auto j = std::next(i); j != submaps_.end(); ++j) {
      if (attempts_.count({i->first, j->first}) != 0) continue;
      SubmapPair pair;
      if (EvaluateOrdered(i->second, j->second, &pair) == PairSkip::kNone) out.push_back(std::move(pair));
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const SubmapPair& x, const SubmapPair& y) { return x.score > y.score; });
  return out;
}

std::optional<SubmapPair> SubmapPairing::Next() {
  std::vector<SubmapPair> candidates = Candidates();
  if (candidates.empty()) return std::nullopt;
  attempts_[{candidates.front().a, candidates.front().b}] = std::nullopt;
  return std::move(candidates.front());
}

void SubmapPairing::MarkAttempted(const SubmapKey& a, const SubmapKey& b, MatchStatus outcome) {
  attempts_[Ordered(a, b)] = outcome;
}

bool SubmapPairing::Attempted(const SubmapKey& a, const SubmapKey& b) const {
  return attempts_.count(Ordered(a, b)) != 0;
}

std::optional<MatchStatus> SubmapPairing::Outcome(const SubmapKey& a, const SubmapKey& b) const {
  const auto it = attempts_.find(Ordered(a, b));
  return it == attempts_.end() ? std::nullopt : it->second;
}

}  // namespace cairn
