#include "drivers/can_wheel_decoder.h"

#include <linux/can/error.h>

#include <gtest/gtest.h>

namespace cairn {
namespace {

CanSignalOptions Signal(int64_t id, int64_t start, int64_t len, bool is_signed, ByteOrder order,
                        double scale) {
  CanSignalOptions s;
  s.id = id;
  s.start_byte = start;
  s.length = len;
  s.is_signed = is_signed;
  s.byte_order = order;
  s.scale = scale;
  return s;
}

TEST(CanSignalTest, DecodesLittleAndBigEndianSignedValues) {
  can_frame f{};
  f.can_id = 0x101;
  f.len = 4;
  // -1234 as little-endian int16 at byte 0: 0x2E 0xFB; 1000 as big-endian uint16 at 2: 0x03 0xE8.
  f.data[0] = 0x2E; f.data[1] = 0xFB; f.data[2] = 0x03; f.data[3] = 0xE8;
  const auto le = Signal(0x101, 0, 2, true, ByteOrder::kLittleEndian, 0.001);
  const auto be = Signal(0x101, 2, 2, false, ByteOrder::kBigEndian, 0.01);
  EXPECT_NEAR(*DecodeCanSignal(le, f), -1.234, 1e-12);
  EXPECT_NEAR(*DecodeCanSignal(be, f), 10.0, 1e-12);
  // A frame too short for the signal is rejected rather than read past its payload.
  f.len = 3;
  EXPECT_FALSE(DecodeCanSignal(be, f).has_value());
}

TEST(CanSignalTest, EncodeDecodeRoundTripIncludingExtendedIds) {
  for (int len = 1; len <= 4; ++len) {
    for (ByteOrder order : {ByteOrder::kLittleEndian, ByteOrder::kBigEndian}) {
      auto s = Signal(0x18FF0102, 3, len, true, order, 0.5);
      s.extended_id = true;
      can_frame f{};
      const double v = len == 1 ? -42.5 : -1234.5;
      EncodeCanSignal(s, v, &f);
      EXPECT_TRUE(CanIdMatches(s, f));
      EXPECT_DOUBLE_EQ(*DecodeCanSignal(s, f), v) << len;
    }
  }
  // Standard and extended identifiers with the same number are different frames.
  auto std_id = Signal(0x101, 0, 2, true, ByteOrder::kLittleEndian, 1.0);
  can_frame ext{};
  ext.can_id = 0x101 | CAN_EFF_FLAG;
  EXPECT_FALSE(CanIdMatches(std_id, ext));
}

CanWheelOptions FourWheels(int64_t sync_id) {
  CanWheelOptions o;
  o.sync_id = sync_id;
  WheelCanOptions* w[] = {&o.front_left, &o.front_right, &o.rear_left, &o.rear_right};
  for (int i = 0; i < 4; ++i) {
    w[i]->speed = Signal(0x101 + i, 0, 2, true, ByteOrder::kLittleEndian, 0.001);
    w[i]->steering = Signal(0x101 + i, 2, 2, true, ByteOrder::kLittleEndian, 0.0001);
    w[i]->steered = true;
  }
  return o;
}

TEST(CanWheelDecoderTest, SyncFramePublishesLatestStateWithFreshMask) {
  const CanWheelOptions o = FourWheels(0x120);
  CanWheelDecoder d(o);
  WheelOdometrySample out;
  const WheelCanOptions* w[] = {&o.front_left, &o.front_right, &o.rear_left, &o.rear_right};
  for (int i = 0; i < 3; ++i) {  // the fourth wheel's frame is missing in this cycle
    can_frame f{};
    EncodeCanSignal(w[i]->speed, 0.1 * (i + 1), &f);
    EncodeCanSignal(w[i]->steering, -0.05 * i, &f);
    EXPECT_EQ(d.Feed(f, Timestamp::FromNanoseconds(i), &out), CanWheelDecoder::Result::kUpdated);
  }
  can_frame sync{};
  sync.can_id = 0x120;
  ASSERT_EQ(d.Feed(sync, Timestamp::FromNanoseconds(99), &out), CanWheelDecoder::Result::kSampleReady);
  EXPECT_EQ(out.time.nanoseconds(), 99);
  EXPECT_EQ(out.fresh_mask, 0b0111);
  EXPECT_NEAR(out.wheels[2].speed, 0.3, 1e-12);
  EXPECT_NEAR(out.wheels[2].steering_angle, -0.1, 1e-12);
  EXPECT_EQ(out.wheels[3].speed, 0.0);
  // The next cycle starts with nothing fresh.
  ASSERT_EQ(d.Feed(sync, Timestamp::FromNanoseconds(100), &out), CanWheelDecoder::Result::kSampleReady);
  EXPECT_EQ(out.fresh_mask, 0);
}

TEST(CanWheelDecoderTest, ErrorShortUnknownAndRemoteFramesAreClassified) {
  CanWheelDecoder d(FourWheels(-1));
  WheelOdometrySample out;
  can_frame f{};
  f.can_id = 0x101;
  f.len = 1;  // speed needs two bytes
  EXPECT_EQ(d.Feed(f, Timestamp(), &out), CanWheelDecoder::Result::kMalformed);
  f.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  EXPECT_EQ(d.Feed(f, Timestamp(), &out), CanWheelDecoder::Result::kErrorFrame);
  f.can_id = 0x7FF;
  f.len = 8;
  EXPECT_EQ(d.Feed(f, Timestamp(), &out), CanWheelDecoder::Result::kIgnored);
  f.can_id = 0x101 | CAN_RTR_FLAG;
  EXPECT_EQ(d.Feed(f, Timestamp(), &out), CanWheelDecoder::Result::kIgnored);
  // Without a sync id every speed frame publishes.
  f.can_id = 0x102;
  EXPECT_EQ(d.Feed(f, Timestamp(), &out), CanWheelDecoder::Result::kSampleReady);
}

}  // namespace
}  // namespace cairn
