#include "daemon/comms/exchange.h"

#include <filesystem>
#include <map>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "cairn/exchange.pb.h"
#include "daemon/comms/testing/link_emulator.h"
#include "io/crc32.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "cairn_exchange_XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { fs::remove_all(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// One robot's exchange with its store; Restart() is a new process on the same disk.
struct Robot {
  Robot(std::string n, std::vector<std::string> p, std::string dir, ExchangeOptions o)
      : name(std::move(n)), peers(std::move(p)), store_dir(std::move(dir)), options(o) {
    Start();
  }
  void Start() {
    exchange.reset();
    store.reset();
    auto s = ItemStore::Open(store_dir, ItemStoreOptions{});
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    store = std::move(*s);
    seen.clear();
    exchange = std::make_unique<Exchange>(name, peers, *store, options, [this](const StoreItem& item) {
      const auto key = std::make_tuple(item.key.origin, item.key.lane, item.key.seq);
      ++seen[key];
      payloads[key] = item.payload;
    });
    exchange->ReplayStore();
  }
  std::string name;
  std::vector<std::string> peers;
  std::string store_dir;
  ExchangeOptions options;
  std::unique_ptr<ItemStore> store;
  std::unique_ptr<Exchange> exchange;
  std::map<std::tuple<std::string, uint8_t, uint64_t>, int> seen;  // in this process
  std::map<std::tuple<std::string, uint8_t, uint64_t>, std::string> payloads;
};

// Robots joined by emulated links, stepped in simulated time.
class Team {
 public:
  Team(const std::vector<std::string>& names, const std::vector<std::pair<std::string, std::string>>& links,
       const LinkProfile& profile, const ExchangeOptions& options, const std::string& cut_off = "",
       std::pair<Timestamp, Timestamp> outage = {}) {
    uint64_t seed = profile.seed;
    for (const auto& [a, b] : links) {
      for (const auto& [from, to] : {std::pair(a, b), std::pair(b, a)}) {
        LinkProfile p = profile;
        p.seed = ++seed;
        if (!cut_off.empty() && (from == cut_off || to == cut_off)) p.outages.push_back(outage);
        links_.emplace(std::pair(from, to), std::make_unique<LinkEmulator>(p));
        neighbours_[from].push_back(to);
      }
    }
    for (const std::string& n : names) {
      robots_[n] = std::make_unique<Robot>(n, neighbours_[n], (dir_.path() + "/" + n), options);
    }
  }
  Robot& robot(const std::string& n) { return *robots_.at(n); }
  LinkEmulator& link(const std::string& from, const std::string& to) { return *links_.at({from, to}); }
  Timestamp now() const { return now_; }

  void Step(Duration dt) {
    now_ += dt;
    for (auto& [key, link] : links_) {
      for (std::string& m : link->Deliver(now_)) robots_.at(key.second)->exchange->OnMessage(key.first, m, now_);
    }
    for (auto& [name, robot] : robots_) {
      robot->exchange->Pump(now_, [&, from = name](const std::string& to, std::string bytes) {
        links_.at({from, to})->Send(now_, std::move(bytes));
        return true;
      });
    }
  }
  // Whether every robot holds every origin's lanes up to the same marks.
  bool Converged() const {
    const auto first = robots_.begin()->second->store->HighWaterMarks();
    for (const auto& [name, robot] : robots_) {
      if (robot->store->HighWaterMarks() != first) return false;
    }
    return true;
  }

 private:
  TempDir dir_;
  Timestamp now_ = Timestamp::FromSeconds(1000.0);
  std::map<std::string, std::unique_ptr<Robot>> robots_;
  std::map<std::pair<std::string, std::string>, std::unique_ptr<LinkEmulator>> links_;
  std::map<std::string, std::vector<std::string>> neighbours_;
};

