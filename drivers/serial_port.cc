#include "drivers/serial_port.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace cairn {
namespace {

speed_t SerialSpeed(int64_t baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    case 2000000:
      return B2000000;
    case 4000000:
      return B4000000;
    default:
      return B0;
  }
}

}  // namespace

bool SerialPort::IsStandardBaud(int64_t baud) { return SerialSpeed(baud) != B0; }

Expected<int> SerialPort::Open(const std::string& device, int64_t baud) {
  const speed_t speed = SerialSpeed(baud);
  if (speed == B0)
    return InvalidArgumentError(device + ": baud " + std::to_string(baud) + " is not a standard rate");
  const int fd = open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return UnavailableError(device + ": " + std::strerror(errno));
  termios t{};
  if (tcgetattr(fd, &t) != 0) {
    const int e = errno;
    close(fd);
    return UnavailableError(device + ": not a serial port (" + std::strerror(e) + ")");
  }
  cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  cfsetispeed(&t, speed);
  cfsetospeed(&t, speed);
  if (tcsetattr(fd, TCSANOW, &t) != 0) {
    const int e = errno;
    close(fd);
    return UnavailableError(device + ": cannot set 8N1 at " + std::to_string(baud) +
                            " baud: " + std::strerror(e));
  }
  tcflush(fd, TCIOFLUSH);
  return fd;
}

}  // namespace cairn
