#include "drivers/nmea_parser.h"

#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"

namespace cairn {
namespace {

// "$<body>*hh<end>" with the XOR of the body's bytes as hh.
std::string NmeaTestSentence(const std::string& body, const std::string& end = "\r\n") {
  unsigned sum = 0;
  for (const char c : body) sum ^= static_cast<unsigned char>(c);
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", sum);
  return "$" + body + "*" + hex + end;
}

// Munich's example position of the NMEA literature, 8 satellites, HDOP 0.9, 545.4 m above the
// geoid, which is 46.9 m above the ellipsoid.
std::string NmeaTestGga(const std::string& time = "123519.00",
                        const std::string& position = "4807.0380,N,01131.0000,E",
                        const std::string& quality = "1", const std::string& talker = "GP") {
  return NmeaTestSentence(talker + "GGA," + time + "," + position + "," + quality +
                          ",08,0.9,545.4,M,46.9,M,,");
}

// An error ellipse of sigmas 3 m (semi-major) and 2 m (semi-minor), sigma alt 4.5 m.
std::string NmeaTestGst(const std::string& time = "123519.00", const std::string& orientation = "0.0",
                        const std::string& talker = "GP") {
  return NmeaTestSentence(talker + "GST," + time + ",1.2,3.0,2.0," + orientation + ",2.0,3.0,4.5");
}

struct NmeaTestOutput {
  std::vector<GnssFix> fixes;
  std::vector<std::string> refused;
};

// Feeds `bytes` in chunks of `chunk`, all arriving at `arrival`.
void NmeaTestFeed(NmeaParser& parser, const std::string& bytes, double arrival, NmeaTestOutput* out,
                  size_t chunk = 1000) {
  for (size_t i = 0; i < bytes.size(); i += chunk) {
    const size_t n = std::min(chunk, bytes.size() - i);
    parser.Feed(
        std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.data()) + i, n),
        Timestamp::FromSeconds(arrival), [&](const GnssFix& f) { out->fixes.push_back(f); },
        [&](const Status& s) {
          EXPECT_EQ(s.code(), StatusCode::kDataLoss);
          out->refused.push_back(s.message());
        });
  }
}

NmeaGnssOptions NmeaTestOptions(bool use_gst = true) {
  NmeaGnssOptions o;
  o.use_gst = use_gst;
  return o;
}

constexpr double kNmeaTestLatitude = (48.0 + 7.038 / 60.0) * kDegree;
constexpr double kNmeaTestLongitude = (11.0 + 31.0 / 60.0) * kDegree;

TEST(NmeaParserTest, GgaAndGstOfOneEpochMakeOneFixInEitherOrderAndAnyChunking) {
  for (const size_t chunk : {size_t{1}, size_t{7}, size_t{1000}}) {
    NmeaGnssOptions o = NmeaTestOptions();
    o.latency = 0.1;
    NmeaParser parser(o);
    NmeaTestOutput out;
    NmeaTestFeed(parser, NmeaTestGga(), 10.0, &out, chunk);
    EXPECT_TRUE(out.fixes.empty());  // waits for its GST
    NmeaTestFeed(parser, NmeaTestGst(), 10.02, &out, chunk);
    // The other order in the next epoch: the time is still the GGA's.
    NmeaTestFeed(parser, NmeaTestGst("123520.00"), 11.0, &out, chunk);
    NmeaTestFeed(parser, NmeaTestGga("123520.00"), 11.03, &out, chunk);
    ASSERT_EQ(out.fixes.size(), 2u) << chunk;
    EXPECT_TRUE(out.refused.empty()) << out.refused.front();
    EXPECT_EQ(out.fixes[0].time, Timestamp::FromSeconds(9.9));
    EXPECT_EQ(out.fixes[1].time, Timestamp::FromSeconds(10.93));
    for (const GnssFix& f : out.fixes) {
      EXPECT_NEAR(f.latitude, kNmeaTestLatitude, 1e-12);
      EXPECT_NEAR(f.longitude, kNmeaTestLongitude, 1e-12);
      EXPECT_NEAR(f.height, 545.4 + 46.9, 1e-9);  // MSL altitude + geoid separation
      EXPECT_EQ(f.quality, GnssQuality::kAutonomous);
      EXPECT_EQ(f.satellites, 8);
      // Semi-major axis to the north: north 3 m, east 2 m, up 4.5 m.
      EXPECT_NEAR(f.covariance(0, 0), 4.0, 1e-12);
      EXPECT_NEAR(f.covariance(1, 1), 9.0, 1e-12);
      EXPECT_NEAR(f.covariance(2, 2), 20.25, 1e-12);
      EXPECT_NEAR(f.covariance(0, 1), 0.0, 1e-12);
      EXPECT_EQ(f.covariance(0, 2), 0.0);
      EXPECT_EQ(f.covariance(1, 2), 0.0);
    }
    EXPECT_EQ(parser.counts().fixes, 2u);
    EXPECT_EQ(parser.counts().sentences, 4u);
    EXPECT_EQ(parser.counts().hdop_fallbacks, 0u);
  }
}

