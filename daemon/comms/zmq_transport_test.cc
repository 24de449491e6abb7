#include "daemon/comms/zmq_transport.h"

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include <gtest/gtest.h>

namespace cairn {
namespace {

using Clock = std::chrono::steady_clock;

CurveKeyPair Keys() {
  auto k = CurveKeys::Generate();
  EXPECT_TRUE(k.ok());
  return *k;
}

// A transport bound to an ephemeral loopback port; peers are added by Connect().
struct Node {
  std::string name;
  CurveKeyPair keys = Keys();
  std::unique_ptr<ZmqTransport> transport;
};

ZmqTransportOptions Options(const std::string& listen = "tcp://127.0.0.1:0") {
  ZmqTransportOptions o;
  o.listen = listen;
  o.reconnect_interval = 0.05;
  o.reconnect_interval_max = 0.2;
  return o;
}

std::unique_ptr<ZmqTransport> Make(const ZmqTransportOptions& options, const CurveKeyPair& keys,
                                   const std::vector<ZmqPeer>& peers) {
  auto t = ZmqTransport::Create(options, keys, peers);
  EXPECT_TRUE(t.ok()) << t.status().ToString();
  return t.ok() ? std::move(*t) : nullptr;
}

// Sends until the peer is connected (IMMEDIATE refuses before), then waits for what arrives.
std::optional<ZmqMessage> SendAndReceive(ZmqTransport& from, const std::string& to, ZmqTransport& at,
                                         const std::string& bytes, std::chrono::seconds limit = std::chrono::seconds(10)) {
  const auto deadline = Clock::now() + limit;
  bool sent = false;
  while (Clock::now() < deadline) {
    if (!sent) sent = from.Send(to, bytes).ok();
    if (auto m = at.Receive(Duration::Milliseconds(20))) return m;
  }
  return std::nullopt;
}

// Two transports that know each other's keys, on ports the kernel picked.
struct Pair {
  Pair() {
    // Bind first (no peers yet) to learn the ports, then make the real ones at those ports.
    a_keys = Keys();
    b_keys = Keys();
    auto probe_a = Make(Options(), a_keys, {});
    auto probe_b = Make(Options(), b_keys, {});
    a_endpoint = probe_a->bound_endpoint();
    b_endpoint = probe_b->bound_endpoint();
    probe_a.reset();
    probe_b.reset();
    a = Make(Options(a_endpoint), a_keys, {{"b", b_endpoint, b_keys.public_key}});
    b = Make(Options(b_endpoint), b_keys, {{"a", a_endpoint, a_keys.public_key}});
  }
  CurveKeyPair a_keys, b_keys;
  std::string a_endpoint, b_endpoint;
  std::unique_ptr<ZmqTransport> a, b;
};

TEST(ZmqTransportTest, TeammatesTalkBothWaysNamedByTheirKeys) {
  Pair p;
  ASSERT_TRUE(p.a && p.b);
  auto m = SendAndReceive(*p.a, "b", *p.b, "hello b");
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->peer, "a");
  EXPECT_EQ(m->bytes, "hello b");
  m = SendAndReceive(*p.b, "a", *p.a, std::string(100000, 'x'));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->peer, "b");
  EXPECT_EQ(m->bytes.size(), 100000u);
  // Many in a row arrive in order.
  for (int i = 0; i < 100; ++i) {
    while (!p.a->Send("b", std::to_string(i)).ok()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  int next = 0;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (next < 100 && Clock::now() < deadline) {
    if (auto r = p.b->Receive(Duration::Milliseconds(20))) {
      EXPECT_EQ(r->bytes, std::to_string(next++));
    }
  }
  EXPECT_EQ(next, 100);
  const ZmqTransportCounters c = p.b->counters();
  EXPECT_EQ(c.received_messages, 101u);
  EXPECT_EQ(c.refused_unknown_key, 0u);
  EXPECT_GT(c.received_bytes_by_peer.at("a"), 0u);
  EXPECT_EQ(p.a->Send("nobody", "x").code(), StatusCode::kNotFound);
}

TEST(ZmqTransportTest, AnUnlistedKeyIsRefusedAndCounted) {
  Pair p;
  ASSERT_TRUE(p.a && p.b);
  // The intruder knows a's address and key, but a's team does not list the intruder's key.
  const CurveKeyPair intruder_keys = Keys();
  auto intruder = Make(Options(), intruder_keys, {{"a", p.a_endpoint, p.a_keys.public_key}});
  ASSERT_TRUE(intruder);
  const auto deadline = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < deadline && p.a->counters().refused_unknown_key == 0) {
    (void)intruder->Send("a", "let me in");
    EXPECT_FALSE(p.a->Receive(Duration::Milliseconds(20)).has_value());
  }
  EXPECT_GT(p.a->counters().refused_unknown_key, 0u);
  // It never connects, so it cannot even queue a message.
  EXPECT_EQ(intruder->counters().sent_messages, 0u);
  // The team still talks.
  auto m = SendAndReceive(*p.b, "a", *p.a, "still here");
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->peer, "b");
}

