#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the test VM's initramfs: static busybox, the kernel modules the tests
# need (vcan, can-raw, configfs, sch_tbf and their dependencies, plus the
# out-of-tree gpio-sim), can-utils, iproute2, the test binaries and every
# shared library they load, the DBC (/etc/hrg.dbc), and tools/vm/guest-init.sh
# as /init.
#   tools/vm/build-initramfs.sh OUT.cpio.gz GPIO_SIM_KO BINARY...
set -euo pipefail
out=$(realpath -m "$1")
gpio_sim_ko=$(realpath "$2")
shift 2
here=$(cd "$(dirname "$0")" && pwd)
ver=$("$here/kernel-version.sh")
stage=$(mktemp -d "${TMPDIR:-/tmp}/hrg-initramfs.XXXXXX")
trap 'rm -rf "$stage"' EXIT

mkdir -p "$stage"/{bin,sbin,dev,proc,sys,tmp,modules,lib64,usr/bin} "$stage/lib/x86_64-linux-gnu"
cp /bin/busybox "$stage/bin/busybox"
mknod -m 600 "$stage/dev/console" c 5 1
mknod -m 666 "$stage/dev/null" c 1 3

# Modules in load order (dependencies first), each once.
: > "$stage/modules/order"
for m in configfs can can-raw vcan sch_tbf; do
  while read -r cmd path _; do
    [ "$cmd" = insmod ] || continue
    name=$(basename "$path")
    grep -qx "$name" "$stage/modules/order" && continue
    case "$path" in
      *.ko) cp "$path" "$stage/modules/$name" ;;
      *.ko.xz) xz -dc "$path" > "$stage/modules/${name%.xz}"; name=${name%.xz} ;;
      *) echo "build-initramfs: unexpected module file $path" >&2; exit 1 ;;
    esac
    echo "$name" >> "$stage/modules/order"
  done < <(modprobe -S "$ver" --show-depends "$m")
done
cp "$gpio_sim_ko" "$stage/modules/gpio-sim.ko"
echo gpio-sim.ko >> "$stage/modules/order"

# Programs and the libraries they load (ldd lists the dynamic loader too).
progs=(/usr/bin/candump /usr/bin/cansend /usr/bin/canplayer /usr/sbin/ip /usr/sbin/tc "$@")
for p in "${progs[@]}"; do
  [ -x "$p" ] || { echo "build-initramfs: missing program $p" >&2; exit 1; }
  cp "$p" "$stage/usr/bin/"
  for lib in $(ldd "$p" | grep -o '/[^ ]*'); do
    dest="$stage$lib"
    [ -e "$dest" ] && continue
    mkdir -p "$(dirname "$dest")"
    cp -L "$lib" "$dest"
  done
done
# The DBC for hrg can-decode in the guest.
mkdir -p "$stage/etc"
cp "$here/../../firmware/can/hrg.dbc" "$stage/etc/hrg.dbc"
cp "$here/guest-init.sh" "$stage/init"
chmod +x "$stage/init"
(cd "$stage" && find . | cpio -o -H newc --quiet | gzip -1) > "$out"
echo "build-initramfs: $out ($(du -k "$out" | cut -f1) kB, kernel $ver)"
