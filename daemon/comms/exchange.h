#pragma once
// Anti-entropy delivery of the team's items (thesis 3.3): every robot holds every origin's logs it
// has heard of in its ItemStore; peers announce their per-(origin, lane) high-water marks and send
// each other what the other lacks, so every item reaches every teammate exactly once, through
// outages, restarts and relays (A reaches C through B). An announcement only covers stored and
// synced items, so it is also the acknowledgement. Constraints go before submaps within each
// link's byte budget; large items travel in fragments so small ones pass between them.
//
// Transport independent: OnMessage() takes what an authenticated peer sent, Pump() hands out what
// to send. Not thread safe: the comms thread owns it (and the store).

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"
#include "common/timestamp.h"
#include "daemon/comms/exchange_options.h"
#include "daemon/comms/item_assembler.h"
#include "daemon/comms/item_store.h"
#include "daemon/comms/token_bucket.h"

namespace cairn {

inline constexpr uint32_t kExchangeProtocolVersion = 1;
inline constexpr uint8_t kExchangeLanes = 2;

struct ExchangePeerStats {
  std::string name;
  uint64_t sent_bytes = 0;
  uint64_t received_bytes = 0;
  uint64_t sent_messages = 0;
  uint64_t received_messages = 0;
  uint64_t items_sent = 0;        // whole items (all fragments) handed to the transport
  uint64_t items_received = 0;    // new items from this peer, stored
  uint64_t duplicates = 0;        // items this robot held already
  uint64_t resends = 0;           // times a lane was sent again after the timeout
  uint64_t skipped_items = 0;     // not sent again: the peer said it held them already
  uint64_t resumed_bytes = 0;     // first bytes of items in pieces not sent again, likewise
  uint64_t refused_messages = 0;  // malformed, wrong version, or not decodable
  uint64_t refused_fragments = 0; // inconsistent or impossible fragments (bad lane, size, CRC)
  uint64_t implausible_marks = 0; // announcements of this robot's own items it never made
  uint64_t transport_busy = 0;    // sends the transport refused (its queue full)
  uint64_t queued_items = 0;      // items this robot holds that the peer has not acknowledged
  uint64_t queued_bytes = 0;
  bool heard = false;
  Timestamp first_contact;
  Timestamp last_contact;
};

struct ExchangeStats {
  uint64_t published = 0;
  uint64_t stored = 0;          // items from peers appended to the store
  uint64_t store_errors = 0;    // appends the store refused (disk full...): fetched again later
  uint64_t reorder_held = 0;    // items held now until their predecessors arrive
  uint64_t reorder_dropped = 0; // items dropped because the reorder buffer was full
  uint64_t own_origin_refused = 0;  // items under this robot's name that it never made
  std::string last_error;
};

class Exchange {
 public:
  // Hands a message to the transport; false when it cannot take it now (nothing is consumed).
  using Sender = std::function<bool(const std::string& peer, std::string bytes)>;
  // Every item in the store, exactly once per process: at ReplayStore() and as new ones arrive.
  using ItemSink = std::function<void(const StoreItem& item)>;

  Exchange(std::string self, std::vector<std::string> peers, ItemStore& store, const ExchangeOptions& options,
           ItemSink sink);

  // Hands every stored item to the sink (after a restart), constraints lanes first.
  void ReplayStore();
  // Appends an item of this robot (durably) and hands it to the sink.
  Expected<ItemKey> Publish(uint8_t lane, uint16_t kind, std::string payload);
  void OnMessage(const std::string& peer, std::string_view bytes, Timestamp now);
  // Announcements and items for every peer, as far as budgets and the transport allow.
  void Pump(Timestamp now, const Sender& send);
  // When Pump() has something to do next (for the caller's poll timeout).
  Timestamp NextWake(Timestamp now);
  // Whether this robot's own logs are complete (for now); announced to the peers.
  void SetFinished(bool finished = true);
  // This robot finished, and every peer has finished and holds exactly what this robot holds (or
  // finished, went silent and left nothing here unheld).
  // Holds once the condition has lasted a few summary intervals, so that a teammate that takes
  // its finish back (new work) is heard first.
  bool Settled(Timestamp now);

