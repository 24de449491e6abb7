#include "hal/device_fault.h"

namespace cairn {

const char* DeviceFaultKindName(DeviceFaultKind kind) {
  switch (kind) {
    case DeviceFaultKind::kCorruptSample: return "corrupt_sample";
    case DeviceFaultKind::kTimeout: return "timeout";
    case DeviceFaultKind::kDisconnected: return "disconnected";
    case DeviceFaultKind::kOverrun: return "overrun";
    case DeviceFaultKind::kOther: return "other";
  }
  return "other";
}

}  // namespace cairn
