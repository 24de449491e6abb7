#include "drivers/socketcan_wheel_driver.h"

#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>

#include <gtest/gtest.h>

#include "tests/support/recording_sink.h"

namespace cairn {
namespace {

using testing::RecordingSink;

CanWheelOptions RoverLayout() {
  CanWheelOptions o;
  o.enabled = true;
  o.sync_id = 0x120;
  o.timeout = 0.2;
  WheelCanOptions* w[] = {&o.front_left, &o.front_right, &o.rear_left, &o.rear_right};
  for (int i = 0; i < 4; ++i) {
    w[i]->speed.id = 0x101 + i;
    w[i]->speed.scale = 0.001;
    w[i]->steering.id = 0x101 + i;
    w[i]->steering.start_byte = 2;
    w[i]->steering.scale = 0.0001;
    w[i]->steered = true;
  }
  return o;
}

// One controller cycle: four wheel frames then the sync frame.
std::vector<can_frame> Cycle(const CanWheelOptions& o, double speed, double steer) {
  std::vector<can_frame> frames;
  const WheelCanOptions* w[] = {&o.front_left, &o.front_right, &o.rear_left, &o.rear_right};
  for (int i = 0; i < 4; ++i) {
    can_frame f{};
    EncodeCanSignal(w[i]->speed, speed + 0.01 * i, &f);
    EncodeCanSignal(w[i]->steering, steer, &f);
    frames.push_back(f);
  }
  can_frame sync{};
  sync.can_id = 0x120;
  frames.push_back(sync);
  return frames;
}

// The read path through a SOCK_SEQPACKET socketpair carrying struct can_frame records, exactly as
// a CAN_RAW socket delivers them; it runs everywhere, unlike vcan.
TEST(SocketCanWheelDriverTest, DecodesFramesFromASeqpacketStream) {
  int sv[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  const CanWheelOptions o = RoverLayout();
  RecordingSink sink;
  SocketCanWheelDriver driver(o, sv[0]);
  ASSERT_TRUE(driver.Start(&sink).ok());
  for (int c = 0; c < 10; ++c) {
    for (const can_frame& f : Cycle(o, 0.5 + 0.1 * c, -0.2)) {
      ASSERT_EQ(write(sv[1], &f, sizeof(f)), static_cast<ssize_t>(sizeof(f)));
    }
  }
  ASSERT_TRUE(sink.WaitFor([&] { return sink.wheel.size() == 10; }));
  {
    std::lock_guard lock(sink.mutex);
    for (int c = 0; c < 10; ++c) {
      const WheelOdometrySample& s = sink.wheel[static_cast<size_t>(c)];
      EXPECT_EQ(s.fresh_mask, 0b1111);
      EXPECT_NEAR(s.wheels[3].speed, 0.5 + 0.1 * c + 0.03, 1e-9);
      EXPECT_NEAR(s.wheels[0].steering_angle, -0.2, 1e-9);
      if (c > 0) {
        EXPECT_GE(s.time, sink.wheel[static_cast<size_t>(c - 1)].time);
      }
    }
  }
  // A record that is not a whole can_frame is reported, not misread.
  const char junk[5] = {1, 2, 3, 4, 5};
  ASSERT_EQ(write(sv[1], junk, sizeof(junk)), 5);
  ASSERT_TRUE(sink.WaitFor([&] {
    return !sink.faults.empty() && sink.faults.back().kind == DeviceFaultKind::kCorruptSample;
  }));
  // The peer vanishing is a disconnect fault; the driver thread ends cleanly.
  close(sv[1]);
  ASSERT_TRUE(sink.WaitFor([&] {
    return sink.faults.back().kind == DeviceFaultKind::kDisconnected;
  }));
  driver.Stop();
  EXPECT_EQ(driver.frames_received(), 50u);
}

TEST(SocketCanWheelDriverTest, SilentBusIsReportedOnceAsTimeout) {
  int sv[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  CanWheelOptions o = RoverLayout();
  o.timeout = 0.05;
  RecordingSink sink;
  SocketCanWheelDriver driver(o, sv[0]);
  ASSERT_TRUE(driver.Start(&sink).ok());
  ASSERT_TRUE(sink.WaitFor([&] { return !sink.faults.empty(); }));
  usleep(200 * 1000);  // several more timeout periods: still one report per outage
  driver.Stop();
  std::lock_guard lock(sink.mutex);
  ASSERT_EQ(sink.faults.size(), 1u);
  EXPECT_EQ(sink.faults[0].kind, DeviceFaultKind::kTimeout);
  close(sv[1]);
}

TEST(SocketCanWheelDriverTest, MissingInterfaceDegradesInsteadOfFailing) {
  CanWheelOptions o = RoverLayout();
  o.interface = "cairn-nocan0";
  RecordingSink sink;
  SocketCanWheelDriver driver(o);
  EXPECT_TRUE(driver.Start(&sink).ok());
  ASSERT_TRUE(sink.WaitFor([&] { return !sink.faults.empty(); }));
  driver.Stop();
  EXPECT_EQ(sink.faults[0].kind, DeviceFaultKind::kDisconnected);
  EXPECT_NE(sink.faults[0].detail.find("cairn-nocan0"), std::string::npos);
}

// The real SocketCAN path on a virtual CAN interface, where the kernel has the vcan module.
TEST(SocketCanWheelDriverTest, DecodesOnVcan) {
  const std::string ifname = "cairnvcan" + std::to_string(getpid() % 1000);
  const std::string add = "ip link add dev " + ifname + " type vcan 2>/dev/null && ip link set up " + ifname;
  if (std::system(add.c_str()) != 0) {
    GTEST_SKIP() << "cannot create a vcan interface here (no vcan kernel module or no CAP_NET_ADMIN)";
  }
  CanWheelOptions o = RoverLayout();
  o.interface = ifname;
  RecordingSink sink;
  SocketCanWheelDriver driver(o);
  ASSERT_TRUE(driver.Start(&sink).ok());
  auto tx = SocketCanWheelDriver::OpenSocket(o);
  ASSERT_TRUE(tx.ok()) << tx.status().ToString();
  for (const can_frame& f : Cycle(o, 1.0, 0.1)) ASSERT_EQ(write(*tx, &f, sizeof(f)), static_cast<ssize_t>(sizeof(f)));
  const bool got = sink.WaitFor([&] { return !sink.wheel.empty(); });
  driver.Stop();
  close(*tx);
  (void)std::system(("ip link del dev " + ifname).c_str());
  ASSERT_TRUE(got);
  EXPECT_NEAR(sink.wheel[0].wheels[1].speed, 1.01, 1e-9);
}

}  // namespace
}  // namespace cairn
