#include "daemon/comms/team_item_codec.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cairn/exchange.pb.h"
#include "mapping/submap_codec.h"

namespace cairn {
namespace {

void SetPose(exchange::RelativePose* out, const Eigen::Isometry3d& T, const Matrix6d* covariance) {
  const Eigen::Quaterniond q(T.rotation());
  out->set_tx(T.translation().x());
  out->set_ty(T.translation().y());
  out->set_tz(T.translation().z());
  out->set_qx(q.x());
  out->set_qy(q.y());
  out->set_qz(q.z());
  out->set_qw(q.w());
  if (covariance != nullptr) {
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) out->add_covariance((*covariance)(i, j));
  }
}

// The pose and (when `covariance`) its 21 upper-triangle covariance entries, checked.
Status GetPose(const exchange::RelativePose& in, Eigen::Isometry3d* T, Matrix6d* covariance, const std::string& what) {
  const double v[7] = {in.tx(), in.ty(), in.tz(), in.qx(), in.qy(), in.qz(), in.qw()};
  for (double x : v) {
    if (!std::isfinite(x) || std::abs(x) > 1e7) return DataLossError(what + ": a pose value is not finite or absurd");
  }
  Eigen::Quaterniond q(in.qw(), in.qx(), in.qy(), in.qz());
  if (std::abs(q.norm() - 1.0) > 1e-3) return DataLossError(what + ": the rotation is not a unit quaternion");
  *T = Eigen::Isometry3d::Identity();
  T->linear() = q.normalized().toRotationMatrix();
  T->translation() = Eigen::Vector3d(in.tx(), in.ty(), in.tz());
  if (covariance == nullptr) return Status::Ok();
  if (in.covariance_size() != 21)
    return DataLossError(what + ": the covariance has " + std::to_string(in.covariance_size()) + " entries, not 21");
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) {
      const double c = in.covariance(k++);
      if (!std::isfinite(c)) return DataLossError(what + ": a covariance entry is not finite");
      (*covariance)(i, j) = (*covariance)(j, i) = c;
    }
  }
  for (int i = 0; i < 6; ++i) {
    if ((*covariance)(i, i) < 0.0) return DataLossError(what + ": a variance is negative");
  }
  return Status::Ok();
}

void SetPair(const TeamMatch& m, exchange::MatchAttemptItem* out) {
  out->set_robot_a(m.robot_a);
  out->set_incarnation_a(m.incarnation_a);
  out->set_incarnation_b(m.incarnation_b);
  out->set_frame_a(m.frame_a);
  out->set_robot_b(m.robot_b);
  out->set_frame_b(m.frame_b);
}

// The robots, runs and frames an observation names (the same fields in both landmark kinds).
template <class Message>
void SetNames(const TeamLandmarkNames& o, Message* p) {
  p->set_observer(o.observer);
  p->set_observer_incarnation(o.observer_incarnation);
  p->set_frame(o.frame);
  p->set_creator(o.creator);
  p->set_creator_incarnation(o.creator_incarnation);
  p->set_creator_frame(o.creator_frame);
}

template <class Message>
Status GetNames(const Message& p, const TeamItemCodec::Names& names, const std::string& which,
                TeamLandmarkNames* o) {
  if (p.observer().empty() || p.creator().empty() || p.observer().size() > 64 || p.creator().size() > 64)
    return DataLossError(which + " names no observer or no creator robot");
  o->observer = p.observer();
  o->observer_letter = names.letter_of(o->observer);
  o->observer_incarnation = p.observer_incarnation();
  o->frame = names.frame_index(o->observer, p.observer_incarnation(), p.frame());
  o->creator = p.creator();
  o->creator_letter = names.letter_of(o->creator);
  o->creator_incarnation = p.creator_incarnation();
  o->creator_frame = names.frame_index(o->creator, p.creator_incarnation(), p.creator_frame());
  return Status::Ok();
}

// A small covariance sent as doubles: symmetric (relative to its size: the entries are small and
// were floats before) and positive definite.
template <int N>
Status CheckCovariance(const Eigen::Matrix<double, N, N>& c, const std::string& which) {
  if ((c - c.transpose()).norm() > 1e-6 * c.norm())
    return DataLossError(which + ": the covariance is not symmetric");
  if (c.llt().info() != Eigen::Success)
    return DataLossError(which + ": the covariance is not positive definite");
  return Status::Ok();
}

}  // namespace

