#include "daemon/comms/testing/link_emulator.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(LinkEmulatorTest, DelaysAndSerializesAtTheBandwidth) {
  LinkProfile p;
  p.delay = Duration::Seconds(2.0);
  p.bytes_per_s = 1000.0;
  LinkEmulator link(p);
  const Timestamp t = Timestamp::FromSeconds(1.0);
  link.Send(t, std::string(500, 'a'));  // on the wire until 1.5 s, arrives at 3.5 s
  link.Send(t, std::string(500, 'b'));  // behind it: 2.0 s, arrives at 4.0 s
  EXPECT_TRUE(link.Deliver(t + Duration::Seconds(2.4)).empty());
  auto first = link.Deliver(t + Duration::Seconds(2.5));
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0][0], 'a');
  EXPECT_TRUE(link.Deliver(t + Duration::Seconds(2.9)).empty());
  EXPECT_EQ(link.Deliver(t + Duration::Seconds(3.0)).size(), 1u);
}

TEST(LinkEmulatorTest, LosesAboutTheConfiguredShareAndReordersWithJitter) {
  LinkProfile p;
  p.loss = 0.3;
  p.jitter = Duration::Seconds(1.0);
  p.seed = 5;
  LinkEmulator link(p);
  Timestamp t = Timestamp::FromSeconds(0.0);
  for (int i = 0; i < 2000; ++i) {
    link.Send(t, "m");
    t += Duration::Milliseconds(10);
  }
  link.Deliver(t + Duration::Seconds(2.0));
  const double lost = static_cast<double>(link.counters().lost) / 2000.0;
  EXPECT_NEAR(lost, 0.3, 0.04);
  EXPECT_EQ(link.counters().delivered + link.counters().lost, 2000u);
  EXPECT_GT(link.counters().reordered, 100u);
}

TEST(LinkEmulatorTest, NothingPassesDuringAnOutage) {
  LinkProfile p;
  p.delay = Duration::Seconds(1.0);
  p.outages = {{Timestamp::FromSeconds(10.0), Timestamp::FromSeconds(20.0)}};
  LinkEmulator link(p);
  link.Send(Timestamp::FromSeconds(9.5), "arrives inside the outage");
  link.Send(Timestamp::FromSeconds(15.0), "sent inside");
  link.Send(Timestamp::FromSeconds(20.0), "after");
  const auto got = link.Deliver(Timestamp::FromSeconds(30.0));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], "after");
  EXPECT_EQ(link.counters().lost_in_outage, 2u);
}

}  // namespace
}  // namespace cairn
