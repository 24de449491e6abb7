#pragma once
// Backend selection for dense stereo (`stereo.backend: cpu | fpga | auto`) with fallback: the
// FPGA offload while it works, the CPU kernel (SgmMatcher, same options, so the same disparities
// in raster_paths mode) otherwise. The first FPGA failure (device absent at start with `fpga`,
// timeout, error flags, removal) logs one warning and switches to the CPU for good; every failure
// is counted for diagnostics, and the pipeline keeps running.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/options_visitor.h"
#include "fpga/fpga_stereo_matcher.h"
#include "fpga/stereo_device.h"
#include "stereo/sgm_matcher.h"

namespace cairn {

enum class StereoBackend { kCpu, kFpga, kAuto };

struct StereoBackendOptions {
  StereoBackend backend = StereoBackend::kCpu;  // auto: the FPGA when present and able
  std::string device = "/dev/uio0";             // UIO node of the board
  int64_t timeout_ms = 200;                     // per frame

  void Visit(OptionsVisitor& v) {
    v.Choice("backend", backend,
             {{"cpu", StereoBackend::kCpu}, {"fpga", StereoBackend::kFpga},
              {"auto", StereoBackend::kAuto}});
    v.Text("device", device);
    v.Integer("timeout_ms", timeout_ms, 1, 10000, "ms");
  }
};

class StereoBackendSwitch final : public StereoMatcher {
 public:
  using DeviceOpener = std::function<Expected<std::unique_ptr<StereoDevice>>()>;
  using WarningSink = std::function<void(const std::string&)>;

  // `open_device` defaults to UioStereoDevice::Open(options.device); `warn` to stderr.
  // InvalidArgument when `fpga` is asked for options the core cannot compute.
  static Expected<std::unique_ptr<StereoBackendSwitch>> Create(
      const StereoBackendOptions& options, const SgmOptions& sgm, DeviceOpener open_device = {},
      WarningSink warn = {});

  std::string_view name() const override;
  Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) override;

  bool fpga_active() const { return fpga_ != nullptr; }
  uint64_t fpga_failures() const { return fpga_failures_; }  // diagnostics counter
  uint64_t fpga_frames() const { return fpga_frames_; }
  uint64_t cpu_frames() const { return cpu_frames_; }
  // Why the FPGA is not (or no longer) used; Ok while it is.
  const Status& fpga_status() const { return fpga_status_; }

 private:
  StereoBackendSwitch(std::unique_ptr<SgmMatcher> cpu, WarningSink warn)
      : cpu_(std::move(cpu)), warn_(std::move(warn)) {}
  void Fail(const Status& why);

  std::unique_ptr<SgmMatcher> cpu_;
  std::unique_ptr<FpgaStereoMatcher> fpga_;
  WarningSink warn_;
  Status fpga_status_;
  uint64_t fpga_failures_ = 0, fpga_frames_ = 0, cpu_frames_ = 0;
};

}  // namespace cairn
