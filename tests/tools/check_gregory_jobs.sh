#!/bin/sh
# SPDX-License-Identifier: MIT
# The Gregory table's rows are independent runs: with --jobs 2 the table is
# the same, line for line, as with --jobs 1 (two rows of 60 s each).
# Usage: check_gregory_jobs.sh HRG SCENARIO OUT_DIR
set -eu
hrg=$1 scenario=$2 out=$3
table=$(dirname "$0")/../../tools/gregory/gregory_table.py
rm -rf "$out" && mkdir -p "$out"
for jobs in 1 2; do
  /usr/bin/python3 "$table" --hrg "$hrg" --scenario "$scenario" --duration 60 \
    --rows pickoff_gain_mismatch --jobs "$jobs" --work "$out/jobs$jobs" >"$out/table$jobs.md"
done
cat "$out/table2.md"
rows=$(grep -c '^| [a-z]' "$out/table1.md")
[ "$rows" -eq 3 ] || { echo "expected 2 rows under the header, got $((rows - 1))" >&2; exit 1; }
diff "$out/table1.md" "$out/table2.md" || { echo "--jobs 2 changed the table" >&2; exit 1; }
echo "--jobs 1 and --jobs 2: the same table"
