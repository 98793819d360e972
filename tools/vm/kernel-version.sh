#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Prints the kernel release of Debian's linux-image-amd64 metapackage (e.g.
# 6.1.0-56-amd64), so the image, the headers and the modules all match.
set -euo pipefail
dep=$(dpkg-query -W -f='${Depends}' linux-image-amd64 2>/dev/null) || {
  echo "kernel-version: linux-image-amd64 is not installed (tools/setup/deps.sh test)" >&2
  exit 1
}
ver=$(sed -n 's/.*linux-image-\([^ ,]*\).*/\1/p' <<<"$dep" | head -n 1)
[ -n "$ver" ] && [ -e "/boot/vmlinuz-$ver" ] || {
  echo "kernel-version: no /boot/vmlinuz for '$dep'" >&2
  exit 1
}
echo "$ver"
