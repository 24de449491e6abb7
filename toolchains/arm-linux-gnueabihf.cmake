# Cross-compiling for 32-bit Arm boards with hardware floating point (armhf, e.g. BeagleBone
# Black as on the thesis' hexacopter) with Debian's cross compiler:
#   apt-get install g++-arm-linux-gnueabihf
#   cmake -S . -B build/armhf -G Ninja -DCMAKE_TOOLCHAIN_FILE=toolchains/arm-linux-gnueabihf.cmake
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CAIRN_CROSS_TRIPLE arm-linux-gnueabihf)
include(${CMAKE_CURRENT_LIST_DIR}/linux-gnu-common.cmake)