TEST(NmeaParserTest, TheErrorEllipseIsRotatedByItsOrientation) {
  const auto covariance = [](const std::string& gst) {
    NmeaParser parser(NmeaTestOptions());
    NmeaTestOutput out;
    NmeaTestFeed(parser, NmeaTestGga() + gst, 1.0, &out);
    EXPECT_EQ(out.fixes.size(), 1u);
    EXPECT_TRUE(out.refused.empty()) << out.refused.front();
    return out.fixes.empty() ? Eigen::Matrix3d::Zero().eval() : out.fixes[0].covariance;
  };
  // 90 deg: the semi-major axis points east.
  Eigen::Matrix3d c = covariance(NmeaTestGst("123519.00", "90.0"));
  EXPECT_NEAR(c(0, 0), 9.0, 1e-12);
  EXPECT_NEAR(c(1, 1), 4.0, 1e-12);
  EXPECT_NEAR(c(0, 1), 0.0, 1e-12);
  // 45 deg (north-east): equal variances, errors east and north correlated positively.
  c = covariance(NmeaTestGst("123519.00", "45.0"));
  EXPECT_NEAR(c(0, 0), 6.5, 1e-12);
  EXPECT_NEAR(c(1, 1), 6.5, 1e-12);
  EXPECT_NEAR(c(0, 1), 2.5, 1e-12);
  EXPECT_NEAR(c(1, 0), 2.5, 1e-12);
  c = covariance(NmeaTestGst("123519.00", "135.0"));  // south-east: negatively
  EXPECT_NEAR(c(0, 1), -2.5, 1e-12);
  // No ellipse (empty, or zeros): sigma lon east, sigma lat north.
  for (const std::string ellipse : {",,", "0.0,0.0,0.0"}) {
    c = covariance(NmeaTestSentence("GPGST,123519.00,1.2," + ellipse + ",2.0,3.0,4.5"));
    EXPECT_NEAR(c(0, 0), 9.0, 1e-12) << ellipse;
    EXPECT_NEAR(c(1, 1), 4.0, 1e-12) << ellipse;
    EXPECT_EQ(c(0, 1), 0.0) << ellipse;
    EXPECT_NEAR(c(2, 2), 20.25, 1e-12) << ellipse;
  }
}

