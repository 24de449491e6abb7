#pragma once
// Local shape-and-colour descriptor for gravity-aligned submaps, after the idea of SHOT and its
// colour extension CSHOT (Tombari et al.), which the thesis matches submaps with (6.1.2): the
// sphere around a keypoint is split into volumes of a grid aligned with a local reference frame,
// and each volume holds a histogram of the cosine between the points' normals and the frame's z
// axis, plus a histogram of the points' colour difference to the keypoint. Both signatures are
// normalized.
//
// Submaps are gravity aligned, so the local frame's z is the world z, and only its x is estimated:
// the dominant horizontal direction of the support, taken as its uphill direction (the gradient of
// the plane z = a x + b y + c fitted to the support, weighted by radius - distance), which carries
// its own sign. Two descriptors of the same place thus differ by a yaw only, and the frames' yaw
// difference is the yaw between the submaps. Normals come from PCA of the points within
// normal_radius and are oriented toward +z (no viewpoint is stored with a submap's points), which
// leaves the cosine with gravity in [0, 1].
//
// The matcher's 6-DoF variant (submap_matcher.h) describes keypoints without gravity: its local
// frame (ShotFrame::kFull) is the one SHOT defines, the eigenvectors of the support's scatter
// about the keypoint (weights radius - distance; x the largest, z the smallest), each signed
// toward the side that holds most support points, y = z x x; the normal cosine is taken with
// that z, unsigned. Everything else is the same.
//
// Layout (kGravityShotSize floats): volumes indexed ((azimuth * 2 + elevation) * 2 + radius) with
// 8 azimuth sectors about the frame's x, 2 elevation halves (below, above the keypoint) and 2
// radial shells (split at half the radius); first the 32 normal-cosine histograms of
// kShotShapeBins bins, then the 32 colour histograms of kShotColourBins bins (L1 distance in
// CIELab to the keypoint's colour). Votes are spread linearly over neighbouring sectors, halves,
// shells and bins, so a point near a boundary does not jump between bins with noise; within 2 cm
// of the vertical axis through the keypoint, where the azimuth is noise, a point's weight fades
// into all sectors alike. Each half has L2 norm 1/sqrt(2), the whole descriptor norm 1.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "mapping/voxel_cloud.h"

namespace cairn {

inline constexpr int kShotAzimuthBins = 8;
inline constexpr int kShotElevationBins = 2;
inline constexpr int kShotRadialBins = 2;
inline constexpr int kShotVolumes = kShotAzimuthBins * kShotElevationBins * kShotRadialBins;
inline constexpr int kShotShapeBins = 8;
inline constexpr int kShotColourBins = 8;
inline constexpr int kGravityShotSize = kShotVolumes * (kShotShapeBins + kShotColourBins);

using GravityShot = std::array<float, kGravityShotSize>;

struct GravityShotOptions {
  double support_radius = 0.2;  // m; the descriptor sphere and the local frame's support
  // m; PCA neighbourhood of each point's normal. The thesis used the support radius (0.2 m); on
  // the 0.05 m cloud 0.1 m still holds about a dozen points, a quarter of the neighbours, and
  // keeps rock edges sharp.
  double normal_radius = 0.1;
  int64_t min_support_points = 20;  // fewer: no descriptor
  int64_t min_normal_points = 5;    // fewer (weighted): the point has no normal and adds colour only
  // CIELab L1 distance to the keypoint's colour spread over the colour bins; larger ones go to the last.
  double colour_range = 120.0;
  // m; the keypoint's colour is the mean within this of it (or the nearest point's).
  double keypoint_colour_radius = 0.05;

  void Visit(OptionsVisitor& v) {
    v.Number("support_radius", support_radius, 0.01, 10.0, "m");
    v.Number("normal_radius", normal_radius, 0.01, 10.0, "m");
    v.Integer("min_support_points", min_support_points, 1, 1000000, "points");
    v.Integer("min_normal_points", min_normal_points, 3, 1000000, "points");
    v.Number("colour_range", colour_range, 1.0, 1000.0, "");
    v.Number("keypoint_colour_radius", keypoint_colour_radius, 0.0, 10.0, "m");
  }
};

enum class ShotFrame { kGravity, kFull };

// The local reference frame of one descriptor.
struct GravityShotFrame {
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();  // columns x, y, z in the submap frame
  float yaw = 0.0f;     // rad; of the frame's x axis in the submap frame
  float slope = 0.0f;   // rise over run of the support's plane; near 0 (flat), x is arbitrary
  int32_t support = 0;  // points in the sphere
};

struct DescribedKeypoints {
  std::vector<Eigen::Vector3f> points;  // submap frame
  std::vector<GravityShot> descriptors;
  std::vector<GravityShotFrame> frames;
  std::vector<uint32_t> keypoint_index;  // into the keypoints given
  int64_t dropped = 0;                   // keypoints with too small a support (or non-finite)
  bool gravity_frames = true;            // ShotFrame::kGravity; else full 3-D frames

  size_t size() const { return points.size(); }
};

class GravityShotDescriptor {
 public:
  // Indexes the finite points of `cloud` (copied; non-finite ones skipped and counted).
  explicit GravityShotDescriptor(const std::vector<CloudPoint>& cloud, const GravityShotOptions& options = {},
                                 ShotFrame frame = ShotFrame::kGravity);
  ~GravityShotDescriptor();
  GravityShotDescriptor(const GravityShotDescriptor&) = delete;
  GravityShotDescriptor& operator=(const GravityShotDescriptor&) = delete;

  int64_t non_finite_points() const;
  size_t indexed_points() const;

  // The descriptor at `keypoint` (submap frame); false when its support is too small. Normals are
  // computed on first use and kept, so descriptors of nearby keypoints share them.
  bool Compute(const Eigen::Vector3f& keypoint, GravityShot* descriptor, GravityShotFrame* frame = nullptr);
  DescribedKeypoints ComputeAll(const std::vector<Eigen::Vector3f>& keypoints);

  // L2 distance scaled to [0, 1] (unit descriptors with non-negative entries are at most sqrt(2) apart).
  static float Distance(const GravityShot& a, const GravityShot& b);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cairn