uint8_t LaneOf(TeamItemKind kind) { return kind == TeamItemKind::kSubmap ? 1 : 0; }

const char* TeamItemKindName(uint16_t kind) {
  switch (static_cast<TeamItemKind>(kind)) {
    case TeamItemKind::kRunStart: return "run_start";
    case TeamItemKind::kFrameSwitch: return "frame_switch";
    case TeamItemKind::kPoseBatch: return "poses";
    case TeamItemKind::kSubmap: return "submap";
    case TeamItemKind::kMatch: return "match";
    case TeamItemKind::kAttempt: return "attempt";
    case TeamItemKind::kDetection: return "detection";
    case TeamItemKind::kGnssFix:
      return "gnss_fix";
    case TeamItemKind::kPlaneObservations:
      return "plane_observations";
    case TeamItemKind::kLineObservations:
      return "line_observations";
  }
  return "unknown";
}

std::string TeamItemCodec::RunStart(uint32_t incarnation, const std::string& robot_kind, Timestamp start) {
  exchange::RunStart m;
  m.set_incarnation(incarnation);
  m.set_robot_kind(robot_kind);
  m.set_start_time_ns(start.nanoseconds());
  return m.SerializeAsString();
}

std::string TeamItemCodec::FrameSwitch(uint32_t incarnation, const FrameSwitchEvent& e) {
  exchange::FrameSwitchItem m;
  m.set_incarnation(incarnation);
  m.set_old_frame(e.old_frame_id);
  m.set_new_frame(e.new_frame_id);
  m.set_time_ns(e.time.nanoseconds());
  SetPose(m.mutable_t_old_new(), e.transform.T_old_new, &e.transform.covariance);
  return m.SerializeAsString();
}

std::string TeamItemCodec::PoseBatch(uint32_t incarnation, const std::vector<OwnEstimate>& estimates) {
  exchange::PoseBatchItem m;
  m.set_incarnation(incarnation);
  for (const OwnEstimate& o : estimates) {
    const FrameEstimate& e = o.estimate;
    auto* p = m.add_points();
    const Eigen::Quaternionf q(e.T_frame_body.rotation().cast<float>());
    p->set_time_ns(e.time.nanoseconds());
    p->set_frame(e.frame_id);
    p->set_tx(static_cast<float>(e.T_frame_body.translation().x()));
    p->set_ty(static_cast<float>(e.T_frame_body.translation().y()));
    p->set_tz(static_cast<float>(e.T_frame_body.translation().z()));
    p->set_qx(q.x());
    p->set_qy(q.y());
    p->set_qz(q.z());
    p->set_qw(q.w());
    if (o.graph_pose) {
      auto* g = m.add_graph_poses();
      g->set_pose_index(o.pose_index);
      g->set_frame(e.frame_id);
      g->set_time_ns(e.time.nanoseconds());
      SetPose(g->mutable_t_frame_body(), e.T_frame_body, &e.pose_covariance);
    }
  }
  return m.SerializeAsString();
}

Expected<std::string> TeamItemCodec::Submap(uint32_t incarnation, const cairn::Submap& submap) {
  auto bytes = SubmapCodec::Encode(submap);
  if (!bytes.ok()) return bytes.status();
  exchange::SubmapItem m;
  m.set_incarnation(incarnation);
  m.set_frame(submap.metadata().id);
  m.set_encoded(bytes->data(), bytes->size());
  return m.SerializeAsString();
}

std::string TeamItemCodec::Match(const TeamMatch& match) {
  exchange::SubmapMatchItem m;
  m.set_incarnation_a(match.incarnation_a);
  m.set_incarnation_b(match.incarnation_b);
  m.set_robot_a(match.robot_a);
  m.set_frame_a(match.frame_a);
  m.set_robot_b(match.robot_b);
  m.set_frame_b(match.frame_b);
  m.set_x(match.T_a_b.x());
  m.set_y(match.T_a_b.y());
  m.set_z(match.T_a_b.z());
  m.set_yaw(match.T_a_b.yaw());
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m.add_covariance(match.covariance(i, j));
  m.set_tilt_sigma(match.tilt_sigma);
  return m.SerializeAsString();
}

