#pragma once
// The comms executor's work: this robot's side of the team exchange. It owns the item store, the
// ZeroMQ transport and the exchange; the graph thread hands it this robot's frame switches,
// estimates, submaps and matches (TeamLink) and takes teammates' items back, decoded. Estimates
// travel in batches (`team.pose_batch_interval`, and at every frame switch); submaps are encoded
// in their wire format here, off the graph thread.
//
// After a restart the store still holds every log: teammates' items are handed to the graph again,
// and this robot's new run gets the next incarnation number, so its frames never collide with the
// earlier run's (which teammates keep as a subgraph of its own).

#include <atomic>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/status.h"
#include "common/timestamp.h"
#include "daemon/comms/exchange.h"
#include "daemon/comms/item_store.h"
#include "daemon/comms/team_file.h"
#include "daemon/comms/team_item_codec.h"
#include "daemon/comms/team_link_status.h"
#include "daemon/comms/team_options.h"
#include "daemon/comms/zmq_transport.h"
#include "daemon/pipeline/executor.h"
#include "daemon/pipeline/team_link.h"

namespace cairn {

struct CommsSetup {
  TeamOptions team;
  std::string robot;       // robot.name: its entry in the team file
  std::string robot_kind;
  std::string output_dir;  // the store goes to <output_dir>/exchange unless team.store_dir says
  ExecutorOptions executor;
};

struct TeamReport {
  std::string robot;
  char letter = 0;
  uint32_t incarnation = 0;
  double seconds = 0.0;  // the exchange ran this long (wall clock)
  Timestamp started_at;  // monotonic clock
  std::vector<ExchangePeerStats> peers;
  ZmqTransportCounters transport;
  ExchangeStats exchange;
  std::map<std::string, std::map<std::string, uint64_t>> items;  // origin -> kind -> items stored
  std::map<std::string, uint64_t> sent_items_by_kind;            // this robot's, published
  uint64_t decode_errors = 0;
  uint64_t earlier_run_items = 0;  // this robot's items of earlier runs found in the store
  bool settled = false;            // the team held the same logs at the end
  // How long the end of the run waited for that, and how it ended (Pipeline::LingerReport).
  double linger_seconds = 0.0;
  std::string linger_ended;
  std::vector<std::string> errors;  // the first few, verbatim
  std::vector<TeamLinkStatus> links;
};

class CommsStage final : public TeamLink {
 public:
  // Loads the team file and this robot's keys, opens the store and binds; errors name the file.
  static Expected<std::unique_ptr<CommsStage>> Create(const CommsSetup& setup);
  ~CommsStage() override;

  void Start();
  void Stop();  // joins the comms thread
  TeamReport report() const;  // complete after Stop()
  ExecutorReport executor_report() const { return executor_.report(); }
  // The links now (any thread), and as one line for the daemon's status.
  std::vector<TeamLinkStatus> Links() const;
  std::string LinkSummary() const;
  const TeamFile& team() const { return team_; }
  char letter() const { return letter_; }
  // Graph letter of a robot of the team file; 0 for anyone else.
  char LetterOf(const std::string& robot) const;

  // TeamLink (any thread).
  void PublishFrameSwitch(const FrameSwitchEvent& event) override;
  void PublishEstimate(const FrameEstimate& estimate, bool graph_pose, uint64_t pose_index) override;
  void PublishSubmap(std::shared_ptr<const Submap> submap) override;
  void PublishMatch(const TeamMatch& match) override;
  void PublishAttempt(const TeamMatch& pair, bool matched, const std::string& outcome) override;
  void PublishDetection(const TeamDetection& detection) override;
  void PublishGnssFix(const TeamGnssFix& fix) override;
  void PublishPlaneObservations(const std::vector<TeamPlaneObservation>& observations) override;
  void PublishLineObservations(const std::vector<TeamLineObservation>& observations) override;
  bool NextInput(TeamInput* input) override;
  void SetNotify(std::function<void()> notify) override;
  void FinishOwnLog() override;
  void SetIdle(bool idle) override { idle_.store(idle, std::memory_order_release); }
  bool Settled() override { return settled_.load(std::memory_order_acquire); }
  double linger_seconds() const override { return setup_.team.linger; }

 private:
  struct Outgoing {
    enum class Kind : uint8_t {
      kSwitch,
      kEstimate,
      kSubmap,
      kMatch,
      kAttempt,
      kDetection,
      kGnssFix,
      kPlaneObservations,
      kLineObservations,
      kFinish
    };
    Kind kind = Kind::kEstimate;
    FrameSwitchEvent frame_switch;
    OwnEstimate estimate;
    std::shared_ptr<const Submap> submap;
    TeamMatch match;
    bool matched = false;
    std::string outcome;
    TeamDetection detection;
    TeamGnssFix gnss;
    std::vector<TeamPlaneObservation> planes;
    std::vector<TeamLineObservation> lines;
  };

  explicit CommsStage(const CommsSetup& setup);
  Status Open();
  void Loop(std::stop_token stop);
  void Push(Outgoing o);
  void PublishOwn(Timestamp now, bool flush);
  void FlushPoses();
  void SplitFrame(const std::string& robot, uint64_t* frame, uint32_t* incarnation) const;
  void SplitFrames(TeamMatch* match) const;
  // One submap's landmark observations as one item (`encode` the codec's), their frames as the
  // wire names them; more than teammates take is an error instead.
  template <class Observation>
  void PublishObservations(TeamItemKind kind, const char* what, size_t max,
                           std::vector<Observation>* observations,
                           std::string (*encode)(const std::vector<Observation>&)) {
    if (observations->size() > max) {
      Error(std::to_string(observations->size()) + " " + what +
            " observations of one submap, more than teammates take");
      return;
    }
    for (Observation& o : *observations) SplitObservationFrames(&o);
    Publish(kind, encode(*observations));
  }
  // An observation's two frames (its observer's and its creator's) as the wire names them.
  template <class Observation>
  void SplitObservationFrames(Observation* o) const {
    SplitFrame(o->observer, &o->frame, &o->observer_incarnation);
    SplitFrame(o->creator, &o->creator_frame, &o->creator_incarnation);
  }
  void Publish(TeamItemKind kind, std::string payload);
  void OnItem(const StoreItem& item);
  void Error(const std::string& what);
  void RefreshLinks(Timestamp now);

  CommsSetup setup_;
  TeamFile team_;
  char letter_ = 0;
  std::unique_ptr<ItemStore> store_;
  std::unique_ptr<ZmqTransport> transport_;
  std::unique_ptr<Exchange> exchange_;
  Executor executor_;
  bool started_ = false;

  mutable std::mutex mutex_;  // guards outbox_, inbox_, notify_
  std::vector<Outgoing> outbox_;
  std::deque<TeamInput> inbox_;
  std::function<void()> notify_;
  std::atomic<bool> settled_{false};
  std::atomic<bool> idle_{false};
  mutable std::mutex links_mutex_;  // guards links_
  std::vector<TeamLinkStatus> links_;
  Timestamp next_links_refresh_;

  // Comms thread.
  bool replaying_ = false;
  bool own_finished_ = false;
  std::vector<OwnEstimate> batch_;
  Timestamp batch_start_;
  Timestamp started_at_;
  TeamReport report_;
};

}  // namespace cairn
