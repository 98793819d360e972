#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`hrg study tolerance` on Dask's distributed scheduler (Debian's
python3-distributed): every grid point is one task that runs
`hrg study tolerance --point K --grid GRID` on a worker and returns its JSON
line; the lines are merged by `hrg study tolerance --merge`, which writes the
same study.json, study.csv and plots as the local run.

usage: dask_study.py HRG GRID OUTDIR [--workers N] [--scheduler ADDRESS] [--no-plots]

Without --scheduler it starts a LocalCluster of N worker processes (default 2,
one thread each) on this machine; with --scheduler tcp://HOST:8786 it uses a
running cluster (`dask-scheduler` and `dask-worker` on the machines, each with
the same hrg build and grid file at the same paths)."""
import argparse
import os
import subprocess
import sys


def run_point(hrg, grid, k):
    """One grid point on a worker: its JSON line (hrg's own one-point run, all
    seeds on the worker's thread)."""
    out = subprocess.run([hrg, "study", "tolerance", "--point", str(k), "--grid", grid,
                          "--jobs", "1"], check=True, capture_output=True, text=True)
    lines = [line for line in out.stdout.splitlines() if line.strip()]
    if len(lines) != 1:
        raise RuntimeError("point %d: expected one JSON line, got %d" % (k, len(lines)))
    return lines[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("hrg")
    ap.add_argument("grid")
    ap.add_argument("outdir")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", default="")
    ap.add_argument("--no-plots", action="store_true")
    a = ap.parse_args()
    hrg = os.path.abspath(a.hrg)
    count = int(subprocess.run([hrg, "study", "tolerance", "--count", "--grid", a.grid],
                               check=True, capture_output=True, text=True).stdout)
    from dask.distributed import Client, LocalCluster
    cluster = None
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = client.map(run_point, [hrg] * count, [a.grid] * count, range(count),
                             pure=False)
        lines = client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    os.makedirs(a.outdir, exist_ok=True)
    merged = os.path.join(a.outdir, "points.jsonl")
    with open(merged, "w") as f:
        f.write("".join(line + "\n" for line in lines))
    cmd = [hrg, "study", "tolerance", "--merge", merged, "--grid", a.grid, "--out", a.outdir]
    if a.no_plots:
        cmd.append("--no-plots")
    return subprocess.run(cmd).returncode


if __name__ == "__main__":
    sys.exit(main())
