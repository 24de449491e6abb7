#pragma once
// The graph executor's work: the robot's SLAM graph (estimation/graph/slam_graph.h) fed online with the
// filter's output, in the filter topology of thesis Fig. 4.2b. Each local frame of the filter is a
// submap origin s (the first one carries the prior and is the global frame); each frame switch
// is a factor w between consecutive origins; every `pose_every`-th estimate is a robot pose x with
// its factor v from its frame's origin. Inputs come in the order the estimation thread made them,
// and in deterministic replays the optimizer is bounded by iterations only, so a replay gives the
// same graph bit for bit. Not thread safe: one graph thread owns it.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/graph_stage_options.h"
#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/robot_trajectories.h"
#include "daemon/pipeline/team_input.h"
#include "daemon/telemetry/graph_scene.h"
#include "estimation/eval/trajectory.h"
#include "estimation/graph/pose_graph.h"
#include "estimation/graph/slam_graph.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/plane_associator.h"

namespace cairn {

struct GraphStageReport {
  uint64_t estimates = 0;        // valid filter estimates received
  uint64_t frame_switches = 0;   // switches added as w factors
  uint64_t submap_origins = 0;
  uint64_t robot_poses = 0;
  uint64_t factors = 0;
  uint64_t solves = 0;           // updates that re-optimized
  uint64_t reinitializations = 0;
  uint64_t rejected_factors = 0;
  uint64_t matches = 0;          // submap matches added as c factors
  uint64_t team_matches = 0;     // of them, between two robots
  uint64_t team_inputs = 0;      // teammates' items taken
  uint64_t team_factors = 0;     // teammates' w, v and c factors taken (c: by the team screen)
  uint64_t team_matches_pending = 0;  // waiting for an origin not in the graph yet
  uint64_t team_matches_held = 0;     // waiting for the screen (TeamMatchScreen)
  uint64_t team_matches_rejected = 0;  // the screen found them contradicting accepted ones
  uint64_t plane_landmarks = 0;       // plane landmarks l started
  uint64_t plane_observations = 0;    // their observations o added (own and teammates')
  uint64_t plane_observations_pending = 0;  // a teammate's, its submap not tied to this robot's yet
  uint64_t line_landmarks = 0;              // line landmarks l started
  uint64_t line_observations = 0;           // their observations o added (own and teammates')
  uint64_t line_observations_pending = 0;   // a teammate's, its submap not tied to this robot's yet
  uint64_t detections = 0;            // robot detections d added (own and teammates')
  uint64_t landmark_observations = 0; // landmark observations o added
  uint64_t detections_pending = 0;    // waiting for a robot's estimates around their time
  uint64_t detections_unplaced = 0;   // no estimate of a robot at their time: never added
  uint64_t detections_flipped = 0;    // added as IPPE's other minimum: only it agrees with gravity
  uint64_t detections_against_gravity = 0;  // refused: neither minimum agrees with gravity
  // Estimates or switches the graph could not place: their frame is not connected to the chain
  // (an input was lost upstream). Counted, never guessed.
  uint64_t unplaced = 0;
  uint64_t unconnected_variables = 0;
  // Trajectories and pose covariances kept for placing sightings and writing the global
  // trajectory, and the sightings' records: they grow with the mission, like the map.
  uint64_t history_bytes = 0;
  uint64_t gnss_fixes = 0;       // fixes given
  uint64_t gnss_factors = 0;     // fixes that entered the graph
  uint64_t gnss_refused = 0;     // no solution, not finite, too inaccurate
  uint64_t gnss_unplaced = 0;    // no estimate of the robot at their time
  uint64_t gnss_team_factors = 0;  // of the factors, teammates' fixes
  uint64_t gnss_placed_subgraphs = 0;  // teammates' subgraphs placed by their fixes alone
  uint64_t gnss_pending = 0;     // waiting for estimates, or for the datum to start
  bool gnss_datum = false;       // the datum is estimated (the fixes give its yaw)
  double chi2 = 0.0;             // after the final solve
  double final_cost = 0.0;
  std::vector<std::string> errors;  // the first few, verbatim
};

// A sighting the graph was given, and what became of it (OUT/detections.csv).
struct DetectionRecord {
  TeamDetection detection;
  std::string status;  // "factor", "refused: ...", "waiting: ...", "unplaced: ...", "graph refused: ..."
};

// One of the robot's submap origins as the graph places it now.
struct OriginEstimate {
  char robot = 0;  // graph letter
  uint64_t frame_id = 0;
  FourDofTransform T_global_origin;  // roll and pitch dropped (origins are gravity aligned)
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();  // (x, y, z, yaw), global axes
  bool has_covariance = false;
  bool connected = true;  // to the robot's prior
};

class GraphStage {
 public:
  GraphStage(const GraphStageOptions& options, bool deterministic);

