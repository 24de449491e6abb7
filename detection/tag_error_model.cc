#include "detection/tag_error_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace cairn {
namespace {

struct KindName {
  TagErrorKind kind;
  const char* name;
};
constexpr KindName kKinds[] = {{TagErrorKind::kCombined, "combined"},
                               {TagErrorKind::kPropagated, "propagated"},
                               {TagErrorKind::kThesis, "thesis"},
                               {TagErrorKind::kTable, "table"},
                               {TagErrorKind::kOnline, "online"},
                               {TagErrorKind::kConstant, "constant"},
                               {TagErrorKind::kQuadratic, "quadratic"}};

// Share of the table's variance added to every coordinate of the propagated model. With the
// mixture, the propagation alone has a median condition number of 1e5 on rendered tags (up to
// 3e7); 5 % of the table brings that to 2-3e4 and lowers their mean NEES by 15-25 %.
constexpr double kCellFloor = 0.05;

// The weight of IPPE's other minimum as the second component of a mixture: the likelihood of each
// given the corners (4 corners' squared distances, noise corner_rms per coordinate), and with
// `with_flip_share` at least the share of eq. 6.9's perturbed corner sets whose best solution was
// the other one (which catches flips that the residuals of this one image do not show).
double AlternativeWeight(const TagPose& pose, double corner_rms, bool with_flip_share) {
  const double sigma2 = corner_rms * corner_rms;
  const double log_ratio = -2.0 * (pose.alternative_reprojection_error * pose.alternative_reprojection_error -
                                   pose.reprojection_error * pose.reprojection_error) / sigma2;
  const double p = 1.0 / (1.0 + std::exp(-std::clamp(log_ratio, -50.0, 50.0)));
  const double q = with_flip_share && pose.solved_samples > 0
                       ? static_cast<double>(pose.flipped_samples) / pose.solved_samples
                       : 0.0;
  return std::max(p * (1.0 - p), q * (1.0 - q));
}

// The propagated model's Gaussian part: see tag_error_model.h.
Matrix6d PropagatedCovariance(const TagPose& pose, const Eigen::Matrix<double, 6, 1>& cell) {
  const Matrix6d shape = pose.corner_jacobian * pose.corner_jacobian.transpose();
  std::array<double, 6> ratio{};
  for (int k = 0; k < 6; ++k) {
    if (!(shape(k, k) > 0.0 && std::isfinite(shape(k, k)))) return cell.asDiagonal();  // no propagation
    ratio[k] = cell[k] / shape(k, k);
  }
  // The median, so that no single axis sets the level.
  std::sort(ratio.begin(), ratio.end());
  Matrix6d c = 0.5 * (ratio[2] + ratio[3]) * shape;
  c.diagonal() += kCellFloor * cell;
  return c;
}

}  // namespace

Expected<TagErrorKind> ParseTagErrorKind(const std::string& name) {
  for (const KindName& k : kKinds) {
    if (name == k.name) return k.kind;
  }
  return InvalidArgumentError("tag error model '" + name +
                              "' is not one of combined, propagated, thesis, table, online, constant, quadratic");
}

const char* TagErrorKindName(TagErrorKind kind) {
  for (const KindName& k : kKinds) {
    if (kind == k.kind) return k.name;
  }
  return "?";
}

Expected<TagErrorModel> TagErrorModel::Create(TagErrorKind kind, std::shared_ptr<const TagErrorTable> table,
                                              double corner_error, double camera_scale) {
  const bool needs_table = kind == TagErrorKind::kCombined || kind == TagErrorKind::kPropagated ||
                           kind == TagErrorKind::kThesis || kind == TagErrorKind::kTable;
  if (needs_table && (table == nullptr || table->empty()))
    return InvalidArgumentError(std::string("tag error model '") + TagErrorKindName(kind) + "' needs an error table");
  if (kind == TagErrorKind::kCombined && !(corner_error > 0.0))
    return InvalidArgumentError("tag error model 'combined' needs a corner perturbation > 0 px");
  if (!(camera_scale > 0.0 && camera_scale <= 1.0 + 1e-9))
    return InvalidArgumentError("tag error model: camera scale " + std::to_string(camera_scale) + " is not in (0, 1]");
  const double ratio = kind == TagErrorKind::kCombined ? table->corner_rms() / corner_error : 1.0;
  return TagErrorModel(kind, std::move(table), ratio * ratio, camera_scale);
}

double TagErrorModel::ResidualChi2(const TagPose& pose) const {
  if (table_ == nullptr || !(table_->corner_rms() > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // reprojection_error is the RMS over the 4 corners of their distance to the projection.
  return 4.0 * pose.reprojection_error * pose.reprojection_error / (table_->corner_rms() * table_->corner_rms());
}

Matrix6d TagErrorModel::Covariance(const TagPose& pose, double tag_size) const {
  Eigen::Matrix<double, 6, 1> variance = Eigen::Matrix<double, 6, 1>::Zero();
  switch (kind_) {
    case TagErrorKind::kOnline:
      return pose.covariance;
    case TagErrorKind::kConstant:
    case TagErrorKind::kQuadratic: {
      // Eq. 8.1: 1 cm and 1.3 deg; eq. 8.2 scales the variances by (1 + d)^2.
      variance << 1e-4, 1e-4, 1e-4, 5e-4, 5e-4, 5e-4;
      if (kind_ == TagErrorKind::kQuadratic) variance *= (1.0 + pose.distance) * (1.0 + pose.distance);
      break;
    }
    case TagErrorKind::kTable:
    case TagErrorKind::kThesis: {
      variance = table_->Sigma(pose.distance / camera_scale_, pose.view_angle, tag_size).cwiseAbs2();
      if (kind_ == TagErrorKind::kThesis) variance = variance.cwiseMax(pose.covariance.diagonal());
      break;
    }
    case TagErrorKind::kPropagated:
    case TagErrorKind::kCombined: {
      const Eigen::Matrix<double, 6, 1> cell =
          table_->Sigma(pose.distance / camera_scale_, pose.view_angle, tag_size).cwiseAbs2();
      Matrix6d c;
      if (kind_ == TagErrorKind::kPropagated) {
        c = PropagatedCovariance(pose, cell);
      } else {
        c = spread_scale_ * pose.sample_covariance;
        for (int k = 0; k < 6; ++k) c(k, k) = std::max(c(k, k), cell[k]);
      }
      if (pose.has_alternative && table_->corner_rms() > 0.0) {
        // IPPE's other minimum as the second component of a mixture: the moment-matched Gaussian
        // of the two spans both where they compete and is the plain one where they do not.
        const Eigen::Matrix<double, 6, 1> delta = TagPoseEstimator::Deviation(pose.T_cam_tag, pose.T_cam_tag_alternative);
        const bool with_flip_share = kind_ == TagErrorKind::kPropagated;
        c += AlternativeWeight(pose, table_->corner_rms(), with_flip_share) * delta * delta.transpose();
      }
      return c;
    }
  }
  return variance.asDiagonal();
}

}  // namespace cairn
