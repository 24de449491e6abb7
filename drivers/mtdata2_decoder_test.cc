#include "drivers/mtdata2_decoder.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

void Packet(std::vector<uint8_t>* out, uint16_t xdi, const std::vector<uint8_t>& data) {
  out->push_back(static_cast<uint8_t>(xdi >> 8));
  out->push_back(static_cast<uint8_t>(xdi & 0xFF));
  out->push_back(static_cast<uint8_t>(data.size()));
  out->insert(out->end(), data.begin(), data.end());
}

std::vector<uint8_t> Floats(std::initializer_list<float> values) {
  std::vector<uint8_t> out;
  for (const float v : values) {
    uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(bits >> s));
  }
  return out;
}

std::vector<uint8_t> Doubles(std::initializer_list<double> values) {
  std::vector<uint8_t> out;
  for (const double v : values) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int s = 56; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(bits >> s));
  }
  return out;
}

TEST(Mtdata2DecoderTest, DecodesEveryKeptPacketAndSkipsOthers) {
  std::vector<uint8_t> p;
  Packet(&p, 0x1020, {0x12, 0x34});
  Packet(&p, 0x1060, {0x00, 0x01, 0x86, 0xA0});  // 100000 ticks = 10 s
  Packet(&p, 0x2010, Floats({1, 0, 0, 0}));      // a quaternion: not an IMU's business
  Packet(&p, 0x4020, Floats({0.5f, -0.25f, 9.75f}));
  Packet(&p, 0x8023, Doubles({0.1, -0.2, 0.3}));  // float64
  Packet(&p, 0xE020, {0, 0, 0, 3});
  const auto s = Mtdata2Decoder::Decode(p);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->counter, 0x1234);
  EXPECT_EQ(s->sample_time_fine, 100000u);
  EXPECT_EQ(s->acceleration, Eigen::Vector3d(0.5, -0.25, 9.75));
  EXPECT_EQ(s->rate_of_turn, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(s->status, 3u);
  EXPECT_EQ(s->skipped_packets, 1);

  std::vector<uint8_t> fixed;
  Packet(&fixed, 0x4021, {0x00, 0x10, 0x00, 0x00, 0xFF, 0xF8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00});  // 12.20
  const auto f = Mtdata2Decoder::Decode(fixed);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_EQ(f->acceleration, Eigen::Vector3d(1.0, -0.5, 0.0));
}

TEST(Mtdata2DecoderTest, RefusesWhatItCannotReadWithTheReason) {
  struct Case {
    std::vector<uint8_t> payload;
    StatusCode code;
    const char* text;
  };
  std::vector<Case> cases;
  std::vector<uint8_t> p;
  Packet(&p, 0x4020, Floats({1, 2}));
  cases.push_back({p, StatusCode::kDataLoss, "0x4020 has 8 bytes, expected 12"});
  p.clear();
  Packet(&p, 0x8020, Floats({1, 2, 3}));
  p.resize(p.size() - 2);
  cases.push_back({p, StatusCode::kDataLoss, "declares 12 bytes, 10 left"});
  cases.push_back({{0x10, 0x20}, StatusCode::kDataLoss, "inside a packet header"});
  p.clear();
  Packet(&p, 0x4024, Floats({1, 2, 3}));  // NED
  cases.push_back({p, StatusCode::kFailedPrecondition, "coordinates other than the sensor's own"});
  p.clear();
  Packet(&p, 0x4022, std::vector<uint8_t>(18, 0));  // fixed-point 16.32
  cases.push_back({p, StatusCode::kFailedPrecondition, "16.32"});
  p.clear();
  Packet(&p, 0x8020, Floats({1, std::numeric_limits<float>::quiet_NaN(), 3}));
  cases.push_back({p, StatusCode::kDataLoss, "non-finite"});
  p.clear();
  Packet(&p, 0x1020, {1});
  cases.push_back({p, StatusCode::kDataLoss, "0x1020 has 1 bytes, expected 2"});
  for (const Case& c : cases) {
    const auto s = Mtdata2Decoder::Decode(c.payload);
    ASSERT_FALSE(s.ok()) << c.text;
    EXPECT_EQ(s.status().code(), c.code) << s.status().ToString();
    EXPECT_NE(s.status().message().find(c.text), std::string::npos) << s.status().message();
  }
}

}  // namespace
}  // namespace cairn
