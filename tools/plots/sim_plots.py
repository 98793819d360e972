#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Plots of an `hrg sim` run: reads DIR/telemetry.csv, bias.csv, allan.csv and
report.json and writes angle_error.png, bias_vs_angle.png, loops.png and
allan.png into DIR. Usage: sim_plots.py DIR"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    rows = list(csv.DictReader(lines))
    cols = {}
    for r in rows:
        for k, v in r.items():
            cols.setdefault(k, []).append(float(v))
    return cols


def shade_windows(ax, t, exc):
    """Grey bands where the excitation is off (free-decay windows)."""
    start = None
    for ti, e in zip(t, exc):
        if e < 0.5 and start is None:
            start = ti
        elif e >= 0.5 and start is not None:
            ax.axvspan(start, ti, color="0.85", lw=0)
            start = None


def main(out):
    tel = read_csv(os.path.join(out, "telemetry.csv"))
    with open(os.path.join(out, "report.json")) as f:
        rep = json.load(f)
    t = tel["t_s"]
    valid = tel["out_valid"]
    dt = t[1] - t[0] if len(t) > 1 else 0.01

    # 1. Angle error against the truth, raw and compensated, and what the
    #    drift model predicts for the raw output.
    fig, ax = plt.subplots(figsize=(10, 4.5))
    shade_windows(ax, t, tel["exc"])
    tv = [ti for ti, v in zip(t, valid) if v]
    # Errors accumulated over the valid output only (hrg sim's raw_error_deg
    # and out_error_deg): a held output while the pattern is moved on purpose
    # is not an error.
    raw = [e for e, v in zip(tel["raw_error_deg"], valid) if v]
    comp = [e for e, v in zip(tel["out_error_deg"], valid) if v]
    model, acc = [], 0.0
    for d, v in zip(tel["drift_true_dph"], valid):
        if v:
            acc -= d * dt / 3600.0
            model.append(acc)
    ax.plot(tv, raw, label="raw output - true")
    ax.plot(tv, comp, label="compensated output - true")
    ax.plot(tv, model, "--", label="drift model: -integral(D/K)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("angle error (deg)")
    ax.set_title("Output angle error (grey: free-decay windows)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "angle_error.png"), dpi=110)
    plt.close(fig)

    # 2. Bias against pattern angle, raw and compensated, with the fits.
    bias_path = os.path.join(out, "bias.csv")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    b = read_csv(bias_path) if os.path.exists(bias_path) else {}
    if b.get("theta_deg"):
        th = b["theta_deg"]
        ax.plot(th, b["raw_dph"], "o", label="raw")
        ax.plot(th, b["compensated_dph"], "s", label="compensated")
        ax.plot(th, b["model_dph"], "x", label="drift model (truth)")
        if th:
            lo, hi = min(th), max(th)
            grid = [lo + (hi - lo) * i / 200 for i in range(201)]
            for key, style in (("raw", "-"), ("compensated", "-")):
                d = rep["drift"][key]
                if d.get("degenerate"):
                    # parks at nearly one 4 theta: the fit's b and ADB are not separable
                    ax.axhline(d["park_mean_dph"], ls="--", alpha=0.6,
                               label=f"{key}: parks span {d['span_deg']:.1f} deg, "
                                     f"mean {d['park_mean_dph']:.4f} deg/h (no ADB)")
                    continue
                ax.plot(grid, [d["mean_dph"] + d["sin4_dph"] * math.sin(4 * math.radians(g)) +
                               d["cos4_dph"] * math.cos(4 * math.radians(g)) for g in grid],
                        style, alpha=0.6,
                        label=f"{key} fit: ADB {d['adb_dph']:.3f} deg/h, b {d['mean_dph']:.3f}")
    ax.set_xlabel("pattern angle theta_A (deg)")
    ax.set_ylabel("bias (deg/h, input axis)")
    ax.set_title("Angle-dependent bias, b + A sin4theta + B cos4theta")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bias_vs_angle.png"), dpi=110)
    plt.close(fig)

    # 3. Amplitude, quadrature and frequency against time.
    fig, axs = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for a in axs:
        shade_windows(a, t, tel["exc"])
        a.grid(True, alpha=0.3)
    axs[0].plot(t, tel["a_a_v"])
    axs[0].set_ylabel("a_A (V)")
    axs[1].plot(t, tel["a_b_v"])
    axs[1].set_ylabel("a_B quadrature (V)")
    axs[2].plot(t, tel["pll_hz"])
    axs[2].set_ylabel("PLL frequency (Hz)")
    axs[2].set_xlabel("t (s)")
    axs[0].set_title("Amplitude, quadrature and frequency (grey: free-decay windows)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "loops.png"), dpi=110)
    plt.close(fig)

    # 4. Allan deviation of the compensated output rate error.
    fig, ax = plt.subplots(figsize=(7, 4.5))
    allan_path = os.path.join(out, "allan.csv")
    a = read_csv(allan_path) if os.path.exists(allan_path) else {}
    if a.get("tau_s"):
        ax.loglog(a["tau_s"], a["adev_dph"], "o-")
    ax.set_xlabel("tau (s)")
    ax.set_ylabel("Allan deviation (deg/h)")
    ax.set_title("Allan deviation of the output rate (compensated, truth removed)")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "allan.png"), dpi=110)
    plt.close(fig)
    print("plots: angle_error.png bias_vs_angle.png loops.png allan.png in " + out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.stderr.write("usage: sim_plots.py DIR\n")
        sys.exit(2)
    main(sys.argv[1])
