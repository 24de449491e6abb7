#pragma once
// Plane and line landmarks of the team (paper 003's planar faces, paper 000's straight edges, as
// landmarks l with thesis 4.2's factors o): every finished submap, this robot's or a teammate's, is
// compared with the submaps held before it, once its origin is tied to this robot's in the graph.
// Faces (edges) that the associator finds to be the same plane (line) become one landmark,
// observed by each submap that sees it. Lives on the graph thread; cheap (a few faces and some
// tens of edges per submap), so it runs inline. One stage per kind: `Kind` is PlaneLandmarks or
// LineLandmarks.
//
// One robot decides each pair of submaps (the smaller graph letter of the two: every robot agrees
// without talking), and sends its decisions to the team, so that every robot's graph holds the
// same factors. A landmark is named by its first feature (the smaller of the first pair's two), so
// two robots that start the same landmark at once give it the same name. A feature already tied to
// a landmark passes it on to the features paired with it; landmarks are never merged.

#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "daemon/pipeline/graph_stage.h"
#include "daemon/pipeline/structure_landmark_options.h"
#include "daemon/pipeline/team_input.h"
#include "daemon/pipeline/team_link.h"
#include "mapping/matching/line_associator.h"
#include "mapping/matching/plane_associator.h"
#include "mapping/submap.h"

namespace cairn {

struct StructureLandmarkReport {
  uint64_t submaps = 0;             // given (own and teammates')
  uint64_t features = 0;            // of them, faces or edges that can be landmarks
  uint64_t pairs = 0;               // pairs of submaps compared here
  uint64_t associations = 0;        // pairs of features found the same landmark
  uint64_t observations = 0;        // observations decided here (sent to the team)
  uint64_t team_observations = 0;   // decided by teammates
  uint64_t refused = 0;             // the graph refused
  uint64_t waiting = 0;             // submaps whose origins are not tied yet
  std::vector<std::string> errors;  // the first few, verbatim
};

// What differs between the kinds; defined in structure_landmark_stage.cc.
struct PlaneLandmarks {
  using Feature = SubmapPlane;
  using Associator = PlaneAssociator;
  using Association = PlaneAssociation;
  using Observation = TeamPlaneObservation;
  using Options = PlaneLandmarkOptions;
  static constexpr const char* kName = "plane";
  static constexpr size_t kMaxFeatures = 256;  // the wire and the graph keys name 8 bits
  static const std::vector<SubmapPlane>& Features(const Submap& submap);
  static void Measure(const PlaneAssociator& associator, const SubmapPlane& p, TeamPlaneObservation* o);
  static void SetIndices(uint32_t observer_index, uint32_t landmark_index, TeamPlaneObservation* o);
  static uint32_t ObserverIndex(const TeamPlaneObservation& o) { return o.observer_plane; }
  static uint32_t LandmarkIndex(const TeamPlaneObservation& o) { return o.plane; }
  static std::vector<Status> Add(GraphStage& graph, const std::vector<TeamPlaneObservation>& observations);
  static Expected<double> Chi2(const GraphStage& graph, const TeamPlaneObservation& o);
  static void Publish(TeamLink& team, const std::vector<TeamPlaneObservation>& observations);
  static const char* CsvHeader();
  static std::string CsvValues(const TeamPlaneObservation& o);  // the measurement's columns
};

struct LineLandmarks {
  using Feature = SubmapLine;
  using Associator = LineAssociator;
  using Association = LineAssociation;
  using Observation = TeamLineObservation;
  using Options = LineLandmarkOptions;
  static constexpr const char* kName = "line";
  static constexpr size_t kMaxFeatures = 1024;  // 10 bits
  static const std::vector<SubmapLine>& Features(const Submap& submap);
  static void Measure(const LineAssociator& associator, const SubmapLine& l, TeamLineObservation* o);
  static void SetIndices(uint32_t observer_index, uint32_t landmark_index, TeamLineObservation* o);
  static uint32_t ObserverIndex(const TeamLineObservation& o) { return o.observer_line; }
  static uint32_t LandmarkIndex(const TeamLineObservation& o) { return o.line; }
  static std::vector<Status> Add(GraphStage& graph, const std::vector<TeamLineObservation>& observations);
  static Expected<double> Chi2(const GraphStage& graph, const TeamLineObservation& o);
  static void Publish(TeamLink& team, const std::vector<TeamLineObservation>& observations);
  static const char* CsvHeader();
  static std::string CsvValues(const TeamLineObservation& o);
};

template <class Kind>
class StructureLandmarkStage {
 public:
  using Feature = typename Kind::Feature;
  using Observation = typename Kind::Observation;

  StructureLandmarkStage(const typename Kind::Options& options, char letter, std::string robot);

  // Team mode: robots' names by graph letter, and where the decisions go.
  void SetTeam(std::map<char, std::string> names, TeamLink* team);
  // A finished submap of robot `letter` at graph frame index `frame`.
  void OnSubmap(char letter, uint64_t frame, const Submap& submap);
  // Teammates' decisions (the graph takes their factors itself): their features' landmarks.
  void OnTeamObservations(const std::vector<Observation>& observations);
  // Compares the submaps whose origins the graph now places.
  void Step(GraphStage& graph);

  // OUT/planes.csv or OUT/lines.csv: every observation decided here or by teammates, with its
  // residual now.
  std::string Csv(const GraphStage& graph) const;
  StructureLandmarkReport report() const { return report_; }

 private:
  using Face = std::tuple<char, uint64_t, uint32_t>;  // letter, frame index, feature
  struct Held {
    char letter = 0;
    uint64_t frame = 0;
    std::vector<Feature> features;
  };
  void Compare(GraphStage& graph, const Held& w, const Held& h, const SubmapPlacement& pw,
               const SubmapPlacement& ph, std::vector<Observation>* out);
  Observation MakeObservation(const Held& observer, uint32_t index, const Face& landmark) const;
  std::string Name(char letter) const;
  void Error(const std::string& what);

  typename Kind::Options options_;
  typename Kind::Associator associator_;
  char letter_;
  std::string robot_;
  std::map<char, std::string> names_;
  TeamLink* team_ = nullptr;
  std::vector<Held> held_;    // compared already, in the order they were placed
  std::deque<Held> waiting_;  // origins not tied yet
  bool arrived_ = false;      // a submap since the last step
  uint64_t factors_at_last_step_ = 0;
  std::map<Face, Face> landmark_of_;  // feature -> the feature that names its landmark
  std::vector<Observation> records_;
  std::set<std::pair<Face, Face>> recorded_;  // (observer feature, landmark)
  StructureLandmarkReport report_;
};

extern template class StructureLandmarkStage<PlaneLandmarks>;
extern template class StructureLandmarkStage<LineLandmarks>;
using PlaneLandmarkStage = StructureLandmarkStage<PlaneLandmarks>;
using LineLandmarkStage = StructureLandmarkStage<LineLandmarks>;

}  // namespace cairn
