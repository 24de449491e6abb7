# Cross-compiling for 64-bit Arm boards (e.g. NVIDIA Jetson, Raspberry Pi 4/5, i.MX8) with Debian's
# cross compiler: apt-get install g++-aarch64-linux-gnu
#   cmake -S . -B build/aarch64 -G Ninja -DCMAKE_TOOLCHAIN_FILE=toolchains/aarch64-linux-gnu.cmake
# Target libraries come from Debian multiarch (see docs/cross-compiling.md) or a sysroot given as
# -DCAIRN_SYSROOT=/path/to/sysroot.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CAIRN_CROSS_TRIPLE aarch64-linux-gnu)
include(${CMAKE_CURRENT_LIST_DIR}/linux-gnu-common.cmake)