TEST(ZmqTransportTest, AServerWithAnotherKeyIsNeverSentTo) {
  const CurveKeyPair a_keys = Keys(), b_keys = Keys(), impostor_keys = Keys();
  auto probe = Make(Options(), impostor_keys, {});
  const std::string endpoint = probe->bound_endpoint();
  probe.reset();
  // The impostor listens where b should be and even lists a's key; a expects b's key there.
  auto impostor = Make(Options(endpoint), impostor_keys, {{"a", "tcp://127.0.0.1:1", a_keys.public_key}});
  auto a = Make(Options(), a_keys, {{"b", endpoint, b_keys.public_key}});
  ASSERT_TRUE(impostor && a);
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  while (Clock::now() < deadline) {
    EXPECT_FALSE(a->Send("b", "secret").ok());
    EXPECT_FALSE(impostor->Receive(Duration::Milliseconds(20)).has_value());
  }
  EXPECT_EQ(a->counters().sent_messages, 0u);
  EXPECT_GT(a->counters().send_queue_full, 0u);
}

TEST(ZmqTransportTest, AnOversizedMessageIsDroppedAndTheLinkRecovers) {
  Pair p;
  ASSERT_TRUE(p.a && p.b);
  ZmqTransportOptions small = Options(p.b_endpoint);
  small.max_message_bytes = 10000;
  p.b.reset();
  p.b = Make(small, p.b_keys, {{"a", p.a_endpoint, p.a_keys.public_key}});
  ASSERT_TRUE(p.b);
  ASSERT_TRUE(SendAndReceive(*p.a, "b", *p.b, "small").has_value());
  // The oversized one drops a's connection: it never arrives; a reconnects for what follows.
  ASSERT_TRUE(p.a->Send("b", std::string(20000, 'y')).ok());
  std::optional<ZmqMessage> m;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline) {
    (void)p.a->Send("b", "after");
    m = p.b->Receive(Duration::Milliseconds(50));
    if (m) break;
  }
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->bytes, "after");
}

TEST(ZmqTransportTest, AnAbsentPeerIsUnavailableAndBadSetupsAreRefused) {
  const CurveKeyPair keys = Keys(), other = Keys();
  auto alone = Make(Options(), keys, {{"b", "tcp://127.0.0.1:9", other.public_key}});
  ASSERT_TRUE(alone);
  EXPECT_EQ(alone->Send("b", "anyone?").code(), StatusCode::kUnavailable);
  EXPECT_FALSE(alone->Receive(Duration::Milliseconds(10)).has_value());

  auto bad = ZmqTransport::Create(Options(), keys, {{"b", "tcp://127.0.0.1:9", "not a key"}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("'b'"), std::string::npos);
  bad = ZmqTransport::Create(Options(), keys, {{"b", "tcp://127.0.0.1:9", keys.public_key}});
  EXPECT_FALSE(bad.ok());
  bad = ZmqTransport::Create(Options(), keys,
                             {{"b", "tcp://127.0.0.1:9", other.public_key}, {"c", "tcp://127.0.0.1:8", other.public_key}});
  EXPECT_FALSE(bad.ok());
  bad = ZmqTransport::Create(Options("tcp://256.1.1.1:5"), keys, {});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("256.1.1.1"), std::string::npos);
}

TEST(ZmqTransportTest, ClosingWhileThePeerStillSendsIsClean) {
  Pair p;
  ASSERT_TRUE(p.a && p.b);
  ASSERT_TRUE(SendAndReceive(*p.a, "b", *p.b, "x").has_value());
  std::atomic<bool> stop{false};
  std::thread sender([&] {
    while (!stop) (void)p.a->Send("b", std::string(1000, 'z'));
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  p.b.reset();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  stop = true;
  sender.join();
  SUCCEED();
}

}  // namespace
}  // namespace cairn
