#pragma once
// Hough voting over keypoint correspondences (thesis 6.1.2, after Hough3D of Tombari and Di
// Stefano): each correspondence predicts where the reference point (the keypoint centroid) of one
// submap lies in the other, using the two keypoints' local frames. Correspondences of one true
// alignment predict the same place and pile up in one bin; wrong ones scatter.
//
// With gravity-aligned frames a correspondence fixes all four unknowns: yaw_b_a = yaw of B's frame
// minus yaw of A's, and the translation from the keypoints. The vote space is therefore 4-D: the
// predicted reference point (x, y, z) and the yaw. Votes are spread linearly over the 16
// surrounding bins. As in the thesis the voting runs both ways, A's centroid predicted in B and
// B's in A, because the spread of a vote grows with the distance of its keypoint from the
// reference point, which differs between the two.
//
// Keypoints with full 3-D frames (the matcher's 6-DoF variant, gravity_shot_descriptor.h) predict
// the reference point through the rotation between their frames and vote in x, y, z only.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "mapping/matching/correspondence_finder.h"
#include "mapping/matching/gravity_shot_descriptor.h"

namespace cairn {

struct HoughVotingOptions {
  double translation_bin = 0.5;      // m
  double yaw_bin = 0.2618;           // rad (15 deg); rounded so the bins tile the circle
  double min_votes = 3.0;            // (interpolated) votes of a kept bin
  double min_relative_votes = 0.25;  // of the strongest bin of the same direction
  int64_t max_clusters = 4;          // per direction

  void Visit(OptionsVisitor& v) {
    v.Number("translation_bin", translation_bin, 0.01, 100.0, "m");
    v.Number("yaw_bin", yaw_bin, 0.001, 3.2, "rad");
    v.Number("min_votes", min_votes, 0.0, 1e6, "");
    v.Number("min_relative_votes", min_relative_votes, 0.0, 1.0, "");
    v.Integer("max_clusters", max_clusters, 1, 1000, "");
  }
};

// Correspondences that voted into one of the strongest bins.
struct HoughCluster {
  bool a_in_b = true;  // true: A's reference point voted in B's frame; false: B's in A's
  double votes = 0.0;
  std::vector<uint32_t> members;  // indices into the correspondences given
  // Mean transform of the members, T_b_a: p_b = R_z(yaw_b_a) p_a + t_b_a.
  float yaw_b_a = 0.0f;
  Eigen::Vector3f t_b_a = Eigen::Vector3f::Zero();
};

struct HoughResult {
  std::vector<HoughCluster> clusters;  // strongest first, both directions
  // Members of any cluster, once each, sorted by (a, b); score = the correspondence's score times
  // the votes of the strongest cluster it is in over those of the strongest cluster.
  std::vector<KeypointCorrespondence> candidates;
};

class HoughVoting {
 public:
  explicit HoughVoting(const HoughVotingOptions& options = {}) : options_(options) {}

  HoughResult Vote(const DescribedKeypoints& a, const DescribedKeypoints& b,
                   const std::vector<KeypointCorrespondence>& correspondences) const;

 private:
  // One direction: keypoints `from` predict their reference point in the frame of `to`.
  void VoteOneWay(const DescribedKeypoints& from, const DescribedKeypoints& to,
                  const std::vector<KeypointCorrespondence>& correspondences, bool a_in_b,
                  std::vector<HoughCluster>* clusters) const;

  HoughVotingOptions options_;
};

}  // namespace cairn
