#!/bin/sh
# SPDX-License-Identifier: MIT
# `hrg study tolerance` on Dask's distributed scheduler (a LocalCluster of two
# workers, tools/study/dask_study.py) gives the same study.json and study.csv
# as the local run on all cores.
# usage: check_distributed.sh HRG DASK_SCRIPT GRID WORKDIR
set -eu
hrg=$1 script=$2 grid=$3 work=$4
if ! /usr/bin/python3 -c "import distributed" 2>/dev/null; then
  echo "SKIP: Dask's distributed scheduler is not installed" \
    "(apt-get install python3-distributed python3-dask; tools/setup/deps.sh test)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
"$hrg" study tolerance --grid "$grid" --jobs 0 --out "$work/local" --no-plots >"$work/local.txt"
/usr/bin/python3 "$script" "$hrg" "$grid" "$work/dask" --workers 2 --no-plots >"$work/dask.txt"
n=$("$hrg" study tolerance --count --grid "$grid")
lines=$(grep -c '^{"point": ' "$work/dask/study.json")
if [ "$lines" -ne "$n" ]; then
  echo "FAIL: the distributed study.json holds $lines points, the grid $n"
  exit 1
fi
cmp "$work/local/study.json" "$work/dask/study.json"
cmp "$work/local/study.csv" "$work/dask/study.csv"
echo "distributed run (Dask LocalCluster, 2 workers) == local run: $n points, study.json and study.csv identical"