  // A submap match c (thesis 6.1) between two of the robot's origins: T_a_b with the matcher's
  // (x, y, z, yaw) covariance in A's axes; roll and pitch get `tilt_sigma`. The factor takes the
  // Cauchy loss; the graph re-optimizes. An error says why the graph refused it.
  Status AddMatch(uint64_t frame_a, uint64_t frame_b, const FourDofTransform& T_a_b,
                  const Eigen::Matrix4d& covariance, double tilt_sigma);
  // The same between origins of any robots of the team, by graph letter. A match between two
  // robots goes to the team screen first (`*held` set): it enters once the screen accepts it, or
  // is counted and named in the errors when the screen rejects it.
  Status AddMatch(char robot_a, uint64_t frame_a, char robot_b, uint64_t frame_b,
                  const FourDofTransform& T_a_b, const Eigen::Matrix4d& covariance, double tilt_sigma,
                  bool* held = nullptr);
  // A teammate's item: its frame switches w and poses v join the graph under its letter (a
  // floating subgraph until a match or detection ties it to this robot's), its estimates make its
  // global trajectory, and matches it made are added (once both origins are known).
  void OnTeamInput(const TeamInput& input);
  // A robot detection d or landmark observation o (this robot's or a teammate's; `usable` false
  // records it with `refused` only). Both ends become graph poses x at the detection's time, each
  // placed by a factor v from its robot's filter estimates around that time (interpolated) with
  // the covariance of its nearest graph pose; it waits until both robots' estimates cover the
  // time. Landmark `observed` names are those of SetLandmarks().
  void AddDetection(const TeamDetection& detection, bool usable, const std::string& refused);
  // A GNSS fix of this robot's antenna: once the filter's estimates cover its time it becomes a graph
  // pose x there (as for a detection) and, after the datum has started, a factor from the datum
  // (gnss_fix_factors.h). Refused fixes are counted with the first reasons in the report's errors.
  // Returns whether it was taken (teammates get those).
  bool AddGnssFix(const GnssFix& fix);
  // A teammate's fix (or this robot's, by its letter and run): the same, once that robot's
  // estimates cover its time and its subgraph is tied to this robot's; until then it waits.
  bool AddGnssFix(const TeamGnssFix& fix);
  const Eigen::Vector3d& gnss_antenna() const { return gnss_.antenna(); }
  // T_world_enu of the GNSS datum; false before fixes have started it.
  bool Datum(Eigen::Isometry3d* T_world_enu) const;
  // Plane landmark observations o (this robot's or a teammate's, by graph letters and frame
  // indices). NotFound while the observing submap is not in the graph or not tied to this robot's
  // (a teammate's: it waits and is retried); AlreadyExists for one the graph holds; other errors
  // for what the graph refused.
  // One status per observation; the graph updates once after them all.
  std::vector<Status> AddPlaneObservations(const std::vector<TeamPlaneObservation>& observations);
  // The squared Mahalanobis residual of an observation the graph holds, at the current estimate.
  Expected<double> PlaneObservationChi2(const TeamPlaneObservation& observation) const;
  // Line landmark observations o, as AddPlaneObservations.
  std::vector<Status> AddLineObservations(const std::vector<TeamLineObservation>& observations);
  Expected<double> LineObservationChi2(const TeamLineObservation& observation) const;
  // The origins (graph letter, frame index) with their marginal covariances; false, with the
  // reason, when one is not in the graph, not tied to this robot's, or the covariances fail.
  bool PlaceOrigins(const std::vector<std::pair<char, uint64_t>>& origins, std::vector<SubmapPlacement>* out,
                    std::string* why);
  // Landmark carriers by name: the index of each is its variable's.
  void SetLandmarks(const std::vector<std::string>& names) { landmarks_ = names; }
  const std::vector<DetectionRecord>& detections() const { return detection_records_; }
  // Every robot with variables in the graph, this one first.
  std::vector<char> Robots() const;
  // Whether the origins of `robot`'s latest run (or of run `run`, see RunIndex) are tied to this
  // robot's prior (always for this robot's current run).
  bool Connected(char robot) const;
  bool Connected(char robot, uint32_t run) const;
  // The runs of `robot` this graph has estimates of, oldest first (this robot's current run last).
  std::vector<uint32_t> Runs(char robot) const;
  // T_global_frame of every origin of `robot` the graph holds.
  std::map<uint64_t, Eigen::Isometry3d> FrameOrigins(char robot) const;
  // `robot`'s estimates placed by its origins; empty when it is not connected (never guessed).
  Trajectory GlobalTrajectory(char robot) const;  // its latest run
  Trajectory GlobalTrajectory(char robot, uint32_t run) const;
  // The latest estimate of `robot`'s latest run, in the global frame; false when the graph has none
  // or cannot place it (its origins are not tied to this robot's).
  bool LatestGlobalPose(char robot, StampedPose* out) const;
  // Landmark `index` (of SetLandmarks) in the global frame; false when not observed yet or not tied
  // to this robot's origins.
  bool LandmarkGlobalPose(size_t index, Eigen::Isometry3d* T_global_landmark) const;
  // The origins of every robot in the graph with, when `covariances`, their marginal covariances
  // (a covariance solve).
  std::vector<OriginEstimate> OriginEstimates(bool covariances);

