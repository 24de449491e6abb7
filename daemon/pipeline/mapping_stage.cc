#include "daemon/pipeline/mapping_stage.h"

#include <cstdio>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "common/atomic_file.h"
#include "common/monotonic_clock.h"
#include "daemon/pipeline/telemetry_stage.h"
#include "fpga/simulated_stereo_device.h"
#include "mapping/map_exporter.h"
#include "mapping/submap_codec.h"

namespace cairn {
namespace {

StereoCamera MappingCamera(const RectifiedStereoCamera& c, const Eigen::Isometry3d& T_body_cam) {
  StereoCamera cam;
  cam.intrinsics.width = c.width;
  cam.intrinsics.height = c.height;
  cam.intrinsics.fx = cam.intrinsics.fy = c.f;
  cam.intrinsics.cx = c.cx;
  cam.intrinsics.cy = c.cy;
  cam.baseline = c.baseline;
  cam.T_body_cam = T_body_cam;
  return cam;
}

std::string SubmapFileName(const std::string& robot, uint64_t id) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "-%06llu.submap", static_cast<unsigned long long>(id));
  return robot + buf;
}

}  // namespace

Expected<std::unique_ptr<MappingStage>> MappingStage::Create(const MappingSetup& setup,
                                                             FrameSwitchRequesterInterface* requester) {
  if (!(setup.camera.f > 0.0) || !(setup.camera.baseline > 0.0) || setup.camera.width <= 0 ||
      setup.camera.height <= 0) {
    return InvalidArgumentError("mapping needs a rectified stereo camera with focal length and baseline");
  }
  if (setup.stereo.sgm.min_disparity + setup.stereo.sgm.num_disparities > setup.camera.width) {
    return InvalidArgumentError("stereo.sgm: disparities up to " +
                                std::to_string(setup.stereo.sgm.min_disparity + setup.stereo.sgm.num_disparities) +
                                " px do not fit the " + std::to_string(setup.camera.width) + " px wide images");
  }
  StereoBackendSwitch::DeviceOpener open;
  if (setup.stereo.backend.device == DenseStereoOptions::kSimulatedDevice) {
    open = []() -> Expected<std::unique_ptr<StereoDevice>> {
      return std::unique_ptr<StereoDevice>(std::make_unique<SimulatedStereoDevice>());
    };
  }
  auto matcher = StereoBackendSwitch::Create(setup.stereo.backend, setup.stereo.sgm, std::move(open),
                                             [](const std::string& m) { spdlog::warn("{}", m); });
  if (!matcher.ok()) return matcher.status().WithContext("stereo");
  return std::unique_ptr<MappingStage>(new MappingStage(setup, std::move(*matcher), requester));
}

MappingStage::MappingStage(const MappingSetup& setup, std::unique_ptr<StereoBackendSwitch> matcher,
                           FrameSwitchRequesterInterface* requester)
    : setup_(setup),
      matcher_(std::move(matcher)),
      mapper_(setup.mapping.map, MappingCamera(setup.camera, setup.T_body_cam), setup.robot, requester),
      composer_(setup.mapping.map.composition, setup.mapping.map.submap) {
  if (setup_.stereo.bidirectional) {
    bidirectional_ = std::make_unique<BidirectionalRasterMatcher>(
        *matcher_, static_cast<int>(setup_.stereo.bidirectional_max_diff), setup_.stereo.sgm.pixel_error_px);
  }
  if (setup_.mapping.map.lines.enabled) {
    lines_ = std::make_unique<KeyframeLineExtractor>(setup_.mapping.map.lines,
                                                     MappingCamera(setup_.camera, setup_.T_body_cam));
  }
  if (setup_.mapping.write_submaps && !setup_.output_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(setup_.output_dir + "/submaps", ec);
    if (ec) Error(setup_.output_dir + "/submaps: cannot create the folder: " + ec.message());
  }
}

void MappingStage::Error(const std::string& what) {
  if (report_.errors.size() < 20) report_.errors.push_back(what);
  spdlog::warn("mapping: {}", what);
}