  const std::string& self() const { return self_; }
  std::vector<ExchangePeerStats> PeerStats() const;
  const ExchangeStats& stats() const { return stats_; }
  // Items held per origin (both lanes), for the team's census.
  std::map<std::string, uint64_t> ItemsByOrigin() const;

 private:
  using LaneId = std::pair<std::string, uint8_t>;
  struct Peer {
    ExchangePeerStats stats;
    bool finished = false;
    std::map<LaneId, uint64_t> marks;      // as the peer announced them
    std::map<LaneId, uint64_t> next;       // next seq to send
    std::map<LaneId, Timestamp> progress;  // when the peer's mark last moved (or we last resent)
    std::map<LaneId, std::map<uint64_t, Timestamp>> sent_at;  // unacknowledged items: when sent
    std::map<LaneId, int> resends;  // in a row, the peer unheard since the one before
    // What the peer's last summary said it holds beyond its marks: whole items, and the first
    // bytes of items in pieces.
    std::map<LaneId, std::set<uint64_t>> held_ahead;
    std::map<LaneId, std::map<uint64_t, uint32_t>> held_prefix;
    // Lanes whose item next[lane] is part sent: the offset of its next piece. Kept per lane so
    // that large items of several origins in turn each make progress.
    std::map<LaneId, uint32_t> partial;
    std::unique_ptr<TokenBucket> bucket;
    Timestamp next_summary;
    bool summary_due = true;
    uint64_t announced_version = 0;  // store_version_ of the last summary sent to this peer
    Timestamp retry_at;              // the transport refused: not before then
    size_t round_robin = 0;
  };
  bool SettledNow(Timestamp now) const;
  void OnSummary(Peer& peer, const std::string& name, const void* summary, Timestamp now);
  void OnFragment(Peer& peer, const void* fragment, Timestamp now);
  // Adds to a summary what this robot holds beyond its marks (reorder buffer, items in pieces).
  void DescribeAhead(void* summary) const;
  void OnAhead(Peer& peer, const std::string& name, const void* summary);
  static bool HeldAhead(const Peer& peer, const LaneId& lane, uint64_t seq);
  // Moves the peer's next items past those it holds already.
  void SkipHeld(Peer& peer);
  void Accept(Peer& from, StoreItem item);
  bool StoreNext(StoreItem item);
  // The first seq of `lane` not yet to be relayed (past the hwm when all may go).
  uint64_t RelayLimit(const LaneId& lane, Timestamp now);
  void DrainReorder(const LaneId& lane);
  void AnnounceSoon();
  void PumpPeer(const std::string& name, Peer& peer, Timestamp now, const Sender& send);
  std::vector<LaneId> SendOrder(Peer& peer) const;
  void UpdateQueued(Peer& peer);
  void PeerHolds(Peer& peer, const LaneId& lane, uint64_t seq, Timestamp now);

  std::string self_;
  ItemStore& store_;
  ExchangeOptions options_;
  ItemSink sink_;
  std::map<std::string, Peer> peers_;
  ItemAssembler assembler_;
  std::map<LaneId, std::map<uint64_t, StoreItem>> reorder_;
  // When teammates' items arrived, within the last relay_delay (older ones relay at once).
  std::map<LaneId, std::map<uint64_t, Timestamp>> arrived_;
  Timestamp now_;  // of the call in progress
  uint64_t reorder_bytes_ = 0;
  bool finished_ = false;
  std::optional<Timestamp> settled_since_;
  uint64_t store_version_ = 1;  // counts the store's appends, so summaries know if they are current
  ExchangeStats stats_;
  // Payload of the item being fragmented, read once.
  ItemKey cached_key_;
  std::string cached_payload_;
  uint16_t cached_kind_ = 0;
  uint32_t cached_crc_ = 0;
};

}  // namespace cairn