  // Full solves after loop closures go through `runner` (live); without one they run inline.
  void SetBackgroundRunner(SlamGraph::BackgroundRunner runner) { graph_.SetBackgroundRunner(std::move(runner)); }
  void OnInput(const GraphInput& input);
  // End of the run: waits for a running full solve, then optimizes to convergence.
  void Finish();

  GraphStageReport report() const;
  char robot() const { return robot_; }
  // Time of the last estimate placed, and the number of submap origins (cheap, for live updates).
  Timestamp last_time() const {
    return trajectories_.Own().empty() ? Timestamp() : trajectories_.Own().back().time;
  }
  uint64_t submap_origins() const { return report_.submap_origins; }
  // Factors that tie `robot` (graph letter) to the others: matches and sightings between it and
  // a teammate, its observations of the lander.
  uint64_t OutsideTies(char robot) const {
    const auto it = outside_ties_.find(robot);
    return it == outside_ties_.end() ? 0 : it->second;
  }
  uint64_t factors_added() const { return report_.factors; }
  // Whether the last estimate taken became graph pose `*index` (a factor v).
  bool last_estimate_is_pose(uint64_t* index) const {
    *index = last_pose_index_;
    return last_estimate_is_pose_;
  }
  const LatencyHistogram& update_time() const { return update_time_; }
  // T_global_frame of every local frame in the graph (global = the first frame).
  std::map<uint64_t, Eigen::Isometry3d> FrameOrigins() const;
  // Every valid estimate received, placed by its frame's optimized origin (eq. 4.6).
  Trajectory GlobalTrajectory() const;
  // The graph's variables (optimized) and binary factors, for g2o export. Keys carry the robot
  // letter in the top byte and the kind ('s' origin, 'x' pose) in the next.
  PoseGraph ExportPoseGraph() const;
  // The graph now, with the origins' marginal covariances as last computed; `covariances`
  // computes them again (a Ceres covariance solve over the graph: the live view asks at each new
  // origin, not at every pose).
  GraphScene Scene(bool covariances);