void MappingStage::OnPair(const RectifiedPair& pair) {
  if (pair.left.stride != pair.right.stride || pair.left.width != pair.right.width ||
      pair.left.height != pair.right.height) {
    ++report_.match_failures;
    Error("stereo pair at " + std::to_string(pair.time.seconds()) + " s: left and right images differ in size");
    return;
  }
  StereoMatcherInput in;
  in.left = pair.left.data.get();
  in.right = pair.right.data.get();
  in.width = pair.left.width;
  in.height = pair.left.height;
  in.stride = pair.left.stride;
  in.focal_px = setup_.camera.f;
  in.baseline_m = setup_.camera.baseline;
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  StereoMatcher& matcher = bidirectional_ != nullptr ? static_cast<StereoMatcher&>(*bidirectional_) : *matcher_;
  if (Status s = matcher.Match(in, &disparity_); !s.ok()) {
    ++report_.match_failures;
    Error("dense stereo at " + std::to_string(pair.time.seconds()) + " s: " + s.ToString());
    return;
  }
  match_time_.Record(clock.Now() - start);
  ++report_.pairs;
  DepthImage& depth = waiting_.Next();
  if (Status s = depth.AssignDisparity(disparity_.disparity, disparity_.width, disparity_.height, in.focal_px,
                                       in.baseline_m);
      !s.ok()) {
    ++report_.match_failures;
    Error(s.ToString());
    return;
  }
  depth.time = pair.time;
  depth.intensity.resize(static_cast<size_t>(in.width) * static_cast<size_t>(in.height));
  for (int y = 0; y < in.height; ++y) {
    std::copy_n(pair.left.row(y), in.width, depth.intensity.data() + static_cast<size_t>(y) * in.width);
  }
  depth.lines.clear();
  // The edges now, while this pair's disparity is at hand; they wait for the pose with the image.
  if (lines_ != nullptr) {
    const Timestamp line_start = clock.Now();
    KeyframeLineExtractor::Stats stats;
    if (lines_->Extract(in.left, in.width, in.height, in.stride, disparity_, &depth.lines, &stats)) {
      line_time_.Record(clock.Now() - line_start);
      report_.line_segments += static_cast<uint64_t>(stats.detected);
      report_.line_sightings += static_cast<uint64_t>(stats.triangulated);
    } else {
      Error("lines at " + std::to_string(pair.time.seconds()) + " s: the disparity does not fit the image");
    }
  }
  waiting_.Push();
  // A pose comes within a few frames; images that wait longer than a second's worth of frames are
  // the oldest and the least useful.
  if (waiting_.size() > kWaitingImages) {
    waiting_.Pop();
    ++report_.images_dropped;
  }
}

void MappingStage::OnEstimate(const FrameEstimate& e) {
  if (estimates_.full()) {
    estimates_.Pop();
    ++report_.estimates_dropped;
  }
  estimates_.Next() = e;
  estimates_.Push();
}

void MappingStage::ProcessReady(bool final) {
  while (!waiting_.empty()) {
    const DepthImage& image = waiting_.Front();
    while (!estimates_.empty() && estimates_.Front().time < image.time) estimates_.Pop();
    if (estimates_.empty() && !final) return;  // its estimate is still to come
    if (!estimates_.empty() && estimates_.Front().time == image.time && estimates_.Front().valid) {
      Map(image, estimates_.Front());
    } else {
      ++report_.images_without_pose;
    }
    waiting_.Pop();
  }
}

