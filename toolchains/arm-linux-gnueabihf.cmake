# SPDX-License-Identifier: MIT
# 32-bit ARM Linux boards (Cortex-A7/A9 class, hard float) with Debian's cross compiler.
set(HRG_TRIPLE arm-linux-gnueabihf)
set(HRG_PROCESSOR armv7l)
set(HRG_QEMU qemu-arm)
set(HRG_CROSS_PACKAGE g++-arm-linux-gnueabihf)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
