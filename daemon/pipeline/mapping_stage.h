#pragma once
// The mapping executor's work (thesis 5.1, 5.2.2): dense stereo on rectified pairs (FPGA offload or
// SIMD CPU kernel through the backend switch), the depth images' filter poses, the local mapper
// (obstacles, rolling map, open submap, partitioning), finished submaps written in their wire
// format, and the composed map along the chain of frame switches.
//
// A depth image waits for the filter's estimate at its exposure. The estimate and the frame
// switches come from the estimation thread; a switch is applied to the mapper when the first
// estimate in the new frame is used, so mapping sees the same sequence whatever the thread timing.
// Not thread safe: one mapping thread owns it.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/reuse_ring.h"
#include "daemon/pipeline/dense_stereo_options.h"
#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/mapping_stage_options.h"
#include "daemon/pipeline/spsc_queue.h"
#include "daemon/pipeline/stereo_rectify_stage.h"
#include "fpga/stereo_backend_switch.h"
#include "mapping/keyframe_line_extractor.h"
#include "mapping/local_mapper.h"
#include "mapping/map_composer.h"
#include "stereo/bidirectional_raster_matcher.h"

namespace cairn {

// A teammate's finished submap at its origin in the graph's global frame.
struct PlacedSubmap {
  std::shared_ptr<const Submap> submap;
  Eigen::Isometry3d T_global_submap = Eigen::Isometry3d::Identity();
};

class TelemetryStage;

struct MappingSetup {
  std::string robot;
  DenseStereoOptions stereo;
  MappingStageOptions mapping;
  RectifiedStereoCamera camera;  // set by Pipeline::EnableMapping
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  std::string output_dir;  // submaps/ and the map exports go below it
};

struct MappingStageReport {
  std::string backend;               // the matcher in use at the end
  std::string device;                // the board's device while the FPGA is in use
  std::string fpga_status;           // why the FPGA is not used ("" while it is)
  uint64_t pairs = 0;                // pairs densely matched
  uint64_t match_failures = 0;
  bool bidirectional = false;        // each pair matched twice (stereo.bidirectional)
  uint64_t fpga_frames = 0, cpu_frames = 0, fpga_failures = 0;  // passes on each backend
  uint64_t images_mapped = 0;
  uint64_t images_without_pose = 0;  // no valid filter estimate at the exposure
  uint64_t images_dropped = 0;       // waiting images pushed out by newer ones
  uint64_t estimates_dropped = 0;    // estimates pushed out while no image waited for them
  uint64_t mapping_errors = 0;
  uint64_t frame_switches = 0;       // switches applied to the mapper
  uint64_t switch_requests = 0;      // partitioning's requests to the filter
  uint64_t submaps_finished = 0;
  uint64_t submaps_written = 0;
  uint64_t submap_write_failures = 0;
  uint64_t submap_bytes = 0;         // wire size of the written submaps
  uint64_t map_points = 0;           // composed cloud at the end
  uint64_t map_voxels = 0;           // composed occupancy voxels at the end
  uint64_t submaps_placed_by_graph = 0;  // composed at the SLAM graph's origins
  uint64_t submaps_memory_bytes = 0;  // clouds and octrees of every submap composed at the end
  uint64_t composer_bytes = 0;  // the composer's cache and tables at the end (MapComposer::memory_bytes)
  uint64_t team_submaps = 0;            // teammates' submaps composed into the map
  uint64_t line_segments = 0;           // straight edges detected in the left images (mapping.lines)
  uint64_t line_sightings = 0;          // of them, triangulated with the disparity
  uint64_t submap_lines = 0;            // edges kept in the finished submaps
  LocalMapperStats mapper;
  std::vector<std::string> errors;   // the first few, verbatim
};

class MappingStage {
 public:
  // `requester` receives partitioning's frame-switch requests (the filter's request path).
  static Expected<std::unique_ptr<MappingStage>> Create(const MappingSetup& setup,
                                                        FrameSwitchRequesterInterface* requester);