std::string TeamItemCodec::Attempt(const TeamMatch& pair, bool matched, const std::string& outcome) {
  exchange::MatchAttemptItem m;
  SetPair(pair, &m);
  m.set_matched(matched);
  m.set_outcome(outcome.substr(0, 200));
  return m.SerializeAsString();
}

std::string TeamItemCodec::Detection(uint32_t incarnation, const TeamDetection& d) {
  exchange::DetectionItem m;
  m.set_incarnation(incarnation);
  m.set_time_ns(d.time.nanoseconds());
  m.set_observed(d.observed);
  m.set_landmark(d.landmark);
  m.set_tag_id(static_cast<uint32_t>(std::max(d.tag_id, 0)));
  SetPose(m.mutable_t_observer_observed(), d.T_observer_observed, &d.covariance);
  if (d.has_alternative)
    SetPose(m.mutable_t_observer_observed_alternative(), d.T_observer_observed_alternative, nullptr);
  m.set_distance(d.distance);
  m.set_view_angle(d.view_angle);
  return m.SerializeAsString();
}

std::string TeamItemCodec::GnssFix(uint32_t incarnation, const TeamGnssFix& g) {
  exchange::GnssFixItem m;
  m.set_incarnation(incarnation);
  m.set_time_ns(g.fix.time.nanoseconds());
  m.set_latitude(g.fix.latitude);
  m.set_longitude(g.fix.longitude);
  m.set_height(g.fix.height);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.add_covariance(g.fix.covariance(r, c));
  }
  m.set_quality(static_cast<uint32_t>(g.fix.quality));
  m.set_antenna_x(g.antenna.x());
  m.set_antenna_y(g.antenna.y());
  m.set_antenna_z(g.antenna.z());
  return m.SerializeAsString();
}

std::string TeamItemCodec::PlaneObservations(const std::vector<TeamPlaneObservation>& observations) {
  exchange::PlaneObservationsItem m;
  for (const TeamPlaneObservation& o : observations) {
    auto* p = m.add_observations();
    SetNames(o, p);
    p->set_plane(o.plane);
    p->set_observer_plane(o.observer_plane);
    p->set_normal_x(o.normal.x());
    p->set_normal_y(o.normal.y());
    p->set_normal_z(o.normal.z());
    p->set_offset(o.offset);
    p->set_centroid_x(o.centroid.x());
    p->set_centroid_y(o.centroid.y());
    p->set_centroid_z(o.centroid.z());
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) p->add_covariance(o.covariance(r, c));
    }
  }
  return m.SerializeAsString();
}

std::string TeamItemCodec::LineObservations(const std::vector<TeamLineObservation>& observations) {
  exchange::LineObservationsItem m;
  for (const TeamLineObservation& o : observations) {
    auto* p = m.add_observations();
    SetNames(o, p);
    p->set_line(o.line);
    p->set_observer_line(o.observer_line);
    p->set_point_x(o.point.x());
    p->set_point_y(o.point.y());
    p->set_point_z(o.point.z());
    p->set_direction_x(o.direction.x());
    p->set_direction_y(o.direction.y());
    p->set_direction_z(o.direction.z());
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) p->add_covariance(o.covariance(r, c));
    }
  }
  return m.SerializeAsString();
}

uint32_t TeamItemCodec::IncarnationOf(const StoreItem& item) {
  exchange::RunStart m;
  if (!m.ParseFromArray(item.payload.data(), static_cast<int>(item.payload.size()))) return 0;
  return m.incarnation();
}

