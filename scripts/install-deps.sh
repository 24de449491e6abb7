#!/usr/bin/env bash
# Installs every Debian 12 package cairn needs to build, test and run. Idempotent: it asks apt only
# for what is missing. Works as root or through sudo.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # the sanitizer builds (CI) use Clang and lld
  clang-14 lld-14 libclang-rt-14-dev
  # libraries
  libeigen3-dev libyaml-cpp-dev libspdlog-dev libfmt-dev libopencv-dev libsystemd-dev libnanoflann-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # image files (OpenCV's imgcodecs only in tests: it loads ~140 libraries)
  libpng-dev libjpeg62-turbo-dev
  # recording (MCAP chunks) and the live Foxglove stream
  libzstd-dev liblz4-dev libprotobuf-dev protobuf-compiler libwebsocketpp-dev libasio-dev nodejs
  # SLAM graph back-end
  libceres-dev
  # local mapping: probabilistic voxel submaps
  liboctomap-dev
  # AprilTag 36h11 code words (simulator markers) and teammate detection
  libapriltag-dev
  # tools used by tests and scripts
  systemd iproute2 can-utils util-linux file python3
  # cairn bench rt: load on every core, and the machine's own scheduling latency
  stress-ng rt-tests
  # tests: the real laser scan of ../shared/data/octomap is bzip2-compressed
  libbz2-dev
  # dense stereo (fpga/): Google Highway SIMD
  libhwy-dev
  # FPGA offload (fpga/rtl): cosimulation and synthesis check
  verilator yosys
  # the team exchange: ZeroMQ with CURVE (libsodium); link tests drop packets with nftables
  libzmq3-dev cppzmq-dev libsodium-dev nftables
  # GigE Vision stereo cameras (Aravis; its fake camera serves the driver's tests)
  libaravis-dev libusb-1.0-0-dev
  # the cameras' trigger line (GPIO character device, libgpiod 1.6)
  libgpiod-dev
)
if [[ "${CAIRN_CROSS:-0}" == "1" ]]; then
  packages+=(g++-aarch64-linux-gnu g++-arm-linux-gnueabihf)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# Tests that check outputs with third-party JavaScript clients need npm; some nodejs builds ship it,
# Debian's comes as its own package.
if ! command -v npm >/dev/null; then missing+=(npm); fi
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
