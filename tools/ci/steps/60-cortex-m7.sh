#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Bare-metal Cortex-M7: build the freestanding libraries and the fixed-point
# suite, run the suite on QEMU mps2-an500 (same digest as the host), print sizes.
set -euo pipefail
tools/ci/preset.sh cortex-m7 --no-test
ctest --test-dir build/cortex-m7/tests/m7 --output-on-failure
cmake --build --preset cortex-m7 --target size_report
