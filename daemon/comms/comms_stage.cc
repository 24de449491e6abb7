#include "daemon/comms/comms_stage.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "common/bounded_errors.h"
#include "common/monotonic_clock.h"
#include "daemon/comms/curve_keys.h"

namespace cairn {
namespace {

constexpr size_t kMaxBatchPoints = 512;

}  // namespace

CommsStage::CommsStage(const CommsSetup& setup) : setup_(setup), executor_("comms", setup.executor) {}

CommsStage::~CommsStage() { Stop(); }

Expected<std::unique_ptr<CommsStage>> CommsStage::Create(const CommsSetup& setup) {
  std::unique_ptr<CommsStage> stage(new CommsStage(setup));
  if (Status s = stage->Open(); !s.ok()) return s;
  return stage;
}

char CommsStage::LetterOf(const std::string& robot) const {
  const TeamMember* m = team_.Find(robot);
  return m == nullptr ? 0 : m->letter[0];
}

Status CommsStage::Open() {
  auto team = TeamFile::Load(setup_.team.members_file);
  if (!team.ok()) return team.status();
  team_ = std::move(*team);
  const TeamMember* self = team_.Find(setup_.robot);
  if (self == nullptr) {
    return NotFoundError(team_.path + ": robot '" + setup_.robot + "' (robot.name) is not a member of the team");
  }
  letter_ = self->letter[0];
  auto keys = CurveKeys::LoadSecret(setup_.team.secret_key_file);
  if (!keys.ok()) return keys.status();
  if (keys->public_key != self->public_key) {
    return InvalidArgumentError(setup_.team.secret_key_file + ": its public key is not the one " + team_.path +
                                " lists for '" + setup_.robot + "'");
  }
  const std::string store_dir =
      setup_.team.store_dir.empty() ? setup_.output_dir + "/exchange" : setup_.team.store_dir;
  ItemStoreOptions store_options;
  store_options.max_item_bytes = static_cast<uint64_t>(setup_.team.exchange.max_item_bytes);
  auto store = ItemStore::Open(store_dir, store_options);
  if (!store.ok()) return store.status();
  store_ = std::move(*store);
  for (const ItemStoreRecovery& r : store_->recoveries()) {
    Error(r.file + ": " + std::to_string(r.dropped_bytes) + " bytes after item " + std::to_string(r.valid_items) +
          " dropped at start (" + r.reason + "); teammates send them again");
  }
  std::vector<ZmqPeer> peers;
  std::vector<std::string> names;
  for (const TeamMember& m : team_.members) {
    if (m.name == setup_.robot) continue;
    peers.push_back(ZmqPeer{m.name, m.address, m.public_key});
    names.push_back(m.name);
  }
  ZmqTransportOptions transport = setup_.team.transport;
  transport.listen = setup_.team.listen.empty() ? self->address : setup_.team.listen;
  auto t = ZmqTransport::Create(transport, *keys, peers);
  if (!t.ok()) return t.status();
  transport_ = std::move(*t);
  exchange_ = std::make_unique<Exchange>(setup_.robot, names, *store_, setup_.team.exchange,
                                         [this](const StoreItem& item) { OnItem(item); });
  report_.robot = setup_.robot;
  report_.letter = letter_;
  // This run's number first: every item naming a run of this robot must know which one is current.
  const uint8_t start_lane = LaneOf(TeamItemKind::kRunStart);
  for (uint64_t seq = 1; seq <= store_->HighWaterMark(setup_.robot, start_lane); ++seq) {
    auto item = store_->Read(ItemKey{setup_.robot, start_lane, seq});
    if (!item.ok()) break;  // the replay below reports it
    if (item->kind == static_cast<uint16_t>(TeamItemKind::kRunStart)) {
      report_.incarnation = std::max(report_.incarnation, TeamItemCodec::IncarnationOf(*item) + 1);
    }
  }
  // Everything already held goes to the graph again, this robot's earlier runs too (as runs of
  // their own, like a teammate's), so that its graph holds what its teammates' hold.
  replaying_ = true;
  exchange_->ReplayStore();
  replaying_ = false;
  return Status::Ok();
}

void CommsStage::Error(const std::string& what) {
  AppendBoundedError(report_.errors, what);
}

void CommsStage::OnItem(const StoreItem& item) {
  report_.items[item.key.origin][TeamItemKindName(item.kind)]++;
  if (item.key.origin == setup_.robot) {
    if (!replaying_) return;  // this run's own items are in the graph already
    ++report_.earlier_run_items;
  }
  TeamItemCodec::Names names;
  names.letter_of = [this](const std::string& robot) { return LetterOf(robot); };
  names.frame_index = [this](const std::string& robot, uint32_t incarnation, uint64_t index) {
    // This run's own frames and poses keep their ids (the graph knows them so); every other run's
    // carry it, so that runs never share a variable.
    if (robot == setup_.robot && incarnation == report_.incarnation) return index;
    return RunIndex(incarnation, index);
  };
  auto input = TeamItemCodec::Decode(item, names);
  if (!input.ok()) {
    ++report_.decode_errors;
    Error(input.status().ToString());
    return;
  }
  std::function<void()> notify;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    inbox_.push_back(std::move(*input));
    notify = notify_;
  }
  if (notify) notify();
}

