#include "drivers/testing/fake_iio_imu.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace cairn::testing {
namespace {

void Put(const std::string& path, const std::string& text) { std::ofstream(path) << text << '\n'; }

std::string Get(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::string t = s.str();
  while (!t.empty() && t.back() == '\n') t.pop_back();
  return t;
}

struct Channel {
  const char* name;
  int index;
  const char* type;
};
constexpr Channel kChannels[] = {
    {"in_voltage0_supply", 0, "be:u12/16>>0"}, {"in_accel_x", 1, "be:s14/16>>0"},  {"in_accel_y", 2, "be:s14/16>>0"},
    {"in_accel_z", 3, "be:s14/16>>0"},         {"in_anglvel_x", 4, "be:s14/16>>0"}, {"in_anglvel_y", 5, "be:s14/16>>0"},
    {"in_anglvel_z", 6, "be:s14/16>>0"},       {"in_temp0", 7, "be:s12/16>>0"},     {"in_timestamp", 8, "le:s64/64>>0"},
};

}  // namespace

Expected<std::unique_ptr<FakeIioImu>> FakeIioImu::Create(const std::string& sysfs_root, const std::string& dev_root) {
  std::unique_ptr<FakeIioImu> f(new FakeIioImu());
  namespace fs = std::filesystem;
  fs::create_directories(sysfs_root + "/iio:device1");
  Put(sysfs_root + "/iio:device1/name", "other");
  f->dir_ = sysfs_root + "/iio:device0";
  fs::create_directories(f->dir_ + "/buffer");
  fs::create_directories(f->dir_ + "/scan_elements");
  Put(f->dir_ + "/name", "adis16407");
  Put(f->dir_ + "/current_timestamp_clock", "realtime");
  Put(f->dir_ + "/sampling_frequency", "409.6");
  Put(f->dir_ + "/buffer/enable", "0");
  Put(f->dir_ + "/buffer/length", "2");
  Put(f->dir_ + "/in_accel_scale", "0.0326");
  Put(f->dir_ + "/in_anglvel_scale", "0.00087266");
  for (const Channel& c : kChannels) {
    const std::string base = f->dir_ + "/scan_elements/" + c.name;
    Put(base + "_en", "1");
    Put(base + "_index", std::to_string(c.index));
    Put(base + "_type", c.type);
  }
  fs::create_directories(dev_root);
  f->fifo_ = dev_root + "/iio:device0";
  std::error_code ec;
  fs::remove(f->fifo_, ec);
  if (mkfifo(f->fifo_.c_str(), 0600) != 0) return UnavailableError(f->fifo_ + ": " + std::strerror(errno));
  // Read-write, so that it opens at once and the reader sees no end of stream before Vanish().
  f->fd_ = open(f->fifo_.c_str(), O_RDWR | O_CLOEXEC);
  if (f->fd_ < 0) return UnavailableError(f->fifo_ + ": " + std::strerror(errno));
  return f;
}

FakeIioImu::~FakeIioImu() {
  if (fd_ >= 0) close(fd_);
}

std::string FakeIioImu::CheckSetup(const std::string& rate, const std::string& length, bool buffer_on) const {
  std::string out;
  const auto expect = [&](const std::string& file, const std::string& value) {
    const std::string got = Get(dir_ + "/" + file);
    if (got != value) out += file + " = '" + got + "', expected '" + value + "'; ";
  };
  expect("buffer/enable", buffer_on ? "1" : "0");
  expect("current_timestamp_clock", "monotonic");
  expect("sampling_frequency", rate);
  expect("buffer/length", length);
  for (const Channel& c : kChannels) {
    const bool imu = std::string(c.name) != "in_voltage0_supply" && std::string(c.name) != "in_temp0";
    expect(std::string("scan_elements/") + c.name + "_en", imu ? "1" : "0");
  }
  return out;
}

std::vector<uint8_t> FakeIioImu::Record(const int16_t accel[3], const int16_t gyro[3], int64_t timestamp_ns) {
  std::vector<uint8_t> r(kRecordSize, 0);
  for (int i = 0; i < 3; ++i) {
    const uint16_t a = static_cast<uint16_t>(accel[i]) & 0x3FFF, g = static_cast<uint16_t>(gyro[i]) & 0x3FFF;
    r[2 * i] = static_cast<uint8_t>(a >> 8);
    r[2 * i + 1] = static_cast<uint8_t>(a & 0xFF);
    r[6 + 2 * i] = static_cast<uint8_t>(g >> 8);
    r[6 + 2 * i + 1] = static_cast<uint8_t>(g & 0xFF);
  }
  for (int b = 0; b < 8; ++b) r[16 + b] = static_cast<uint8_t>(static_cast<uint64_t>(timestamp_ns) >> (8 * b));
  return r;
}

void FakeIioImu::Write(std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd_, bytes.data() + done, bytes.size() - done);
    if (n <= 0) return;
    done += static_cast<size_t>(n);
  }
}

void FakeIioImu::Vanish() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  std::error_code ec;
  std::filesystem::remove(fifo_, ec);
  std::filesystem::remove_all(dir_, ec);
}

}  // namespace cairn::testing
