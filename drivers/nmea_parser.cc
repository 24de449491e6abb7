#include "drivers/nmea_parser.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/angles.h"

namespace cairn {
namespace {

constexpr std::array<std::string_view, 8> kNmeaTalkers = {"GP", "GN", "GL", "GA", "GB", "BD", "GQ", "GI"};
// Field 0 is the address; the standard numbers the data fields from 1.
constexpr size_t kNmeaGgaFields = 15;
constexpr std::array<const char*, kNmeaGgaFields> kNmeaGgaNames = {
    "address",         "UTC time",           "latitude", "N/S",      "longitude",     "E/W",
    "quality",         "satellites",         "HDOP",     "altitude", "altitude unit", "geoid separation",
    "separation unit", "age of corrections", "station"};
constexpr size_t kNmeaGstFields = 9;
constexpr std::array<const char*, kNmeaGstFields> kNmeaGstNames = {
    "address",          "UTC time",         "RMS",
    "semi-major sigma", "semi-minor sigma", "orientation",
    "latitude sigma",   "longitude sigma",  "altitude sigma"};

bool NmeaNumber(std::string_view f, double* v) {
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), *v, std::chars_format::fixed);
  return ec == std::errc() && end == f.data() + f.size() && std::isfinite(*v);
}

bool NmeaInteger(std::string_view f, int* v) {
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), *v);
  return ec == std::errc() && end == f.data() + f.size();
}