void CommsStage::Start() {
  if (started_) return;
  started_ = true;
  started_at_ = MonotonicClock().Now();
  report_.started_at = started_at_;
  Publish(TeamItemKind::kRunStart, TeamItemCodec::RunStart(report_.incarnation, setup_.robot_kind, started_at_));
  executor_.Start([this](std::stop_token stop) { Loop(stop); });
}

void CommsStage::Stop() {
  if (!started_) return;
  executor_.RequestStop();
  executor_.Join();
  started_ = false;
}

void CommsStage::Push(Outgoing o) {
  std::lock_guard<std::mutex> lock(mutex_);
  outbox_.push_back(std::move(o));
}

void CommsStage::PublishFrameSwitch(const FrameSwitchEvent& event) {
  Outgoing o;
  o.kind = Outgoing::Kind::kSwitch;
  o.frame_switch = event;
  Push(std::move(o));
}

void CommsStage::PublishEstimate(const FrameEstimate& estimate, bool graph_pose, uint64_t pose_index) {
  Outgoing o;
  o.kind = Outgoing::Kind::kEstimate;
  o.estimate = OwnEstimate{estimate, graph_pose, pose_index};
  Push(std::move(o));
}

void CommsStage::PublishSubmap(std::shared_ptr<const Submap> submap) {
  Outgoing o;
  o.kind = Outgoing::Kind::kSubmap;
  o.submap = std::move(submap);
  Push(std::move(o));
}

void CommsStage::PublishMatch(const TeamMatch& match) {
  Outgoing o;
  o.kind = Outgoing::Kind::kMatch;
  o.match = match;
  Push(std::move(o));
}

void CommsStage::PublishAttempt(const TeamMatch& pair, bool matched, const std::string& outcome) {
  Outgoing o;
  o.kind = Outgoing::Kind::kAttempt;
  o.match = pair;
  o.matched = matched;
  o.outcome = outcome;
  Push(std::move(o));
}

void CommsStage::PublishDetection(const TeamDetection& detection) {
  Outgoing o;
  o.kind = Outgoing::Kind::kDetection;
  o.detection = detection;
  Push(std::move(o));
}

void CommsStage::PublishGnssFix(const TeamGnssFix& fix) {
  Outgoing o;
  o.kind = Outgoing::Kind::kGnssFix;
  o.gnss = fix;
  Push(std::move(o));
}

void CommsStage::PublishPlaneObservations(const std::vector<TeamPlaneObservation>& observations) {
  if (observations.empty()) return;  // teammates refuse an empty item
  Outgoing o;
  o.kind = Outgoing::Kind::kPlaneObservations;
  o.planes = observations;
  Push(std::move(o));
}

void CommsStage::PublishLineObservations(const std::vector<TeamLineObservation>& observations) {
  if (observations.empty()) return;  // teammates refuse an empty item
  Outgoing o;
  o.kind = Outgoing::Kind::kLineObservations;
  o.lines = observations;
  Push(std::move(o));
}

