#include "daemon/pipeline/gnss_fix_factors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Eigenvalues>

namespace cairn {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
// Fixes held while the robot stands still must not grow without bound; the newest are kept.
constexpr size_t kMaxHeld = 1000;
// The datum prior's weight where it knows nothing: a sigma of 10 km (and rad) keeps the problem
// well posed before the fixes fix the datum, without pulling it.
constexpr double kFlatInformation = 1e-8;

}  // namespace

GnssFixFactors::GnssFixFactors(const GnssFixOptions& options)
    : options_(options),
      plane_(GeodeticPoint{options.datum_latitude * kDegree, options.datum_longitude * kDegree,
                           options.datum_height}),
      antenna_(options.antenna_x, options.antenna_y, options.antenna_z) {}

uint64_t GnssFixFactors::DatumKey() { return VariableKey(VariableKind::kDatum, '*', 0); }

Status GnssFixFactors::Check(const GnssFix& fix) const {
  if (fix.quality == GnssQuality::kNone) return InvalidArgumentError("GNSS fix without a solution");
  if (!std::isfinite(fix.latitude) || !std::isfinite(fix.longitude) || !std::isfinite(fix.height) ||
      !fix.covariance.allFinite()) {
    return InvalidArgumentError("GNSS fix with a non-finite position or accuracy");
  }
  if (std::abs(fix.latitude) > std::numbers::pi / 2 || std::abs(fix.longitude) > std::numbers::pi) {
    return InvalidArgumentError("GNSS fix outside latitude/longitude ranges");
  }
  const Eigen::Matrix3d c = 0.5 * (fix.covariance + fix.covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
  if (eig.eigenvalues().minCoeff() < 0.0) return InvalidArgumentError("GNSS fix with a negative variance");
  const double worst = std::sqrt(eig.eigenvalues().maxCoeff());
  if (worst > options_.max_sigma) {
    char text[96];
    std::snprintf(text, sizeof text, "GNSS fix of accuracy %.2f m, worse than max_sigma %.2f m", worst,
                  options_.max_sigma);
    return InvalidArgumentError(text);
  }
  return Status::Ok();
}

std::vector<SlamFactor> GnssFixFactors::Add(const GnssFix& fix, uint64_t pose_key, const Pose3& T_world_body,
                                            const Eigen::Vector3d& antenna) {
  ++counts_.fixes;
  Held h;
  h.pose_key = pose_key;
  h.z_enu = plane_.ToEnu(GeodeticPoint{fix.latitude, fix.longitude, fix.height});
  h.covariance = CovarianceInDatum(fix);
  h.antenna = antenna;
  h.antenna_world = T_world_body.t + T_world_body.R() * antenna;
  std::vector<SlamFactor> out;
  if (counts_.datum_started) {
    out.push_back(FactorOf(h));
    ++counts_.factors;
    return out;
  }
  if (held_.size() == kMaxHeld) held_.erase(held_.begin());
  held_.push_back(h);
  counts_.held = held_.size();
  std::vector<Eigen::Vector3d> world, enu;
  std::vector<double> weights;
  for (const Held& k : held_) {
    world.push_back(k.antenna_world);
    enu.push_back(k.z_enu);
    weights.push_back(Weight(k.covariance));
  }
  if (YawSigma(world, weights) > options_.start_yaw_sigma) return out;
  const Expected<Pose3> T_world_enu = FitDatum(world, enu, weights);
  if (!T_world_enu.ok()) return out;
  SlamFactor prior;
  prior.kind = FactorKind::kAbsolutePose;
  prior.a = DatumKey();
  prior.z = *T_world_enu;
  prior.information = Matrix6d::Identity() * kFlatInformation;
  const double tilt_information = 1.0 / (options_.tilt_sigma * options_.tilt_sigma);
  prior.information(3, 3) = prior.information(4, 4) = tilt_information;
  out.push_back(prior);
  for (const Held& k : held_) out.push_back(FactorOf(k));
  counts_.factors += held_.size();
  counts_.datum_started = true;
  held_.clear();
  counts_.held = 0;
  return out;
}

SlamFactor GnssFixFactors::FactorOf(const Held& h) const {
  SlamFactor f;
  f.kind = FactorKind::kGnssPosition;
  f.a = DatumKey();
  f.b = h.pose_key;
  f.position = h.z_enu;
  f.position_information = h.covariance.inverse();
  f.antenna = h.antenna;
  return f;
}

double GnssFixFactors::YawSigma(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<double>& weights) {
  // Fisher information of a rotation about the vertical: sum of w_i |p_i - p_mean|^2 horizontally.
  double total = 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    total += weights[i];
    mean += weights[i] * points[i].head<2>();
  }
  if (!(total > 0.0)) return std::numeric_limits<double>::infinity();
  mean /= total;
  double information = 0.0;
  for (size_t i = 0; i < points.size(); ++i)
    information += weights[i] * (points[i].head<2>() - mean).squaredNorm();
  return information > 0.0 ? 1.0 / std::sqrt(information) : std::numeric_limits<double>::infinity();
}

