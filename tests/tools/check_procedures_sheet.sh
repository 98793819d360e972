#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs the shortened `hrg characterize --test all` (the firmware on the
# simulated target through every procedure), renders its data sheet and opens
# report.html in headless Chromium: 6 sections, each with its figure table,
# every figure named below present and every inlined PNG decoded.
# Usage: check_procedures_sheet.sh HRG OUT_DIR
set -eu
. "$(dirname "$0")/sheet_dom.sh"
hrg=$1 out=$2
rm -rf "$out" && mkdir -p "$out"
"$hrg" characterize --test all --short --turn-ons 2 --out "$out" --quiet
test -s "$out/summary.txt"
if [ -z "$(sheet_browser)" ]; then
  echo "check_procedures_sheet: chromium not found; install it with 'tools/setup/deps.sh test'" >&2
  exit 77
fi
sheet_dump_dom "$out"
sections=$(sheet_count "$out" '<section id=')
figures=$(sheet_count "$out" '<table class="figures"')
images=$(sheet_count "$out" '<img id="plot-')
decoded=$(sheet_decoded "$out")
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