void CommsStage::FinishOwnLog() {
  Outgoing o;
  o.kind = Outgoing::Kind::kFinish;
  Push(std::move(o));
}

bool CommsStage::NextInput(TeamInput* input) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (inbox_.empty()) return false;
  *input = std::move(inbox_.front());
  inbox_.pop_front();
  return true;
}

void CommsStage::SetNotify(std::function<void()> notify) {
  std::lock_guard<std::mutex> lock(mutex_);
  notify_ = std::move(notify);
}

void CommsStage::Publish(TeamItemKind kind, std::string payload) {
  auto key = exchange_->Publish(LaneOf(kind), static_cast<uint16_t>(kind), std::move(payload));
  if (!key.ok()) {
    Error("publishing a " + std::string(TeamItemKindName(static_cast<uint16_t>(kind))) + ": " + key.status().ToString());
    return;
  }
  report_.sent_items_by_kind[TeamItemKindName(static_cast<uint16_t>(kind))]++;
}

void CommsStage::SplitFrame(const std::string& robot, uint64_t* frame, uint32_t* incarnation) const {
  // Graph frame indices back into (run, frame) as the wire names them.
  if (robot == setup_.robot && RunOfIndex(*frame) == kCurrentRun) {
    *incarnation = report_.incarnation;
    return;
  }
  *incarnation = IncarnationOfRun(RunOfIndex(*frame));
  *frame = LocalIndex(*frame);
}

void CommsStage::SplitFrames(TeamMatch* m) const {
  SplitFrame(m->robot_a, &m->frame_a, &m->incarnation_a);
  SplitFrame(m->robot_b, &m->frame_b, &m->incarnation_b);
}

void CommsStage::FlushPoses() {
  if (batch_.empty()) return;
  Publish(TeamItemKind::kPoseBatch, TeamItemCodec::PoseBatch(report_.incarnation, batch_));
  batch_.clear();
}

void CommsStage::PublishOwn(Timestamp now, bool flush) {
  std::vector<Outgoing> taken;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    taken.swap(outbox_);
  }
  for (Outgoing& o : taken) {
    switch (o.kind) {
      case Outgoing::Kind::kEstimate:
        if (batch_.empty()) batch_start_ = now;
        batch_.push_back(o.estimate);
        if (batch_.size() >= kMaxBatchPoints) FlushPoses();
        break;
      case Outgoing::Kind::kSwitch:
        // The estimates of the old frame go first, so that a teammate has them in order.
        FlushPoses();
        Publish(TeamItemKind::kFrameSwitch, TeamItemCodec::FrameSwitch(report_.incarnation, o.frame_switch));
        break;
      case Outgoing::Kind::kSubmap: {
        auto payload = TeamItemCodec::Submap(report_.incarnation, *o.submap);
        if (!payload.ok()) {
          Error("submap " + std::to_string(o.submap->metadata().id) + ": " + payload.status().ToString());
          break;
        }
        Publish(TeamItemKind::kSubmap, std::move(*payload));
        break;
      }
      case Outgoing::Kind::kMatch:
        SplitFrames(&o.match);
        Publish(TeamItemKind::kMatch, TeamItemCodec::Match(o.match));
        break;
      case Outgoing::Kind::kAttempt:
        SplitFrames(&o.match);
        Publish(TeamItemKind::kAttempt, TeamItemCodec::Attempt(o.match, o.matched, o.outcome));
        break;
      case Outgoing::Kind::kDetection:
        // Teammates hold it until the poses around its time arrive (batched as usual).
        Publish(TeamItemKind::kDetection, TeamItemCodec::Detection(report_.incarnation, o.detection));
        break;
      case Outgoing::Kind::kGnssFix:
        Publish(TeamItemKind::kGnssFix, TeamItemCodec::GnssFix(report_.incarnation, o.gnss));
        break;
      case Outgoing::Kind::kPlaneObservations:
        PublishObservations(TeamItemKind::kPlaneObservations, "plane", TeamItemCodec::kMaxPlaneObservations,
                            &o.planes, &TeamItemCodec::PlaneObservations);
        break;
      case Outgoing::Kind::kLineObservations:
        PublishObservations(TeamItemKind::kLineObservations, "line", TeamItemCodec::kMaxLineObservations,
                            &o.lines, &TeamItemCodec::LineObservations);
        break;
      case Outgoing::Kind::kFinish:
        FlushPoses();
        own_finished_ = true;
        break;
    }
  }
  if (flush || (!batch_.empty() && now - batch_start_ >= Duration::Seconds(setup_.team.pose_batch_interval))) {
    FlushPoses();
  }
}

