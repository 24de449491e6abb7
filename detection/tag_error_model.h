#pragma once
// The covariance given to a tag's pose (thesis 6.2.3), from the precomputed error table
// (tag_error_table.h) and the online spread of eq. 6.9's 256 corner perturbations.
//
// propagated (the default): the corners' linear propagation J J^T of this detection
//   (TagPose::corner_jacobian: its correlations, and which axes the view leaves weak), scaled to the
//   level the table measured at this distance and angle (the median over the six coordinates of
//   their ratio), with a floor of 5 % of the table's variance. IPPE's other minimum enters as the
//   second component of a mixture, weighted by the larger of the corners' likelihood under each
//   (their reprojection errors against the table's corner error) and the share of eq. 6.9's
//   perturbed corner sets that jumped to it; the moment-matched covariance of the two is the
//   result, so where the minima compete it spans both. On rendered tags it is the nearest to
//   consistent of the models (docs/results.md#robot-detection).
// combined: the sample covariance of the 257 solutions (TagPose::sample_covariance,
//   J diag(delta^2) J^T where the solver is linear) rescaled from the perturbation delta to the
//   corner error the table measured, with each variance raised to the table's where that is
//   larger. It keeps the correlations and the inflation where the perturbations jump between
//   IPPE's minima, without the thesis' worst-case factor. IPPE's other minimum enters as in
//   propagated, weighted by the corners' likelihood only. About 2x wider than the errors.
// thesis: per coordinate the larger of the table's sigma and the largest deviation of the 257
//   solutions from their mean (TagPose::covariance), as thesis 6.2.3 combines them.
// table, online: either half of the thesis' model alone; constant (eq. 8.1: 1 cm, 1.3 deg) and
//   quadratic (eq. 8.2: the same variances times (1 + d)^2): the simpler models of Table 8.3.

#include <memory>
#include <string>

#include "common/status.h"
#include "detection/tag_error_table.h"
#include "detection/tag_pose_estimator.h"

namespace cairn {

enum class TagErrorKind { kCombined, kPropagated, kThesis, kTable, kOnline, kConstant, kQuadratic };

// "combined", "propagated", "thesis", "table", "online", "constant", "quadratic"; an error names
// the accepted ones.
Expected<TagErrorKind> ParseTagErrorKind(const std::string& name);
const char* TagErrorKindName(TagErrorKind kind);

class TagErrorModel {
 public:
  // `table` is needed by every kind but kOnline, kConstant and kQuadratic; `corner_error` is the
  // perturbation (px) the poses' online spread was sampled with. `camera_scale` (<= 1) is the
  // camera's focal length over the table's for a camera of the same field of view at a lower
  // resolution: a tag at d looks as it would to the table's camera at d / scale, which gives its
  // rotation and sideways errors exactly and its depth error conservatively (by 1 / scale).
  static Expected<TagErrorModel> Create(TagErrorKind kind, std::shared_ptr<const TagErrorTable> table,
                                        double corner_error = 0.5, double camera_scale = 1.0);

  // The covariance of `pose` (a tag of `tag_size` m) in the tangent of tag_pose_estimator.h. Every
  // kind but kTable, kConstant and kQuadratic needs the online spread in `pose` (sample_corners on).
  Matrix6d Covariance(const TagPose& pose, double tag_size) const;

  // How far the corners are from the projection of a square at the pose, against the table's
  // corner error: chi-square with 2 degrees of freedom (8 coordinates, 6 pose parameters). A
  // detection far out (corners of a wrong quad, seen too obliquely) has no pose to trust. NaN
  // without a table.
  double ResidualChi2(const TagPose& pose) const;

  TagErrorKind kind() const { return kind_; }
  const TagErrorTable* table() const { return table_.get(); }

 private:
  TagErrorModel(TagErrorKind kind, std::shared_ptr<const TagErrorTable> table, double spread_scale, double camera_scale)
      : kind_(kind), table_(std::move(table)), spread_scale_(spread_scale), camera_scale_(camera_scale) {}

  TagErrorKind kind_ = TagErrorKind::kCombined;
  std::shared_ptr<const TagErrorTable> table_;
  double spread_scale_ = 1.0;  // (table corner error / perturbation)^2
  double camera_scale_ = 1.0;
};

}  // namespace cairn