TEST(NmeaParserTest, WithoutGstTheCovarianceComesFromHdop) {
  // Off: every GGA is a fix at once; sigma 0.9 * 3 m per horizontal axis, 1.5 times that up.
  NmeaParser off(NmeaTestOptions(false));
  NmeaTestOutput out;
  NmeaTestFeed(off, NmeaTestGga() + NmeaTestGst(), 5.0, &out);
  ASSERT_EQ(out.fixes.size(), 1u);
  EXPECT_NEAR(out.fixes[0].covariance(0, 0), 2.7 * 2.7, 1e-12);
  EXPECT_NEAR(out.fixes[0].covariance(1, 1), 2.7 * 2.7, 1e-12);
  EXPECT_NEAR(out.fixes[0].covariance(2, 2), 4.05 * 4.05, 1e-12);
  EXPECT_EQ(off.counts().hdop_fallbacks, 1u);
  EXPECT_EQ(off.counts().ignored, 1u);  // the GST

  // On, but an epoch's GST does not come: the next epoch's first sentence publishes it, with
  // its own arrival time.
  NmeaParser on(NmeaTestOptions());
  out = {};
  NmeaTestFeed(on, NmeaTestGga("123519.00"), 1.0, &out);
  NmeaTestFeed(on, NmeaTestGga("123520.00"), 2.0, &out);
  ASSERT_EQ(out.fixes.size(), 1u);
  EXPECT_EQ(out.fixes[0].time, Timestamp::FromSeconds(1.0));
  EXPECT_NEAR(out.fixes[0].covariance(0, 0), 2.7 * 2.7, 1e-12);
  NmeaTestFeed(on, NmeaTestGst("123521.00"), 3.0, &out);  // a GST of yet another epoch
  ASSERT_EQ(out.fixes.size(), 2u);
  EXPECT_EQ(out.fixes[1].time, Timestamp::FromSeconds(2.0));
  NmeaTestFeed(on, NmeaTestGga("123521.00"), 3.1, &out);  // completes the pending GST's epoch
  ASSERT_EQ(out.fixes.size(), 3u);
  EXPECT_NEAR(out.fixes[2].covariance(1, 1), 9.0, 1e-12);
  // A GST without sigmas: its GGA goes out at once with HDOP.
  NmeaTestFeed(on, NmeaTestGga("123522.00") + NmeaTestSentence("GPGST,123522.00,1.2,,,,,,"), 4.0, &out);
  ASSERT_EQ(out.fixes.size(), 4u);
  EXPECT_NEAR(out.fixes[3].covariance(2, 2), 4.05 * 4.05, 1e-12);
  EXPECT_EQ(on.counts().hdop_fallbacks, 3u);
  EXPECT_TRUE(out.refused.empty());
}

TEST(NmeaParserTest, SouthernAndWesternHemispheresTalkersAndLineEnds) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  // GNSS, GLONASS, Galileo and BeiDou talkers; LF alone; a lowercase checksum; a negative geoid
  // separation; RTK fixed.
  std::string gga =
      NmeaTestSentence("GNGGA,235959.50,3352.1280,S,15112.5600,W,4,21,0.6,12.0,M,-23.5,M,2,0042", "\n");
  for (size_t i = gga.size() - 3; i < gga.size() - 1; ++i) gga[i] = static_cast<char>(std::tolower(gga[i]));
  NmeaTestFeed(parser, gga + NmeaTestGst("235959.50", "0.0", "GL"), 1.0, &out);
  NmeaTestFeed(parser, NmeaTestGga("000000.00", "0000.0000,N,00000.0000,E", "5", "GA"), 2.0, &out);
  NmeaTestFeed(parser, NmeaTestGst("000000.00", "0.0", "GB"), 2.0, &out);
  ASSERT_EQ(out.fixes.size(), 2u);
  EXPECT_TRUE(out.refused.empty()) << out.refused.front();
  EXPECT_NEAR(out.fixes[0].latitude, -(33.0 + 52.128 / 60.0) * kDegree, 1e-12);
  EXPECT_NEAR(out.fixes[0].longitude, -(151.0 + 12.56 / 60.0) * kDegree, 1e-12);
  EXPECT_NEAR(out.fixes[0].height, 12.0 - 23.5, 1e-9);
  EXPECT_EQ(out.fixes[0].quality, GnssQuality::kRtkFixed);
  EXPECT_EQ(out.fixes[0].satellites, 21);
  EXPECT_EQ(out.fixes[1].quality, GnssQuality::kRtkFloat);  // the epoch after midnight
  EXPECT_EQ(out.fixes[1].latitude, 0.0);
}

TEST(NmeaParserTest, OtherSentencesAreIgnoredAndCounted) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  const std::string others =
      NmeaTestSentence("GPRMC,123519.00,A,4807.0380,N,01131.0000,E,0.0,0.0,230394,,,A") +
      NmeaTestSentence("GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00") +
      NmeaTestSentence("PUBX,00,123519.00") + NmeaTestSentence("XXGGA,1,2,3");
  NmeaTestFeed(parser, NmeaTestGga() + others + NmeaTestGst(), 1.0, &out);
  EXPECT_EQ(out.fixes.size(), 1u);
  EXPECT_TRUE(out.refused.empty()) << out.refused.front();
  EXPECT_EQ(parser.counts().ignored, 4u);
  EXPECT_EQ(parser.counts().sentences, 6u);
}

