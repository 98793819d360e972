#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Each toolchain file, configured where its compiler cannot be found, must stop
# with a FATAL_ERROR that names the Debian package to install.
set -euo pipefail
cmake_bin=$(command -v cmake)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
check() {
  local toolchain=$1 package=$2
  local log=$tmp/$(basename "$toolchain").log
  if env PATH=/nonexistent "$cmake_bin" -S . -B "$tmp/b-$(basename "$toolchain")" \
      -DCMAKE_TOOLCHAIN_FILE="$PWD/toolchains/$toolchain" \
      -DCMAKE_FIND_USE_SYSTEM_ENVIRONMENT_PATH=OFF -DCMAKE_FIND_USE_CMAKE_SYSTEM_PATH=OFF \
      >"$log" 2>&1; then
    echo "toolchain $toolchain configured without its compiler" >&2; return 1
  fi
  if ! tr -s " \n" "  " <"$log" | grep -q "apt-get install $package"; then
    echo "toolchain $toolchain failed without naming '$package':" >&2; cat "$log" >&2; return 1
  fi
  echo "toolchain $toolchain: missing compiler reported, names $package"
}
check aarch64-linux-gnu.cmake g++-aarch64-linux-gnu
check arm-linux-gnueabihf.cmake g++-arm-linux-gnueabihf
check arm-none-eabi-cortex-m7.cmake gcc-arm-none-eabi
