#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs the shortened `hrg characterize --test all` (the firmware on the
# simulated target through every procedure), renders its data sheet and opens
# report.html in headless Chromium: 6 sections, each with its figure table,
# every figure named below present and every inlined PNG decoded.
# Usage: check_procedures_sheet.sh HRG OUT_DIR
set -eu
hrg=$1 out=$2
browser=$(command -v chromium || command -v chromium-browser || true)
rm -rf "$out" && mkdir -p "$out"
"$hrg" characterize --test all --short --turn-ons 2 --out "$out" --quiet
test -s "$out/summary.txt"
if [ -z "$browser" ]; then
  echo "check_procedures_sheet: chromium not found; install it with 'tools/setup/deps.sh test'" >&2
  exit 77
fi
"$browser" --headless --no-sandbox --disable-gpu --disable-background-networking \
  --disable-component-update --disable-sync --no-first-run --user-data-dir="$out/profile" \
  --virtual-time-budget=5000 --dump-dom "file://$out/report.html" >"$out/dom.html" 2>"$out/chromium.log"
count() { grep -o "$1" "$out/dom.html" | wc -l; }
sections=$(count '<section id=')
figures=$(count '<table class="figures"')
images=$(count '<img id="plot-')
decoded=$(sed -n 's/.*data-images-decoded="\([0-9]*\)".*/\1/p' "$out/dom.html")
echo "sections $sections (figure tables $figures), images $images, decoded ${decoded:-none}"
fail=0
[ "$sections" -eq 6 ] || { echo "expected 6 sections" >&2; fail=1; }
[ "$figures" -eq 6 ] || { echo "expected a figure table per section" >&2; fail=1; }
[ "$images" -ge 7 ] || { echo "expected at least 7 plots" >&2; fail=1; }
[ "${decoded:-0}" -eq "$images" ] || { echo "only ${decoded:-0} of $images images decoded" >&2; fail=1; }
for name in "Scale factor error" "Nonlinearity" "ADB 4 theta amplitude, raw" "Bias repeatability" \
  "Rate threshold, raw" "Rate threshold, compensated" "Largest input rate followed" \
  "Angle random walk" "Bias instability" "Run-down time"; do
  grep -q "<td>$name" "$out/dom.html" || { echo "figure '$name' missing" >&2; fail=1; }
done
exit $fail
