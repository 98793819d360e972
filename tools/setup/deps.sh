#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages a profile needs, only those missing.
#   tools/setup/deps.sh sim    build the host CLI and run the simulated gyro
#   tools/setup/deps.sh test   everything CI builds and runs (cross, bare metal, kernel VM)
#   tools/setup/deps.sh --list PROFILE   prints the profile's packages, one a line
# As root it runs apt-get; otherwise it prints the exact apt-get line and stops.
set -euo pipefail

host_pkgs=(g++ cmake ninja-build pkg-config ccache git libeigen3-dev cpputest libcpputest-dev
  libtomlplusplus-dev libceres-dev zlib1g-dev python3 python3-numpy python3-scipy python3-matplotlib)
test_pkgs=(clang clang-format libclang-rt-14-dev valgrind can-utils gpiod libgpiod-dev
  python3-can g++-aarch64-linux-gnu g++-arm-linux-gnueabihf libc6-dev-arm64-cross
  libc6-dev-armhf-cross qemu-user qemu-system-arm qemu-system-x86 gcc-arm-none-eabi
  libstdc++-arm-none-eabi-newlib linux-image-amd64 linux-headers-amd64 linux-source-6.1
  busybox-static cpio kmod xz-utils make iproute2 debootstrap chromium
  python3-distributed python3-dask)
# Target libraries for the Linux board tests (Debian multiarch).
cross_pkgs=(libcpputest-dev:arm64 libcpputest-dev:armhf libgpiod-dev:arm64 libgpiod-dev:armhf)

list_only=0
if [ "${1:-}" = --list ]; then list_only=1; shift; fi
profile=${1:-}
case "$profile" in
  sim) wanted=("${host_pkgs[@]}") ;;
  test) wanted=("${host_pkgs[@]}" "${test_pkgs[@]}" "${cross_pkgs[@]}") ;;
  *) echo "usage: $0 [--list] sim|test" >&2; exit 2 ;;
esac
if [ "$list_only" -eq 1 ]; then printf '%s\n' "${wanted[@]}"; exit 0; fi

is_installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q '^install ok installed'
}

missing=()
for p in "${wanted[@]}"; do
  is_installed "$p" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

needs_foreign=()
for p in "${missing[@]}"; do
  case "$p" in *:*) needs_foreign+=("${p##*:}") ;; esac
done

if [ "$(id -u)" -ne 0 ]; then
  echo "Missing Debian packages. Install them as root with:" >&2
  for a in $(printf '%s\n' "${needs_foreign[@]}" | sort -u); do
    echo "  dpkg --add-architecture $a" >&2
  done
  echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
  exit 1
fi

for a in $(printf '%s\n' "${needs_foreign[@]}" | sort -u); do
  dpkg --print-foreign-architectures | grep -qx "$a" || dpkg --add-architecture "$a"
done
echo "deps: installing ${#missing[@]} Debian packages: ${missing[*]}"
# With foreign architectures enabled, a mirror's security index can be
# inconsistent and make 'apt-get update' exit 100 although installs work.
apt-get update -qq || echo "deps: apt-get update reported an error; trying the install anyway" >&2
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" \
  >/tmp/hrg-apt.log 2>&1 || { tail -n 30 /tmp/hrg-apt.log >&2; exit 1; }
echo "deps: done"
