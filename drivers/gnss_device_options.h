#pragma once
// `gnss:` of a profile: the GNSS receiver for source: live (Earth-analogue field tests; planetary
// missions have none). Its fixes are used when `graph.gnss.enabled` is on.

#include "common/options_visitor.h"
#include "drivers/nmea_gnss_options.h"

namespace cairn {

enum class GnssDriverKind { kNone, kNmea };

struct GnssDeviceOptions {
  GnssDriverKind driver = GnssDriverKind::kNone;
  NmeaGnssOptions nmea;

  void Visit(OptionsVisitor& v) {
    v.Choice("driver", driver, {{"none", GnssDriverKind::kNone}, {"nmea", GnssDriverKind::kNmea}});
    v.Section("nmea", nmea);
  }
};

}  // namespace cairn
