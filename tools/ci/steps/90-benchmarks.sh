#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Benchmarks print their figures (speed, instructions, accuracy); they are
# CTest entries labelled 'bench' in the host build, run one at a time so the
# figures are not disturbed by each other.
set -euo pipefail
ctest --preset bench -j 1
