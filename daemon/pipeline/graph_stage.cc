#include "daemon/pipeline/graph_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include "common/bounded_errors.h"
#include "common/heap_bytes.h"
#include "common/monotonic_clock.h"
#include "daemon/pipeline/structure_observation_factors.h"
#include "detection/gravity_agreement.h"

namespace cairn {
namespace {

// A relative pose's covariance with its translation in the first frame (as the filter's switch
// and the matcher state it) turned into the factor's, whose translation residual is in the second
// frame (R_ab^T (t - t_ab), g2o's convention). The rotation part is a right perturbation already.
Matrix6d TranslationInSecondFrame(const Matrix6d& covariance, const Eigen::Matrix3d& R_a_b) {
  Matrix6d J = Matrix6d::Identity();
  J.topLeftCorner<3, 3>() = R_a_b.transpose();
  const Matrix6d c = J * covariance * J.transpose();
  return 0.5 * (c + c.transpose());
}

Pose3 ToPose3(const Eigen::Isometry3d& T) {
  return Pose3{T.translation(), Eigen::Quaterniond(T.rotation()).normalized()};
}

bool FiniteFactor(const SlamFactor& f) {
  return f.information.allFinite() && f.z.t.allFinite() && f.z.q.coeffs().allFinite();
}

Eigen::Isometry3d ToIsometry(const Pose3& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.R();
  T.translation() = p.t;
  return T;
}


}  // namespace

GraphStage::GraphStage(const GraphStageOptions& options, bool deterministic)
    : options_([&] {
        GraphStageOptions o = options;
        // Deterministic replays bound each update by its iterations only: a time bound would make
        // the optimum depend on the machine's load.
        if (deterministic) o.optimizer.update_seconds = 1e9;
        return o;
      }()),
      graph_(options_.optimizer),
      robot_(options_.optimizer.own_robot),
      trajectories_(robot_),
      screen_(options_.team_matches),
      gnss_(options_.gnss) {}

uint64_t GraphStage::OriginKey(uint64_t frame_id) const {
  return VariableKey(VariableKind::kSubmap, robot_, frame_id);
}

Matrix6d GraphStage::Floored(const Matrix6d& covariance) const {
  Matrix6d c = 0.5 * (covariance + covariance.transpose());
  for (int i = 0; i < 3; ++i) c(i, i) += options_.min_position_sigma * options_.min_position_sigma;
  for (int i = 3; i < 6; ++i) c(i, i) += options_.min_rotation_sigma * options_.min_rotation_sigma;
  return c;
}

void GraphStage::Error(const std::string& what) {
  AppendBoundedError(report_.errors, what);
}

bool GraphStage::Add(const SlamFactor& f) {
  Status s = Status::Ok();
  if (!FiniteFactor(f)) {
    s = InvalidArgumentError("factor " + std::to_string(static_cast<int>(f.kind)) + " with a non-finite measurement or covariance");
  } else {
    s = graph_.AddFactor(f);
  }
  if (!s.ok()) {
    ++report_.rejected_factors;
    Error(s.ToString());
    return false;
  }
  ++report_.factors;
  if (f.kind == FactorKind::kFrameSwitch) screen_.AddFrameSwitch(f);
  if (f.kind == FactorKind::kLandmark) {
    ++outside_ties_[RobotOfVariable(f.a)];
  } else if ((f.kind == FactorKind::kMatch || f.kind == FactorKind::kDetection) &&
             RobotOfVariable(f.a) != RobotOfVariable(f.b)) {
    ++outside_ties_[RobotOfVariable(f.a)];
    ++outside_ties_[RobotOfVariable(f.b)];
  }
  return true;
}

void GraphStage::Update() {
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  const SlamUpdateStats stats = graph_.Update();
  update_time_.Record(clock.Now() - start);
  if (stats.solved) ++report_.solves;
  if (stats.reinitialized) ++report_.reinitializations;
}

void GraphStage::OnInput(const GraphInput& input) {
  if (input.kind == GraphInput::Kind::kEstimate) {
    OnEstimate(input.estimate);
  } else {
    OnFrameSwitch(input.frame_switch);
  }
}

void GraphStage::OnEstimate(const FrameEstimate& e) {
  last_estimate_is_pose_ = false;
  if (!e.valid) return;
  ++report_.estimates;
  if (!started_) {
    // The filter's first frame is the global frame: the prior holds its origin at the identity.
    SlamFactor prior;
    prior.kind = FactorKind::kPrior;
    prior.a = OriginKey(e.frame_id);
    prior.information = Floored(Matrix6d::Zero()).inverse();
    Add(prior);
    ++report_.submap_origins;
    started_ = true;
  }
  if (!graph_.HasVariable(OriginKey(e.frame_id))) {
    ++report_.unplaced;
    return;
  }
  trajectories_.AddOwnEstimate(PlacedEstimate{e.time, e.frame_id, e.T_frame_body});
  if (screen_.held() != 0) TakeScreenedMatches(false);
  if (!pending_detections_.empty()) RetryPendingDetections();
  if (!pending_fixes_.empty()) RetryPendingFixes();
  if ((trajectories_.Own().size() - 1) % static_cast<uint64_t>(options_.pose_every) != 0) return;
  trajectories_.AddPoseCovariance(robot_, kCurrentRun, e.time, e.frame_id, e.pose_covariance);
  SlamFactor v;
  v.kind = FactorKind::kFilterEstimate;
  v.a = OriginKey(e.frame_id);
  v.b = VariableKey(VariableKind::kRobotPose, robot_, next_pose_++);
  v.z = ToPose3(e.T_frame_body);
  v.information = Floored(e.pose_covariance).inverse();
  if (!Add(v)) return;
  last_estimate_is_pose_ = true;
  last_pose_index_ = IndexOfVariable(v.b);
  ++report_.robot_poses;
  Update();
}

void GraphStage::OnFrameSwitch(const FrameSwitchEvent& e) {
  if (!started_ || !graph_.HasVariable(OriginKey(e.old_frame_id))) {
    // A switch before the first estimate (none: the filter switches only once initialized) or
    // from a frame the graph never saw.
    ++report_.unplaced;
    Error("frame switch " + std::to_string(e.old_frame_id) + " -> " + std::to_string(e.new_frame_id) +
          " from a frame not in the graph");
    return;
  }
  SlamFactor w;
  w.kind = FactorKind::kFrameSwitch;
  w.a = OriginKey(e.old_frame_id);
  w.b = OriginKey(e.new_frame_id);
  w.z = ToPose3(e.transform.T_old_new);
  w.information = SwitchInformation(e.transform.covariance, e.transform.T_old_new);
  if (!Add(w)) {
    ++report_.unplaced;  // the new frame stays unknown: its estimates are counted as unplaced
    return;
  }
  ++report_.frame_switches;
  ++report_.submap_origins;
  Update();
}

void GraphStage::Finish() {
  if (graph_.num_factors() == 0) return;
  TakeScreenedMatches(true);
  if (!pending_fixes_.empty()) RetryPendingFixes();
  const SlamUpdateStats stats = graph_.SolveFinal();
  if (stats.solved) ++report_.solves;
  report_.final_cost = stats.cost;
  report_.chi2 = graph_.Chi2();
  report_.unconnected_variables = graph_.Unconnected().size();
}

Status GraphStage::AddMatch(uint64_t frame_a, uint64_t frame_b, const FourDofTransform& T_a_b,
                            const Eigen::Matrix4d& covariance, double tilt_sigma) {
  return AddMatch(robot_, frame_a, robot_, frame_b, T_a_b, covariance, tilt_sigma);
}

Status GraphStage::AddMatch(char robot_a, uint64_t frame_a, char robot_b, uint64_t frame_b,
                            const FourDofTransform& T_a_b, const Eigen::Matrix4d& covariance,
                            double tilt_sigma, bool* held) {
  if (held != nullptr) *held = false;
  const uint64_t key_a = VariableKey(VariableKind::kSubmap, robot_a, frame_a);
  const uint64_t key_b = VariableKey(VariableKind::kSubmap, robot_b, frame_b);
  if (!graph_.HasVariable(key_a) || !graph_.HasVariable(key_b))
    return NotFoundError("match between origins " + std::string(1, robot_a) + std::to_string(frame_a) + " and " +
                         std::string(1, robot_b) + std::to_string(frame_b) + ": not both in the graph");
  // (x, y, z, yaw) into (translation, rotation vector); yaw is the rotation about z, the same axis
  // in both gravity-aligned frames. The matcher states the translation in A's frame.
  Matrix6d c = Matrix6d::Zero();
  const int index[4] = {0, 1, 2, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) c(index[i], index[j]) = covariance(i, j);
  c(3, 3) = c(4, 4) = tilt_sigma * tilt_sigma;
  c = TranslationInSecondFrame(c, T_a_b.ToIsometry().linear());
  SlamFactor f;
  f.kind = FactorKind::kMatch;
  f.a = key_a;
  f.b = key_b;
  f.z = ToPose3(T_a_b.ToIsometry());
  f.information = Floored(c).inverse();
  if (robot_a == robot_b) return AddMatchFactor(f);
  if (!FiniteFactor(f) || f.information.llt().info() != Eigen::Success) {
    ++report_.rejected_factors;
    const std::string what = "match with a non-finite measurement or covariance";
    Error(what);
    return InvalidArgumentError(what);
  }
  screen_.Offer(f, last_time());
  if (held != nullptr) *held = true;
  TakeScreenedMatches(false);
  return Status::Ok();
}

Status GraphStage::AddMatchFactor(const SlamFactor& f) {
  const size_t rejected = report_.rejected_factors;
  if (!Add(f)) return InvalidArgumentError(report_.errors.empty() || report_.rejected_factors == rejected
                                               ? "the graph refused the match"
                                               : report_.errors.back());
  ++report_.matches;
  const bool team = RobotOfVariable(f.a) != RobotOfVariable(f.b);
  if (team) ++report_.team_matches;
  Update();
  // A match may tie a teammate's subgraph, whose fixes wait for that.
  if (team && !pending_fixes_.empty()) RetryPendingFixes();
  return Status::Ok();
}

void GraphStage::TakeScreenedMatches(bool final) {
  for (const ScreenedMatch& m : screen_.Decide(last_time(), final)) {
    if (!m.accepted) {
      ++report_.team_matches_rejected;
      Error(m.reason);
      continue;
    }
    // Refusals are counted and named by Add().
    (void)AddMatchFactor(m.factor);
  }
  report_.team_matches_held = screen_.held();
}

Matrix6d GraphStage::SwitchInformation(const Matrix6d& covariance, const Eigen::Isometry3d& T_old_new) const {
  // The filter states the new origin's position error in the old frame.
  return Floored(TranslationInSecondFrame(covariance, T_old_new.linear())).inverse();
}

void GraphStage::OnTeamInput(const TeamInput& in) {
  ++report_.team_inputs;
  const char r = in.letter;
  // The exchange hands over this robot's earlier runs (as a teammate's), never its current one.
  if (r == 0) return;
  switch (in.kind) {
    case TeamInput::Kind::kFrameSwitch: {
      SlamFactor w;
      w.kind = FactorKind::kFrameSwitch;
      w.a = VariableKey(VariableKind::kSubmap, r, in.old_frame);
      w.b = VariableKey(VariableKind::kSubmap, r, in.new_frame);
      w.z = ToPose3(in.T_old_new);
      w.information = SwitchInformation(in.switch_covariance, in.T_old_new);
      if (Add(w)) ++report_.team_factors;
      break;
    }
    case TeamInput::Kind::kPoses: {
      for (const TeamPose& p : in.poses)
        trajectories_.AddTeamEstimate(r, RunOfIndex(p.frame),
                                      PlacedEstimate{p.time, p.frame, p.T_frame_body});
      for (const TeamGraphPose& g : in.graph_poses) {
        SlamFactor v;
        v.kind = FactorKind::kFilterEstimate;
        v.a = VariableKey(VariableKind::kSubmap, r, g.pose.frame);
        v.b = VariableKey(VariableKind::kRobotPose, r, g.pose_index);
        v.z = ToPose3(g.pose.T_frame_body);
        v.information = Floored(g.covariance).inverse();
        if (Add(v)) ++report_.team_factors;
        trajectories_.AddPoseCovariance(r, RunOfIndex(g.pose.frame), g.pose.time, g.pose.frame, g.covariance);
      }
      if (!pending_detections_.empty()) RetryPendingDetections();
      break;
    }
    case TeamInput::Kind::kGnssFix: {
      TeamGnssFix g = in.gnss;
      g.letter = r;
      AddGnssFix(g);
      break;
    }
    case TeamInput::Kind::kDetection: {
      TeamDetection d = in.detection;
      d.observer_letter = r;
      AddDetection(d, true, "");
      break;
    }
    case TeamInput::Kind::kPlaneObservations: {
      for (const TeamPlaneObservation& o : in.planes) pending_planes_.push_back(o);
      break;
    }
    case TeamInput::Kind::kLineObservations: {
      for (const TeamLineObservation& o : in.lines) pending_lines_.push_back(o);
      break;
    }
    case TeamInput::Kind::kMatch: {
      if (in.match.letter_a == 0 || in.match.letter_b == 0) break;  // a robot not in the team file
      pending_matches_.push_back(PendingMatch{in.match.letter_a, in.match.letter_b, in.match.frame_a, in.match.frame_b,
                                              in.match.T_a_b, in.match.covariance, in.match.tilt_sigma});
      break;
    }
    default:
      break;
  }
  RetryPendingMatches();
  RetryPendingPlanes();
  RetryPendingLines();
  // New estimates of a teammate, or a tie to its subgraph, may place its waiting fixes.
  if (!pending_fixes_.empty() && in.kind != TeamInput::Kind::kGnssFix) RetryPendingFixes();
  Update();
}

Status GraphStage::AddStructureFactor(const SlamFactor& f, char observer, uint64_t frame, bool* created) {
  const char* what = f.kind == FactorKind::kPlaneObservation ? "plane" : "line";
  if (structure_factors_.count({f.a, f.b}) != 0) {
    return AlreadyExistsError(std::string(what) + " observation held already");
  }
  if (!graph_.Tied(f.a)) {
    return NotFoundError(std::string(what) + " observation by origin " + observer + std::to_string(frame) +
                         ": not tied to this robot's origins yet");
  }
  *created = !graph_.HasVariable(f.b);
  const size_t errors = report_.errors.size();
  if (!Add(f)) {
    return InvalidArgumentError(report_.errors.size() > errors ? report_.errors.back()
                                                               : "the graph refused it");
  }
  structure_factors_.insert({f.a, f.b});
  return Status::Ok();
}

template <class Observation, class AddOne>
std::vector<Status> GraphStage::AddObservationBatch(const std::vector<Observation>& observations,
                                                    AddOne add_one) {
  std::vector<Status> out;
  out.reserve(observations.size());
  bool added = false;
  for (const Observation& o : observations) {
    out.push_back(add_one(o));
    added = added || out.back().ok();
  }
  if (added) Update();
  return out;
}

std::vector<Status> GraphStage::AddPlaneObservations(const std::vector<TeamPlaneObservation>& observations) {
  return AddObservationBatch(
      observations, [this](const TeamPlaneObservation& o) { return AddPlaneObservationNoUpdate(o); });
}

std::vector<Status> GraphStage::AddLineObservations(const std::vector<TeamLineObservation>& observations) {
  return AddObservationBatch(observations,
                             [this](const TeamLineObservation& o) { return AddLineObservationNoUpdate(o); });
}

// The graph checks the measurement and its covariance (the codec has checked teammates' already).
Status GraphStage::AddPlaneObservationNoUpdate(const TeamPlaneObservation& o) {
  const Expected<SlamFactor> f = PlaneObservationFactor(o);
  if (!f.ok()) return f.status();
  bool created = false;
  const Status s = AddStructureFactor(*f, o.observer_letter, o.frame, &created);
  if (s.ok()) {
    ++report_.plane_observations;
    if (created) ++report_.plane_landmarks;
  }
  return s;
}

Status GraphStage::AddLineObservationNoUpdate(const TeamLineObservation& o) {
  const Expected<SlamFactor> f = LineObservationFactor(o);
  if (!f.ok()) return f.status();
  bool created = false;
  const Status s = AddStructureFactor(*f, o.observer_letter, o.frame, &created);
  if (s.ok()) {
    ++report_.line_observations;
    if (created) ++report_.line_landmarks;
  }
  return s;
}

Expected<double> GraphStage::StructureObservationChi2(const Expected<SlamFactor>& f) const {
  if (!f.ok()) return f.status();
  if (structure_factors_.count({f->a, f->b}) == 0) return NotFoundError("observation not in the graph");
  return graph_.FactorChi2(*f);
}

Expected<double> GraphStage::PlaneObservationChi2(const TeamPlaneObservation& o) const {
  return StructureObservationChi2(PlaneObservationFactor(o));
}

Expected<double> GraphStage::LineObservationChi2(const TeamLineObservation& o) const {
  return StructureObservationChi2(LineObservationFactor(o));
}

bool GraphStage::PlaceOrigins(const std::vector<std::pair<char, uint64_t>>& origins,
                              std::vector<SubmapPlacement>* out, std::string* why) {
  out->clear();
  std::vector<uint64_t> keys;
  for (const auto& [letter, frame] : origins) {
    const uint64_t key = VariableKey(VariableKind::kSubmap, letter, frame);
    if (!graph_.Tied(key)) {
      *why = std::string("origin ") + letter + std::to_string(frame) + " not tied to this robot's";
      return false;
    }
    keys.push_back(key);
  }
  const auto covariances = graph_.Covariances(keys);
  if (!covariances.ok()) {
    *why = "covariances: " + covariances.status().ToString();
    return false;
  }
  for (size_t i = 0; i < keys.size(); ++i)
    out->push_back(SubmapPlacement{ToIsometry(*graph_.Pose(keys[i])), (*covariances)[i]});
  return true;
}

namespace {

// Teammates' observations whose submaps the graph now ties to this robot's are added; the others
// wait. Only after a teammate's item, which updates the graph next.
template <class Observation, class AddFn>
void RetryPendingStructure(std::vector<Observation>& pending, const SlamGraph& graph, uint64_t* added,
                           AddFn add) {
  for (size_t i = 0; i < pending.size();) {
    const Observation& o = pending[i];
    const uint64_t origin = VariableKey(VariableKind::kSubmap, o.observer_letter, o.frame);
    if (o.observer_letter != 0 && !graph.Tied(origin)) {
      ++i;
      continue;
    }
    const Status s = add(o);
    if (s.code() == StatusCode::kNotFound) {
      ++i;
      continue;
    }
    if (s.ok()) ++*added;
    pending.erase(pending.begin() + static_cast<long>(i));
  }
}

}  // namespace

void GraphStage::RetryPendingPlanes() {
  RetryPendingStructure(pending_planes_, graph_, &report_.team_factors,
                        [this](const TeamPlaneObservation& o) { return AddPlaneObservationNoUpdate(o); });
  report_.plane_observations_pending = pending_planes_.size();
}

void GraphStage::RetryPendingLines() {
  RetryPendingStructure(pending_lines_, graph_, &report_.team_factors,
                        [this](const TeamLineObservation& o) { return AddLineObservationNoUpdate(o); });
  report_.line_observations_pending = pending_lines_.size();
}

void GraphStage::RetryPendingMatches() {
  for (size_t i = 0; i < pending_matches_.size();) {
    const PendingMatch& m = pending_matches_[i];
    const Status s = AddMatch(m.robot_a, m.frame_a, m.robot_b, m.frame_b, m.T_a_b, m.covariance, m.tilt_sigma);
    if (s.code() == StatusCode::kNotFound) {
      ++i;
      continue;
    }
    if (s.ok()) ++report_.team_factors;
    pending_matches_.erase(pending_matches_.begin() + static_cast<long>(i));
  }
  report_.team_matches_pending = pending_matches_.size();
}

void GraphStage::AddDetection(const TeamDetection& detection, bool usable, const std::string& refused) {
  detection_records_.push_back(DetectionRecord{detection, usable ? "waiting" : "refused: " + refused});
  if (!usable) return;
  const TeamDetection& d = detection_records_.back().detection;
  if (d.observer_letter == 0) {
    detection_records_.back().status = "unplaced: the observer is not in the team";
  } else if (d.landmark ? std::find(landmarks_.begin(), landmarks_.end(), d.observed) == landmarks_.end()
                        : d.observed_letter == 0) {
    detection_records_.back().status = "unplaced: '" + d.observed + "' is not in the team or the landmarks";
  } else if (d.observed_letter == d.observer_letter && !d.landmark) {
    detection_records_.back().status = "unplaced: a robot seeing its own tag";
  } else {
    pending_detections_.push_back(detection_records_.size() - 1);
    RetryPendingDetections();
    return;
  }
  ++report_.detections_unplaced;
}

std::vector<uint32_t> GraphStage::Runs(char robot) const { return trajectories_.Runs(robot); }

uint64_t GraphStage::DetectionPose(char robot, uint32_t run, Timestamp time, const PlacedEstimate& pose,
                                   const Matrix6d& covariance) {
  // Indexed by run and millisecond, apart from the filter's poses: every robot names it alike.
  // 42 bits of milliseconds reach past 2100 in Unix time; runs wrap after 32.
  const uint64_t ms = static_cast<uint64_t>(time.nanoseconds() / 1000000) & ((uint64_t{1} << 42) - 1);
  const uint64_t index = (uint64_t{1} << 47) | (static_cast<uint64_t>(run & 31u) << 42) | ms;
  const uint64_t key = VariableKey(VariableKind::kRobotPose, robot, index);
  if (graph_.HasVariable(key)) return key;
  SlamFactor v;
  v.kind = FactorKind::kFilterEstimate;
  v.a = VariableKey(VariableKind::kSubmap, robot, pose.frame_id);
  v.b = key;
  v.z = ToPose3(pose.T_frame_body);
  v.information = Floored(covariance).inverse();
  Add(v);
  return key;
}

bool GraphStage::AgreesWithGravity(const TeamDetection& d, const PlacedEstimate& observer,
                                   const PlacedEstimate& observed, Eigen::Isometry3d* T_observer_observed,
                                   std::string* chosen, std::string* refused) {
  // Each robot's roll and pitch, as its filter knows them from gravity: a conservative sigma for
  // an IMU of the MTi-10 class. The gate is chi-square with 2 degrees of freedom at 99.9 %.
  constexpr double kAttitudeSigma = 1.0 * std::numbers::pi / 180;
  constexpr double kGate = 13.8;
  const Eigen::Matrix3d cov = d.covariance.bottomRightCorner<3, 3>();
  const Eigen::Matrix3d R_a = observer.T_frame_body.linear(), R_b = observed.T_frame_body.linear();
  const GravityAgreement best =
      GravityAgreementOf(R_a, R_b, d.T_observer_observed.linear(), cov, kAttitudeSigma);
  if (best.mahalanobis2 <= kGate) return true;
  const double degrees = best.angle * 180 / std::numbers::pi;
  char text[160];
  if (d.has_alternative) {
    const GravityAgreement other =
        GravityAgreementOf(R_a, R_b, d.T_observer_observed_alternative.linear(), cov, kAttitudeSigma);
    if (other.mahalanobis2 <= kGate) {
      *T_observer_observed = d.T_observer_observed_alternative;
      std::snprintf(text, sizeof text, " (IPPE's other minimum: the best tilts %.1f deg off gravity)",
                    degrees);
      *chosen = text;
      ++report_.detections_flipped;
      return true;
    }
  }
  std::snprintf(text, sizeof text, "tilts %.1f deg off the robots' gravity (%.1f sigma)%s", degrees,
                std::sqrt(best.mahalanobis2), d.has_alternative ? ", as does the other minimum" : "");
  *refused = text;
  return false;
}

void GraphStage::RetryPendingDetections() {
  for (size_t i = 0; i < pending_detections_.size();) {
    DetectionRecord& rec = detection_records_[pending_detections_[i]];
    const TeamDetection& d = rec.detection;
    PlacedEstimate obs, tgt;
    Matrix6d obs_cov, tgt_cov;
    std::string why_a, why_b;
    const uint32_t observed_run = d.landmark ? 0 : trajectories_.RunAt(d.observed_letter, d.time);
    RobotTrajectories::Lookup a =
        trajectories_.PoseAt(d.observer_letter, d.observer_run, d.time, &obs, &obs_cov, &why_a);
    RobotTrajectories::Lookup b =
        d.landmark ? RobotTrajectories::Lookup::kReady
                   : trajectories_.PoseAt(d.observed_letter, observed_run, d.time, &tgt, &tgt_cov, &why_b);
    if (a == RobotTrajectories::Lookup::kNever || b == RobotTrajectories::Lookup::kNever) {
      rec.status = "unplaced: " + (a == RobotTrajectories::Lookup::kNever ? why_a : why_b);
      ++report_.detections_unplaced;
      pending_detections_.erase(pending_detections_.begin() + static_cast<long>(i));
      continue;
    }
    if (a == RobotTrajectories::Lookup::kWait || b == RobotTrajectories::Lookup::kWait) {
      ++i;
      continue;
    }
    if (!graph_.HasVariable(VariableKey(VariableKind::kSubmap, d.observer_letter, obs.frame_id)) ||
        (!d.landmark && !graph_.HasVariable(VariableKey(VariableKind::kSubmap, d.observed_letter, tgt.frame_id)))) {
      ++i;  // the frame's switch factor is not in yet
      continue;
    }
    Eigen::Isometry3d T_observer_observed = d.T_observer_observed;
    std::string chosen;
    if (!d.landmark) {
      std::string refused;
      if (!AgreesWithGravity(d, obs, tgt, &T_observer_observed, &chosen, &refused)) {
        rec.status = "refused: " + refused;
        ++report_.detections_against_gravity;
        pending_detections_.erase(pending_detections_.begin() + static_cast<long>(i));
        continue;
      }
    }
    SlamFactor f;
    f.a = DetectionPose(d.observer_letter, d.observer_run, d.time, obs, obs_cov);
    if (d.landmark) {
      f.kind = FactorKind::kLandmark;
      const int index = static_cast<int>(std::find(landmarks_.begin(), landmarks_.end(), d.observed) - landmarks_.begin());
      f.b = VariableKey(VariableKind::kLandmark, '*', static_cast<uint64_t>(index));
    } else {
      f.kind = FactorKind::kDetection;
      f.b = DetectionPose(d.observed_letter, observed_run, d.time, tgt, tgt_cov);
    }
    f.z = ToPose3(T_observer_observed);
    f.information = Floored(d.covariance).inverse();
    const size_t errors = report_.errors.size();
    if (Add(f)) {
      rec.status = "factor" + chosen;
      // The record shows the pose the graph holds.
      if (!chosen.empty())
        std::swap(rec.detection.T_observer_observed, rec.detection.T_observer_observed_alternative);
      ++(d.landmark ? report_.landmark_observations : report_.detections);
      Update();
      if (!pending_fixes_.empty()) RetryPendingFixes();  // it may tie a teammate's subgraph
    } else {
      rec.status = "graph refused: " + (report_.errors.size() > errors ? report_.errors.back() : std::string("see errors"));
    }
    pending_detections_.erase(pending_detections_.begin() + static_cast<long>(i));
  }
  report_.detections_pending = pending_detections_.size();
}

bool GraphStage::AddGnssFix(const GnssFix& fix) {
  return AddGnssFix(TeamGnssFix{robot_, kCurrentRun, fix, gnss_.antenna()});
}

bool GraphStage::AddGnssFix(const TeamGnssFix& fix) {
  ++report_.gnss_fixes;
  if (const Status s = gnss_.Check(fix.fix); !s.ok()) {
    ++report_.gnss_refused;
    Error(std::string(1, fix.letter) + ": " + s.ToString());
    return false;
  }
  // A teammate never tied to this robot's subgraph must not hold fixes without bound.
  constexpr size_t kMaxPendingFixes = 4096;
  if (pending_fixes_.size() == kMaxPendingFixes) {
    pending_fixes_.erase(pending_fixes_.begin());
    ++report_.gnss_unplaced;
  }
  pending_fixes_.push_back(fix);
  RetryPendingFixes();
  return true;
}

void GraphStage::RetryPendingFixes() {
  std::set<uint64_t> loose;  // variables not tied to this robot's, computed once when needed
  bool loose_known = false;
  struct FloatingFixes {
    uint64_t key = 0;  // a variable of the subgraph
    std::vector<GnssFix> fixes;
    std::vector<Eigen::Vector3d> antenna_floating;
  };
  std::map<RunKey, FloatingFixes> floating;
  size_t kept = 0;
  for (size_t k = 0; k < pending_fixes_.size(); ++k) {
    const TeamGnssFix& f = pending_fixes_[k];
    PlacedEstimate pose;
    Matrix6d covariance;
    std::string why;
    const RobotTrajectories::Lookup lookup =
        trajectories_.PoseAt(f.letter, f.run, f.fix.time, &pose, &covariance, &why);
    const uint64_t origin = VariableKey(VariableKind::kSubmap, f.letter, pose.frame_id);
    if (lookup == RobotTrajectories::Lookup::kNever) {
      ++report_.gnss_unplaced;
      continue;
    }
    bool wait = lookup == RobotTrajectories::Lookup::kWait || !graph_.HasVariable(origin);
    if (!wait && f.letter != robot_) {
      if (!loose_known) {
        const std::vector<uint64_t> u = graph_.Unconnected();
        loose.insert(u.begin(), u.end());
        loose_known = true;
      }
      wait = loose.count(origin) != 0;  // its fix cannot place a floating subgraph
    }
    if (wait && lookup == RobotTrajectories::Lookup::kReady && graph_.HasVariable(origin)) {
      // Placeable in its floating subgraph: a candidate for placing that subgraph by its fixes.
      const uint64_t key = DetectionPose(f.letter, f.run, f.fix.time, pose, covariance);
      if (const auto T_floating_body = graph_.Pose(key); T_floating_body.ok()) {
        FloatingFixes& run = floating[RunKey{f.letter, f.run}];
        run.key = key;
        run.fixes.push_back(f.fix);
        run.antenna_floating.push_back(T_floating_body->t + T_floating_body->q * f.antenna);
      }
    }
    if (wait) {
      pending_fixes_[kept++] = f;
      continue;
    }
    const uint64_t key = DetectionPose(f.letter, f.run, f.fix.time, pose, covariance);
    const auto T_world_body = graph_.Pose(key);
    if (!T_world_body.ok()) {
      ++report_.gnss_unplaced;
      continue;
    }
    bool added = false;
    for (const SlamFactor& factor : gnss_.Add(f.fix, key, *T_world_body, f.antenna)) {
      if (!Add(factor)) continue;
      added = true;
      if (factor.kind == FactorKind::kGnssPosition && RobotOfVariable(factor.b) != robot_)
        ++report_.gnss_team_factors;
    }
    if (added) Update();
  }
  pending_fixes_.resize(kept);
  // A teammate never tied to this robot (no match, no sighting) is placed by its own fixes once
  // they fix its yaw; then its fixes tie it.
  bool placed = false;
  Eigen::Isometry3d T_world_enu;
  if (!floating.empty() && Datum(&T_world_enu)) {
    for (const auto& [run, f] : floating) {
      const Expected<Pose3> correction =
          gnss_.PlaceFloating(f.fixes, f.antenna_floating, ToPose3(T_world_enu));
      if (!correction.ok()) continue;
      if (graph_.PlaceComponent(f.key, *correction).ok()) {
        ++report_.gnss_placed_subgraphs;
        placed = true;
      }
    }
  }
  if (placed) {
    RetryPendingFixes();
    return;
  }
  report_.gnss_factors = gnss_.counts().factors;
  report_.gnss_pending = pending_fixes_.size() + gnss_.counts().held;
  report_.gnss_datum = gnss_.counts().datum_started;
}

bool GraphStage::Datum(Eigen::Isometry3d* T_world_enu) const {
  if (!gnss_.counts().datum_started) return false;
  const auto pose = graph_.Pose(GnssFixFactors::DatumKey());
  if (!pose.ok()) return false;
  *T_world_enu = ToIsometry(*pose);
  return true;
}

std::vector<char> GraphStage::Robots() const {
  std::vector<char> out{robot_};
  std::set<char> seen{robot_};
  for (uint64_t key : graph_.VariableKeys()) {
    if (KindOfKey(key) == VariableKind::kLandmark || KindOfKey(key) == VariableKind::kDatum) continue;
    if (seen.insert(RobotOfVariable(key)).second) out.push_back(RobotOfVariable(key));
  }
  return out;
}

bool GraphStage::Connected(char robot) const { return Connected(robot, trajectories_.LatestRun(robot)); }

bool GraphStage::Connected(char robot, uint32_t run) const {
  if (robot == robot_ && run == kCurrentRun) return true;
  const std::vector<uint64_t> unconnected = graph_.Unconnected();
  const std::set<uint64_t> loose(unconnected.begin(), unconnected.end());
  bool any = false;
  for (uint64_t key : graph_.VariableKeys()) {
    if (RobotOfVariable(key) != robot || KindOfKey(key) != VariableKind::kSubmap) continue;
    if (RunOfIndex(IndexOfVariable(key)) != run) continue;
    if (loose.count(key) != 0) return false;
    any = true;
  }
  return any;
}

std::vector<OriginEstimate> GraphStage::OriginEstimates(bool covariances) {
  std::vector<OriginEstimate> out;
  std::vector<uint64_t> keys;
  const std::vector<uint64_t> unconnected = graph_.Unconnected();
  for (uint64_t key : graph_.VariableKeys()) {
    if (KindOfKey(key) != VariableKind::kSubmap) continue;
    const auto p = graph_.Pose(key);
    if (!p.ok()) continue;
    OriginEstimate o;
    o.robot = RobotOfVariable(key);
    o.frame_id = IndexOfVariable(key);
    const Eigen::Matrix3d R = p->R();
    o.T_global_origin = FourDofTransform(p->t, std::atan2(R(1, 0), R(0, 0)));
    o.connected = std::find(unconnected.begin(), unconnected.end(), key) == unconnected.end();
    out.push_back(o);
    keys.push_back(key);
  }
  if (covariances && !keys.empty()) {
    auto cov = graph_.Covariances(keys);
    if (cov.ok()) {
      const int index[4] = {0, 1, 2, 5};
      for (size_t k = 0; k < keys.size(); ++k) {
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) out[k].covariance(i, j) = (*cov)[k](index[i], index[j]);
        out[k].has_covariance = out[k].covariance.allFinite();
      }
    } else {
      Error("covariances for submap pairing: " + cov.status().ToString());
    }
  }
  return out;
}

