#!/bin/sh
# SPDX-License-Identifier: MIT
# Writes the data sheet of known inputs, renders it, opens report.html in
# headless Chromium and checks the DOM it built: 4 sections, their figure
# tables and data tables, and every inlined PNG decoded.
# Usage: check_datasheet.sh DEMO_EXE DATASHEET_PY OUT_DIR
set -eu
. "$(dirname "$0")/sheet_dom.sh"
demo=$1 script=$2 out=$3
if [ -z "$(sheet_browser)" ]; then
  echo "datasheet_renders: chromium not found; install it with 'tools/setup/deps.sh test'" \
    "(apt-get install chromium)" >&2
  exit 77
fi
rm -rf "$out" && mkdir -p "$out"
"$demo" "$out/sheet.json"
/usr/bin/python3 "$script" "$out/sheet.json" "$out"
test -s "$out/summary.txt"
# A fresh profile, no network, no background services.
sheet_dump_dom "$out"
sections=$(sheet_count "$out" '<section id=')
tables=$(sheet_count "$out" '<table class=')
figures=$(sheet_count "$out" '<table class="figures"')
images=$(sheet_count "$out" '<img id="plot-')
decoded=$(sheet_decoded "$out")
echo "sections $sections, tables $tables (figure tables $figures), images $images, decoded ${decoded:-none}"
fail=0
[ "$sections" -eq 4 ] || { echo "expected 4 sections" >&2; fail=1; }
[ "$figures" -eq 4 ] || { echo "expected a figure table per section" >&2; fail=1; }
[ "$tables" -eq 7 ] || { echo "expected 7 tables (4 figure tables, 3 data tables)" >&2; fail=1; }
[ "$images" -eq 4 ] || { echo "expected 4 plots" >&2; fail=1; }
[ "${decoded:-0}" -eq "$images" ] || { echo "only ${decoded:-0} of $images images decoded" >&2; fail=1; }
for name in "Angle random walk" "Bias instability" "Rate random walk" "Nonlinearity" \
  "Asymmetry" "Bias repeatability" "Rate threshold, raw" "Run-down time"; do
  grep -q "<td>$name" "$out/dom.html" || { echo "figure '$name' missing" >&2; fail=1; }
done
exit $fail
