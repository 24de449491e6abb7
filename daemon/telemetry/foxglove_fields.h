#pragma once
// The two fields every Foxglove message cairn writes shares: a google.protobuf.Timestamp from a
// Timestamp, and a foxglove.Pose from a rigid transform.

#include <Eigen/Geometry>
#include <google/protobuf/timestamp.pb.h>

#include "common/timestamp.h"
#include "foxglove/Geometry.pb.h"

namespace cairn {

inline void SetFoxgloveTime(Timestamp t, google::protobuf::Timestamp* out) {
  out->set_seconds(t.nanoseconds() / 1000000000);
  out->set_nanos(static_cast<int32_t>(t.nanoseconds() % 1000000000));
}

inline void SetFoxglovePose(const Eigen::Isometry3d& T, foxglove::Pose* out) {
  const Eigen::Quaterniond q(T.linear());
  out->mutable_position()->set_x(T.translation().x());
  out->mutable_position()->set_y(T.translation().y());
  out->mutable_position()->set_z(T.translation().z());
  out->mutable_orientation()->set_x(q.x());
  out->mutable_orientation()->set_y(q.y());
  out->mutable_orientation()->set_z(q.z());
  out->mutable_orientation()->set_w(q.w());
}

}  // namespace cairn