TEST(NmeaParserTest, NoPositionIsNoFixNotAnError) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  // Quality 0 as receivers send it before their first fix, quality 6 (dead reckoning), and a
  // quality 1 with the altitude missing.
  NmeaTestFeed(parser,
               NmeaTestSentence("GPGGA,123519.00,,,,,0,00,99.99,,,,,,") +
                   NmeaTestGga("123520.00", "4807.0380,N,01131.0000,E", "6") +
                   NmeaTestSentence("GPGGA,123521.00,4807.0380,N,01131.0000,E,1,08,0.9,,M,46.9,M,,") +
                   NmeaTestSentence("GPGST,123521.00,,,,,,,"),
               1.0, &out);
  EXPECT_TRUE(out.fixes.empty());
  EXPECT_TRUE(out.refused.empty()) << out.refused.front();
  EXPECT_EQ(parser.counts().no_fix, 3u);
  EXPECT_EQ(parser.counts().corrupt, 0u);
}

TEST(NmeaParserTest, ABadChecksumIsRefusedAndTheNextSentenceRead) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  std::string damaged = NmeaTestGga();
  damaged[20] = '9';  // a digit of the latitude changed on the line
  NmeaTestFeed(parser, damaged + NmeaTestGst(), 1.0, &out);
  EXPECT_TRUE(out.fixes.empty());
  ASSERT_EQ(out.refused.size(), 1u);
  EXPECT_NE(out.refused[0].find("GPGGA: checksum"), std::string::npos) << out.refused[0];
  NmeaTestFeed(parser, NmeaTestGga("123520.00") + NmeaTestGst("123520.00"), 2.0, &out);
  EXPECT_EQ(out.fixes.size(), 1u);
  // No checksum at all, or not hexadecimal.
  NmeaTestFeed(parser,
               "$GPGGA,123521.00,,,,,0,00,99.99,,,,,,\r\n$GPGGA,123521.00,,,,,0,00,99.99,,,,,,*ZZ\r\n", 3.0,
               &out);
  ASSERT_EQ(out.refused.size(), 3u);
  EXPECT_NE(out.refused[1].find("GPGGA: no checksum"), std::string::npos) << out.refused[1];
  EXPECT_NE(out.refused[2].find("not hexadecimal"), std::string::npos) << out.refused[2];
  EXPECT_EQ(parser.counts().corrupt, 3u);
}

TEST(NmeaParserTest, GarbageTruncationAndAnEndlessLineAreRefusedAndResynchronized) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  const std::string garbage("\x00\xFF\x13zz", 5);
  const std::string truncated = NmeaTestGga().substr(0, 30);  // the next '$' cuts it
  const std::string endless = "$GPGGA," + std::string(400, '7');
  NmeaTestFeed(parser,
               garbage + NmeaTestGga() + NmeaTestGst() + truncated + NmeaTestGga("123520.00") +
                   NmeaTestGst("123520.00") + endless + "\r\n" + NmeaTestGga("123521.00") + "\r\n\r\n" +
                   NmeaTestGst("123521.00"),
               1.0, &out, 13);
  EXPECT_EQ(out.fixes.size(), 3u);
  ASSERT_EQ(out.refused.size(), 3u);
  EXPECT_EQ(out.refused[0], "5 bytes outside any NMEA sentence");
  EXPECT_EQ(out.refused[1], "GPGGA: cut short by the next '$' after 30 bytes");
  EXPECT_EQ(out.refused[2], "GPGGA: no line end within 128 bytes");
  EXPECT_EQ(parser.counts().corrupt, 3u);
  EXPECT_GT(parser.counts().skipped_bytes, 400u);
  // Control characters inside a sentence.
  NmeaTestFeed(parser,
               NmeaTestSentence("GPGGA,123522.00,4807.0380,N,\x01"
                                "01131.0000,E,1,08,0.9,545.4,M,46.9,M,,"),
               2.0, &out);
  ASSERT_EQ(out.refused.size(), 4u);
  EXPECT_EQ(out.refused[3], "GPGGA: byte 0x01 at column 29 is not printable ASCII");
}

