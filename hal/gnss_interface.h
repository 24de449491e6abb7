#pragma once

#include "hal/sensor_source_interface.h"

namespace cairn {

// A GNSS receiver; fixes arrive through SensorSink::OnGnss.
class GnssInterface : public SensorSourceInterface {};

}  // namespace cairn
