#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the gpio-sim driver out of tree for Debian's kernel, which does not
# ship it (nor IRQ_SIM): drivers/gpio/gpio-sim.c and kernel/irq/irq_sim.c from
# linux-source-6.1 compiled into one module against /lib/modules/<ver>/build.
#   tools/vm/build-gpio-sim.sh OUT_DIR      -> OUT_DIR/gpio-sim.ko
set -euo pipefail
out=$(realpath -m "$1")
here=$(cd "$(dirname "$0")" && pwd)
ver=$("$here/kernel-version.sh")
kdir=/lib/modules/$ver/build
src_tar=$(ls /usr/src/linux-source-6.1.tar.xz 2>/dev/null) || {
  echo "build-gpio-sim: linux-source-6.1 is not installed" >&2
  exit 1
}
[ -d "$kdir" ] || { echo "build-gpio-sim: no kernel headers at $kdir" >&2; exit 1; }
mkdir -p "$out/src"
if [ -e "$out/gpio-sim.ko" ] && [ "$out/gpio-sim.ko" -nt "$src_tar" ] &&
   [ "$out/gpio-sim.ko" -nt "$0" ] && [ "$(cat "$out/kernel" 2>/dev/null)" = "$ver" ]; then
  exit 0
fi
files=(drivers/gpio/gpio-sim.c drivers/gpio/gpiolib.h kernel/irq/irq_sim.c)
# Unpacking three files still decompresses the archive up to them (~15 s).
tar -xJf "$src_tar" -C "$out/src" --strip-components=1 "${files[@]/#/linux-source-6.1/}"
cd "$out/src"
cp drivers/gpio/gpio-sim.c drivers/gpio/gpiolib.h .
# irq_to_desc() is not exported to modules; generic_handle_irq_safe() is, and
# does the same for an interrupt raised outside hard-irq context.
sed 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq_safe(irqnum);/' \
  kernel/irq/irq_sim.c > irq_sim.c
grep -q 'generic_handle_irq_safe(irqnum)' irq_sim.c || {
  echo "build-gpio-sim: irq_sim.c did not take the export fix-up" >&2
  exit 1
}
cat > Kbuild <<'KBUILD'
obj-m := gpio-sim.o
gpio-sim-y := gpio-sim-main.o irq_sim.o
KBUILD
mv gpio-sim.c gpio-sim-main.c
make -s -C "$kdir" M="$PWD" modules >build.log 2>&1 || { tail -n 30 build.log >&2; exit 1; }
cp gpio-sim.ko "$out/gpio-sim.ko"
echo "$ver" > "$out/kernel"
echo "build-gpio-sim: $out/gpio-sim.ko for $ver"
