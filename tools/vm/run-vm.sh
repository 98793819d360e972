#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Boots Debian's kernel under QEMU (TCG) with the test initramfs and waits for
# the guest's verdict on the isa-debug-exit port. Exit 0 only when the guest
# reported PASS; the console is written to LOG.
#   tools/vm/run-vm.sh INITRAMFS LOG [TIMEOUT_S [EXTRA_KERNEL_ARGS]]
set -uo pipefail
initrd=$1
log=$2
limit=${3:-150}
extra=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
ver=$("$here/kernel-version.sh") || exit 1
t0=$(date +%s%N)
# -M pc (microvm hung in some boots); KVM here is nested and hangs Debian's kernel.
timeout --kill-after=5 "$limit" qemu-system-x86_64 -M pc -accel tcg -m 512M -smp 1 \
  -nographic -no-reboot -kernel "/boot/vmlinuz-$ver" -initrd "$initrd" \
  -append "console=ttyS0 panic=-1 quiet loglevel=3 $extra" \
  -device isa-debug-exit,iobase=0xf4,iosize=0x04 >"$log" 2>&1 </dev/null
rc=$?
dt=$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.1f", (b - a) / 1e9 }')
case $rc in
  3) echo "run-vm: guest reported PASS (boot + tests ${dt} s)"; exit 0 ;;
  5) echo "run-vm: guest reported FAIL (${dt} s)" ;;
  124|137) echo "run-vm: no report within ${limit} s (did the VM boot?)" ;;
  *) echo "run-vm: qemu exited with $rc without a report (${dt} s)" ;;
esac
exit 1
