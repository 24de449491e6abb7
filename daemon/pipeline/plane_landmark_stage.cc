#include "daemon/pipeline/plane_landmark_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/bounded_errors.h"

namespace cairn {

PlaneLandmarkStage::PlaneLandmarkStage(const PlaneLandmarkOptions& options, char letter, std::string robot)
    : options_(options), associator_(options.association), letter_(letter), robot_(std::move(robot)) {}

void PlaneLandmarkStage::SetTeam(std::map<char, std::string> names, TeamLink* team) {
  names_ = std::move(names);
  team_ = team;
}

std::string PlaneLandmarkStage::Name(char letter) const {
  if (letter == letter_) return robot_;
  const auto it = names_.find(letter);
  return it == names_.end() ? std::string(1, letter) : it->second;
}

void PlaneLandmarkStage::Error(const std::string& what) { AppendBoundedError(report_.errors, what); }

void PlaneLandmarkStage::OnSubmap(char letter, uint64_t frame, const Submap& submap) {
  ++report_.submaps;
  Held h;
  h.letter = letter;
  h.frame = frame;
  h.planes = submap.structure().planes;
  // Faces past 255 cannot be named on the wire; the extractor keeps the largest first.
  if (h.planes.size() > 256) h.planes.resize(256);
  const auto eligible = std::count_if(h.planes.begin(), h.planes.end(),
                                      [&](const SubmapPlane& p) { return associator_.Eligible(p); });
  report_.faces += static_cast<uint64_t>(eligible);
  waiting_.push_back(std::move(h));
  arrived_ = true;
  report_.waiting = waiting_.size();
}

void PlaneLandmarkStage::OnTeamObservations(const std::vector<TeamPlaneObservation>& observations) {
  for (const TeamPlaneObservation& o : observations) {
    if (o.observer_letter == 0 || o.creator_letter == 0) continue;
    const Face face{o.observer_letter, o.frame, o.observer_plane};
    const Face landmark{o.creator_letter, o.creator_frame, o.plane};
    landmark_of_.emplace(face, landmark);  // a face keeps the landmark it had
    landmark_of_.emplace(landmark, landmark);
    if (recorded_.insert({face, landmark}).second) {
      records_.push_back(o);
      ++report_.team_observations;
    }
  }
}

TeamPlaneObservation PlaneLandmarkStage::Observation(const Held& observer, uint32_t plane,
                                                     const Face& landmark) const {
  const SubmapPlane& p = observer.planes[plane];
  TeamPlaneObservation o;
  o.observer = Name(observer.letter);
  o.observer_letter = observer.letter;
  o.frame = observer.frame;
  o.observer_plane = plane;
  o.creator = Name(std::get<0>(landmark));
  o.creator_letter = std::get<0>(landmark);
  o.creator_frame = std::get<1>(landmark);
  o.plane = std::get<2>(landmark);
  o.normal = p.normal.cast<double>().normalized();
  o.offset = static_cast<double>(p.offset);
  o.centroid = p.centroid.cast<double>();
  o.covariance = associator_.Covariance(p);
  return o;
}

void PlaneLandmarkStage::Compare(GraphStage& graph, const Held& w, const Held& h, const SubmapPlacement& pw,
                                 const SubmapPlacement& ph, std::vector<TeamPlaneObservation>* out) {
  ++report_.pairs;
  for (const PlaneAssociation& a : associator_.Associate(w.planes, pw, h.planes, ph)) {
    const Face fw{w.letter, w.frame, static_cast<uint32_t>(a.a)};
    const Face fh{h.letter, h.frame, static_cast<uint32_t>(a.b)};
    const auto lw = landmark_of_.find(fw), lh = landmark_of_.find(fh);
    // (observer, its face's plane index, landmark), the landmark's naming face first.
    std::vector<std::tuple<const Held*, uint32_t, Face>> observations;
    if (lw == landmark_of_.end() && lh == landmark_of_.end()) {
      const Face name = std::min(fw, fh);
      landmark_of_[fw] = landmark_of_[fh] = name;
      const bool h_names = name == fh;
      observations.emplace_back(h_names ? &h : &w, static_cast<uint32_t>(h_names ? a.b : a.a), name);
      observations.emplace_back(h_names ? &w : &h, static_cast<uint32_t>(h_names ? a.a : a.b), name);
    } else if (lw == landmark_of_.end()) {
      landmark_of_[fw] = lh->second;
      observations.emplace_back(&w, static_cast<uint32_t>(a.a), lh->second);
    } else if (lh == landmark_of_.end()) {
      landmark_of_[fh] = lw->second;
      observations.emplace_back(&h, static_cast<uint32_t>(a.b), lw->second);
    } else {
      continue;  // both are landmarks already (the same, or two never merged)
    }
    ++report_.associations;
    for (const auto& [held, plane, landmark] : observations) {
      const TeamPlaneObservation o = Observation(*held, plane, landmark);
      const Status s = graph.AddPlaneObservation(o);
      if (!s.ok() && s.code() != StatusCode::kAlreadyExists) {
        ++report_.refused;
        Error(std::string("plane ") + std::to_string(plane) + " of origin " + held->letter +
              std::to_string(held->frame) + ": " + s.ToString());
        continue;
      }
      const Face face{held->letter, held->frame, plane};
      if (recorded_.insert({face, landmark}).second) {
        records_.push_back(o);
        ++report_.observations;
        out->push_back(o);
      }
    }
  }
}

void PlaneLandmarkStage::Step(GraphStage& graph) {
  if (!options_.enabled) {
    waiting_.clear();
    return;
  }
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
        std::vector<TeamPlaneObservation> out;
        for (size_t k = 0; k < candidates.size(); ++k)
          Compare(graph, w, *candidates[k], placed[0], placed[k + 1], &out);
        if (!out.empty() && team_ != nullptr) team_->PublishPlaneObservations(out);
      }
    }
    held_.push_back(std::move(*it));
    it = waiting_.erase(it);
  }
  report_.waiting = waiting_.size();
}

std::string PlaneLandmarkStage::Csv(const GraphStage& graph) const {
  std::string out =
      "observer,run,frame,plane,landmark_robot,landmark_run,landmark_frame,landmark_plane,nx,ny,nz,offset,cx,"
      "cy,cz,"
      "sigma_a,sigma_b,sigma_d,chi2\n";
  char numbers[256];
  for (const TeamPlaneObservation& o : records_) {
    const auto chi2 = graph.PlaneObservationChi2(o);
    out += o.observer + "," + std::to_string(RunOfIndex(o.frame)) + "," +
           std::to_string(LocalIndex(o.frame)) + "," + std::to_string(o.observer_plane) + "," + o.creator +
           "," + std::to_string(RunOfIndex(o.creator_frame)) + "," +
           std::to_string(LocalIndex(o.creator_frame)) + "," + std::to_string(o.plane);
    std::snprintf(numbers, sizeof numbers, ",%.6f,%.6f,%.6f,%.4f,%.3f,%.3f,%.3f,%.5f,%.5f,%.4f,",
                  o.normal.x(), o.normal.y(), o.normal.z(), o.offset, o.centroid.x(), o.centroid.y(),
                  o.centroid.z(), std::sqrt(o.covariance(0, 0)), std::sqrt(o.covariance(1, 1)),
                  std::sqrt(o.covariance(2, 2)));
    out += numbers;
    if (chi2.ok()) {
      std::snprintf(numbers, sizeof numbers, "%.3f", *chi2);
      out += numbers;
    }
    out += "\n";
  }
  return out;
}

PlaneLandmarkReport PlaneLandmarkStage::report() const { return report_; }

}  // namespace cairn
