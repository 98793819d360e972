# SPDX-License-Identifier: MIT
# 64-bit ARM Linux boards (Cortex-A53/A72 class) with Debian's cross compiler.
set(HRG_TRIPLE aarch64-linux-gnu)
set(HRG_PROCESSOR aarch64)
set(HRG_QEMU qemu-aarch64)
set(HRG_CROSS_PACKAGE g++-aarch64-linux-gnu)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
