# Shared part of the Debian cross toolchain files; CAIRN_CROSS_TRIPLE names the target.
set(CMAKE_C_COMPILER ${CAIRN_CROSS_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${CAIRN_CROSS_TRIPLE}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${CAIRN_CROSS_TRIPLE})

if(CAIRN_SYSROOT)
  set(CMAKE_SYSROOT ${CAIRN_SYSROOT})
  set(CMAKE_FIND_ROOT_PATH ${CAIRN_SYSROOT})
else()
  # Debian multiarch: target libraries live in /usr/lib/<triple>, headers in /usr/include.
  set(CMAKE_FIND_ROOT_PATH /usr/${CAIRN_CROSS_TRIPLE} /usr)
endif()
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
# Header-only, architecture-independent packages such as Eigen install their CMake config under
# /usr/share, which is valid for every target.
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
