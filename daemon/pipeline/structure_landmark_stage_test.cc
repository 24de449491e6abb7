#include "daemon/pipeline/structure_landmark_stage.h"

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include "daemon/pipeline/testing/loop_mission.h"
#include "mapping/testing/submap_edges.h"
#include "mapping/testing/submap_faces.h"

namespace cairn {
namespace {

using testing::LoopMission;
using testing::MakeLoop;
using testing::OriginError;

// A loop around a yard with walls: five tall faces around the circle (and a level ground that is
// no landmark), each origin seeing the faces within reach, measured in its own frame.
struct Wall {
  Eigen::Vector3d normal, centre;
};
const std::vector<Wall> kWalls = {{Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5.5, 0, 1)},
                                  {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 5.5, 1)},
                                  {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-5.5, 0, 1)},
                                  {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -5.5, 1)},
                                  {Eigen::Vector3d(-0.7071, -0.7071, 0), Eigen::Vector3d(4.2, 4.2, 1)}};

SubmapPlane Seen(const Eigen::Isometry3d& T_w_s, const Wall& w, double sigma) {
  return testing::FaceSeenFrom(T_w_s, w.normal, w.centre, Eigen::Vector2d(3.0, 1.0), sigma, 2000);
}

std::shared_ptr<const Submap> WithFaces(const Submap& s, const Eigen::Isometry3d& T_w_s, double reach) {
  SubmapStructure structure;
  SubmapPlane ground = Seen(
      T_w_s,
      Wall{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(T_w_s.translation().x(), T_w_s.translation().y(), 0)},
      0.005);
  structure.planes.push_back(ground);
  for (const Wall& w : kWalls) {
    if ((w.centre - T_w_s.translation()).head<2>().norm() < reach)
      structure.planes.push_back(Seen(T_w_s, w, 0.005));
  }
  return std::make_shared<const Submap>(
      s.metadata(), s.points(), std::unique_ptr<octomap::OcTree>(new octomap::OcTree(s.tree())), structure);
}

GraphStageOptions LoopGraphOptions() {
  GraphStageOptions go;
  go.enabled = true;
  go.pose_every = 1;
  return go;
}

// The loop through `graph` with `stage` given each finished origin's submap as `with_structure`
// makes it, and through `odometry_only` without landmarks.
template <class Stage, class WithStructure>
void RunLoop(const LoopMission& m, Stage& stage, GraphStage& graph, GraphStage& odometry_only,
             WithStructure with_structure) {
  for (const GraphInput& in : m.inputs) {
    graph.OnInput(in);
    odometry_only.OnInput(in);
    if (in.kind == GraphInput::Kind::kFrameSwitch) {
      const uint64_t done = in.frame_switch.old_frame_id;
      stage.OnSubmap(graph.robot(), done, *with_structure(*m.submaps[done], m.T_world_origin[done], 6.5));
      stage.Step(graph);
    }
  }
  stage.OnSubmap(graph.robot(), m.submaps.size() - 1,
                 *with_structure(*m.submaps.back(), m.T_world_origin.back(), 6.5));
  stage.Step(graph);
  graph.Finish();
  odometry_only.Finish();
}

// planes.csv or lines.csv: a row per observation, each residual well inside the gate.
void ExpectResidualsInside(const std::string& csv_text, double gate, uint64_t observations) {
  std::istringstream csv(csv_text);
  std::string line;
  std::getline(csv, line);
  uint64_t rows = 0;
  while (std::getline(csv, line)) {
    const double chi2 = std::stod(line.substr(line.rfind(',') + 1));
    EXPECT_LT(chi2, gate) << line;
    ++rows;
  }
  EXPECT_EQ(rows, observations);
}