Expected<TeamInput> TeamItemCodec::Decode(const StoreItem& item, const Names& names) {
  const auto& letter_of = names.letter_of;
  const auto index = [&](const std::string& robot, uint32_t incarnation, uint64_t frame) {
    return names.frame_index(robot, incarnation, frame);
  };
  const std::string what = "item " + item.key.origin + "/" + std::to_string(item.key.lane) + "/" +
                           std::to_string(item.key.seq) + " (" + TeamItemKindName(item.kind) + ")";
  TeamInput in;
  in.robot = item.key.origin;
  in.letter = letter_of(item.key.origin);
  const auto& bytes = item.payload;
  const int size = static_cast<int>(bytes.size());
  switch (static_cast<TeamItemKind>(item.kind)) {
    case TeamItemKind::kRunStart: {
      exchange::RunStart m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kRunStart;
      in.time = Timestamp::FromNanoseconds(m.start_time_ns());
      return in;
    }
    case TeamItemKind::kFrameSwitch: {
      exchange::FrameSwitchItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kFrameSwitch;
      in.old_frame = index(in.robot, m.incarnation(), m.old_frame());
      in.new_frame = index(in.robot, m.incarnation(), m.new_frame());
      in.time = Timestamp::FromNanoseconds(m.time_ns());
      if (in.old_frame == in.new_frame) return DataLossError(what + ": switches frame " + std::to_string(in.old_frame) + " into itself");
      CAIRN_RETURN_IF_ERROR(GetPose(m.t_old_new(), &in.T_old_new, &in.switch_covariance, what));
      return in;
    }
    case TeamItemKind::kPoseBatch: {
      exchange::PoseBatchItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kPoses;
      for (const auto& p : m.points()) {
        const float v[7] = {p.tx(), p.ty(), p.tz(), p.qx(), p.qy(), p.qz(), p.qw()};
        bool ok = true;
        for (float x : v) ok = ok && std::isfinite(x);
        Eigen::Quaterniond q(p.qw(), p.qx(), p.qy(), p.qz());
        if (!ok || std::abs(q.norm() - 1.0) > 1e-3) return DataLossError(what + ": a pose is not finite or not a rotation");
        TeamPose pose;
        pose.time = Timestamp::FromNanoseconds(p.time_ns());
        pose.frame = index(in.robot, m.incarnation(), p.frame());
        pose.T_frame_body.linear() = q.normalized().toRotationMatrix();
        pose.T_frame_body.translation() = Eigen::Vector3d(p.tx(), p.ty(), p.tz());
        in.poses.push_back(pose);
      }
      for (const auto& g : m.graph_poses()) {
        TeamGraphPose pose;
        pose.pose_index = index(in.robot, m.incarnation(), g.pose_index());  // runs restart their count
        pose.pose.frame = index(in.robot, m.incarnation(), g.frame());
        pose.pose.time = Timestamp::FromNanoseconds(g.time_ns());
        CAIRN_RETURN_IF_ERROR(GetPose(g.t_frame_body(), &pose.pose.T_frame_body, &pose.covariance, what));
        in.graph_poses.push_back(pose);
      }
      return in;
    }
    case TeamItemKind::kSubmap: {
      exchange::SubmapItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      auto submap = SubmapCodec::Decode(std::span<const uint8_t>(
          reinterpret_cast<const uint8_t*>(m.encoded().data()), m.encoded().size()));
      if (!submap.ok()) return DataLossError(what + ": " + submap.status().message());
      if ((*submap)->metadata().robot != item.key.origin)
        return DataLossError(what + ": the submap says it is of robot '" + (*submap)->metadata().robot + "'");
      in.kind = TeamInput::Kind::kSubmap;
      in.submap = *submap;
      in.new_frame = index(in.robot, m.incarnation(), (*submap)->metadata().id);
      return in;
    }
    case TeamItemKind::kMatch: {
      exchange::SubmapMatchItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      if (m.covariance_size() != 16) return DataLossError(what + ": the covariance has " + std::to_string(m.covariance_size()) + " entries, not 16");
      in.kind = TeamInput::Kind::kMatch;
      TeamMatch& t = in.match;
      t.robot_a = m.robot_a();
      t.robot_b = m.robot_b();
      t.letter_a = letter_of(t.robot_a);
      t.letter_b = letter_of(t.robot_b);
      t.frame_a = index(t.robot_a, m.incarnation_a(), m.frame_a());
      t.frame_b = index(t.robot_b, m.incarnation_b(), m.frame_b());
      const double v[5] = {m.x(), m.y(), m.z(), m.yaw(), m.tilt_sigma()};
      for (double x : v) {
        if (!std::isfinite(x)) return DataLossError(what + ": a value is not finite");
      }
      t.T_a_b = FourDofTransform(Eigen::Vector3d(m.x(), m.y(), m.z()), m.yaw());
      for (int i = 0; i < 16; ++i) {
        if (!std::isfinite(m.covariance(i))) return DataLossError(what + ": a covariance entry is not finite");
        t.covariance(i / 4, i % 4) = m.covariance(i);
      }
      t.tilt_sigma = m.tilt_sigma();
      return in;
    }
    case TeamItemKind::kAttempt: {
      exchange::MatchAttemptItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kAttempt;
      in.match.robot_a = m.robot_a();
      in.match.robot_b = m.robot_b();
      in.match.letter_a = letter_of(m.robot_a());
      in.match.letter_b = letter_of(m.robot_b());
      in.match.frame_a = index(m.robot_a(), m.incarnation_a(), m.frame_a());
      in.match.frame_b = index(m.robot_b(), m.incarnation_b(), m.frame_b());
      in.matched = m.matched();
      in.outcome = m.outcome();
      return in;
    }
    case TeamItemKind::kDetection: {
      exchange::DetectionItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kDetection;
      TeamDetection& d = in.detection;
      d.time = Timestamp::FromNanoseconds(m.time_ns());
      d.observer = in.robot;
      d.observer_letter = in.letter;
      d.observer_run = RunOfIndex(index(in.robot, m.incarnation(), 0));
      d.observed = m.observed();
      d.landmark = m.landmark();
      if (d.observed.empty() || d.observed.size() > 64) return DataLossError(what + ": names no observed robot or landmark");
      d.observed_letter = d.landmark ? 0 : letter_of(d.observed);
      d.tag_id = static_cast<int>(std::min<uint32_t>(m.tag_id(), 1u << 20));
      CAIRN_RETURN_IF_ERROR(GetPose(m.t_observer_observed(), &d.T_observer_observed, &d.covariance, what));
      if (d.covariance.llt().info() != Eigen::Success) return DataLossError(what + ": the covariance is not positive definite");
      d.has_alternative = m.has_t_observer_observed_alternative();
      if (d.has_alternative) {
        CAIRN_RETURN_IF_ERROR(GetPose(m.t_observer_observed_alternative(), &d.T_observer_observed_alternative,
                                      nullptr, what + " (its other minimum)"));
      }
      d.distance = std::isfinite(m.distance()) ? m.distance() : 0.0;
      d.view_angle = std::isfinite(m.view_angle()) ? m.view_angle() : 0.0;
      return in;
    }
    case TeamItemKind::kGnssFix: {
      exchange::GnssFixItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      in.kind = TeamInput::Kind::kGnssFix;
      TeamGnssFix& g = in.gnss;
      g.letter = in.letter;
      g.run = RunOfIndex(index(in.robot, m.incarnation(), 0));
      g.fix.time = Timestamp::FromNanoseconds(m.time_ns());
      g.fix.latitude = m.latitude();
      g.fix.longitude = m.longitude();
      g.fix.height = m.height();
      if (!std::isfinite(g.fix.latitude) || !std::isfinite(g.fix.longitude) || !std::isfinite(g.fix.height) ||
          std::abs(g.fix.latitude) > std::numbers::pi / 2 || std::abs(g.fix.longitude) > std::numbers::pi) {
        return DataLossError(what + ": latitude, longitude or height out of range");
      }
      if (m.covariance_size() != 9) return DataLossError(what + ": the covariance needs 9 values");
      for (int k = 0; k < 9; ++k) g.fix.covariance(k / 3, k % 3) = m.covariance(k);
      if (!g.fix.covariance.allFinite() || (g.fix.covariance - g.fix.covariance.transpose()).norm() > 1e-9 ||
          g.fix.covariance.llt().info() != Eigen::Success) {
        return DataLossError(what + ": the covariance is not symmetric positive definite");
      }
      const uint32_t q = m.quality();
      if (q != 1 && q != 2 && q != 4 && q != 5)
        return DataLossError(what + ": quality " + std::to_string(q) + " is not a fix");
      g.fix.quality = static_cast<GnssQuality>(q);
      g.antenna = Eigen::Vector3d(m.antenna_x(), m.antenna_y(), m.antenna_z());
      if (!g.antenna.allFinite() || g.antenna.norm() > 20.0)
        return DataLossError(what + ": the antenna is not on the robot");
      return in;
    }
    case TeamItemKind::kPlaneObservations: {
      exchange::PlaneObservationsItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      const size_t count = static_cast<size_t>(m.observations_size());
      if (count == 0) return DataLossError(what + ": has no observations");
      if (count > kMaxPlaneObservations)
        return DataLossError(what + ": has " + std::to_string(count) + " observations, more than " +
                             std::to_string(kMaxPlaneObservations));
      in.kind = TeamInput::Kind::kPlaneObservations;
      in.planes.reserve(count);
      for (size_t k = 0; k < count; ++k) {
        const exchange::PlaneObservation& p = m.observations(static_cast<int>(k));
        const std::string which = what + ": observation " + std::to_string(k);
        TeamPlaneObservation o;
        CAIRN_RETURN_IF_ERROR(GetNames(p, names, which, &o));
        if (p.plane() > kMaxPlaneIndex || p.observer_plane() > kMaxPlaneIndex)
          return DataLossError(which + ": plane index " +
                               std::to_string(std::max(p.plane(), p.observer_plane())) + " is above " +
                               std::to_string(kMaxPlaneIndex));
        if (p.covariance_size() != 9)
          return DataLossError(which + ": the covariance has " + std::to_string(p.covariance_size()) +
                               " entries, not 9");
        o.plane = p.plane();
        o.observer_plane = p.observer_plane();
        o.normal = Eigen::Vector3d(p.normal_x(), p.normal_y(), p.normal_z());
        o.offset = p.offset();
        o.centroid = Eigen::Vector3d(p.centroid_x(), p.centroid_y(), p.centroid_z());
        for (int i = 0; i < 9; ++i) o.covariance(i / 3, i % 3) = p.covariance(i);
        if (!o.normal.allFinite() || !std::isfinite(o.offset) || !o.centroid.allFinite() ||
            !o.covariance.allFinite())
          return DataLossError(which + ": a value is not finite");
        if (std::abs(1.0 - o.normal.norm()) > 1e-3)
          return DataLossError(which + ": the normal is not of unit length");
        CAIRN_RETURN_IF_ERROR(CheckCovariance(o.covariance, which));
        in.planes.push_back(std::move(o));
      }
      return in;
    }
    case TeamItemKind::kLineObservations: {
      exchange::LineObservationsItem m;
      if (!m.ParseFromArray(bytes.data(), size)) return DataLossError(what + ": does not decode");
      const size_t count = static_cast<size_t>(m.observations_size());
      if (count == 0) return DataLossError(what + ": has no observations");
      if (count > kMaxLineObservations)
        return DataLossError(what + ": has " + std::to_string(count) + " observations, more than " +
                             std::to_string(kMaxLineObservations));
      in.kind = TeamInput::Kind::kLineObservations;
      in.lines.reserve(count);
      for (size_t k = 0; k < count; ++k) {
        const exchange::LineObservation& p = m.observations(static_cast<int>(k));
        const std::string which = what + ": observation " + std::to_string(k);
        TeamLineObservation o;
        CAIRN_RETURN_IF_ERROR(GetNames(p, names, which, &o));
        if (p.line() > kMaxLineIndex || p.observer_line() > kMaxLineIndex)
          return DataLossError(which + ": line index " +
                               std::to_string(std::max(p.line(), p.observer_line())) + " is above " +
                               std::to_string(kMaxLineIndex));
        if (p.covariance_size() != 16)
          return DataLossError(which + ": the covariance has " + std::to_string(p.covariance_size()) +
                               " entries, not 16");
        o.line = p.line();
        o.observer_line = p.observer_line();
        o.point = Eigen::Vector3d(p.point_x(), p.point_y(), p.point_z());
        o.direction = Eigen::Vector3d(p.direction_x(), p.direction_y(), p.direction_z());
        for (int i = 0; i < 16; ++i) o.covariance(i / 4, i % 4) = p.covariance(i);
        if (!o.point.allFinite() || !o.direction.allFinite() || !o.covariance.allFinite())
          return DataLossError(which + ": a value is not finite");
        if (std::abs(1.0 - o.direction.norm()) > 1e-3)
          return DataLossError(which + ": the direction is not of unit length");
        CAIRN_RETURN_IF_ERROR(CheckCovariance(o.covariance, which));
        in.lines.push_back(std::move(o));
      }
      return in;
    }
  }
  return DataLossError(what + ": unknown kind " + std::to_string(item.kind));
}

}  // namespace cairn