void MappingStage::ApplySwitchesUpTo(uint64_t frame_id) {
  if (T_first_frame_.empty()) return;  // nothing mapped yet: the first mapped frame is the origin
  // Switches made before the first mapped image.
  while (!switches_.empty() && switches_.front().new_frame_id <= frame_id_) switches_.pop_front();
  while (frame_id_ < frame_id && !switches_.empty() && switches_.front().new_frame_id <= frame_id) {
    const FrameSwitchEvent e = switches_.front();
    switches_.pop_front();
    if (e.old_frame_id != frame_id_) {
      // A switch the filter made while this stage was elsewhere in the chain cannot be placed.
      Error("frame switch " + std::to_string(e.old_frame_id) + " -> " + std::to_string(e.new_frame_id) +
            " does not start from mapping's frame " + std::to_string(frame_id_));
    }
    // A frame reached without its switch event (a full queue) has no place in the chain, and
    // neither has what follows it.
    if (const auto from = T_first_frame_.find(e.old_frame_id); from != T_first_frame_.end()) {
      T_first_frame_[e.new_frame_id] = from->second * e.transform.T_old_new;
    }
    origin_times_.emplace(e.new_frame_id, e.time);
    ++report_.frame_switches;
    Keep(mapper_.OnFrameSwitch(e.new_frame_id, e.transform.T_old_new));
    frame_id_ = e.new_frame_id;
  }
}

void MappingStage::Map(const DepthImage& image, const FrameEstimate& e) {
  if (T_first_frame_.empty()) {
    // The first frame mapped is the map's frame, as it is trajectory.tum's.
    frame_id_ = e.frame_id;
    T_first_frame_[e.frame_id] = Eigen::Isometry3d::Identity();
    origin_times_.emplace(e.frame_id, e.time);
  }
  ApplySwitchesUpTo(e.frame_id);
  if (e.frame_id != frame_id_) {
    // No switch event for this frame (its queue overflowed): the mapper finishes the submap itself.
    frame_id_ = e.frame_id;
  }
  MappingPose pose;
  pose.time = e.time;
  pose.frame_id = e.frame_id;
  pose.T_local_body = e.T_frame_body;
  pose.position_covariance = e.position_covariance;
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  if (Status s = mapper_.Process(image, pose); !s.ok()) {
    ++report_.mapping_errors;
    Error("image at " + std::to_string(image.time.seconds()) + " s: " + s.ToString());
    return;
  }
  map_time_.Record(clock.Now() - start);
  ++report_.images_mapped;
  Keep(mapper_.TakeFinished());
  // About once a second at the profiles' rates: the grid is a planner's view, not a per-image one.
  constexpr uint64_t kGridEvery = 5;
  if (telemetry_ != nullptr && report_.images_mapped % kGridEvery == 1) {
    if (const auto frame = T_first_frame_.find(frame_id_); frame != T_first_frame_.end()) {
      telemetry_->OfferObstacleGrid(e.time, std::make_shared<const GridMap>(mapper_.obstacle_map().Snapshot()),
                                    frame->second, e.T_frame_body.translation().z());
    }
  }
}

void MappingStage::Keep(std::shared_ptr<const Submap> submap) {
  if (submap == nullptr) return;
  ++report_.submaps_finished;
  report_.submap_lines += submap->structure().lines.size();
  // On disk first: whatever the graph, the exchange or the recording learn of a submap survives a
  // crash right after.
  WriteSubmapFile(*submap);
  if (submap_queue_ != nullptr) submap_queue_->TryPush(submap);
  const uint64_t id = submap->metadata().id;
  const auto pose = T_first_frame_.find(id);
  if (pose != T_first_frame_.end()) {
    if (Status s = composer_.SetSubmap(submap, pose->second); !s.ok()) Error(s.ToString());
    composer_.Update();
    if (telemetry_ != nullptr) telemetry_->OfferSubmap(submap->metadata().end, submap, pose->second);
  } else {
    Error("submap " + std::to_string(id) + " has no place in the chain of frames; not composed");
  }
}

void MappingStage::WriteSubmapFile(const Submap& submap) {
  if (!setup_.mapping.write_submaps || setup_.output_dir.empty()) return;
  const std::string path = setup_.output_dir + "/submaps/" + SubmapFileName(setup_.robot, submap.metadata().id);
  auto bytes = SubmapCodec::Encode(submap);
  Status s = bytes.ok() ? WriteFileAtomically(path, std::string(bytes->begin(), bytes->end())) : bytes.status();
  if (!s.ok()) {
    ++report_.submap_write_failures;
    Error(path + ": " + s.ToString());
    return;
  }
  ++report_.submaps_written;
  report_.submap_bytes += bytes->size();
  spdlog::debug("submap {} written: {} ({} bytes)", submap.metadata().id, path, bytes->size());
}

