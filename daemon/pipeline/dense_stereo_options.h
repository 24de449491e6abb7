#pragma once
// `stereo:` in a cairnd profile: dense matching of rectified pairs for mapping (thesis 3.1, 5.1).
// The backend switch picks the FPGA offload or the SIMD CPU kernel (same disparities bit for bit in
// raster_paths mode); `device: sim` drives the cycle-accurate simulation of the board through the
// unchanged host driver (hardware-in-the-loop benches without a board; slow, small images only).

#include <cstdint>

#include "common/options_visitor.h"
#include "common/status.h"
#include "fpga/stereo_backend_switch.h"
#include "stereo/sgm_options.h"

namespace cairn {

struct DenseStereoOptions {
  bool enabled = false;
  // Dense matching runs on every Nth rectified pair; the odometry still sees every pair.
  int64_t every_nth_frame = 2;
  StereoBackendOptions backend;  // keys backend, device, timeout_ms sit directly under stereo:
  // With sgm raster_paths: also match each pair flipped upside down and average the two where they
  // agree, which removes the raster paths' bias on the ground (stereo/bidirectional_raster_matcher.h)
  // at twice the matching cost.
  bool bidirectional = false;
  int64_t bidirectional_max_diff = 16;  // 1/16 px between the two passes' disparities
  SgmOptions sgm;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("every_nth_frame", every_nth_frame, 1, 1000, "frames");
    backend.Visit(v);
    v.Flag("bidirectional", bidirectional);
    v.Integer("bidirectional_max_diff", bidirectional_max_diff, 0, 1024, "1/16 px");
    v.Section("sgm", sgm);
  }
  Status Validate() const {
    if (bidirectional && !sgm.raster_paths) {
      return InvalidArgumentError("stereo.bidirectional corrects sgm.raster_paths; the other path sets are symmetric");
    }
    return Status::Ok();
  }
  // Device path of the simulated board.
  static constexpr const char* kSimulatedDevice = "sim";
};

}  // namespace cairn
