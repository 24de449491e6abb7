#pragma once

#include <string>

#include "common/timestamp.h"

namespace cairn {

// A driver reports what went wrong with its device instead of dying: the daemon counts faults per
// device, logs them and keeps running with what remains.
enum class DeviceFaultKind {
  kCorruptSample,   // a sample that could not be decoded (bad image, short CAN frame)
  kTimeout,         // no data for longer than expected
  kDisconnected,    // the device vanished
  kOverrun,         // the device or kernel dropped data
  kOther,
};

const char* DeviceFaultKindName(DeviceFaultKind kind);

struct DeviceFault {
  Timestamp time;
  std::string device;  // e.g. "replay/cam1", "can0"
  DeviceFaultKind kind = DeviceFaultKind::kOther;
  std::string detail;
};

}  // namespace cairn
