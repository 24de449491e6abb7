#pragma once
// Plane landmarks of the team (paper 003's planar faces as landmarks l, thesis 4.2's factors o):
// every finished submap, this robot's or a teammate's, is compared with the submaps held before
// it, once its origin is tied to this robot's in the graph. Faces that PlaneAssociator finds to
// be the same plane become one landmark, observed by each submap that sees it. Lives on the graph
// thread; cheap (a few faces per submap), so it runs inline.
//
// One robot decides each pair of submaps (the smaller graph letter of the two: every robot agrees
// without talking), and sends its decisions to the team, so that every robot's graph holds the
// same factors. A landmark is named by its first face (the smaller of the first pair's two), so
// two robots that start the same landmark at once give it the same name. A face already tied to
// a landmark passes it on to the faces paired with it; landmarks are never merged.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "daemon/pipeline/graph_stage.h"
#include "daemon/pipeline/plane_landmark_options.h"
#include "daemon/pipeline/team_input.h"
#include "daemon/pipeline/team_link.h"
#include "mapping/matching/plane_associator.h"
#include "mapping/submap.h"

namespace cairn {

struct PlaneLandmarkReport {
  uint64_t submaps = 0;             // given (own and teammates')
  uint64_t faces = 0;               // of them, faces that can be landmarks
  uint64_t pairs = 0;               // pairs of submaps compared here
  uint64_t associations = 0;        // pairs of faces found the same plane
  uint64_t observations = 0;        // observations decided here (sent to the team)
  uint64_t team_observations = 0;   // decided by teammates
  uint64_t refused = 0;             // the graph refused
  uint64_t waiting = 0;             // submaps whose origins are not tied yet
  std::vector<std::string> errors;  // the first few, verbatim
};

class PlaneLandmarkStage {
 public:
  PlaneLandmarkStage(const PlaneLandmarkOptions& options, char letter, std::string robot);

  // Team mode: robots' names by graph letter, and where the decisions go.
  void SetTeam(std::map<char, std::string> names, TeamLink* team);
  // A finished submap of robot `letter` at graph frame index `frame`.
  void OnSubmap(char letter, uint64_t frame, const Submap& submap);
  // Teammates' decisions (the graph takes their factors itself): their faces' landmarks.
  void OnTeamObservations(const std::vector<TeamPlaneObservation>& observations);
  // Compares the submaps whose origins the graph now places.
  void Step(GraphStage& graph);

  // OUT/planes.csv: every observation decided here or by teammates, with its residual now.
  std::string Csv(const GraphStage& graph) const;
  PlaneLandmarkReport report() const;

 private:
  using Face = std::tuple<char, uint64_t, uint32_t>;  // letter, frame index, plane
  struct Held {
    char letter = 0;
    uint64_t frame = 0;
    std::vector<SubmapPlane> planes;
  };
  void Compare(GraphStage& graph, const Held& w, const Held& h, const SubmapPlacement& pw,
               const SubmapPlacement& ph, std::vector<TeamPlaneObservation>* out);
  TeamPlaneObservation Observation(const Held& observer, uint32_t plane, const Face& landmark) const;
  std::string Name(char letter) const;
  void Error(const std::string& what);

  PlaneLandmarkOptions options_;
  PlaneAssociator associator_;
  char letter_;
  std::string robot_;
  std::map<char, std::string> names_;
  TeamLink* team_ = nullptr;
  std::vector<Held> held_;    // compared already, in the order they were placed
  std::deque<Held> waiting_;  // origins not tied yet
  bool arrived_ = false;      // a submap since the last step
  uint64_t factors_at_last_step_ = 0;
  std::map<Face, Face> landmark_of_;  // face -> the face that names its landmark
  std::vector<TeamPlaneObservation> records_;
  std::set<std::pair<Face, Face>> recorded_;  // (observer face, landmark)
  PlaneLandmarkReport report_;
};

}  // namespace cairn