std::string Payload(const std::string& origin, uint8_t lane, uint64_t seq, size_t size) {
  std::string s(size, '\0');
  std::mt19937 rng(static_cast<uint32_t>(std::hash<std::string>()(origin) + lane * 7919 + seq));
  for (char& c : s) c = static_cast<char>(rng());
  return s;
}

TEST(ExchangeTest, TwoRobotsOnAPerfectLinkGetEveryItemOnce) {
  Team team({"a", "b"}, {{"a", "b"}}, LinkProfile{}, ExchangeOptions{});
  for (uint64_t i = 1; i <= 20; ++i) {
    ASSERT_TRUE(team.robot("a").exchange->Publish(0, 7, Payload("a", 0, i, 100)).ok());
  }
  ASSERT_TRUE(team.robot("a").exchange->Publish(1, 9, Payload("a", 1, 1, 100000)).ok());
  for (int i = 0; i < 3000 && !team.Converged(); ++i) {
    // b publishes as it goes: what it gets back of its own would be an echo.
    if (i % 10 == 0 && i < 200) {
      ASSERT_TRUE(team.robot("b").exchange->Publish(0, 7, Payload("b", 0, i / 10 + 1, 50)).ok());
    }
    team.Step(Duration::Milliseconds(10));
  }
  ASSERT_TRUE(team.Converged());
  for (int i = 0; i < 200; ++i) team.Step(Duration::Milliseconds(10));  // the last acknowledgement
  Robot& b = team.robot("b");
  EXPECT_EQ(b.store->HighWaterMark("a", 0), 20u);
  EXPECT_EQ(b.store->HighWaterMark("a", 1), 1u);
  for (const auto& [key, count] : b.seen) EXPECT_EQ(count, 1);
  EXPECT_EQ(b.payloads.at({"a", 1, 1}), Payload("a", 1, 1, 100000));
  EXPECT_EQ(b.payloads.at({"a", 0, 20}), Payload("a", 0, 20, 100));
  const auto stats = team.robot("a").exchange->PeerStats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].items_sent, 21u);
  EXPECT_EQ(stats[0].queued_items, 0u);
  EXPECT_EQ(stats[0].duplicates, 0u);
  EXPECT_EQ(b.exchange->PeerStats()[0].duplicates, 0u);
  EXPECT_EQ(b.exchange->PeerStats()[0].items_sent, 20u);
}

TEST(ExchangeTest, ConstraintsOvertakeASubmapBacklog) {
  ExchangeOptions options;
  options.link_bytes_per_s = 10000;
  Team team({"a", "b"}, {{"a", "b"}}, LinkProfile{}, options);
  for (uint64_t i = 1; i <= 3; ++i) ASSERT_TRUE(team.robot("a").exchange->Publish(1, 9, Payload("a", 1, i, 60000)).ok());
  for (int i = 0; i < 200; ++i) team.Step(Duration::Milliseconds(10));  // 2 s: the first submap is on its way
  ASSERT_TRUE(team.robot("a").exchange->Publish(0, 7, Payload("a", 0, 1, 200)).ok());
  const Timestamp published = team.now();
  Timestamp constraint_arrived, submaps_arrived;
  for (int i = 0; i < 5000 && !team.Converged(); ++i) {
    team.Step(Duration::Milliseconds(10));
    if (constraint_arrived == Timestamp() && team.robot("b").store->HighWaterMark("a", 0) == 1)
      constraint_arrived = team.now();
  }
  ASSERT_TRUE(team.Converged());
  submaps_arrived = team.now();
  // 180 KB at 10 KB/s take 18 s; the constraint waits for one fragment at most.
  EXPECT_LT((constraint_arrived - published).seconds(), 2.0);
  EXPECT_GT((submaps_arrived - published).seconds(), 10.0);
}