GraphStageReport GraphStage::report() const {
  GraphStageReport r = report_;
  r.history_bytes = HeapBytes(detection_records_) + trajectories_.bytes();
  return r;
}

std::map<uint64_t, Eigen::Isometry3d> GraphStage::FrameOrigins() const { return FrameOrigins(robot_); }

std::map<uint64_t, Eigen::Isometry3d> GraphStage::FrameOrigins(char robot) const {
  std::map<uint64_t, Eigen::Isometry3d> out;
  for (uint64_t key : graph_.VariableKeys()) {
    if (KindOfKey(key) != VariableKind::kSubmap || RobotOfVariable(key) != robot) continue;
    if (auto p = graph_.Pose(key); p.ok()) out[IndexOfVariable(key)] = ToIsometry(*p);
  }
  return out;
}

bool GraphStage::LatestGlobalPose(char robot, StampedPose* out) const {
  const uint32_t run = trajectories_.LatestRun(robot);
  const std::vector<PlacedEstimate>* placed = trajectories_.Estimates(robot, run);
  if (placed == nullptr || placed->empty() || !Connected(robot, run)) return false;
  const PlacedEstimate& e = placed->back();
  const auto origin = graph_.Pose(VariableKey(VariableKind::kSubmap, robot, e.frame_id));
  if (!origin.ok()) return false;
  *out = StampedPose{e.time, ToIsometry(*origin) * e.T_frame_body};
  return true;
}

