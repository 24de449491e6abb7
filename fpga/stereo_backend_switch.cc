#include "fpga/stereo_backend_switch.h"

#include <cstdio>

#include "fpga/uio_stereo_device.h"

namespace cairn {

Expected<std::unique_ptr<StereoBackendSwitch>> StereoBackendSwitch::Create(
    const StereoBackendOptions& options, const SgmOptions& sgm, DeviceOpener open_device,
    WarningSink warn) {
  auto cpu = SgmMatcher::Create(sgm);
  if (!cpu.ok()) return cpu.status();
  if (!warn) {
    warn = [](const std::string& m) { std::fprintf(stderr, "cairn: warning: %s\n", m.c_str()); };
  }
  auto s = std::unique_ptr<StereoBackendSwitch>(
      new StereoBackendSwitch(std::move(*cpu), std::move(warn)));
  if (options.backend == StereoBackend::kCpu) {
    s->fpga_status_ = FailedPreconditionError("stereo.backend is cpu");
    return s;
  }
  // Options the core cannot compute are a configuration error when the FPGA was asked for, and
  // simply mean the CPU under auto.
  FpgaStereoMatcher::Capabilities any;
  any.lanes = 1;
  any.max_disparities = 1 << 16;
  const Status compatible = FpgaStereoMatcher::CheckOptions(sgm, any);
  if (!compatible.ok()) {
    if (options.backend == StereoBackend::kFpga) {
      return compatible.WithContext("stereo.backend fpga");
    }
    s->fpga_status_ = compatible;
    return s;
  }
  if (!open_device) {
    const std::string path = options.device;
    open_device = [path]() -> Expected<std::unique_ptr<StereoDevice>> {
      auto d = UioStereoDevice::Open(path);
      if (!d.ok()) return d.status();
      return std::unique_ptr<StereoDevice>(std::move(*d));
    };
  }
  auto device = open_device();
  Expected<std::unique_ptr<FpgaStereoMatcher>> fpga =
      device.ok() ? FpgaStereoMatcher::Create(sgm, std::move(*device),
                                              std::chrono::milliseconds(options.timeout_ms))
                  : Expected<std::unique_ptr<FpgaStereoMatcher>>(device.status());
  if (fpga.ok()) {
    s->fpga_ = std::move(*fpga);
  } else if (options.backend == StereoBackend::kFpga) {
    s->Fail(fpga.status());  // asked for: warn and count, but keep running on the CPU
  } else {
    s->fpga_status_ = fpga.status();
  }
  return s;
}

std::string_view StereoBackendSwitch::name() const {
  return fpga_ != nullptr ? fpga_->name() : cpu_->name();
}

void StereoBackendSwitch::Fail(const Status& why) {
  ++fpga_failures_;
  if (fpga_ != nullptr || fpga_status_.ok()) {
    warn_("stereo: FPGA backend failed, using the CPU from now on: " + why.ToString());
  }
  fpga_.reset();
  fpga_status_ = why;
}

Status StereoBackendSwitch::Match(const StereoMatcherInput& input, StereoMatcherOutput* output) {
  if (fpga_ != nullptr) {
    const Status s = fpga_->Match(input, output);
    if (s.ok()) {
      ++fpga_frames_;
      return s;
    }
    // Bad input is the caller's fault, not the device's: the CPU would refuse it as well.
    if (s.code() == StatusCode::kInvalidArgument) return s;
    Fail(s);
  }
  ++cpu_frames_;
  return cpu_->Match(input, output);
}

}  // namespace cairn