// Acknowledgements that do not come back (the return link is down) must not fill the forward
// link with copies: each resend without progress waits twice as long as the one before.
TEST(ExchangeTest, ResendsBackOffWhileTheReturnLinkIsDown) {
  ExchangeOptions options;
  options.link_bytes_per_s = 200000;  // more than the link carries
  options.resend_timeout = 3.0;
  LinkProfile profile;
  profile.bytes_per_s = 50000;
  Team team({"a", "b"}, {{"a", "b"}}, profile, options);
  // Both hear each other and agree on the lane first, then b's summaries are lost for a minute.
  ASSERT_TRUE(team.robot("a").exchange->Publish(1, 9, Payload("a", 1, 1, 100)).ok());
  for (int i = 0; i < 300; ++i) team.Step(Duration::Milliseconds(10));
  ASSERT_EQ(team.robot("a").exchange->PeerStats()[0].queued_items, 0u);
  LinkProfile back = profile;
  back.seed = 99;
  back.outages.emplace_back(team.now(), team.now() + Duration::Seconds(60.0));
  team.link("b", "a") = LinkEmulator(back);
  for (uint64_t i = 2; i <= 5; ++i) ASSERT_TRUE(team.robot("a").exchange->Publish(1, 9, Payload("a", 1, i, 40000)).ok());
  for (int i = 0; i < 6000; ++i) team.Step(Duration::Milliseconds(10));
  EXPECT_EQ(team.robot("b").store->HighWaterMark("a", 1), 5u);
  // The 160 KB went once and were resent after 3, 9, 21 and 45 s (timeouts 3, 6, 12, 24 s);
  // without the back-off, every 3 s: 20 times.
  const auto stats = team.robot("a").exchange->PeerStats()[0];
  EXPECT_EQ(stats.resends, 4u);
  EXPECT_LE(stats.items_sent, 1u + 5u * 4u);
  EXPECT_LT(team.link("a", "b").counters().bytes, 5u * 4u * 42000u);
  // Heard again: the first summary acknowledges everything, and the peer settles.
  for (int i = 0; i < 500 && !team.Converged(); ++i) team.Step(Duration::Milliseconds(10));
  for (int i = 0; i < 300; ++i) team.Step(Duration::Milliseconds(10));
  EXPECT_EQ(team.robot("a").exchange->PeerStats()[0].queued_items, 0u);
  EXPECT_EQ(team.robot("a").exchange->PeerStats()[0].resends, 4u);
}

// A resend goes back to the first item the peer lacks, but not over what the peer holds already
// beyond it: whole items waiting for that one, and the first pieces of the items in pieces.
TEST(ExchangeTest, ResendsSkipWhatThePeerHoldsAhead) {
  // 800 KB through a link that loses one message in five, on five seeds: 7.6 MB sent in all,
  // where resending everything after a lost piece took 10.6 MB. On 30 seeds, delivery took 18.0 s
  // (median; at most 24.0 s) instead of 25.0 s (33.4 s).
  uint64_t sent = 0, skipped = 0, resumed = 0;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    ExchangeOptions options;
    options.resend_timeout = 3.0;
    options.link_bytes_per_s = 100000;
    LinkProfile profile;
    profile.bytes_per_s = 100000;
    profile.delay = Duration::Milliseconds(100);
    profile.loss = 0.2;
    profile.seed = seed;
    Team team({"a", "b"}, {{"a", "b"}}, profile, options);
    for (uint64_t i = 1; i <= 8; ++i) {
      ASSERT_TRUE(team.robot("a").exchange->Publish(1, 9, Payload("a", 1, i, 100000)).ok());
    }
    for (int i = 0; i < 12000 && !team.Converged(); ++i) team.Step(Duration::Milliseconds(10));
    ASSERT_TRUE(team.Converged());
    for (uint64_t i = 1; i <= 8; ++i) EXPECT_EQ(team.robot("b").payloads.at({"a", 1, i}), Payload("a", 1, i, 100000));
    const auto stats = team.robot("a").exchange->PeerStats()[0];
    sent += stats.sent_bytes;
    skipped += stats.skipped_items;
    resumed += stats.resumed_bytes;
  }
  EXPECT_GT(skipped, 0u);
  EXPECT_GT(resumed, 0u);
  EXPECT_LT(sent, 9000000u);
}