  // Dense stereo on one rectified pair; its depth image waits for its pose.
  void OnPair(const RectifiedPair& pair);
  void OnEstimate(const FrameEstimate& e);
  void OnFrameSwitch(const FrameSwitchEvent& e) { switches_.push_back(e); }
  // Maps every waiting image whose estimate is known. `final`: no more estimates will come.
  void ProcessReady(bool final);
  // Finished submaps also go into `queue` (the matcher's; a full queue drops and counts).
  void PublishSubmapsTo(SpscQueue<std::shared_ptr<const Submap>>* queue) { submap_queue_ = queue; }
  // End of the run, first part: maps what waits and finishes the open submap.
  void FinishSubmaps();
  // End of the run: maps what waits, finishes the open submap and writes the map exports. With
  // `graph_origins` (T_global_frame per local frame, from the SLAM graph) the submaps are composed
  // at the graph's optimized origins instead of along the chain of frame switches.
  void Finish(const std::map<uint64_t, Eigen::Isometry3d>* graph_origins = nullptr,
              const std::vector<PlacedSubmap>* team_submaps = nullptr);
  // Finished submaps and obstacle-map snapshots also go to recording and the live stream.
  void SetTelemetry(TelemetryStage* telemetry) { telemetry_ = telemetry; }

  MappingStageReport report() const;
  // When each local frame began (the frame switch into it; the first frame: its first estimate).
  const std::map<uint64_t, Timestamp>& origin_times() const { return origin_times_; }
  const LatencyHistogram& match_time() const { return match_time_; }
  const LatencyHistogram& map_time() const { return map_time_; }
  const LatencyHistogram& line_time() const { return line_time_; }
  size_t waiting_images() const { return waiting_.size(); }

 private:
  MappingStage(const MappingSetup& setup, std::unique_ptr<StereoBackendSwitch> matcher,
               FrameSwitchRequesterInterface* requester);
  void Map(const DepthImage& image, const FrameEstimate& e);
  void ApplySwitchesUpTo(uint64_t frame_id);
  void Keep(std::shared_ptr<const Submap> submap);
  // submaps/ROBOT-NNNNNN.submap, atomically; failures are counted and reported.
  void WriteSubmapFile(const Submap& submap);
  void PlaceByGraph(const std::map<uint64_t, Eigen::Isometry3d>& origins, const std::vector<PlacedSubmap>* team);
  void Error(const std::string& what);

  MappingSetup setup_;
  SpscQueue<std::shared_ptr<const Submap>>* submap_queue_ = nullptr;
  std::map<uint64_t, Timestamp> origin_times_;
  bool submaps_finished_ = false;
  std::unique_ptr<StereoBackendSwitch> matcher_;
  // Both passes over matcher_ when stereo.bidirectional is on; null otherwise.
  std::unique_ptr<BidirectionalRasterMatcher> bidirectional_;
  StereoMatcherOutput disparity_;
  std::unique_ptr<KeyframeLineExtractor> lines_;  // with mapping.lines
  LocalMapper mapper_;
  MapComposer composer_;
  uint64_t frame_id_ = 0;  // the mapper's current local frame
  // T_first_frame of every local frame seen (the chain of switches; the graph refines it later).
  std::map<uint64_t, Eigen::Isometry3d> T_first_frame_;
  // Images waiting for their pose: a second's worth of frames at most (older ones are the least
  // useful), in slots whose buffers are reused, so a pair costs no allocation of its size. One
  // slot more, to convert a pair into before the oldest image is given up for it.
  static constexpr size_t kWaitingImages = 16;
  ReuseRing<DepthImage, kWaitingImages + 1> waiting_;
  // Estimates wait only while no image does (ProcessReady gives up those older than the first
  // image): more than this is seconds of frames without an image, and the oldest is of no use.
  static constexpr size_t kWaitingEstimates = 256;
  ReuseRing<FrameEstimate, kWaitingEstimates> estimates_;
  std::deque<FrameSwitchEvent> switches_;
  LatencyHistogram match_time_, map_time_, line_time_;
  MappingStageReport report_;
  TelemetryStage* telemetry_ = nullptr;
};

}  // namespace cairn
