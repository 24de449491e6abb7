#pragma once
// NMEA 0183 from a GNSS receiver into GnssFix, as plain code (no I/O, no threads, no allocation
// per good sentence): frames the byte stream into sentences ($<address>,<fields>*<hh>, ended by
// CR LF or LF alone), checks each one's XOR checksum and reads GGA (position, quality, satellites,
// HDOP, heights) and GST (accuracy) of the talkers GP, GN, GL, GA, GB, BD, GQ and GI. Other sentences
// with a valid checksum are ignored and counted.
//
// One fix per epoch (a UTC time of day): when the GGA and the GST of the same time have both
// arrived, in either order, the covariance comes from GST: the horizontal 2x2 from its error
// ellipse (semi-major and semi-minor sigma, azimuth of the semi-major axis from true north) when
// given, else diag(sigma_lon^2, sigma_lat^2); up is sigma_alt^2. Otherwise the HDOP model, sigma
// east = sigma north = HDOP * uere, sigma up = vertical_factor * that, counted: with use_gst off
// at once; when a GST without sigmas comes, at once; when the epoch's GST does not come, at the
// next GGA or GST of another time (one epoch late, but stamped with its own time). A GGA without a
// position (quality 0, 6 dead reckoning, 7 manual, 8 simulation, or empty fields) is no fix,
// counted, not an error.
//
// Time: the robot's monotonic clock, not the sentence's UTC (no PPS maps one to the other): the
// arrival time of the bytes that ended the epoch's GGA line, minus `latency`, the receiver's
// delay from measurement to output. The serial transfer of a GGA adds ~6 ms at 115200 bit/s.
//
// Malformed input (bad checksum, wrong field count, unparsable number, latitude beyond 90 deg,
// longitude beyond 180 deg, negative sigma, non-printable bytes, a line longer than kMaxLine
// without an end, a sentence cut by the next '$', stray bytes between sentences) is refused with
// a message naming the sentence and field, counted, and the parser resynchronizes on the next '$'.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include <Eigen/Core>

#include "common/status.h"
#include "common/timestamp.h"
#include "drivers/nmea_gnss_options.h"
#include "hal/gnss_fix.h"

namespace cairn {

struct NmeaParserCounts {
  uint64_t sentences = 0;       // with a valid checksum
  uint64_t fixes = 0;           // published
  uint64_t corrupt = 0;         // sentences, lines and runs of stray bytes refused
  uint64_t no_fix = 0;          // GGA without a position, or without the HDOP its covariance needed
  uint64_t hdop_fallbacks = 0;  // fixes with the HDOP model's covariance
  uint64_t ignored = 0;         // other sentences (GST too when use_gst is off), GST without a time
  uint64_t skipped_bytes = 0;   // outside any sentence
};

class NmeaParser {
 public:
  // The standard's 82 characters ($ to LF) and slack for receivers that print more digits.
  static constexpr size_t kMaxLine = 128;
  static constexpr size_t kMaxFields = 24;

  explicit NmeaParser(const NmeaGnssOptions& options);

  // Frames and interprets `bytes`, received at `arrival`: calls on_fix(const GnssFix&) for every
  // completed epoch and on_refused(const Status&) (kDataLoss) for every refused sentence or line.
  template <class OnFix, class OnRefused>
  void Feed(std::span<const uint8_t> bytes, Timestamp arrival, const OnFix& on_fix,
            const OnRefused& on_refused) {
    for (const uint8_t b : bytes) {
      if (!Push(b, arrival)) continue;
      if (!refusal_.ok()) {
        on_refused(refusal_);
        refusal_ = Status::Ok();
      }
      for (size_t i = 0; i < ready_count_; ++i) on_fix(ready_[i]);
      ready_count_ = 0;
    }
  }

  // Forgets a partial line and the pending epoch (a reopened port); the counts stay.
  void Reset();
  const NmeaParserCounts& counts() const { return counts_; }

 private:
  enum class State { kSearching, kInSentence, kDiscarding };
  // A GGA with a position, waiting for its GST.
  struct Epoch {
    int64_t time_ms = 0;                                   // UTC time of day
    double latitude = 0.0, longitude = 0.0, height = 0.0;  // rad, rad, m
    GnssQuality quality = GnssQuality::kNone;
    int satellites = 0;
    double hdop = 0.0;  // 0 when not given
    Timestamp arrival;
  };

  // Takes one byte; true when a fix is ready or something was refused.
  bool Push(uint8_t b, Timestamp arrival);
  void Begin();
  // The complete line in line_ (without '$' and the line end).
  void Interpret(Timestamp arrival);
  void OnGga(std::string_view name, Timestamp arrival);
  void OnGst(std::string_view name);
  // Publishes the pending GGA with the HDOP model's covariance (no fix without HDOP).
  void FlushWithHdop();
  void Emit(const Epoch& e, const Eigen::Matrix3d& covariance);
  void Refuse(Status status);

  double uere_, vertical_factor_;
  Duration latency_;
  bool use_gst_;
  State state_ = State::kSearching;
  std::array<char, kMaxLine> line_{};
  size_t length_ = 0;
  size_t stray_ = 0;  // bytes of the current run outside any sentence
  std::array<std::string_view, kMaxFields> fields_;
  size_t field_count_ = 0;
  bool have_gga_ = false;
  Epoch gga_;
  bool have_gst_ = false;
  int64_t gst_time_ms_ = 0;
  Eigen::Matrix3d gst_covariance_ = Eigen::Matrix3d::Zero();
  // What the current byte produced: at most two fixes (a flushed epoch and the next) or a refusal.
  std::array<GnssFix, 2> ready_;
  size_t ready_count_ = 0;
  Status refusal_;
  NmeaParserCounts counts_;
};

}  // namespace cairn
