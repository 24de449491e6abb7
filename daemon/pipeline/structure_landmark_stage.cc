#include "daemon/pipeline/structure_landmark_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/bounded_errors.h"

namespace cairn {

const std::vector<SubmapPlane>& PlaneLandmarks::Features(const Submap& submap) {
  return submap.structure().planes;
}

void PlaneLandmarks::Measure(const PlaneAssociator& associator, const SubmapPlane& p,
                             TeamPlaneObservation* o) {
  o->normal = p.normal.cast<double>().normalized();
  o->offset = static_cast<double>(p.offset);
  o->centroid = p.centroid.cast<double>();
  o->covariance = associator.Covariance(p);
}

void PlaneLandmarks::SetIndices(uint32_t observer_index, uint32_t landmark_index, TeamPlaneObservation* o) {
  o->observer_plane = observer_index;
  o->plane = landmark_index;
}

std::vector<Status> PlaneLandmarks::Add(GraphStage& graph,
                                        const std::vector<TeamPlaneObservation>& observations) {
  return graph.AddPlaneObservations(observations);
}

Expected<double> PlaneLandmarks::Chi2(const GraphStage& graph, const TeamPlaneObservation& o) {
  return graph.PlaneObservationChi2(o);
}

void PlaneLandmarks::Publish(TeamLink& team, const std::vector<TeamPlaneObservation>& observations) {
  team.PublishPlaneObservations(observations);
}

const char* PlaneLandmarks::CsvHeader() {
  return "observer,run,frame,plane,landmark_robot,landmark_run,landmark_frame,landmark_plane,nx,ny,nz,offset,"
         "cx,"
         "cy,cz,sigma_a,sigma_b,sigma_d,chi2\n";
}

std::string PlaneLandmarks::CsvValues(const TeamPlaneObservation& o) {
  char numbers[256];
  std::snprintf(numbers, sizeof numbers, "%.6f,%.6f,%.6f,%.4f,%.3f,%.3f,%.3f,%.5f,%.5f,%.4f", o.normal.x(),
                o.normal.y(), o.normal.z(), o.offset, o.centroid.x(), o.centroid.y(), o.centroid.z(),
                std::sqrt(o.covariance(0, 0)), std::sqrt(o.covariance(1, 1)), std::sqrt(o.covariance(2, 2)));
  return numbers;
}

const std::vector<SubmapLine>& LineLandmarks::Features(const Submap& submap) {
  return submap.structure().lines;
}

void LineLandmarks::Measure(const LineAssociator& associator, const SubmapLine& l, TeamLineObservation* o) {
  o->point = LineAssociator::Middle(l);
  o->direction = l.direction.cast<double>().normalized();
  o->covariance = associator.Covariance(l);
}

void LineLandmarks::SetIndices(uint32_t observer_index, uint32_t landmark_index, TeamLineObservation* o) {
  o->observer_line = observer_index;
  o->line = landmark_index;
}

std::vector<Status> LineLandmarks::Add(GraphStage& graph,
                                       const std::vector<TeamLineObservation>& observations) {
  return graph.AddLineObservations(observations);
}

Expected<double> LineLandmarks::Chi2(const GraphStage& graph, const TeamLineObservation& o) {
  return graph.LineObservationChi2(o);
}

void LineLandmarks::Publish(TeamLink& team, const std::vector<TeamLineObservation>& observations) {
  team.PublishLineObservations(observations);
}

const char* LineLandmarks::CsvHeader() {
  return "observer,run,frame,line,landmark_robot,landmark_run,landmark_frame,landmark_line,px,py,pz,dx,dy,dz,"
         "sigma_du,sigma_dw,sigma_u,sigma_w,chi2\n";
}

std::string LineLandmarks::CsvValues(const TeamLineObservation& o) {
  char numbers[256];
  std::snprintf(numbers, sizeof numbers, "%.3f,%.3f,%.3f,%.6f,%.6f,%.6f,%.5f,%.5f,%.4f,%.4f", o.point.x(),
                o.point.y(), o.point.z(), o.direction.x(), o.direction.y(), o.direction.z(),
                std::sqrt(o.covariance(0, 0)), std::sqrt(o.covariance(1, 1)), std::sqrt(o.covariance(2, 2)),
                std::sqrt(o.covariance(3, 3)));
  return numbers;
}

template <class Kind>
StructureLandmarkStage<Kind>::StructureLandmarkStage(const typename Kind::Options& options, char letter,
                                                     std::string robot)
    : options_(options), associator_(options.association), letter_(letter), robot_(std::move(robot)) {}

template <class Kind>
void StructureLandmarkStage<Kind>::SetTeam(std::map<char, std::string> names, TeamLink* team) {
  names_ = std::move(names);
  team_ = team;
}

template <class Kind>
std::string StructureLandmarkStage<Kind>::Name(char letter) const {
  if (letter == letter_) return robot_;
  const auto it = names_.find(letter);
  return it == names_.end() ? std::string(1, letter) : it->second;
}

template <class Kind>
void StructureLandmarkStage<Kind>::Error(const std::string& what) {
  AppendBoundedError(report_.errors, what);
}

template <class Kind>
void StructureLandmarkStage<Kind>::OnSubmap(char letter, uint64_t frame, const Submap& submap) {
  ++report_.submaps;
  Held h;
  h.letter = letter;
  h.frame = frame;
  // Only the features that can be landmarks, under their own indices (past kMaxFeatures they cannot
  // be named; the extractors keep the largest first).
  const std::vector<Feature>& all = Kind::Features(submap);
  h.features.assign(all.begin(), all.begin() + static_cast<long>(std::min(all.size(), Kind::kMaxFeatures)));
  const auto eligible = std::count_if(h.features.begin(), h.features.end(),
                                      [&](const Feature& f) { return associator_.Eligible(f); });
  report_.features += static_cast<uint64_t>(eligible);
  if (eligible == 0) h.features.clear();  // nothing to compare, ever
  waiting_.push_back(std::move(h));
  arrived_ = true;
  report_.waiting = waiting_.size();
}

template <class Kind>
void StructureLandmarkStage<Kind>::OnTeamObservations(const std::vector<Observation>& observations) {
  for (const Observation& o : observations) {
    if (o.observer_letter == 0 || o.creator_letter == 0) continue;
    const Face face{o.observer_letter, o.frame, Kind::ObserverIndex(o)};
    const Face landmark{o.creator_letter, o.creator_frame, Kind::LandmarkIndex(o)};
    landmark_of_.emplace(face, landmark);  // a feature keeps the landmark it had
    landmark_of_.emplace(landmark, landmark);
    if (recorded_.insert({face, landmark}).second) {
      records_.push_back(o);
      ++report_.team_observations;
    }
  }
}

template <class Kind>
typename Kind::Observation StructureLandmarkStage<Kind>::MakeObservation(const Held& observer, uint32_t index,
                                                                         const Face& landmark) const {
  Observation o;
  o.observer = Name(observer.letter);
  o.observer_letter = observer.letter;
  o.frame = observer.frame;
  o.creator = Name(std::get<0>(landmark));
  o.creator_letter = std::get<0>(landmark);
  o.creator_frame = std::get<1>(landmark);
  Kind::SetIndices(index, std::get<2>(landmark), &o);
  Kind::Measure(associator_, observer.features[index], &o);
  return o;
}

template <class Kind>
void StructureLandmarkStage<Kind>::Compare(GraphStage& graph, const Held& w, const Held& h,
                                           const SubmapPlacement& pw, const SubmapPlacement& ph,
                                           std::vector<Observation>* out) {
  ++report_.pairs;
  struct Decided {
    const Held* held;
    uint32_t index;
    Face landmark;
  };
  std::vector<Decided> decided;
  for (const auto& a : associator_.Associate(w.features, pw, h.features, ph)) {
    const Face fw{w.letter, w.frame, static_cast<uint32_t>(a.a)};
    const Face fh{h.letter, h.frame, static_cast<uint32_t>(a.b)};
    const auto lw = landmark_of_.find(fw), lh = landmark_of_.find(fh);
    const size_t before = decided.size();
    if (lw == landmark_of_.end() && lh == landmark_of_.end()) {
      // A new landmark, its naming feature's observation first.
      const Face name = std::min(fw, fh);
      landmark_of_[fw] = landmark_of_[fh] = name;
      const bool h_names = name == fh;
      decided.push_back({h_names ? &h : &w, static_cast<uint32_t>(h_names ? a.b : a.a), name});
      decided.push_back({h_names ? &w : &h, static_cast<uint32_t>(h_names ? a.a : a.b), name});
    } else if (lw == landmark_of_.end()) {
      landmark_of_[fw] = lh->second;
      decided.push_back({&w, static_cast<uint32_t>(a.a), lh->second});
    } else if (lh == landmark_of_.end()) {
      landmark_of_[fh] = lw->second;
      decided.push_back({&h, static_cast<uint32_t>(a.b), lw->second});
    }
    // Otherwise both are landmarks already (the same, or two never merged).
    if (decided.size() > before) ++report_.associations;
  }
  std::vector<Observation> batch;
  batch.reserve(decided.size());
  for (const Decided& d : decided) batch.push_back(MakeObservation(*d.held, d.index, d.landmark));
  const std::vector<Status> statuses = Kind::Add(graph, batch);
  for (size_t k = 0; k < decided.size(); ++k) {
    const Decided& d = decided[k];
    const Status& s = statuses[k];
    if (!s.ok() && s.code() != StatusCode::kAlreadyExists) {
      ++report_.refused;
      Error(std::string(Kind::kName) + " " + std::to_string(d.index) + " of origin " + d.held->letter +
            std::to_string(d.held->frame) + ": " + s.ToString());
      continue;
    }
    if (recorded_.insert({Face{d.held->letter, d.held->frame, d.index}, d.landmark}).second) {
      records_.push_back(batch[k]);
      ++report_.observations;
      out->push_back(batch[k]);
    }
  }
}

template <class Kind>
void StructureLandmarkStage<Kind>::Step(GraphStage& graph) {
  // Nothing to place anew while no submap arrived and the graph took no factor: the live graph
  // thread steps often.
  const uint64_t factors = graph.factors_added();
  if (!arrived_ && factors == factors_at_last_step_) return;
  arrived_ = false;
  factors_at_last_step_ = factors;
  std::map<char, std::map<uint64_t, Eigen::Isometry3d>> origins;
  std::map<std::pair<char, uint32_t>, bool> connected;
  auto is_connected = [&](char letter, uint32_t run) {
    auto it = connected.find({letter, run});
    if (it == connected.end())
      it = connected.emplace(std::make_pair(letter, run), graph.Connected(letter, run)).first;
    return it->second;
  };
  auto origin_of = [&](char letter, uint64_t frame) -> const Eigen::Isometry3d* {
    auto it = origins.find(letter);
    if (it == origins.end()) it = origins.emplace(letter, graph.FrameOrigins(letter)).first;
    const auto o = it->second.find(frame);
    return o == it->second.end() ? nullptr : &o->second;
  };
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    const Held& w = *it;
    const Eigen::Isometry3d* ow = origin_of(w.letter, w.frame);
    if (ow == nullptr || !is_connected(w.letter, RunOfIndex(w.frame))) {
      ++it;
      continue;
    }
    std::vector<const Held*> candidates;
    std::vector<std::pair<char, uint64_t>> keys{{w.letter, w.frame}};
    for (const Held& h : held_) {
      if (w.features.empty()) break;
      if (h.features.empty()) continue;
      if (std::min(w.letter, h.letter) != letter_) continue;  // a teammate decides this pair
      const Eigen::Isometry3d* oh = origin_of(h.letter, h.frame);
      if (oh == nullptr) continue;
      if ((oh->translation() - ow->translation()).head<2>().norm() > options_.max_origin_distance) continue;
      candidates.push_back(&h);
      keys.emplace_back(h.letter, h.frame);
    }
    if (!candidates.empty()) {
      std::vector<SubmapPlacement> placed;
      std::string why;
      if (!graph.PlaceOrigins(keys, &placed, &why)) {
        // Never retried: a covariance that fails now would fail at every step.
        Error(std::string("origin ") + w.letter + std::to_string(w.frame) + " compared with nothing: " + why);
      } else {
        std::vector<Observation> out;
        for (size_t k = 0; k < candidates.size(); ++k)
          Compare(graph, w, *candidates[k], placed[0], placed[k + 1], &out);
        if (!out.empty() && team_ != nullptr) Kind::Publish(*team_, out);
      }
    }
    held_.push_back(std::move(*it));
    it = waiting_.erase(it);
  }
  report_.waiting = waiting_.size();
}

template <class Kind>
std::string StructureLandmarkStage<Kind>::Csv(const GraphStage& graph) const {
  std::string out = Kind::CsvHeader();
  for (const Observation& o : records_) {
    out += o.observer + "," + std::to_string(RunOfIndex(o.frame)) + "," +
           std::to_string(LocalIndex(o.frame)) + "," + std::to_string(Kind::ObserverIndex(o)) + "," +
           o.creator + "," + std::to_string(RunOfIndex(o.creator_frame)) + "," +
           std::to_string(LocalIndex(o.creator_frame)) + "," + std::to_string(Kind::LandmarkIndex(o)) + "," +
           Kind::CsvValues(o) + ",";
    if (const auto chi2 = Kind::Chi2(graph, o); chi2.ok()) {
      char number[32];
      std::snprintf(number, sizeof number, "%.3f", *chi2);
      out += number;
    }
    out += "\n";
  }
  return out;
}

template class StructureLandmarkStage<PlaneLandmarks>;
template class StructureLandmarkStage<LineLandmarks>;

}  // namespace cairn
