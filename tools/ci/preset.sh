#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configure, build and (unless told otherwise) test one CMake preset.
#   tools/ci/preset.sh PRESET [--no-test] [--target T]
set -euo pipefail
preset=$1; shift
run_tests=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --no-test) run_tests=0 ;;
    --target) targets+=(--target "$2"); shift ;;
  esac
  shift
done
jobs=${HRG_JOBS:-$(nproc)}
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$jobs" "${targets[@]}"
if [ "$run_tests" -eq 1 ]; then
  ctest --preset "$preset" -j "$jobs"
fi