 private:
  void OnEstimate(const FrameEstimate& e);
  void OnFrameSwitch(const FrameSwitchEvent& e);
  bool Add(const SlamFactor& f);
  void Update();
  Expected<double> StructureObservationChi2(const Expected<SlamFactor>& f) const;
  Status AddPlaneObservationNoUpdate(const TeamPlaneObservation& o);
  Status AddLineObservationNoUpdate(const TeamLineObservation& o);
  // Adds each observation with `add_one`, then updates the graph once if any was taken.
  template <class Observation, class AddOne>
  std::vector<Status> AddObservationBatch(const std::vector<Observation>& observations, AddOne add_one);
  // The checks and bookkeeping both landmark kinds share; `*created` when the factor starts its
  // landmark.
  Status AddStructureFactor(const SlamFactor& f, char observer, uint64_t frame, bool* created);
  void Error(const std::string& what);
  Matrix6d Floored(const Matrix6d& covariance) const;
  uint64_t OriginKey(uint64_t frame_id) const;

  GraphStageOptions options_;
  SlamGraph graph_;
  char robot_ = 'a';
  bool started_ = false;
  uint64_t next_pose_ = 0;
  bool last_estimate_is_pose_ = false;
  uint64_t last_pose_index_ = 0;
  RobotTrajectories trajectories_;
  using RunKey = std::pair<char, uint32_t>;  // a robot's letter and run (see RunIndex)
  struct PendingMatch {
    char robot_a, robot_b;
    uint64_t frame_a, frame_b;
    FourDofTransform T_a_b;
    Eigen::Matrix4d covariance;
    double tilt_sigma;
  };
  std::vector<PendingMatch> pending_matches_;
  TeamMatchScreen screen_;
  void RetryPendingMatches();
  // Adds the matches the team screen accepted, counts and names those it rejected.
  void TakeScreenedMatches(bool final);
  // Adds a match factor the screen let through (or one of the robot's own).
  Status AddMatchFactor(const SlamFactor& f);
  std::vector<TeamPlaneObservation> pending_planes_;
  std::set<std::pair<uint64_t, uint64_t>> structure_factors_;  // (origin, landmark) held
  void RetryPendingPlanes();
  std::vector<TeamLineObservation> pending_lines_;
  void RetryPendingLines();
  // Detections.
  // Adds the pose variable of `robot` at `time` (once) with its factor v; returns its key.
  uint64_t DetectionPose(char robot, uint32_t run, Timestamp time, const PlacedEstimate& pose,
                         const Matrix6d& covariance);
  void RetryPendingDetections();
  void RetryPendingFixes();
  GnssFixFactors gnss_;
  std::vector<TeamGnssFix> pending_fixes_;
  // Whether a sighting of a robot agrees with both robots' gravity (their estimates' roll and
  // pitch); if only IPPE's other minimum does, `T_observer_observed` becomes it and `chosen` says so.
  bool AgreesWithGravity(const TeamDetection& d, const PlacedEstimate& observer,
                         const PlacedEstimate& observed, Eigen::Isometry3d* T_observer_observed,
                         std::string* chosen, std::string* refused);
  std::vector<std::string> landmarks_;
  std::vector<DetectionRecord> detection_records_;
  std::vector<size_t> pending_detections_;  // indices into detection_records_
  Matrix6d SwitchInformation(const Matrix6d& covariance, const Eigen::Isometry3d& T_old_new) const;
  std::map<uint64_t, Eigen::Matrix3d> origin_covariance_;  // of the live view, as last computed
  LatencyHistogram update_time_;
  GraphStageReport report_;
  std::map<char, uint64_t> outside_ties_;
};

}  // namespace cairn
