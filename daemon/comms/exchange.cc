#include "daemon/comms/exchange.h"

#include <algorithm>
#include <cctype>

#include "cairn/exchange.pb.h"
#include "io/crc32.h"

namespace cairn {
namespace {

bool ValidOrigin(const std::string& name) {
  if (name.empty() || name.size() > 32) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

constexpr int64_t kRetryMilliseconds = 50;
// A finished peer unheard for this many summary intervals has stopped.
constexpr double kGoneSummaries = 5.0;
// Settled must hold this many summary intervals: a teammate's change of mind arrives within one.
constexpr double kStableSummaries = 3.0;
// Each resend of a lane while the peer is not heard doubles its timeout, up to 2^this. When the
// acknowledgements do not come back (the return link is down), going back to the first unheld
// item every timeout fills the slow forward link with copies, and the items behind them never
// get through.
constexpr int kMaxResendDoublings = 3;
// Items per lane a summary lists as held beyond the mark, and in pieces (bounds a summary's size
// and what a peer's summary can make this robot keep).
constexpr int kMaxAhead = 64;

uint32_t CrcOf(const std::string& bytes) {
  return Crc32::Of(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
}

}  // namespace

Exchange::Exchange(std::string self, std::vector<std::string> peers, ItemStore& store,
                   const ExchangeOptions& options, ItemSink sink)
    : self_(std::move(self)),
      store_(store),
      options_(options),
      sink_(std::move(sink)),
      assembler_(static_cast<uint64_t>(options.reorder_bytes)) {
  for (std::string& name : peers) {
    Peer& p = peers_[name];
    p.stats.name = name;
    p.bucket = std::make_unique<TokenBucket>(options_.link_bytes_per_s, options_.link_burst_bytes);
  }
}

void Exchange::ReplayStore() {
  const auto marks = store_.HighWaterMarks();
  for (uint8_t lane = 0; lane < kExchangeLanes; ++lane) {
    for (const auto& [id, hwm] : marks) {
      if (id.second != lane) continue;
      for (uint64_t seq = 1; seq <= hwm; ++seq) {
        auto item = store_.Read(ItemKey{id.first, lane, seq});
        if (!item.ok()) {
          stats_.last_error = item.status().ToString();
          ++stats_.store_errors;
          break;  // the rest of this lane cannot be read in order
        }
        if (sink_) sink_(*item);
      }
    }
  }
}

Expected<ItemKey> Exchange::Publish(uint8_t lane, uint16_t kind, std::string payload) {
  if (lane >= kExchangeLanes) return InvalidArgumentError("lane " + std::to_string(lane) + " does not exist");
  StoreItem item;
  item.key = ItemKey{self_, lane, store_.HighWaterMark(self_, lane) + 1};
  item.kind = kind;
  item.payload = std::move(payload);
  if (Status s = store_.Append(item); !s.ok()) {
    ++stats_.store_errors;
    stats_.last_error = s.ToString();
    return s;
  }
  ++stats_.published;
  ++store_version_;
  if (sink_) sink_(item);
  return item.key;
}

void Exchange::AnnounceSoon() {
  for (auto& [name, peer] : peers_) peer.summary_due = true;
}

void Exchange::OnMessage(const std::string& name, std::string_view bytes, Timestamp now) {
  now_ = now;
  const auto it = peers_.find(name);
  if (it == peers_.end()) return;  // the transport admits teammates only
  Peer& peer = it->second;
  peer.stats.received_bytes += bytes.size();
  ++peer.stats.received_messages;
  exchange::Envelope envelope;
  if (!envelope.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    ++peer.stats.refused_messages;
    stats_.last_error = "a message from " + name + " of " + std::to_string(bytes.size()) + " bytes does not decode";
    return;
  }
  if (envelope.version() != kExchangeProtocolVersion) {
    ++peer.stats.refused_messages;
    stats_.last_error = "a message from " + name + " speaks protocol version " + std::to_string(envelope.version()) +
                        ", this robot " + std::to_string(kExchangeProtocolVersion);
    return;
  }
  if (!peer.stats.heard) peer.stats.first_contact = now;
  peer.stats.heard = true;
  peer.stats.last_contact = now;
  if (envelope.has_summary()) OnSummary(peer, name, &envelope.summary(), now);
  for (const exchange::Fragment& f : envelope.fragments()) OnFragment(peer, &f, now);
}

void Exchange::OnSummary(Peer& peer, const std::string& name, const void* summary_ptr, Timestamp now) {
  const auto& summary = *static_cast<const exchange::Summary*>(summary_ptr);
  peer.finished = summary.finished();
  std::set<LaneId> listed;
  for (const exchange::LaneMark& m : summary.marks()) {
    if (!ValidOrigin(m.origin()) || m.lane() >= kExchangeLanes) {
      ++peer.stats.refused_fragments;
      stats_.last_error = "a summary from " + name + " names lane " + std::to_string(m.lane()) + " of origin '" +
                          m.origin().substr(0, 40) + "'";
      continue;
    }
    LaneId lane{m.origin(), static_cast<uint8_t>(m.lane())};
    uint64_t mark = m.high_water_mark();
    if (m.origin() == self_) {
      const uint64_t own = store_.HighWaterMark(self_, lane.second);
      if (mark > own) {
        // A teammate cannot hold more of this robot's log than it made: a lie or a bug; trust only
        // what this robot made.
        ++peer.stats.implausible_marks;
        mark = own;
      }
    }
    listed.insert(lane);
    const auto old = peer.marks.find(lane);
    const bool advanced = old == peer.marks.end() || mark > old->second;
    if (old != peer.marks.end() && mark < old->second) {
      // The peer lost part of its store (a new disk): it needs those items again.
      peer.next[lane] = mark + 1;
      peer.partial.erase(lane);
    }
    peer.marks[lane] = mark;
    if (advanced) {
      peer.progress[lane] = now;
      peer.resends.erase(lane);
    }
    auto& sent = peer.sent_at[lane];
    sent.erase(sent.begin(), sent.upper_bound(mark));
    auto next = peer.next.find(lane);
    if (next == peer.next.end() || next->second <= mark) {
      peer.next[lane] = mark + 1;
      peer.partial.erase(lane);
    }
  }
  // Lanes the peer did not list it holds nothing of.
  for (const auto& [lane, hwm] : store_.HighWaterMarks()) {
    if (listed.count(lane) != 0) continue;
    if (peer.marks.count(lane) == 0) {
      peer.marks[lane] = 0;
      if (peer.next.count(lane) == 0) peer.next[lane] = 1;
      peer.progress[lane] = now;
    }
    (void)hwm;
  }
  OnAhead(peer, name, summary_ptr);
}

void Exchange::OnAhead(Peer& peer, const std::string& name, const void* summary_ptr) {
  const auto& summary = *static_cast<const exchange::Summary*>(summary_ptr);
  peer.held_ahead.clear();
  peer.held_prefix.clear();
  for (const exchange::LaneAhead& a : summary.ahead()) {
    if (!ValidOrigin(a.origin()) || a.lane() >= kExchangeLanes || a.partial_seq_size() != a.partial_bytes_size()) {
      ++peer.stats.refused_fragments;
      stats_.last_error = "a summary from " + name + " says what it holds ahead of lane " + std::to_string(a.lane()) +
                          " of origin '" + a.origin().substr(0, 40) + "' inconsistently";
      continue;
    }
    const LaneId lane{a.origin(), static_cast<uint8_t>(a.lane())};
    const auto m = peer.marks.find(lane);
    const uint64_t mark = m == peer.marks.end() ? 0 : m->second;
    auto& held = peer.held_ahead[lane];
    for (int i = 0; i < std::min(a.held_size(), kMaxAhead); ++i) {
      if (a.held(i) > mark) held.insert(a.held(i));
    }
    auto& prefix = peer.held_prefix[lane];
    for (int i = 0; i < std::min(a.partial_seq_size(), kMaxAhead); ++i) {
      if (a.partial_seq(i) > mark && a.partial_bytes(i) > 0) prefix[a.partial_seq(i)] = a.partial_bytes(i);
    }
  }
}

void Exchange::DescribeAhead(void* summary_ptr) const {
  auto& summary = *static_cast<exchange::Summary*>(summary_ptr);
  std::map<LaneId, exchange::LaneAhead*> lanes;
  const auto entry = [&](const LaneId& lane) {
    exchange::LaneAhead*& a = lanes[lane];
    if (a == nullptr) {
      a = summary.add_ahead();
      a->set_origin(lane.first);
      a->set_lane(lane.second);
    }
    return a;
  };
  for (const auto& [lane, items] : reorder_) {
    exchange::LaneAhead* a = entry(lane);
    for (const auto& [seq, item] : items) {
      if (a->held_size() >= kMaxAhead) break;
      a->add_held(seq);
    }
  }
  for (const auto& [key, covered] : assembler_.Prefixes()) {
    exchange::LaneAhead* a = entry({std::get<0>(key), std::get<1>(key)});
    if (a->partial_seq_size() >= kMaxAhead) continue;
    a->add_partial_seq(std::get<2>(key));
    a->add_partial_bytes(static_cast<uint32_t>(covered));
  }
}

bool Exchange::HeldAhead(const Peer& peer, const LaneId& lane, uint64_t seq) {
  const auto held = peer.held_ahead.find(lane);
  return held != peer.held_ahead.end() && held->second.count(seq) != 0;
}

void Exchange::SkipHeld(Peer& peer) {
  for (auto& [lane, next] : peer.next) {
    if (peer.partial.count(lane) != 0) continue;
    const uint64_t hwm = store_.HighWaterMark(lane.first, lane.second);
    while (next <= hwm && HeldAhead(peer, lane, next)) {
      ++next;
      ++peer.stats.skipped_items;
    }
  }
}

void Exchange::PeerHolds(Peer& peer, const LaneId& lane, uint64_t seq, Timestamp now) {
  // A peer sends only what its store holds, and a store holds each lane without gaps: so it holds
  // this lane up to `seq`. Known now, not at its next summary, so its own new items are never
  // echoed back to it.
  uint64_t& mark = peer.marks[lane];
  if (seq <= mark) return;
  mark = seq;
  peer.progress[lane] = now;
  peer.resends.erase(lane);
  auto& sent = peer.sent_at[lane];
  sent.erase(sent.begin(), sent.upper_bound(mark));
  uint64_t& next = peer.next[lane];
  if (next <= mark) {
    next = mark + 1;
    peer.partial.erase(lane);
  }
}

void Exchange::OnFragment(Peer& peer, const void* fragment_ptr, Timestamp now) {
  const auto& f = *static_cast<const exchange::Fragment*>(fragment_ptr);
  const uint64_t total = f.total_bytes();
  if (!ValidOrigin(f.origin()) || f.lane() >= kExchangeLanes || f.seq() == 0 || f.kind() > 0xffff ||
      total > static_cast<uint64_t>(options_.max_item_bytes) || f.offset() > total ||
      f.data().size() > total - f.offset()) {
    ++peer.stats.refused_fragments;
    stats_.last_error = "an impossible fragment from " + peer.stats.name + " (origin '" + f.origin().substr(0, 40) +
                        "', lane " + std::to_string(f.lane()) + ", seq " + std::to_string(f.seq()) + ", " +
                        std::to_string(f.offset()) + "+" + std::to_string(f.data().size()) + " of " +
                        std::to_string(total) + " bytes)";
    return;
  }
  const LaneId lane{f.origin(), static_cast<uint8_t>(f.lane())};
  const uint64_t hwm = store_.HighWaterMark(lane.first, lane.second);
  if (f.origin() != self_) PeerHolds(peer, lane, f.seq(), now);
  if (f.origin() == self_) {
    if (f.seq() > hwm) {
      ++stats_.own_origin_refused;
      stats_.last_error = peer.stats.name + " sent item " + std::to_string(f.seq()) + " of lane " +
                          std::to_string(f.lane()) + " under this robot's name, which it never made";
    } else if (f.offset() == 0) {
      ++peer.stats.duplicates;
    }
    return;
  }
  const auto held = reorder_.find(lane);
  if (f.seq() <= hwm || (held != reorder_.end() && held->second.count(f.seq()) != 0)) {
    if (f.offset() == 0) ++peer.stats.duplicates;
    return;
  }
  const std::string& data = f.data();
  ItemAssembler::Outcome got = assembler_.Add(
      {f.origin(), static_cast<uint8_t>(f.lane()), f.seq()},
      {static_cast<uint16_t>(f.kind()), f.payload_crc32(), static_cast<uint32_t>(total), f.offset(), &data});
  if (got.conflict) ++peer.stats.refused_fragments;
  if (got.full) ++stats_.reorder_dropped;
  if (!got.complete) return;
  if (CrcOf(got.payload) != got.crc) {
    ++peer.stats.refused_fragments;
    stats_.last_error = "item " + f.origin() + "/" + std::to_string(f.lane()) + "/" + std::to_string(f.seq()) +
                        " from " + peer.stats.name + " fails its CRC";
    return;
  }
  StoreItem item;
  item.key = ItemKey{f.origin(), static_cast<uint8_t>(f.lane()), f.seq()};
  item.kind = got.kind;
  item.payload = std::move(got.payload);
  Accept(peer, std::move(item));
}

bool Exchange::StoreNext(StoreItem item) {
  if (Status s = store_.Append(item); !s.ok()) {
    ++stats_.store_errors;
    stats_.last_error = s.ToString();
    return false;
  }
  ++stats_.stored;
  ++store_version_;
  if (options_.relay_delay > 0.0) arrived_[{item.key.origin, item.key.lane}][item.key.seq] = now_;
  if (sink_) sink_(item);
  return true;
}

void Exchange::Accept(Peer& from, StoreItem item) {
  const LaneId lane{item.key.origin, item.key.lane};
  const uint64_t hwm = store_.HighWaterMark(lane.first, lane.second);
  if (item.key.seq == hwm + 1) {
    if (!StoreNext(std::move(item))) return;
    ++from.stats.items_received;
    DrainReorder(lane);
    AnnounceSoon();
    return;
  }
  if (reorder_bytes_ + item.payload.size() > static_cast<uint64_t>(options_.reorder_bytes)) {
    ++stats_.reorder_dropped;
    return;
  }
  reorder_bytes_ += item.payload.size();
  ++from.stats.items_received;
  reorder_[lane].emplace(item.key.seq, std::move(item));
}

void Exchange::DrainReorder(const LaneId& lane) {
  auto held = reorder_.find(lane);
  if (held == reorder_.end()) return;
  auto& items = held->second;
  while (!items.empty()) {
    auto first = items.begin();
    const uint64_t hwm = store_.HighWaterMark(lane.first, lane.second);
    if (first->first <= hwm) {
      reorder_bytes_ -= first->second.payload.size();
      items.erase(first);
      continue;
    }
    if (first->first != hwm + 1) break;
    reorder_bytes_ -= first->second.payload.size();
    StoreItem item = std::move(first->second);
    items.erase(first);
    if (!StoreNext(std::move(item))) break;
  }
  if (items.empty()) reorder_.erase(held);
}

std::vector<Exchange::LaneId> Exchange::SendOrder(Peer& peer) const {
  // Constraints of every origin before any submap; origins in turn so that none starves.
  std::vector<LaneId> order;
  const auto marks = store_.HighWaterMarks();
  for (uint8_t lane = 0; lane < kExchangeLanes; ++lane) {
    std::vector<LaneId> lanes;
    for (const auto& [id, hwm] : marks) {
      if (id.second != lane) continue;
      const auto next = peer.next.find(id);
      if (next != peer.next.end() && next->second <= hwm) lanes.push_back(id);
    }
    if (!lanes.empty()) std::rotate(lanes.begin(), lanes.begin() + static_cast<long>(peer.round_robin % lanes.size()),
                                    lanes.end());
    order.insert(order.end(), lanes.begin(), lanes.end());
  }
  return order;
}

uint64_t Exchange::RelayLimit(const LaneId& lane, Timestamp now) {
  const auto it = arrived_.find(lane);
  if (it == arrived_.end()) return UINT64_MAX;
  auto& times = it->second;
  const Duration delay = Duration::Seconds(options_.relay_delay);
  while (!times.empty() && now - times.begin()->second >= delay) times.erase(times.begin());
  if (times.empty()) {
    arrived_.erase(it);
    return UINT64_MAX;
  }
  return times.begin()->first;
}

void Exchange::Pump(Timestamp now, const Sender& send) {
  for (auto& [name, peer] : peers_) PumpPeer(name, peer, now, send);
}

void Exchange::PumpPeer(const std::string& name, Peer& peer, Timestamp now, const Sender& send) {
  // The first item the peer lacks goes again (and what followed it) once it was sent the timeout
  // ago without being acknowledged: lost with a message or a broken link.
  for (auto& [lane, next] : peer.next) {
    const uint64_t mark = peer.marks.count(lane) ? peer.marks[lane] : 0;
    if (next <= mark + 1) continue;
    auto& sent = peer.sent_at[lane];
    const auto first = sent.find(mark + 1);
    const Timestamp since = first != sent.end() ? first->second : peer.progress[lane];
    // Heard from since: the link works both ways and what was sent is lost; the plain timeout.
    const bool heard = peer.stats.heard && peer.stats.last_contact > since;
    int& resends = peer.resends[lane];
    const int doublings = heard ? 0 : std::min(resends, kMaxResendDoublings);
    if (now - since > Duration::Seconds(options_.resend_timeout * (1 << doublings))) {
      next = mark + 1;
      peer.partial.erase(lane);
      sent.clear();
      peer.progress[lane] = now;
      resends = heard ? 0 : resends + 1;
      ++peer.stats.resends;
    }
  }
  SkipHeld(peer);
  if (now >= peer.next_summary) peer.summary_due = true;
  if (now < peer.retry_at) return;
  while (peer.bucket->Ready(now)) {
    exchange::Envelope envelope;
    envelope.set_version(kExchangeProtocolVersion);
    const bool with_summary = peer.summary_due &&
        now >= peer.next_summary - Duration::Seconds(options_.summary_interval - options_.summary_min_interval);
    if (with_summary) {
      auto* summary = envelope.mutable_summary();
      summary->set_finished(finished_);
      for (const auto& [id, hwm] : store_.HighWaterMarks()) {
        auto* m = summary->add_marks();
        m->set_origin(id.first);
        m->set_lane(id.second);
        m->set_high_water_mark(hwm);
      }
      DescribeAhead(summary);
    }
    // Items only to a peer that said what it holds; planned on copies, committed once sent.
    std::map<LaneId, uint64_t> next = peer.next;
    std::map<LaneId, uint32_t> partial = peer.partial;
    std::vector<std::pair<LaneId, uint64_t>> completed;
    uint64_t whole_items = 0;
    uint64_t resumed = 0, skipped = 0;
    if (peer.stats.heard) {
      for (const LaneId& lane : SendOrder(peer)) {
        const uint64_t hwm = store_.HighWaterMark(lane.first, lane.second);
        // Items of a third robot wait relay_delay: the peer may have them from their origin.
        const uint64_t limit = lane.first == self_ ? UINT64_MAX : RelayLimit(lane, now);
        uint64_t& seq = next[lane];
        while (seq <= hwm && seq < limit && envelope.ByteSizeLong() < static_cast<size_t>(options_.message_bytes)) {
          if (partial.count(lane) == 0 && HeldAhead(peer, lane, seq)) {
            ++seq;
            ++skipped;
            continue;
          }
          const ItemKey key{lane.first, lane.second, seq};
          if (!(cached_key_.origin == key.origin && cached_key_.lane == key.lane && cached_key_.seq == key.seq)) {
            auto item = store_.Read(key);
            if (!item.ok()) {
              ++stats_.store_errors;
              stats_.last_error = item.status().ToString();
              break;
            }
            cached_key_ = key;
            cached_payload_ = std::move(item->payload);
            cached_kind_ = item->kind;
            cached_crc_ = CrcOf(cached_payload_);
          }
          const size_t size = cached_payload_.size();
          const auto part = partial.find(lane);
          uint32_t offset = part == partial.end() ? 0 : part->second;
          if (part == partial.end()) {
            // A resend resumes where the peer's pieces end.
            const auto prefix = peer.held_prefix.find(lane);
            if (prefix != peer.held_prefix.end()) {
              const auto bytes = prefix->second.find(seq);
              if (bytes != prefix->second.end() && bytes->second < size) {
                offset = bytes->second;
                resumed += offset;
              }
            }
          }
          const size_t chunk = std::min<size_t>(size - offset, static_cast<size_t>(options_.fragment_bytes));
          auto* f = envelope.add_fragments();
          f->set_origin(lane.first);
          f->set_lane(lane.second);
          f->set_seq(seq);
          f->set_kind(cached_kind_);
          f->set_total_bytes(static_cast<uint32_t>(size));
          f->set_offset(offset);
          f->set_data(cached_payload_.data() + offset, chunk);
          f->set_payload_crc32(cached_crc_);
          if (offset + chunk < size) {
            partial[lane] = static_cast<uint32_t>(offset + chunk);
            break;  // one piece of a large item per message: small items pass between pieces
          }
          partial.erase(lane);
          completed.emplace_back(lane, seq);
          ++seq;
          ++whole_items;
        }
        if (envelope.ByteSizeLong() >= static_cast<size_t>(options_.message_bytes)) break;
      }
    }
    if (!with_summary && envelope.fragments_size() == 0) return;
    std::string bytes = envelope.SerializeAsString();
    const size_t size = bytes.size();
    if (!send(name, std::move(bytes))) {
      // Not connected or its queue full: try again a little later rather than spin.
      ++peer.stats.transport_busy;
      peer.retry_at = now + Duration::Milliseconds(kRetryMilliseconds);
      return;
    }
    peer.bucket->Spend(now, size);
    peer.stats.sent_bytes += size;
    ++peer.stats.sent_messages;
    peer.stats.items_sent += whole_items;
    peer.stats.resumed_bytes += resumed;
    peer.stats.skipped_items += skipped;
    peer.next = std::move(next);
    peer.partial = std::move(partial);
    for (const auto& [lane, seq] : completed) peer.sent_at[lane][seq] = now;
    ++peer.round_robin;
    if (with_summary) {
      peer.summary_due = false;
      peer.announced_version = store_version_;
      peer.next_summary = now + Duration::Seconds(options_.summary_interval);
    }
  }
}

Timestamp Exchange::NextWake(Timestamp now) {
  Timestamp wake = now + Duration::Seconds(options_.summary_interval);
  for (auto& [name, peer] : peers_) {
    Timestamp peer_wake = std::max(now, peer.next_summary);
    if (peer.summary_due) {
      peer_wake = std::min(peer_wake, std::max(now, peer.next_summary - Duration::Seconds(options_.summary_interval -
                                                                                         options_.summary_min_interval)));
    }
    bool pending = false, relay_waits = false;
    for (const auto& [lane, next] : peer.next) {
      if (next > store_.HighWaterMark(lane.first, lane.second)) continue;
      if (lane.first == self_ || next < RelayLimit(lane, now)) {
        pending = true;
      } else {
        relay_waits = true;
      }
    }
    if (pending) peer_wake = std::min(peer_wake, now + peer.bucket->Wait(now));
    if (relay_waits) peer_wake = std::min(peer_wake, now + Duration::Milliseconds(kRetryMilliseconds));
    wake = std::min(wake, std::max(peer_wake, peer.retry_at));
  }
  return wake;
}

void Exchange::SetFinished(bool finished) {
  if (finished == finished_) return;
  finished_ = finished;
  AnnounceSoon();
}

bool Exchange::Settled(Timestamp now) {
  if (!SettledNow(now)) {
    settled_since_.reset();
    return false;
  }
  if (!settled_since_) settled_since_ = now;
  return now - *settled_since_ >= Duration::Seconds(kStableSummaries * options_.summary_interval);
}

bool Exchange::SettledNow(Timestamp now) const {
  if (!finished_) return false;
  const auto mine = store_.HighWaterMarks();
  const Duration quiet = Duration::Seconds(kGoneSummaries * options_.summary_interval);
  for (const auto& [name, peer] : peers_) {
    if (!peer.stats.heard || !peer.finished) return false;
    bool holds_theirs = true;  // this robot holds all the peer announced
    for (const auto& [lane, mark] : peer.marks) {
      const auto m = mine.find(lane);
      holds_theirs &= mark <= (m == mine.end() ? 0 : m->second);
    }
    // A finished peer silent this long has stopped (a replay's end): what it lacks it fetches when
    // it runs again; nothing of it is missing here.
    if (holds_theirs && now - peer.stats.last_contact > quiet) continue;
    // Otherwise both hold the same, and the peer was told so: the last summary to it is current.
    if (peer.announced_version != store_version_) return false;
    for (const auto& [lane, hwm] : mine) {
      const auto m = peer.marks.find(lane);
      if (m == peer.marks.end() || m->second != hwm) return false;
    }
    for (const auto& [lane, mark] : peer.marks) {
      const auto m = mine.find(lane);
      if (mark != (m == mine.end() ? 0 : m->second)) return false;
    }
  }
  return true;
}

std::vector<ExchangePeerStats> Exchange::PeerStats() const {
  std::vector<ExchangePeerStats> out;
  const auto marks = store_.HighWaterMarks();
  for (const auto& [name, peer] : peers_) {
    ExchangePeerStats s = peer.stats;
    s.queued_items = 0;
    s.queued_bytes = 0;
    if (peer.stats.heard) {
      for (const auto& [lane, hwm] : marks) {
        const auto m = peer.marks.find(lane);
        const uint64_t mark = m == peer.marks.end() ? 0 : m->second;
        for (uint64_t seq = mark + 1; seq <= hwm; ++seq) {
          ++s.queued_items;
          if (auto info = store_.Info(ItemKey{lane.first, lane.second, seq}); info.ok()) s.queued_bytes += info->size;
        }
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::map<std::string, uint64_t> Exchange::ItemsByOrigin() const {
  std::map<std::string, uint64_t> out;
  for (const auto& [lane, hwm] : store_.HighWaterMarks()) out[lane.first] += hwm;
  return out;
}

}  // namespace cairn
