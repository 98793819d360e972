#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The outputs of `hrg study tolerance` made from its study.json: study.csv
(one row per point), a summary on stdout, and the plots adb_plane.png (the
compensated ADB over the split / dQ/Q plane at the run length, the 3 deg/h
contour, one panel per gap harmonic and Q) and adb_time.png (the model's ADB
against time with its Cramer-Rao bound for a few points).

usage: study_report.py STUDY.json OUTDIR [--no-plots]
The local and the distributed run both write their files through here."""
import csv
import json
import math
import os
import sys

THRESHOLDS = ("3", "0.1", "0.01")


def fmt(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return "%.6g" % v
    return str(v)


def write_csv(study, path):
    cols = ["point", "split_hz", "dq_over_q", "gap", "q", "raw_adb_dph", "comp_adb_dph",
            "raw_bias_dph", "comp_bias_dph", "model_adb_end_dph", "crb_adb_end_dph",
            "meas_sigma_dph", "control_drift_mean_dph", "predicted_adb_dph", "ratio",
            "meets_bound"]
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(cols + ["t_reach_%s_dph_s" % t for t in THRESHOLDS]
                   + ["crb_at_%s_dph_reach" % t for t in THRESHOLDS]
                   + ["pump_needed_v", "setup_error", "reasons"])
        for p in study["points"]:
            row = [fmt(p[c]) for c in cols]
            row += [fmt(p["t_reach_s"][t]) for t in THRESHOLDS]
            row += [fmt(p["crb_at_reach_dph"][t]) for t in THRESHOLDS]
            row += [fmt(p["pump_needed_v"]), p["setup_error"], "; ".join(p["reasons"])]
            w.writerow(row)


def none_as_nan(v):
    """A figure the study could not measure (null in the JSON) printed as nan."""
    return float("nan") if v is None else v


def summary(study):
    print("tolerance study: %d points x %d seeds of %.0f s (grid %s)" %
          (len(study["points"]), study["seeds"], study["duration_s"], study["grid"]))
    print("%5s %9s %6s %6s %8s %9s %9s %9s %6s %8s %8s %8s  %s" %
          ("point", "split_Hz", "dQ/Q", "gap", "Q", "raw_ADB", "comp_ADB", "bound", "ratio",
           "t_3", "t_0.1", "t_0.01", "verdict"))
    met = 0
    for p in study["points"]:
        t = ["%8.0f" % p["t_reach_s"][k] if p["t_reach_s"][k] is not None else "       -"
             for k in THRESHOLDS]
        verdict = "within 2x" if p["meets_bound"] else (
            "; ".join(p["reasons"]) if p["reasons"] else "MISSES 2x WITH NO KNOWN CAUSE")
        met += p["meets_bound"]
        ratio = none_as_nan(p["ratio"])
        print("%5d %9.2g %6.3g %6.3g %8.2g %9.4g %9.4g %9.4g %6.2f %s %s %s  %s" %
              (p["point"], p["split_hz"], p["dq_over_q"], p["gap"], p["q"],
               none_as_nan(p["raw_adb_dph"]), none_as_nan(p["comp_adb_dph"]),
               p["predicted_adb_dph"], ratio, t[0], t[1], t[2], verdict))
    print("%d of %d points within 2x the bound; the others carry their reason" %
          (met, len(study["points"])))


def plane_panels(points):
    panels = {}
    for p in points:
        panels.setdefault((p["gap"], p["q"]), []).append(p)
    return panels


def compensated(point):
    """Whether a compensated ADB exists: some seed had its compensation applied and
    its parks spread enough for the 4 theta fit (a null ADB is not measured)."""
    return point["comp_adb_dph"] is not None and any(
        r.get("compensation_applied", True) for r in point.get("per_seed", [{}]))


def masked(rows):
    """The rows as an array with NaN masked (drawn in the colour map's 'bad' colour)."""
    import numpy as np
    return np.ma.masked_invalid(np.array(rows, dtype=float))


def plot_plane(study, path, plt):
    panels = plane_panels(study["points"])
    n = len(panels)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.9 * rows), squeeze=False)
    for ax, ((gap, q), pts) in zip(axes.flat, sorted(panels.items())):
        splits = sorted({p["split_hz"] for p in pts})
        dqs = sorted({p["dq_over_q"] for p in pts})
        # A point where no seed had its compensation applied has no compensated
        # ADB: it stays blank (grey), never drawn as a low value.
        z = [[float("nan")] * len(splits) for _ in dqs]
        for p in pts:
            if compensated(p):
                z[dqs.index(p["dq_over_q"])][splits.index(p["split_hz"])] = max(p["comp_adb_dph"], 1e-4)
        logz = [[math.log10(v) for v in r] for r in z]
        cmap = plt.get_cmap("viridis").copy()
        cmap.set_bad("0.8")
        im = ax.pcolormesh(range(len(splits) + 1), range(len(dqs) + 1), masked(logz), cmap=cmap,
                           shading="flat")
        seen = [v for r in logz for v in r if not math.isnan(v)]
        if len(splits) > 1 and len(dqs) > 1 and seen:
            xs = [i + 0.5 for i in range(len(splits))]
            ys = [j + 0.5 for j in range(len(dqs))]
            lo, hi = min(seen), max(seen)
            if lo < math.log10(3.0) < hi:
                cs = ax.contour(xs, ys, masked(logz), levels=[math.log10(3.0)], colors="white",
                                linewidths=2)
                ax.clabel(cs, fmt={math.log10(3.0): "3 deg/h"}, fontsize=8)
        for p in pts:
            i, j = splits.index(p["split_hz"]), dqs.index(p["dq_over_q"])
            mark = "" if p["meets_bound"] else "\n(misses: see reasons)"
            text = "%.3g%s" % (p["comp_adb_dph"], mark) if compensated(p) else "no valid\ncompensation"
            ax.text(i + 0.5, j + 0.5, text, ha="center", va="center", fontsize=7,
                    color="white" if logz[j][i] < 1 else "black")
        ax.set_xticks([i + 0.5 for i in range(len(splits))], ["%.0e" % s for s in splits])
        ax.set_yticks([j + 0.5 for j in range(len(dqs))], ["%.3g" % d for d in dqs])
        ax.set_xlabel("split, Hz")
        ax.set_ylabel("dQ/Q")
        ax.set_title("Q %.2g, gap harmonic %.3g" % (q, gap), fontsize=9)
        fig.colorbar(im, ax=ax, label="log10 compensated ADB, deg/h")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle("compensated ADB after %.0f s (mean over %d seeds)" %
                 (study["duration_s"], study["seeds"]))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_time(study, path, plt):
    pts = study["points"]
    picks = sorted({0, len(pts) // 3, (2 * len(pts)) // 3, len(pts) - 1})
    fig, ax = plt.subplots(figsize=(8, 5))
    for k, i in enumerate(picks):
        p = pts[i]
        s = p["series"]
        colour = "C%d" % k
        label = "point %d: split %.0e Hz, dQ/Q %.3g, gap %.3g, Q %.1e" % (
            p["point"], p["split_hz"], p["dq_over_q"], p["gap"], p["q"])
        t = [x for x, y in zip(s["t_s"], s["model_adb_dph"]) if y is not None and y > 0]
        y = [y for y in s["model_adb_dph"] if y is not None and y > 0]
        ax.loglog(t, y, color=colour, label=label)
        tb = [x for x, y in zip(s["t_s"], s["crb_adb_dph"]) if y is not None and y > 0]
        yb = [y for y in s["crb_adb_dph"] if y is not None and y > 0]
        ax.loglog(tb, yb, color=colour, linestyle="--")
    for th in (3.0, 0.1, 0.01):
        ax.axhline(th, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlabel("time, s")
    ax.set_ylabel("ADB left by the model in force, deg/h")
    ax.set_title("ADB against time (solid, mean over seeds) and its Cramer-Rao bound (dashed)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv):
    if len(argv) not in (3, 4) or (len(argv) == 4 and argv[3] != "--no-plots"):
        sys.stderr.write(__doc__)
        return 2
    with open(argv[1]) as f:
        study = json.load(f)
    out = argv[2]
    write_csv(study, os.path.join(out, "study.csv"))
    summary(study)
    if len(argv) == 4:
        return 0
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plot_plane(study, os.path.join(out, "adb_plane.png"), plt)
    plot_time(study, os.path.join(out, "adb_time.png"), plt)
    print("plots: %s, %s" % (os.path.join(out, "adb_plane.png"), os.path.join(out, "adb_time.png")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
