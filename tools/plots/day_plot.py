#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""ADB against time with its Cramer-Rao bound, from bench_sim_day's CSV: the
model's angle-dependent bias error (deg/h) and the bound for the windows
taken, every hour, with the 1/sqrt(T) line from the first hour's bound, and
the excitation-off share. Usage: day_plot.py CSV PNG"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: day_plot.py CSV PNG")
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"day_plot.py: {argv[1]} holds no rows")
    t = [float(r["t_h"]) for r in rows]
    adb = [float(r["model_adb_dph"]) for r in rows]
    crb = [float(r["crb_adb_dph"]) for r in rows]
    off = [float(r["excitation_off_pct"]) for r in rows]
    fig, (ax, ax_off) = plt.subplots(2, 1, figsize=(8, 7), sharex=True,
                                     gridspec_kw={"height_ratios": [3, 1]})
    ax.loglog(t, adb, "o-", label="model ADB error (truth)")
    ax.loglog(t, crb, "s--", label="Cramer-Rao bound, windows taken")
    ax.loglog(t, [2.0 * c for c in crb], ":", color="grey", label="2x bound")
    ax.loglog(t, [crb[0] * math.sqrt(t[0] / x) for x in t], "-", color="black", lw=0.8,
              label="1/sqrt(T) from the first hour")
    ax.set_ylabel("deg/h")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    ax.set_title("Compensated model's angle-dependent bias over the run")
    ax_off.plot(t, off, "o-")
    ax_off.set_xscale("log")
    ax_off.set_ylabel("excitation off, %")
    ax_off.set_xlabel("time, h")
    ax_off.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)


if __name__ == "__main__":
    main(sys.argv)
