#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
set -euo pipefail
tools/ci/preset.sh cortex-m7 --no-test
cmake --build --preset cortex-m7 --target size_report