TEST(NmeaParserTest, MalformedFieldsAreRefusedNamingSentenceAndField) {
  const struct {
    std::string sentence;
    std::string message;
  } cases[] = {
      {"GPGGA,123519.00,4807.0380,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M", "GPGGA: 12 fields, 14 expected"},
      {"GPGGA,123519.00,9130.0000,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 2 (latitude) '9130.0000' is beyond 90 deg"},
      {"GPGGA,123519.00,4861.0000,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 2 (latitude) '4861.0000' is not ddmm.mmmm"},
      {"GPGGA,123519.00,4807.0380,N,18030.0000,E,1,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 4 (longitude) '18030.0000' is beyond 180 deg"},
      {"GPGGA,123519.00,4807.0380,X,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 3 (N/S) 'X' is neither N nor S"},
      {"GPGGA,123519.00,4807.0380,N,01131.0000,E,9,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 6 (quality) '9' is not a quality 0 to 8"},
      {"GPGGA,123519.00,4807.0380,N,01131.0000,E,1,08,nan,545.4,M,46.9,M,,",
       "GPGGA: field 8 (HDOP) 'nan' is not a dilution >= 0"},
      {"GPGGA,123519.00,4807.0380,N,01131.0000,E,1,08,0.9,5x5.4,M,46.9,M,,",
       "GPGGA: field 9 (altitude) '5x5.4' is not a number"},
      {"GPGGA,126019.00,4807.0380,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,",
       "GPGGA: field 1 (UTC time) '126019.00' is not a time of day hhmmss.ss"},
      {"GPGGA,123519.00,4807.0380,N,01131.0000,E,1,08,0.9,545.4,F,46.9,M,,",
       "GPGGA: field 10 (altitude unit) 'F' is not M"},
      {"GPGST,123519.00,1.2,3.0,2.0,0.0,-2.0,3.0,4.5", "GPGST: field 6 (latitude sigma) '-2.0' is negative"},
      {"GPGST,123519.00,1.2,3.0,2.0,400.0,2.0,3.0,4.5",
       "GPGST: field 5 (orientation) '400.0' is beyond 360 deg"},
      {"GPGST,123519.00,1.2,3.0,2.0,0.0,2.0,inf,4.5",
       "GPGST: field 7 (longitude sigma) 'inf' is not a number"},
      {"GPGST,123519.00,1.2,3.0,2.0,0.0,2.0,3.0", "GPGST: 7 fields, 8 expected"},
      {"GPGGA" + std::string(30, ','), "GPGGA: more than 24 fields"},
  };
  for (const auto& c : cases) {
    NmeaParser parser(NmeaTestOptions());
    NmeaTestOutput out;
    NmeaTestFeed(parser, NmeaTestSentence(c.sentence), 1.0, &out);
    ASSERT_EQ(out.refused.size(), 1u) << c.sentence;
    EXPECT_EQ(out.refused[0], c.message);
    EXPECT_EQ(parser.counts().corrupt, 1u);
    // Nothing of it remains: a valid epoch follows.
    NmeaTestFeed(parser, NmeaTestGga() + NmeaTestGst(), 2.0, &out);
    EXPECT_EQ(out.fixes.size(), 1u) << c.sentence;
  }
}

TEST(NmeaParserTest, ResetForgetsThePartialLineAndEpoch) {
  NmeaParser parser(NmeaTestOptions());
  NmeaTestOutput out;
  NmeaTestFeed(parser, NmeaTestGga() + NmeaTestGst().substr(0, 20), 1.0, &out);
  parser.Reset();
  NmeaTestFeed(parser, NmeaTestGst().substr(20) + NmeaTestGst(), 2.0, &out);
  EXPECT_TRUE(out.fixes.empty());     // the GGA belonged to the old connection
  EXPECT_EQ(out.refused.size(), 1u);  // the rest of the cut GST are stray bytes
}

}  // namespace
}  // namespace cairn
