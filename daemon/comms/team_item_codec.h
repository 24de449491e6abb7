#pragma once
// This robot's items into the exchange's payloads (io/proto/cairn/exchange.proto) and teammates'
// payloads back into the pipeline's plain structs. Decoding checks everything a teammate could get
// wrong (sizes, non-finite numbers, rotations that are not rotations) and names the item.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/status.h"
#include "daemon/comms/item_store.h"
#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/team_input.h"
#include "mapping/submap.h"

namespace cairn {

enum class TeamItemKind : uint16_t {
  kRunStart = 1,
  kFrameSwitch = 2,
  kPoseBatch = 3,
  kSubmap = 4,
  kMatch = 5,
  kAttempt = 6,
  kDetection = 7,
  kGnssFix = 8,
  kPlaneObservations = 9,
  kLineObservations = 10,
};

// Which lane an item of `kind` travels in (submaps behind the constraints).
uint8_t LaneOf(TeamItemKind kind);
const char* TeamItemKindName(uint16_t kind);

struct OwnEstimate {
  FrameEstimate estimate;
  bool graph_pose = false;
  uint64_t pose_index = 0;
};

class TeamItemCodec {
 public:
  static std::string RunStart(uint32_t incarnation, const std::string& robot_kind, Timestamp start);
  static std::string FrameSwitch(uint32_t incarnation, const FrameSwitchEvent& event);
  static std::string PoseBatch(uint32_t incarnation, const std::vector<OwnEstimate>& estimates);
  static Expected<std::string> Submap(uint32_t incarnation, const cairn::Submap& submap);
  static std::string Match(const TeamMatch& match);
  static std::string Attempt(const TeamMatch& pair, bool matched, const std::string& outcome);
  static std::string Detection(uint32_t incarnation, const TeamDetection& detection);
  static std::string GnssFix(uint32_t incarnation, const TeamGnssFix& fix);
  // The observations name their robots and runs themselves (frames as the wire names them).
  static std::string PlaneObservations(const std::vector<TeamPlaneObservation>& observations);
  // Most observations one item may carry (one submap's; teammates refuse more), and the highest
  // plane index an observation may name.
  static constexpr size_t kMaxPlaneObservations = 4096;
  static constexpr uint32_t kMaxPlaneIndex = 255;
  // The same for straight edges.
  static std::string LineObservations(const std::vector<TeamLineObservation>& observations);
  static constexpr size_t kMaxLineObservations = 4096;
  static constexpr uint32_t kMaxLineIndex = 1023;

  // How a decoded item names graph variables: a robot's letter (0 for a robot not in the team
  // file) and the index of its frame `frame` of run `incarnation`.
  struct Names {
    std::function<char(const std::string& robot)> letter_of;
    // The graph's index of a run's frame or pose index (see RunIndex).
    std::function<uint64_t(const std::string& robot, uint32_t incarnation, uint64_t frame)> frame_index;
  };
  static Expected<TeamInput> Decode(const StoreItem& item, const Names& names);
  static uint32_t IncarnationOf(const StoreItem& run_start);  // 0 when it does not decode
};

}  // namespace cairn
