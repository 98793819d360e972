#!/bin/busybox sh
# SPDX-License-Identifier: MIT
# /init of the test VM: brings up vcan0/vcan1 and a gpio-sim chip, runs the
# Linux HAL tests against the real kernel, and reports to the host through
# qemu's isa-debug-exit port (0xf4): byte 1 = pass (qemu exits 3), 2 = fail (5).
/bin/busybox --install -s /bin
export PATH=/usr/bin:/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp

report() {
  echo "HRG-VM-RESULT: $1"
  if [ "$1" = PASS ]; then v='\001'; else v='\002'; fi
  printf "$v" | dd of=/dev/port bs=1 seek=244 count=1 2>/dev/null
  poweroff -f
}

step() {
  echo "=== guest: $1"
}

failed=0
check() {  # check NAME COMMAND...: runs, prints, remembers a failure
  name=$1
  shift
  if "$@"; then echo "guest: $name ok"; else echo "guest: $name FAILED"; failed=1; fi
}

# The host checks that a failing guest is seen as failing (run-vm.sh with
# hrg.selfcheck=fail on the kernel command line).
if grep -q "hrg.selfcheck=fail" /proc/cmdline; then
  echo "guest: self-check, reporting FAIL on purpose"
  report FAIL
fi

step "modules"
for m in $(cat /modules/order); do
  insmod /modules/$m || { echo "guest: insmod $m failed"; report FAIL; }
done
mount -t configfs configfs /sys/kernel/config || report FAIL

step "interfaces"
/usr/bin/ip link add dev vcan0 type vcan && /usr/bin/ip link set vcan0 up || report FAIL
# vcan1 sends through a 100 kbit/s token bucket so its TX queue fills.
/usr/bin/ip link add dev vcan1 type vcan && /usr/bin/ip link set vcan1 up || report FAIL
/usr/bin/tc qdisc add dev vcan1 root tbf rate 100kbit burst 1600 limit 3000 || report FAIL

sim=/sys/kernel/config/gpio-sim/hrg
mkdir "$sim" "$sim/bank0" || report FAIL
echo 4 > "$sim/bank0/num_lines"
echo hrg-sim > "$sim/bank0/label"
echo 1 > "$sim/live" || report FAIL
dev_name=$(cat "$sim/dev_name")
chip_name=$(cat "$sim/bank0/chip_name")
export HRG_GPIO_CHIP=hrg-sim
export HRG_GPIO_SYSFS=/sys/devices/platform/$dev_name/$chip_name
echo "guest: gpio-sim chip $chip_name ($dev_name), lines at $HRG_GPIO_SYSFS"
ls "$HRG_GPIO_SYSFS/sim_gpio0" >/dev/null || report FAIL

step "Linux HAL tests (SocketCAN, libgpiod)"
check test_hal_linux_kernel test_hal_linux_kernel -v

step "scripted board run on vcan0"
cd /tmp
candump -r 8000000 -L vcan0 > /tmp/capture.log &
dump=$!
can_rig run vcan0 60 > /tmp/rig.out 2>&1 &
rig=$!
sleep 0.5
eval "$(can_rig frames)"
send() {
  eval "frame=\$CMD_$1"
  cansend vcan0 "$frame"
  sleep 0.05
}
for c in STATUS1 UNKNOWN BADLEN AGC_RANGE REPEAT BADCRC RINGUP AGC_STEP AGC_OK WINDOW \
         IDENT_START; do
  send $c
done
sleep 1.3
# A controller error frame reporting bus-off, as a real controller would.
cansend vcan0 20000040#0000000000000000
sleep 2.5
for c in IDENT_STOP SAFE STATUS2; do
  send $c
  sleep 0.1
done
# Long enough for the 1 Hz HRG_CAN_STATS to report the restart.
sleep 1.5
kill -TERM $rig
wait $rig
rig_rc=$?
sleep 0.2
kill $dump
cat /tmp/rig.out
check "board run" [ $rig_rc -eq 0 ]
check "capture" can_rig check /tmp/capture.log

step "canplayer replays a log written by CandumpLogWriter"
can_rig write-log /tmp/replay.log
candump -L vcan0 > /tmp/replay-capture.log &
dump=$!
sleep 0.2
canplayer -I /tmp/replay.log vcan0=can0
sleep 0.3
kill $dump
check "canplayer replay" can_rig check-replay /tmp/replay-capture.log

step "full TX queue on vcan1 (100 kbit/s) survived"
can_rig run vcan1 1.5 > /tmp/rig1.out 2>&1
rig_rc=$?
cat /tmp/rig1.out
check "board run on a full queue" [ $rig_rc -eq 0 ]
check "queue-full counted" grep -q "tx_queue_full [1-9]" /tmp/rig1.out

if [ -x /usr/bin/hrg-board ]; then
  step "the firmware on this target (hrg-board: simulated converters, vcan0, gpio-sim)"
  candump -r 8000000 -L vcan0 > /tmp/firmware.log &
  dump=$!
  hrg-board --can vcan0 --gpio-chip hrg-sim --exc-line 0 --fault-line 1 --seconds 60 \
    > /tmp/board.out 2>&1 &
  board=$!
  sleep 3
  cansend vcan0 "$CMD_STATUS1"
  sleep 0.2
  cansend vcan0 "$CMD_WINDOW"
  sleep 1
  echo "guest: excitation enable line on gpio-sim reads $(cat "$HRG_GPIO_SYSFS/sim_gpio0/value")"
  kill -TERM $board
  wait $board
  board_rc=$?
  sleep 0.2
  kill $dump
  cat /tmp/board.out
  check "hrg-board run" [ $board_rc -eq 0 ]
  check "firmware capture" can_rig check-firmware /tmp/firmware.log
fi

if [ -x /usr/bin/hrg-board ] && [ -x /usr/bin/hrg ]; then
  # The board user's path with nothing but the bus: the firmware's telemetry
  # and the bench's LAB_TABLE captured by candump, decoded and audited. The
  # default resonator has no effect: the audit must find nothing (the same
  # verdict as the simulator's telemetry.csv, CTest can_audit_agrees_null).
  # 50 s: ring-up and lock take 35 s, then free-decay windows every 2 s. In
  # lockstep: the emulated CPU cannot keep the 1 kHz frames in real time; the
  # recording's time is the firmware's own (HRG_ROW.t_s), not the capture's.
  # The simulated lines, not gpio-sim's: the simulated resonator is excited
  # only through its own excitation switch (HRG_GPIO_CHIP is set above).
  step "audit-grade CAN telemetry: hrg-board on vcan0 -> candump -> hrg can-decode -> hrg audit"
  candump -r 8000000 -L vcan0 > /tmp/null.log &
  dump=$!
  (unset HRG_GPIO_CHIP; hrg-board --can vcan0 --lockstep --seconds 50) > /tmp/null-board.out 2>&1
  null_rc=$?
  sleep 0.2
  kill $dump
  cat /tmp/null-board.out
  hrg can-decode /tmp/null.log --dbc /etc/hrg.dbc -o /tmp/null.csv > /tmp/null-decode.out 2>&1
  cat /tmp/null-decode.out
  hrg audit /tmp/null.csv > /tmp/null-audit.out 2>&1
  head -12 /tmp/null-audit.out
  check "hrg-board null run" [ $null_rc -eq 0 ]
  check "null run decoded without loss" grep -q "no frame lost" /tmp/null-decode.out
  check "null run audited consistent" grep -q "^VERDICT: consistent" /tmp/null-audit.out
fi

if [ $failed -eq 0 ]; then report PASS; else report FAIL; fi