Eigen::Matrix3d GnssFixFactors::CovarianceInDatum(const GnssFix& fix) const {
  const Eigen::Matrix3d R = plane_.R_datum_local(GeodeticPoint{fix.latitude, fix.longitude, fix.height});
  return R * (0.5 * (fix.covariance + fix.covariance.transpose())) * R.transpose() +
         options_.min_sigma * options_.min_sigma * Eigen::Matrix3d::Identity();
}

double GnssFixFactors::Weight(const Eigen::Matrix3d& covariance) {
  return 2.0 / covariance.topLeftCorner<2, 2>().trace();
}

Expected<Pose3> GnssFixFactors::PlaceFloating(const std::vector<GnssFix>& fixes,
                                              const std::vector<Eigen::Vector3d>& antenna_floating,
                                              const Pose3& T_world_enu) const {
  std::vector<Eigen::Vector3d> world;
  std::vector<double> weights;
  for (const GnssFix& fix : fixes) {
    weights.push_back(Weight(CovarianceInDatum(fix)));
    world.push_back(T_world_enu.t +
                    T_world_enu.q * plane_.ToEnu(GeodeticPoint{fix.latitude, fix.longitude, fix.height}));
  }
  if (YawSigma(antenna_floating, weights) > options_.start_yaw_sigma) {
    return FailedPreconditionError("the fixes do not fix the subgraph's yaw yet");
  }
  return FitDatum(world, antenna_floating, weights);
}

Expected<Pose3> GnssFixFactors::FitDatum(const std::vector<Eigen::Vector3d>& p_world,
                                         const std::vector<Eigen::Vector3d>& z_enu,
                                         const std::vector<double>& weights) {
  if (p_world.size() != z_enu.size() || p_world.size() != weights.size() || p_world.size() < 2) {
    return InvalidArgumentError("datum fit needs two or more pairs of points");
  }
  double total = 0.0;
  Eigen::Vector3d mean_world = Eigen::Vector3d::Zero(), mean_enu = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < p_world.size(); ++i) {
    total += weights[i];
    mean_world += weights[i] * p_world[i];
    mean_enu += weights[i] * z_enu[i];
  }
  if (!(total > 0.0)) return InvalidArgumentError("datum fit without weight");
  mean_world /= total;
  mean_enu /= total;
  // The yaw that best rotates the centred ENU points onto the centred world points (2-D Procrustes).
  double dot = 0.0, cross = 0.0;
  for (size_t i = 0; i < p_world.size(); ++i) {
    const Eigen::Vector2d a = (z_enu[i] - mean_enu).head<2>(), b = (p_world[i] - mean_world).head<2>();
    dot += weights[i] * a.dot(b);
    cross += weights[i] * (a.x() * b.y() - a.y() * b.x());
  }
  if (std::hypot(dot, cross) <= 0.0) return InvalidArgumentError("datum fit on coincident points");
  const Eigen::Quaterniond q(Eigen::AngleAxisd(std::atan2(cross, dot), Eigen::Vector3d::UnitZ()));
  return Pose3{mean_world - q * mean_enu, q};
}

}  // namespace cairn
