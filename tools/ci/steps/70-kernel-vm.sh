#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Linux HAL against a real kernel: Debian's kernel boots under QEMU (TCG) with
# vcan and an out-of-tree gpio-sim; the guest runs the SocketCAN/libgpiod tests,
# a scripted board run checked from a candump capture (commands with cansend,
# window toggles read back through gpio-sim's sysfs, bus-off, a full TX queue),
# a canplayer replay of our log, and the firmware itself on this target
# (hrg-board: simulated converters, vcan0, gpio-sim), whose candump capture
# `hrg can-decode` and `hrg audit` read (the null case of the audit-grade
# telemetry). Fails when the VM does not boot or report.
set -euo pipefail
tools/ci/preset.sh host --no-test --target test_hal_linux_kernel --target can_rig \
  --target hrg-board --target hrg
vm=build/vm
mkdir -p "$vm"
tools/vm/build-gpio-sim.sh "$vm"
tools/vm/build-initramfs.sh "$vm/initramfs.cpio.gz" "$vm/gpio-sim.ko" \
  build/host/bin/test_hal_linux_kernel build/host/bin/can_rig build/host/bin/hrg-board \
  build/host/bin/hrg
# The report channel must tell a failing guest from a passing one.
if tools/vm/run-vm.sh "$vm/initramfs.cpio.gz" "$vm/selfcheck.log" 60 hrg.selfcheck=fail; then
  echo "kernel-vm: a guest reporting FAIL was taken as a pass" >&2
  exit 1
fi
echo "kernel-vm: self-check ok (the FAIL above was requested: a failing guest is detected)"
status=0
tools/vm/run-vm.sh "$vm/initramfs.cpio.gz" "$vm/console.log" 300 || status=1
# The guest's own lines (the kernel is quiet); the full console is in the log.
sed -n '/^=== guest/,$p' "$vm/console.log" | tr -d '\r' | grep -v '^TEST(' || true
exit $status