void MappingStage::FinishSubmaps() {
  if (submaps_finished_) return;
  submaps_finished_ = true;
  ProcessReady(/*final=*/true);
  ApplySwitchesUpTo(UINT64_MAX);
  Keep(mapper_.FinishOpenSubmap());
}

void MappingStage::Finish(const std::map<uint64_t, Eigen::Isometry3d>* graph_origins,
                          const std::vector<PlacedSubmap>* team_submaps) {
  FinishSubmaps();
  if (graph_origins != nullptr && !T_first_frame_.empty()) PlaceByGraph(*graph_origins, team_submaps);
  composer_.Update();
  const std::vector<CloudPoint> cloud = composer_.Cloud();
  const std::unique_ptr<octomap::OcTree> tree = composer_.Octree();
  report_.map_points = cloud.size();
  report_.composer_bytes = composer_.memory_bytes();
  report_.submaps_memory_bytes = composer_.submap_bytes();
  report_.map_voxels = tree ? tree->getNumLeafNodes() : 0;
  if (!setup_.mapping.write_map || setup_.output_dir.empty() || report_.submaps_finished == 0) return;
  const std::string& dir = setup_.output_dir;
  // Exports write their own files; a failure is reported and the others are still written.
  if (Status s = MapExporter::WriteCloud(cloud, dir + "/map.ply"); !s.ok()) Error(s.ToString());
  if (tree) {
    if (Status s = MapExporter::WriteOctree(*tree, dir + "/map.bt"); !s.ok()) Error(s.ToString());
  }
  if (Status s = MapExporter::WriteGridMap(mapper_.obstacle_map().Snapshot(), dir + "/obstacles.png"); !s.ok()) {
    Error(s.ToString());
  }
}

void MappingStage::PlaceByGraph(const std::map<uint64_t, Eigen::Isometry3d>& origins,
                                const std::vector<PlacedSubmap>* team) {
  // The map's frame stays the first mapped frame; the graph places every submap relative to it.
  const auto base = origins.find(T_first_frame_.begin()->first);
  if (base == origins.end()) {
    Error("the graph has no origin for the map's first frame; the map keeps the chain of frame switches");
    return;
  }
  const Eigen::Isometry3d T_map_global = base->second.inverse();
  for (const auto& [id, chained] : T_first_frame_) {
    const auto origin = origins.find(id);
    if (origin == origins.end()) continue;  // no submap began there, or the graph lost the frame
    const Status s = composer_.SetPose(SubmapRef{setup_.robot, id}, T_map_global * origin->second);
    if (s.ok()) {
      ++report_.submaps_placed_by_graph;
    } else if (s.code() != StatusCode::kNotFound) {
      Error(s.ToString());
    }
  }
  // Teammates' submaps join the same map where the graph has placed them.
  if (team == nullptr) return;
  for (const PlacedSubmap& p : *team) {
    if (Status s = composer_.SetSubmap(p.submap, T_map_global * p.T_global_submap); s.ok()) {
      ++report_.team_submaps;
    } else {
      Error("teammate's submap " + p.submap->metadata().robot + "/" + std::to_string(p.submap->metadata().id) + ": " +
            s.ToString());
    }
  }
}

MappingStageReport MappingStage::report() const {
  MappingStageReport r = report_;
  r.backend = std::string(matcher_->name());
  r.bidirectional = bidirectional_ != nullptr;
  if (matcher_->fpga_active()) r.device = setup_.stereo.backend.device;
  r.fpga_status = matcher_->fpga_status().ok() ? "" : matcher_->fpga_status().ToString();
  r.fpga_frames = matcher_->fpga_frames();
  r.cpu_frames = matcher_->cpu_frames();
  r.fpga_failures = matcher_->fpga_failures();
  r.mapper = mapper_.stats();
  return r;
}

}  // namespace cairn