bool GraphStage::LandmarkGlobalPose(size_t index, Eigen::Isometry3d* T_global_landmark) const {
  const uint64_t key = VariableKey(VariableKind::kLandmark, '*', static_cast<uint64_t>(index));
  const auto pose = graph_.Pose(key);
  if (!pose.ok()) return false;
  const std::vector<uint64_t> loose = graph_.Unconnected();
  if (std::find(loose.begin(), loose.end(), key) != loose.end()) return false;
  *T_global_landmark = ToIsometry(*pose);
  return true;
}

Trajectory GraphStage::GlobalTrajectory() const { return GlobalTrajectory(robot_); }

Trajectory GraphStage::GlobalTrajectory(char robot) const {
  return GlobalTrajectory(robot, trajectories_.LatestRun(robot));
}

Trajectory GraphStage::GlobalTrajectory(char robot, uint32_t run) const {
  Trajectory t;
  t.frame = "global";
  if (!Connected(robot, run)) return t;
  const auto origins = FrameOrigins(robot);
  const std::vector<PlacedEstimate>* placed = trajectories_.Estimates(robot, run);
  if (placed == nullptr) return t;
  t.poses.reserve(placed->size());
  for (const PlacedEstimate& e : *placed) {
    const auto origin = origins.find(e.frame_id);
    if (origin == origins.end()) continue;
    t.poses.push_back(StampedPose{e.time, origin->second * e.T_frame_body});
  }
  return t;
}

