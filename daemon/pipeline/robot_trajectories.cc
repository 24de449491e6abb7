#include "daemon/pipeline/robot_trajectories.h"

#include <algorithm>
#include <cmath>

#include "common/heap_bytes.h"
#include "daemon/pipeline/team_input.h"

namespace cairn {

const std::vector<PlacedEstimate>* RobotTrajectories::Estimates(char robot, uint32_t run) const {
  if (robot == own_ && run == kCurrentRun) return &own_estimates_;
  const auto it = estimates_.find(RunKey{robot, run});
  return it == estimates_.end() ? nullptr : &it->second;
}

std::vector<uint32_t> RobotTrajectories::Runs(char robot) const {
  std::vector<uint32_t> out;
  for (auto it = estimates_.lower_bound(RunKey{robot, 0}); it != estimates_.end() && it->first.first == robot;
       ++it) {
    if (!it->second.empty()) out.push_back(it->first.second);
  }
  if (robot == own_) {
    // Run 0 sorts first but is the newest.
    out.erase(std::remove(out.begin(), out.end(), kCurrentRun), out.end());
    out.push_back(kCurrentRun);
  }
  return out;
}

uint32_t RobotTrajectories::LatestRun(char robot) const {
  const std::vector<uint32_t> runs = Runs(robot);
  return runs.empty() ? RunOfIndex(RunIndex(0, 0)) : runs.back();
}

uint32_t RobotTrajectories::RunAt(char robot, Timestamp time) const {
  // A restarted robot's clock may start over: of the runs begun by `time`, the one begun last.
  const std::vector<uint32_t> runs = Runs(robot);
  uint32_t best = runs.empty() ? LatestRun(robot) : runs.back();
  bool found = false;
  Timestamp best_start;
  for (uint32_t run : runs) {
    const std::vector<PlacedEstimate>* s = Estimates(robot, run);
    if (s == nullptr || s->empty() || s->front().time > time) continue;
    if (!found || s->front().time >= best_start) {
      best = run;
      best_start = s->front().time;
      found = true;
    }
  }
  return best;
}

RobotTrajectories::Lookup RobotTrajectories::PoseAt(char robot, uint32_t run, Timestamp time,
                                                    PlacedEstimate* pose, Matrix6d* covariance,
                                                    std::string* why) const {
  const std::vector<PlacedEstimate>* stream = Estimates(robot, run);
  if (stream == nullptr) return Lookup::kWait;
  if (stream->empty() || stream->back().time < time) return Lookup::kWait;
  const auto after = std::lower_bound(stream->begin(), stream->end(), time,
                                      [](const PlacedEstimate& p, Timestamp t) { return p.time < t; });
  // Estimates come at the camera rate: a gap of several frames means the filter was not running.
  const Duration max_gap = Duration::Seconds(0.5);
  if (after->time == time) {
    *pose = *after;
  } else if (after == stream->begin()) {
    *why = std::string("no estimate of ") + robot + " before that time";
    return Lookup::kNever;
  } else {
    const PlacedEstimate& before = *(after - 1);
    if (after->time - before.time > max_gap) {
      *why = std::string("a gap in ") + robot + "'s estimates at that time";
      return Lookup::kNever;
    }
    if (before.frame_id != after->frame_id) {
      // A frame switch between the two: the nearer one, if near.
      const PlacedEstimate& near = (time - before.time) < (after->time - time) ? before : *after;
      if (std::abs((near.time - time).seconds()) > 0.05) {
        *why = std::string("a frame switch of ") + robot + " at that time";
        return Lookup::kNever;
      }
      *pose = near;
    } else {
      const double s = (time - before.time).seconds() / (after->time - before.time).seconds();
      pose->time = time;
      pose->frame_id = before.frame_id;
      pose->T_frame_body = Eigen::Isometry3d::Identity();
      pose->T_frame_body.translation() =
          (1.0 - s) * before.T_frame_body.translation() + s * after->T_frame_body.translation();
      pose->T_frame_body.linear() = Eigen::Quaterniond(before.T_frame_body.linear())
                                        .slerp(s, Eigen::Quaterniond(after->T_frame_body.linear()))
                                        .normalized()
                                        .toRotationMatrix();
    }
  }
  // The filter's covariance in its frame changes slowly: the nearest graph pose's, same frame.
  // Which one is nearest is settled once a graph pose at or after `time` is in; choosing earlier
  // would make the factor depend on when the poses arrived, and teammates' graphs differ.
  const auto c = pose_covariances_.find(RunKey{robot, run});
  if (c == pose_covariances_.end() || c->second.empty() || c->second.back().time < time) return Lookup::kWait;
  const Duration window = Duration::Seconds(2.0);
  const PoseCovariance* best = nullptr;
  for (auto it = c->second.rbegin(); it != c->second.rend(); ++it) {
    if (it->frame_id != pose->frame_id) continue;
    if (best == nullptr || std::abs((it->time - time).seconds()) < std::abs((best->time - time).seconds()))
      best = &*it;
    if (it->time < time - window) break;
  }
  if (best != nullptr && std::abs((best->time - time).seconds()) <= window.seconds()) {
    *covariance = best->covariance;
    return Lookup::kReady;
  }
  *why = std::string("no graph pose of ") + robot + " near that time";
  return Lookup::kNever;
}

size_t RobotTrajectories::bytes() const {
  size_t total = HeapBytes(own_estimates_);
  for (const auto& [run, v] : estimates_) total += HeapBytes(v);
  for (const auto& [run, v] : pose_covariances_) total += HeapBytes(v);
  return total;
}

}  // namespace cairn