// hhmmss[.sss] as milliseconds of the day.
bool NmeaTimeOfDay(std::string_view f, int64_t* ms) {
  if (f.size() < 6 || !std::all_of(f.begin(), f.begin() + 6, [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  const int hours = (f[0] - '0') * 10 + (f[1] - '0');
  const int minutes = (f[2] - '0') * 10 + (f[3] - '0');
  double seconds = 0.0;
  if (!NmeaNumber(f.substr(4), &seconds) || hours > 23 || minutes > 59 || seconds >= 61.0) return false;
  *ms = (hours * 3600 + minutes * 60) * int64_t{1000} + std::llround(seconds * 1000.0);
  return true;
}

// ddmm.mmmm or dddmm.mmmm as degrees.
bool NmeaDegreesMinutes(std::string_view f, double* degrees) {
  double v = 0.0;
  if (!NmeaNumber(f, &v) || v < 0.0) return false;
  const double whole = std::floor(v / 100.0);
  const double minutes = v - 100.0 * whole;
  if (minutes >= 60.0) return false;
  *degrees = whole + minutes / 60.0;
  return true;
}

// The address field as far as it is printable, for messages.
std::string_view NmeaName(std::string_view line) {
  size_t n = 0;
  while (n < line.size() && n < 8 && line[n] > ' ' && line[n] < 0x7F && line[n] != ',' && line[n] != '*') ++n;
  return n == 0 ? std::string_view("NMEA sentence") : line.substr(0, n);
}

bool NmeaIsType(std::string_view address, std::string_view type) {
  return address.size() == 5 && address.substr(2) == type &&
         std::find(kNmeaTalkers.begin(), kNmeaTalkers.end(), address.substr(0, 2)) != kNmeaTalkers.end();
}

Status NmeaFieldError(std::string_view name, size_t index, const char* field, std::string_view value,
                      const char* why) {
  return DataLossError(std::string(name) + ": field " + std::to_string(index) + " (" + field + ") '" +
                       std::string(value) + "' " + why);
}

}  // namespace

NmeaParser::NmeaParser(const NmeaGnssOptions& options)
    : uere_(options.uere),
      vertical_factor_(options.vertical_factor),
      latency_(Duration::Seconds(options.latency)),
      use_gst_(options.use_gst) {}

void NmeaParser::Reset() {
  state_ = State::kSearching;
  length_ = 0;
  stray_ = 0;
  have_gga_ = have_gst_ = false;
  ready_count_ = 0;
  refusal_ = Status::Ok();
}

void NmeaParser::Refuse(Status status) {
  ++counts_.corrupt;
  refusal_ = std::move(status);
}

void NmeaParser::Begin() {
  state_ = State::kInSentence;
  length_ = 0;
}

bool NmeaParser::Push(uint8_t b, Timestamp arrival) {
  switch (state_) {
    case State::kSearching:
      if (b == '$') {
        Begin();
        if (stray_ == 0) return false;
        Refuse(DataLossError(std::to_string(stray_) + " bytes outside any NMEA sentence"));
        stray_ = 0;
        return true;
      }
      if (b != '\r' && b != '\n') {
        ++stray_;
        ++counts_.skipped_bytes;
      }
      return false;
    case State::kDiscarding:  // the rest of a line already refused
      if (b == '$') {
        Begin();
      } else {
        ++counts_.skipped_bytes;
        if (b == '\n') state_ = State::kSearching;
      }
      return false;
    case State::kInSentence:
      if (b == '\n') {
        state_ = State::kSearching;
        Interpret(arrival);
        return ready_count_ > 0 || !refusal_.ok();
      }
      if (b == '$') {
        Refuse(DataLossError(std::string(NmeaName({line_.data(), length_})) +
                             ": cut short by the next '$' after " + std::to_string(length_ + 1) + " bytes"));
        Begin();
        return true;
      }
      if (length_ == line_.size()) {
        Refuse(DataLossError(std::string(NmeaName({line_.data(), length_})) + ": no line end within " +
                             std::to_string(kMaxLine) + " bytes"));
        counts_.skipped_bytes += length_ + 1;
        state_ = State::kDiscarding;
        return true;
      }
      line_[length_++] = static_cast<char>(b);
      return false;
  }
  return false;
}

void NmeaParser::Interpret(Timestamp arrival) {
  std::string_view s(line_.data(), length_);
  if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
  for (size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c > 0x7E) {
      char what[96];
      std::snprintf(what, sizeof what, ": byte 0x%02X at column %zu is not printable ASCII", c, i + 1);
      return Refuse(DataLossError(std::string(NmeaName(s)) + what));
    }
  }
  const std::string_view name = NmeaName(s);
  const size_t star = s.rfind('*');
  if (star == std::string_view::npos || star + 3 != s.size())
    return Refuse(DataLossError(std::string(name) + ": no checksum (*hh) at the end"));
  unsigned given = 0;
  const auto [end, ec] = std::from_chars(s.data() + star + 1, s.data() + s.size(), given, 16);
  if (ec != std::errc() || end != s.data() + s.size())
    return Refuse(DataLossError(std::string(name) + ": checksum '" + std::string(s.substr(star + 1)) +
                                "' is not hexadecimal"));
  unsigned computed = 0;
  for (size_t i = 0; i < star; ++i) computed ^= static_cast<unsigned char>(s[i]);
  if (computed != given) {
    char what[48];
    std::snprintf(what, sizeof what, ": checksum %02X, computed %02X", given, computed);
    return Refuse(DataLossError(std::string(name) + what));
  }
  ++counts_.sentences;
  const std::string_view body = s.substr(0, star);
  const std::string_view address = body.substr(0, body.find(','));
  const bool gga = NmeaIsType(address, "GGA");
  if (!gga && !(use_gst_ && NmeaIsType(address, "GST"))) {
    ++counts_.ignored;
    return;
  }
  field_count_ = 0;
  for (size_t start = 0;;) {
    if (field_count_ == kMaxFields)
      return Refuse(
          DataLossError(std::string(name) + ": more than " + std::to_string(kMaxFields) + " fields"));
    const size_t comma = body.find(',', start);
    fields_[field_count_++] = body.substr(start, comma == std::string_view::npos ? comma : comma - start);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (gga) {
    OnGga(name, arrival);
  } else {
    OnGst(name);
  }
}

void NmeaParser::OnGga(std::string_view name, Timestamp arrival) {
  if (field_count_ != kNmeaGgaFields) {
    return Refuse(DataLossError(std::string(name) + ": " + std::to_string(field_count_ - 1) + " fields, " +
                                std::to_string(kNmeaGgaFields - 1) + " expected"));
  }
  const auto& f = fields_;
  const auto bad = [&](size_t i, const char* why) {
    Refuse(NmeaFieldError(name, i, kNmeaGgaNames[i], f[i], why));
  };
  // Every field is checked when present; a position needs all but satellites and HDOP.
  Epoch e;
  e.arrival = arrival;
  if (!f[1].empty() && !NmeaTimeOfDay(f[1], &e.time_ms)) return bad(1, "is not a time of day hhmmss.ss");
  double latitude = 0.0, longitude = 0.0, altitude = 0.0, separation = 0.0;
  if (!f[2].empty() && !NmeaDegreesMinutes(f[2], &latitude)) return bad(2, "is not ddmm.mmmm");
  if (latitude > 90.0) return bad(2, "is beyond 90 deg");
  if (!f[3].empty() && f[3] != "N" && f[3] != "S") return bad(3, "is neither N nor S");
  if (!f[4].empty() && !NmeaDegreesMinutes(f[4], &longitude)) return bad(4, "is not dddmm.mmmm");
  if (longitude > 180.0) return bad(4, "is beyond 180 deg");
  if (!f[5].empty() && f[5] != "E" && f[5] != "W") return bad(5, "is neither E nor W");
  int quality = 0;
  if (!f[6].empty() && (!NmeaInteger(f[6], &quality) || quality < 0 || quality > 8))
    return bad(6, "is not a quality 0 to 8");
  if (!f[7].empty() && (!NmeaInteger(f[7], &e.satellites) || e.satellites < 0))
    return bad(7, "is not a count of satellites");
  if (!f[8].empty() && (!NmeaNumber(f[8], &e.hdop) || e.hdop < 0.0)) return bad(8, "is not a dilution >= 0");
  if (!f[9].empty() && !NmeaNumber(f[9], &altitude)) return bad(9, "is not a number");
  if (!f[10].empty() && f[10] != "M") return bad(10, "is not M");
  if (!f[11].empty() && !NmeaNumber(f[11], &separation)) return bad(11, "is not a number");
  if (!f[12].empty() && f[12] != "M") return bad(12, "is not M");

  // A sentence of another epoch ends the pending one: its GST is not coming.
  if (have_gga_ && (f[1].empty() || gga_.time_ms != e.time_ms)) FlushWithHdop();
  const bool complete = !f[1].empty() && !f[2].empty() && !f[3].empty() && !f[4].empty() && !f[5].empty() &&
                        !f[9].empty() && !f[11].empty();
  // 6 (dead reckoning), 7 (manual input) and 8 (simulation) are not measurements.
  if (!complete || quality == 0 || quality > 5) {
    ++counts_.no_fix;
    have_gst_ = false;
    return;
  }
  e.latitude = (f[3] == "S" ? -latitude : latitude) * kDegree;
  e.longitude = (f[5] == "W" ? -longitude : longitude) * kDegree;
  e.height = altitude + separation;  // above mean sea level (the geoid) + the geoid above the ellipsoid
  // 3 (PPS, precise code) is an autonomous solution for what the estimator is concerned.
  e.quality = quality == 2   ? GnssQuality::kDifferential
              : quality == 4 ? GnssQuality::kRtkFixed
              : quality == 5 ? GnssQuality::kRtkFloat
                             : GnssQuality::kAutonomous;
  gga_ = e;
  have_gga_ = true;
  if (!use_gst_) return FlushWithHdop();
  if (have_gst_ && gst_time_ms_ == e.time_ms) {
    have_gst_ = have_gga_ = false;
    return Emit(e, gst_covariance_);
  }
  have_gst_ = false;  // a GST of another epoch, whose GGA did not come
}

void NmeaParser::OnGst(std::string_view name) {
  if (field_count_ != kNmeaGstFields) {
    return Refuse(DataLossError(std::string(name) + ": " + std::to_string(field_count_ - 1) + " fields, " +
                                std::to_string(kNmeaGstFields - 1) + " expected"));
  }
  const auto& f = fields_;
  const auto bad = [&](size_t i, const char* why) {
    Refuse(NmeaFieldError(name, i, kNmeaGstNames[i], f[i], why));
  };
  int64_t time_ms = 0;
  if (!f[1].empty() && !NmeaTimeOfDay(f[1], &time_ms)) return bad(1, "is not a time of day hhmmss.ss");
  std::array<double, kNmeaGstFields> v{};
  for (size_t i = 2; i < kNmeaGstFields; ++i) {
    if (f[i].empty()) continue;
    if (!NmeaNumber(f[i], &v[i])) return bad(i, "is not a number");
    if (i == 5 ? std::abs(v[i]) > 360.0 : v[i] < 0.0)
      return bad(i, i == 5 ? "is beyond 360 deg" : "is negative");
  }
  if (f[1].empty()) {
    ++counts_.ignored;
    return;
  }
  if (have_gga_ && gga_.time_ms != time_ms) FlushWithHdop();
  have_gst_ = false;
  const double major = v[3], minor = v[4], azimuth = v[5] * kDegree;
  // Receivers without an ellipse leave its fields empty or zero.
  const bool ellipse = !f[3].empty() && !f[4].empty() && !f[5].empty() && (major > 0.0 || minor > 0.0);
  const bool axes = !f[6].empty() && !f[7].empty();
  if (f[8].empty() || (!ellipse && !axes)) return FlushWithHdop();  // a GGA of this epoch: no better to come
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  if (ellipse) {
    // The semi-major axis points to (east, north) = (sin, cos) of its azimuth, the minor axis
    // perpendicular to it.
    const double s = std::sin(azimuth), k = std::cos(azimuth);
    c(0, 0) = major * major * s * s + minor * minor * k * k;
    c(1, 1) = major * major * k * k + minor * minor * s * s;
    c(0, 1) = c(1, 0) = (major * major - minor * minor) * s * k;
  } else {
    c(0, 0) = v[7] * v[7];
    c(1, 1) = v[6] * v[6];
  }
  c(2, 2) = v[8] * v[8];
  if (have_gga_) {
    have_gga_ = false;
    return Emit(gga_, c);
  }
  have_gst_ = true;
  gst_time_ms_ = time_ms;
  gst_covariance_ = c;
}

void NmeaParser::FlushWithHdop() {
  if (!have_gga_) return;
  have_gga_ = false;
  if (!(gga_.hdop > 0.0)) {
    ++counts_.no_fix;
    return;
  }
  const double horizontal = gga_.hdop * uere_, vertical = vertical_factor_ * horizontal;
  ++counts_.hdop_fallbacks;
  Emit(gga_,
       Eigen::Vector3d(horizontal * horizontal, horizontal * horizontal, vertical * vertical).asDiagonal());
}

void NmeaParser::Emit(const Epoch& e, const Eigen::Matrix3d& covariance) {
  if (ready_count_ == ready_.size()) return;  // not reached: one line completes at most two epochs
  GnssFix& fix = ready_[ready_count_++];
  fix.time = e.arrival - latency_;
  fix.latitude = e.latitude;
  fix.longitude = e.longitude;
  fix.height = e.height;
  fix.covariance = covariance;
  fix.quality = e.quality;
  fix.satellites = e.satellites;
  ++counts_.fixes;
}

}  // namespace cairn