GraphScene GraphStage::Scene(bool covariances) {
  GraphScene scene;
  std::vector<uint64_t> origin_keys;
  const std::vector<uint64_t> unconnected = graph_.Unconnected();
  const std::set<uint64_t> loose(unconnected.begin(), unconnected.end());
  // A robot's latest run goes by its letter, runs before a restart by their incarnation.
  const auto run_name = [this](char robot, uint32_t run) {
    return std::string(1, robot) + (run == trajectories_.LatestRun(robot) ? "" : EarlierRunSuffix(run));
  };
  for (uint64_t key : graph_.VariableKeys()) {
    if (loose.count(key) != 0) continue;  // where the graph cannot place it yet: not drawn
    if (KindOfKey(key) == VariableKind::kDatum || IsStructureVariable(key)) continue;
    auto p = graph_.Pose(key);
    if (!p.ok()) continue;
    GraphScene::Node node{key, ToIsometry(*p), Eigen::Matrix3d::Zero(), ""};
    if (KindOfKey(key) == VariableKind::kSubmap) {
      const char r = RobotOfVariable(key);
      const uint32_t run = RunOfIndex(IndexOfVariable(key));
      node.label = run_name(r, run) + "/s" + std::to_string(LocalIndex(IndexOfVariable(key)));
      scene.origins.push_back(node);
      origin_keys.push_back(key);
    } else {
      scene.poses.push_back(node);
    }
  }
  if (covariances && !origin_keys.empty()) {
    auto cov = graph_.Covariances(origin_keys);
    if (cov.ok()) {
      for (size_t i = 0; i < origin_keys.size(); ++i) origin_covariance_[origin_keys[i]] = (*cov)[i].topLeftCorner<3, 3>();
    } else {
      Error("covariances for the live view: " + cov.status().ToString());
    }
  }
  for (GraphScene::Node& n : scene.origins) {
    if (const auto c = origin_covariance_.find(n.key); c != origin_covariance_.end()) n.position_covariance = c->second;
  }
  for (const SlamFactor& f : graph_.factors()) {
    if (IsPoseEdge(f.kind)) scene.edges.push_back(GraphScene::Edge{f.a, f.b, f.kind});
  }
  constexpr size_t kMaxTrackPoints = 400;
  for (char r : Robots()) {
    const std::vector<uint32_t> runs = Runs(r);
    for (uint32_t run : runs) {
      const Trajectory t = GlobalTrajectory(r, run);
      if (t.poses.empty()) continue;
      GraphScene::Track track{r, run_name(r, run), {}};
      const size_t step = std::max<size_t>(1, t.poses.size() / kMaxTrackPoints);
      for (size_t i = 0; i < t.poses.size(); i += step) track.positions.push_back(t.poses[i].T_frame_body.translation());
      if ((t.poses.size() - 1) % step != 0) track.positions.push_back(t.poses.back().T_frame_body.translation());
      scene.tracks.push_back(std::move(track));
    }
  }
  return scene;
}

PoseGraph GraphStage::ExportPoseGraph() const {
  PoseGraph g;
  for (uint64_t key : graph_.VariableKeys()) {
    // The datum and the planes and lines have no pose edges (their factors are not g2o's).
    if (KindOfKey(key) == VariableKind::kDatum || IsStructureVariable(key)) continue;
    if (auto p = graph_.Pose(key); p.ok()) g.SetVertex(key, *p);
  }
  g.set_has_initial_estimate(true);
  for (const SlamFactor& f : graph_.factors()) {
    // Not the prior: g2o readers take the first vertex as the gauge.
    if (IsPoseEdge(f.kind)) g.AddEdge(EdgeOfFactor(f));
  }
  return g;
}

}  // namespace cairn