// What a broken or lying teammate sends: every message refused or clamped, counted, and the
// exchange still delivers the honest items afterwards.
TEST(ExchangeTest, RefusesCorruptTruncatedForgedAndLyingMessages) {
  Team team({"a", "b"}, {{"a", "b"}}, LinkProfile{}, ExchangeOptions{});
  Robot& a = team.robot("a");
  Robot& b = team.robot("b");
  ASSERT_TRUE(b.exchange->Publish(0, 7, Payload("b", 0, 1, 500)).ok());
  for (int i = 0; i < 100; ++i) team.Step(Duration::Milliseconds(10));
  ASSERT_EQ(a.store->HighWaterMark("b", 0), 1u);
  const Timestamp now = team.now();

  auto fragment = [](exchange::Envelope& e, const std::string& origin, uint64_t seq, const std::string& payload,
                     uint32_t offset, size_t size, uint32_t crc) {
    auto* f = e.add_fragments();
    f->set_origin(origin);
    f->set_lane(0);
    f->set_seq(seq);
    f->set_kind(7);
    f->set_total_bytes(static_cast<uint32_t>(payload.size()));
    f->set_offset(offset);
    f->set_data(payload.substr(offset, size));
    f->set_payload_crc32(crc);
  };
  exchange::Envelope good;
  good.set_version(kExchangeProtocolVersion);
  const std::string payload = Payload("b", 0, 2, 400);
  fragment(good, "b", 2, payload, 0, payload.size(), Crc32::Of(std::span<const uint8_t>(
      reinterpret_cast<const uint8_t*>(payload.data()), payload.size())));
  const std::string bytes = good.SerializeAsString();

  // Not protobuf, truncated, another protocol version.
  a.exchange->OnMessage("b", "\xff\xff\xff\xff garbage", now);
  a.exchange->OnMessage("b", bytes.substr(0, bytes.size() / 2), now);
  exchange::Envelope future = good;
  future.set_version(kExchangeProtocolVersion + 1);
  a.exchange->OnMessage("b", future.SerializeAsString(), now);
  EXPECT_EQ(a.exchange->PeerStats()[0].refused_messages, 3u);
  EXPECT_EQ(a.store->HighWaterMark("b", 0), 1u);

  // A payload that fails its CRC, a fragment beyond its item, an item larger than allowed.
  exchange::Envelope bad;
  bad.set_version(kExchangeProtocolVersion);
  fragment(bad, "b", 2, payload, 0, payload.size(), 12345);
  fragment(bad, "b", 3, payload, 0, payload.size(), 0);
  bad.mutable_fragments(1)->set_offset(1000);
  fragment(bad, "b", 4, payload, 0, 10, 0);
  bad.mutable_fragments(2)->set_total_bytes(static_cast<uint32_t>(ExchangeOptions{}.max_item_bytes + 1));
  a.exchange->OnMessage("b", bad.SerializeAsString(), now);
  EXPECT_EQ(a.exchange->PeerStats()[0].refused_fragments, 3u);
  EXPECT_EQ(a.store->HighWaterMark("b", 0), 1u);

  // Items forged under a's own name, and a summary claiming more of a's log than a made.
  exchange::Envelope forged;
  forged.set_version(kExchangeProtocolVersion);
  fragment(forged, "a", 1, payload, 0, payload.size(), 0);
  auto* mark = forged.mutable_summary()->add_marks();
  mark->set_origin("a");
  mark->set_lane(0);
  mark->set_high_water_mark(1000000);
  a.exchange->OnMessage("b", forged.SerializeAsString(), now);
  EXPECT_EQ(a.exchange->stats().own_origin_refused, 1u);
  EXPECT_EQ(a.exchange->PeerStats()[0].implausible_marks, 1u);
  EXPECT_EQ(a.store->HighWaterMark("a", 0), 0u);

  // What b holds beyond its marks, of a lane that does not exist and stated unevenly.
  exchange::Envelope ahead;
  ahead.set_version(kExchangeProtocolVersion);
  auto* no_lane = ahead.mutable_summary()->add_ahead();
  no_lane->set_origin("a");
  no_lane->set_lane(7);
  no_lane->add_held(1);
  auto* uneven = ahead.mutable_summary()->add_ahead();
  uneven->set_origin("a");
  uneven->set_lane(0);
  uneven->add_partial_seq(1);
  a.exchange->OnMessage("b", ahead.SerializeAsString(), now);
  EXPECT_EQ(a.exchange->PeerStats()[0].refused_fragments, 5u);

  // A piece of the next item, then the whole item cut differently (another sender's fragment
  // size): the longer piece replaces the shorter one.
  exchange::Envelope piece;
  piece.set_version(kExchangeProtocolVersion);
  const std::string next = Payload("b", 0, 3, 400);
  const uint32_t next_crc = Crc32::Of(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(next.data()), next.size()));
  fragment(piece, "b", 3, next, 0, 100, next_crc);
  a.exchange->OnMessage("b", piece.SerializeAsString(), now);
  piece.mutable_fragments(0)->set_data(next);
  a.exchange->OnMessage("b", piece.SerializeAsString(), now);
  EXPECT_EQ(a.store->HighWaterMark("b", 0), 1u);  // held until item 2 arrives

  // The same honest message twice: stored once.
  a.exchange->OnMessage("b", bytes, now);
  a.exchange->OnMessage("b", bytes, now);
  EXPECT_EQ(a.store->HighWaterMark("b", 0), 3u);
  EXPECT_EQ(a.payloads.at({"b", 0, 3}), next);
  EXPECT_EQ(a.seen.at({"b", 0, 2}), 1);
  EXPECT_EQ(a.exchange->PeerStats()[0].duplicates, 1u);

  // And the link still works: a's own items reach b, which believes a holds nothing of b's lies.
  ASSERT_TRUE(a.exchange->Publish(0, 7, Payload("a", 0, 1, 300)).ok());
  for (int i = 0; i < 300; ++i) team.Step(Duration::Milliseconds(10));
  EXPECT_EQ(b.store->HighWaterMark("a", 0), 1u);
  EXPECT_EQ(b.payloads.at({"a", 0, 1}), Payload("a", 0, 1, 300));
}

