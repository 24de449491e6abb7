#pragma once
// The graph thread's side of the team exchange: it publishes this robot's items (frame switches,
// estimates, finished submaps, matches, attempts and detections) and takes teammates' items in the order the
// exchange stored them. Implemented by the comms stage (daemon/comms/); thread safe.

#include <functional>
#include <memory>
#include <vector>

#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/team_input.h"
#include "mapping/submap.h"

namespace cairn {

class TeamLink {
 public:
  virtual ~TeamLink() = default;
  virtual void PublishFrameSwitch(const FrameSwitchEvent& event) = 0;
  // `graph_pose`: the estimate is the graph's pose `pose_index` (a factor v).
  virtual void PublishEstimate(const FrameEstimate& estimate, bool graph_pose, uint64_t pose_index) = 0;
  virtual void PublishSubmap(std::shared_ptr<const Submap> submap) = 0;
  virtual void PublishMatch(const TeamMatch& match) = 0;
  virtual void PublishAttempt(const TeamMatch& pair, bool matched, const std::string& outcome) = 0;
  // A sighting of a teammate's or a landmark's tag (robot detection d, landmark observation o).
  virtual void PublishDetection(const TeamDetection& detection) = 0;
  // A GNSS fix the graph took (its letter and run are this robot's).
  virtual void PublishGnssFix(const TeamGnssFix& fix) = 0;
  // Plane landmark observations: one robot's decisions for one of its submaps (graph frame
  // indices, as the graph names them).
  virtual void PublishPlaneObservations(const std::vector<TeamPlaneObservation>& observations) = 0;
  // The same for line landmarks.
  virtual void PublishLineObservations(const std::vector<TeamLineObservation>& observations) = 0;
  // Teammates' items not taken yet; false when there are none.
  virtual bool NextInput(TeamInput* input) = 0;
  // Called (from the comms thread) when inputs arrive, to wake the graph thread.
  virtual void SetNotify(std::function<void()> notify) = 0;
  // End of the data: this robot's log is complete (what is batched goes out now).
  virtual void FinishOwnLog() = 0;
  // After the end of the data: whether this robot has anything left that may add items (matching
  // of teammates' late submaps). Teammates count it finished only while it is idle.
  virtual void SetIdle(bool idle) = 0;
  // Whether every teammate holds all this robot holds and this robot all they hold, all having
  // finished their logs; the end of the run waits for it at most `linger_seconds()`.
  virtual bool Settled() = 0;
  virtual double linger_seconds() const = 0;
};

}  // namespace cairn
