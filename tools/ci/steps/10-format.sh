#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Every tracked C++ file must already be formatted as .clang-format says.
set -euo pipefail
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.c' | grep -v '/violation_fixture/')
[ ${#files[@]} -eq 0 ] && exit 0
clang-format --dry-run --Werror "${files[@]}"
echo "format: ${#files[@]} files clean"