TEST(ExchangeTest, AMeshedTeamRelaysNothingTwice) {
  // Every robot hears every other directly: relays would only duplicate, so they wait.
  Team team({"a", "b", "c"}, {{"a", "b"}, {"b", "c"}, {"a", "c"}}, LinkProfile{}, ExchangeOptions{});
  for (int i = 0; i < 2000 && (i < 300 || !team.Converged()); ++i) {
    if (i % 15 == 0 && i < 300) {
      for (const std::string n : {"a", "b", "c"}) {
        ASSERT_TRUE(team.robot(n).exchange->Publish(0, 1, Payload(n, 0, i / 15 + 1, 200)).ok());
      }
    }
    team.Step(Duration::Milliseconds(10));
  }
  ASSERT_TRUE(team.Converged());
  for (const std::string n : {"a", "b", "c"}) {
    EXPECT_EQ(team.robot(n).store->HighWaterMark("a", 0), 20u);
    for (const ExchangePeerStats& s : team.robot(n).exchange->PeerStats()) {
      EXPECT_EQ(s.duplicates, 0u) << n << " from " << s.name;
      EXPECT_EQ(s.items_sent, 20u) << n << " to " << s.name;  // its own only
    }
  }
}

void RunFaultMission(uint64_t seed) {
  // a - b - c: a and c reach each other only through b. 30 % of messages lost, 2 s one way plus
  // up to 0.5 s jitter (reordering), 20 KB/s links, c cut off for 60 s, b restarted mid-run.
  LinkProfile profile;
  profile.delay = Duration::Seconds(2.0);
  profile.jitter = Duration::Seconds(0.5);
  profile.bytes_per_s = 20000;
  profile.loss = 0.3;
  profile.seed = seed;
  const Timestamp t0 = Timestamp::FromSeconds(1000.0);  // Team's clock starts here
  ExchangeOptions options;
  options.resend_timeout = 6.0;
  Team team({"a", "b", "c"}, {{"a", "b"}, {"b", "c"}}, profile, options, "c",
            {t0 + Duration::Seconds(30.0), t0 + Duration::Seconds(90.0)});
  std::map<std::string, uint64_t> small, large;
  const Duration dt = Duration::Milliseconds(20);
  const Timestamp start = team.now();
  bool restarted = false;
  for (int step = 0; step < 6000; ++step) {  // 120 s
    const double t = (team.now() - start).seconds();
    for (const std::string n : {"a", "b", "c"}) {
      Robot& r = team.robot(n);
      if (step % 25 == 0) {  // poses and constraints, 2 Hz
        ++small[n];
        ASSERT_TRUE(r.exchange->Publish(0, 1, Payload(n, 0, small[n], 300)).ok());
      }
      if (step % 1000 == 500) {  // a submap every 20 s
        ++large[n];
        ASSERT_TRUE(r.exchange->Publish(1, 2, Payload(n, 1, large[n], 50000)).ok());
      }
    }
    if (!restarted && t > 70.0) {  // b's process dies and comes back on the same disk
      team.robot("b").Start();
      restarted = true;
    }
    team.Step(dt);
  }
  int settle = 0;
  while (!team.Converged() && settle < 30000) {
    team.Step(dt);
    ++settle;
  }
  ASSERT_TRUE(team.Converged()) << "not converged after " << settle * dt.seconds() << " s";
  for (const std::string n : {"a", "b", "c"}) {
    Robot& r = team.robot(n);
    for (const std::string origin : {"a", "b", "c"}) {
      EXPECT_EQ(r.store->HighWaterMark(origin, 0), small[origin]) << n << " of " << origin;
      EXPECT_EQ(r.store->HighWaterMark(origin, 1), large[origin]) << n << " of " << origin;
    }
    for (const auto& [key, count] : r.seen) EXPECT_EQ(count, 1) << n;
    for (const auto& [key, payload] : r.payloads) {
      EXPECT_EQ(payload, Payload(std::get<0>(key), std::get<1>(key), std::get<2>(key), payload.size())) << n;
    }
  }
  // The restarted b saw every item once in its second life: replayed from disk or received.
  uint64_t total = 0;
  for (const auto& [o, k] : small) total += k;
  for (const auto& [o, k] : large) total += k;
  EXPECT_EQ(team.robot("b").seen.size(), total);
  EXPECT_GT(team.link("a", "b").counters().lost, 0u);
  EXPECT_GT(team.link("a", "b").counters().reordered, 0u);
  EXPECT_GT(team.link("b", "c").counters().lost_in_outage, 0u);
  // Within budget: what each robot sent over each link, per second of the run.
  const double seconds = (team.now() - start).seconds();
  for (const std::string n : {"a", "b", "c"}) {
    for (const ExchangePeerStats& s : team.robot(n).exchange->PeerStats()) {
      EXPECT_LE(static_cast<double>(s.sent_bytes) / seconds, options.link_bytes_per_s) << n << " -> " << s.name;
    }
  }
}

TEST(ExchangeTest, ThroughLossDelayOutageRelayAndRestartEveryItemArrivesOnce) {
  for (uint64_t seed : {11u, 23u, 37u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    RunFaultMission(seed);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace cairn
