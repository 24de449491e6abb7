#include "fpga/uio_stereo_device.h"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

namespace cairn {
namespace {

// Reads a hexadecimal sysfs value such as /sys/class/uio/uio0/maps/map1/size.
Expected<uint64_t> ReadSysfsHex(const std::string& file) {
  std::ifstream in(file);
  std::string text;
  if (!in || !(in >> text)) return NotFoundError("cannot read " + file);
  char* end = nullptr;
  const uint64_t v = std::strtoull(text.c_str(), &end, 16);
  if (end == text.c_str()) return DataLossError(file + " holds '" + text + "', not a number");
  return v;
}

std::string Errno() { return std::strerror(errno); }

}  // namespace

Expected<std::unique_ptr<UioStereoDevice>> UioStereoDevice::Open(const std::string& path) {
  const size_t slash = path.rfind('/');
  const std::string node = slash == std::string::npos ? path : path.substr(slash + 1);
  if (node.rfind("uio", 0) != 0) {
    return InvalidArgumentError("fpga device '" + path + "' is not a UIO node (/dev/uioN)");
  }
  auto dev = std::unique_ptr<UioStereoDevice>(new UioStereoDevice(path));
  dev->fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (dev->fd_ < 0) {
    return errno == ENOENT ? NotFoundError("fpga device " + path + " not present")
                           : UnavailableError("cannot open fpga device " + path + ": " + Errno());
  }
  const std::string maps = "/sys/class/uio/" + node + "/maps/";
  auto regs_size = ReadSysfsHex(maps + "map0/size");
  if (!regs_size.ok()) return regs_size.status().WithContext("fpga device " + path);
  auto dma_size = ReadSysfsHex(maps + "map1/size");
  if (!dma_size.ok()) return dma_size.status().WithContext("fpga device " + path + " DMA window");
  auto dma_addr = ReadSysfsHex(maps + "map1/addr");
  if (!dma_addr.ok()) return dma_addr.status().WithContext("fpga device " + path + " DMA window");
  const long page = ::sysconf(_SC_PAGESIZE);
  // UIO selects map N with an mmap offset of N pages.
  void* regs = ::mmap(nullptr, *regs_size, PROT_READ | PROT_WRITE, MAP_SHARED, dev->fd_, 0);
  if (regs == MAP_FAILED) return IoError("mmap of " + path + " registers: " + Errno());
  dev->regs_ = static_cast<volatile uint32_t*>(regs);
  dev->regs_bytes_ = *regs_size;
  void* dma = ::mmap(nullptr, *dma_size, PROT_READ | PROT_WRITE, MAP_SHARED, dev->fd_, page);
  if (dma == MAP_FAILED) return IoError("mmap of " + path + " DMA window: " + Errno());
  dev->dma_ = static_cast<uint8_t*>(dma);
  dev->dma_bytes_ = *dma_size;
  dev->dma_bus_ = *dma_addr;
  const uint32_t enable = 1;  // unmask the interrupt
  if (::write(dev->fd_, &enable, sizeof(enable)) != static_cast<ssize_t>(sizeof(enable))) {
    return IoError("cannot enable the interrupt of " + path + ": " + Errno());
  }
  return dev;
}

UioStereoDevice::~UioStereoDevice() {
  if (regs_ != nullptr) ::munmap(const_cast<uint32_t*>(regs_), regs_bytes_);
  if (dma_ != nullptr) ::munmap(dma_, dma_bytes_);
  if (fd_ >= 0) ::close(fd_);
}

uint32_t UioStereoDevice::Read32(uint32_t offset) {
  if (offset + 4 > regs_bytes_) return 0xFFFFFFFFu;
  return regs_[offset / 4];
}

void UioStereoDevice::Write32(uint32_t offset, uint32_t value) {
  if (offset + 4 <= regs_bytes_) regs_[offset / 4] = value;
}

Expected<DmaBuffer> UioStereoDevice::AllocateDma(size_t bytes) {
  constexpr size_t kAlign = 4096;
  const size_t begin = (dma_used_ + kAlign - 1) / kAlign * kAlign;
  if (bytes == 0 || begin + bytes > dma_bytes_) {
    return OutOfRangeError("fpga device " + path_ + ": DMA window of " +
                           std::to_string(dma_bytes_) + " bytes cannot hold " +
                           std::to_string(bytes) + " more bytes");
  }
  dma_used_ = begin + bytes;
  return DmaBuffer{dma_ + begin, dma_bus_ + begin, bytes};
}

Status UioStereoDevice::WaitForInterrupt(std::chrono::nanoseconds timeout) {
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(timeout).count());
  const int n = ::poll(&p, 1, ms);
  if (n < 0) return IoError("poll on " + path_ + ": " + Errno());
  if (n == 0) return TimeoutError("fpga device " + path_ + ": no interrupt within " +
                                  std::to_string(ms) + " ms");
  if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) {
    return UnavailableError("fpga device " + path_ + " removed");
  }
  uint32_t count = 0;
  if (::read(fd_, &count, sizeof(count)) != static_cast<ssize_t>(sizeof(count))) {
    return UnavailableError("fpga device " + path_ + " removed: " + Errno());
  }
  const uint32_t enable = 1;
  if (::write(fd_, &enable, sizeof(enable)) != static_cast<ssize_t>(sizeof(enable))) {
    return UnavailableError("fpga device " + path_ + ": cannot re-enable the interrupt: " +
                            Errno());
  }
  return Status::Ok();
}

}  // namespace cairn
