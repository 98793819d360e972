#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
set -euo pipefail
tools/ci/preset.sh armhf
