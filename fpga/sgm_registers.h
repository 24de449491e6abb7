#pragma once
// Register map of the SGM offload (BAR0; fpga/REGISTERS.md has the full description). The RTL
// (fpga/rtl/sgm_top.v), the simulated device and the driver share these offsets.

#include <cstdint>

namespace cairn::sgm_reg {

inline constexpr uint32_t kId = 0x000;          // RO "SGM1"
inline constexpr uint32_t kVersion = 0x004;     // RO major << 16 | minor
inline constexpr uint32_t kCapsLanes = 0x008;   // RO lanes << 16 | max disparities
inline constexpr uint32_t kCapsSize = 0x00C;    // RO max height << 16 | max width
inline constexpr uint32_t kControl = 0x010;     // bit 0 start, bit 1 abort (self-clearing), bit 8 irq enable
inline constexpr uint32_t kStatus = 0x014;      // RO, see kStatus* bits
inline constexpr uint32_t kIrqStatus = 0x018;   // bit 0 done, bit 1 error; write 1 to clear
inline constexpr uint32_t kWidth = 0x020;
inline constexpr uint32_t kHeight = 0x024;
inline constexpr uint32_t kNumDisparities = 0x028;
inline constexpr uint32_t kP1 = 0x02C;
inline constexpr uint32_t kUniqueness = 0x030;  // percent
inline constexpr uint32_t kLrCheck = 0x034;     // bit 0 enable, bits 12:8 max difference
inline constexpr uint32_t kSubpixel = 0x038;    // bit 0
inline constexpr uint32_t kSrcLeftLo = 0x040;
inline constexpr uint32_t kSrcLeftHi = 0x044;
inline constexpr uint32_t kSrcRightLo = 0x048;
inline constexpr uint32_t kSrcRightHi = 0x04C;
inline constexpr uint32_t kSrcStride = 0x050;   // bytes, multiple of 8
inline constexpr uint32_t kDstLo = 0x054;
inline constexpr uint32_t kDstHi = 0x058;
inline constexpr uint32_t kDstStride = 0x05C;   // bytes, multiple of 8
inline constexpr uint32_t kCycles = 0x060;      // RO clock cycles of the last frame
inline constexpr uint32_t kTailCycles = 0x064;  // RO cycles from the last input pixel to done
inline constexpr uint32_t kP2Table = 0x400;     // WO 256 words: P2' for |dI| = 0..255

inline constexpr uint32_t kIdValue = 0x53474D31;
inline constexpr uint32_t kVersionMajor = 1;

inline constexpr uint32_t kControlStart = 1u << 0;
inline constexpr uint32_t kControlAbort = 1u << 1;
inline constexpr uint32_t kControlIrqEnable = 1u << 8;

inline constexpr uint32_t kStatusBusy = 1u << 0;
inline constexpr uint32_t kStatusDone = 1u << 1;
inline constexpr uint32_t kStatusError = 1u << 2;
inline constexpr uint32_t kStatusConfigError = 1u << 8;
inline constexpr uint32_t kStatusDmaReadError = 1u << 9;
inline constexpr uint32_t kStatusDmaWriteError = 1u << 10;
inline constexpr uint32_t kStatusOverrun = 1u << 11;  // start while busy

inline constexpr uint32_t kIrqDone = 1u << 0;
inline constexpr uint32_t kIrqError = 1u << 1;

}  // namespace cairn::sgm_reg