void CommsStage::Loop(std::stop_token stop) {
  const MonotonicClock clock;
  const auto send = [this](const std::string& peer, std::string bytes) {
    return transport_->Send(peer, bytes).ok();
  };
  while (!stop.stop_requested()) {
    Timestamp now = clock.Now();
    PublishOwn(now, false);
    exchange_->SetFinished(own_finished_ && idle_.load(std::memory_order_acquire));
    exchange_->Pump(now, send);
    // Wait for a message at most until the exchange has something to do (and 50 ms, so that the
    // graph thread's items go out promptly).
    const Duration wait = std::clamp(exchange_->NextWake(now) - now, Duration(), Duration::Milliseconds(50));
    auto message = transport_->Receive(wait);
    while (message) {
      exchange_->OnMessage(message->peer, message->bytes, clock.Now());
      message = transport_->Receive(Duration());
    }
    settled_.store(exchange_->Settled(now), std::memory_order_release);
    if (now >= next_links_refresh_) {
      RefreshLinks(now);
      next_links_refresh_ = now + Duration::Seconds(1.0);
    }
  }
  // A last word: what this robot holds, so that teammates see it finished.
  PublishOwn(clock.Now(), true);
  exchange_->Pump(clock.Now(), send);
  report_.seconds = (clock.Now() - started_at_).seconds();
  report_.settled = exchange_->Settled(clock.Now());
  report_.peers = exchange_->PeerStats();
  report_.exchange = exchange_->stats();
  report_.transport = transport_->counters();
  RefreshLinks(clock.Now());
  report_.links = Links();
}

void CommsStage::RefreshLinks(Timestamp now) {
  const std::vector<ExchangePeerStats> peers = exchange_->PeerStats();
  std::lock_guard<std::mutex> lock(links_mutex_);
  for (const ExchangePeerStats& p : peers) {
    auto it = std::find_if(links_.begin(), links_.end(), [&](const TeamLinkStatus& l) { return l.peer == p.name; });
    if (it == links_.end()) {
      links_.push_back(TeamLinkStatus{});
      it = std::prev(links_.end());
      it->peer = p.name;
    }
    it->sent_bytes = p.sent_bytes;
    it->received_bytes = p.received_bytes;
    it->queued_items = p.queued_items;
    it->queued_bytes = p.queued_bytes;
    it->queued_items_max = std::max(it->queued_items_max, p.queued_items);
    it->queued_bytes_max = std::max(it->queued_bytes_max, p.queued_bytes);
    it->since_contact = p.heard ? (now - p.last_contact).seconds() : -1.0;
  }
}

std::vector<TeamLinkStatus> CommsStage::Links() const {
  std::lock_guard<std::mutex> lock(links_mutex_);
  return links_;
}

std::string CommsStage::LinkSummary() const {
  std::string out;
  char buffer[160];
  for (const TeamLinkStatus& l : Links()) {
    if (!out.empty()) out += "; ";
    if (l.since_contact < 0.0) {
      std::snprintf(buffer, sizeof(buffer), "%s never heard, %llu items queued", l.peer.c_str(),
                    static_cast<unsigned long long>(l.queued_items));
    } else {
      std::snprintf(buffer, sizeof(buffer), "%s sent %.1f kB, received %.1f kB, %llu items (%.1f kB) queued, heard %.0f s ago",
                    l.peer.c_str(), static_cast<double>(l.sent_bytes) / 1e3, static_cast<double>(l.received_bytes) / 1e3,
                    static_cast<unsigned long long>(l.queued_items), static_cast<double>(l.queued_bytes) / 1e3,
                    l.since_contact);
    }
    out += buffer;
  }
  return out;
}

TeamReport CommsStage::report() const { return report_; }

}  // namespace cairn