TEST(PlaneLandmarkStageTest, SharedWallsPullTheLoopTogether) {
  const LoopMission m = MakeLoop(6);
  GraphStage graph(LoopGraphOptions(), /*deterministic=*/true);
  GraphStage odometry_only(LoopGraphOptions(), /*deterministic=*/true);
  PlaneLandmarkStage stage(PlaneLandmarkOptions{}, graph.robot(), "rover");
  RunLoop(m, stage, graph, odometry_only, WithFaces);

  const StructureLandmarkReport r = stage.report();
  const GraphStageReport g = graph.report();
  const double with = OriginError(graph, m), without = OriginError(odometry_only, m);
  std::printf(
      "[ planes] %llu faces, %llu pairs, %llu associations, %llu observations, %llu landmarks; origin RMSE "
      "%.3f m with planes, %.3f m without\n",
      static_cast<unsigned long long>(r.features), static_cast<unsigned long long>(r.pairs),
      static_cast<unsigned long long>(r.associations), static_cast<unsigned long long>(r.observations),
      static_cast<unsigned long long>(g.plane_landmarks), with, without);
  EXPECT_EQ(r.refused, 0u);
  EXPECT_EQ(r.waiting, 0u);
  EXPECT_GE(g.plane_landmarks, 4u);
  EXPECT_LE(g.plane_landmarks, kWalls.size());  // never two landmarks of one wall here
  EXPECT_EQ(g.plane_observations, r.observations);
  EXPECT_LT(with, 0.5 * without);

  ExpectResidualsInside(stage.Csv(graph), 11.34, r.observations);
}

// The same yard's walls as straight edges: each wall's top and foot (6 m long, 2 m apart), seen
// by the origins within reach.
std::shared_ptr<const Submap> WithEdges(const Submap& s, const Eigen::Isometry3d& T_w_s, double reach) {
  SubmapStructure structure;
  for (const Wall& w : kWalls) {
    if ((w.centre - T_w_s.translation()).head<2>().norm() >= reach) continue;
    const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(w.normal).normalized();
    for (double z : {0.0, 2.0}) {
      const Eigen::Vector3d mid(w.centre.x(), w.centre.y(), z);
      structure.lines.push_back(testing::EdgeSeenFrom(T_w_s, mid - 3.0 * along, mid + 3.0 * along));
    }
  }
  return std::make_shared<const Submap>(
      s.metadata(), s.points(), std::unique_ptr<octomap::OcTree>(new octomap::OcTree(s.tree())), structure);
}

TEST(LineLandmarkStageTest, SharedEdgesPullTheLoopTogether) {
  const LoopMission m = MakeLoop(6);
  GraphStage graph(LoopGraphOptions(), /*deterministic=*/true);
  GraphStage odometry_only(LoopGraphOptions(), /*deterministic=*/true);
  LineLandmarkStage stage(LineLandmarkOptions{}, graph.robot(), "rover");
  RunLoop(m, stage, graph, odometry_only, WithEdges);

  const StructureLandmarkReport r = stage.report();
  const GraphStageReport g = graph.report();
  const double with = OriginError(graph, m), without = OriginError(odometry_only, m);
  std::printf(
      "[  lines] %llu edges, %llu pairs, %llu associations, %llu observations, %llu landmarks; origin RMSE "
      "%.3f m with lines, %.3f m without\n",
      static_cast<unsigned long long>(r.features), static_cast<unsigned long long>(r.pairs),
      static_cast<unsigned long long>(r.associations), static_cast<unsigned long long>(r.observations),
      static_cast<unsigned long long>(g.line_landmarks), with, without);
  EXPECT_EQ(r.refused, 0u);
  EXPECT_EQ(r.waiting, 0u);
  EXPECT_GE(g.line_landmarks, 8u);
  EXPECT_LE(g.line_landmarks, 2 * kWalls.size());  // never two landmarks of one edge here
  EXPECT_EQ(g.line_observations, r.observations);
  EXPECT_LT(with, 0.5 * without);

  const std::string csv = stage.Csv(graph);
  EXPECT_EQ(csv.rfind("observer,run,frame,line,", 0), 0u) << csv.substr(0, 80);
  ExpectResidualsInside(csv, 13.28, r.observations);
}

TEST(PlaneLandmarkStageTest, TeammatesDecideTheirPairsAndTheirFacesKeepTheirLandmarks) {
  // Robot 'b' sees that robot 'a' decides pairs with it, and takes a's landmark for its face.
  PlaneLandmarkStage stage(PlaneLandmarkOptions{}, 'b', "hexa");
  TeamPlaneObservation o;
  o.observer = "hexa";
  o.observer_letter = 'b';
  o.frame = 3;
  o.observer_plane = 1;
  o.creator = "rover";
  o.creator_letter = 'a';
  o.creator_frame = 7;
  o.plane = 2;
  stage.OnTeamObservations({o, o});
  EXPECT_EQ(stage.report().team_observations, 1u);
  GraphStageOptions go;
  go.enabled = true;
  GraphStage graph(go, true);
  const std::string csv = stage.Csv(graph);
  EXPECT_NE(csv.find("hexa,0,3,1,rover,0,7,2,"), std::string::npos) << csv;
}

}  // namespace
}  // namespace cairn
