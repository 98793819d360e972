#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Plots of `hrg audit --plots DIR`: residual maps and the fit before/after.

usage: plot_audit.py audit_blocks.csv OUTDIR TITLE
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def before_after(ax, x, y_before, y_after, xlabel, ylabel, title, log=False):
    """One residual panel: the baseline's and the selected model's points."""
    ax.plot(x, y_before, ".", ms=1.5, label="baseline")
    ax.plot(x, y_after, ".", ms=1.5, label="selected model")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if log:
        ax.set_yscale("log")
    ax.legend()
    ax.set_title(title)


def main():
    csv, out, title = sys.argv[1], sys.argv[2], sys.argv[3]
    d = np.genfromtxt(csv, delimiter=",", names=True)
    t = d["t_s"]
    th4 = np.mod(4.0 * d["theta_deg"], 360.0)

    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    da_b = d["a_meas_v"] - d["a_before_v"]
    da_a = d["a_meas_v"] - d["a_after_v"]
    dq_b = d["q_meas_v"] - d["q_before_v"]
    dq_a = d["q_meas_v"] - d["q_after_v"]
    rms_label = "block residual rms (noise units)"
    before_after(ax[0, 0], t, d["res_before"], d["res_after"], "t (s)", rms_label,
                 "residual against time (free decays)", log=True)
    before_after(ax[0, 1], th4, da_b, da_a, "4 theta (deg)", "amplitude residual (V)",
                 "amplitude residual against pattern angle")
    before_after(ax[1, 0], th4, dq_b, dq_a, "4 theta (deg)", "quadrature a_B residual (V)",
                 "quadrature residual against pattern angle")
    before_after(ax[1, 1], d["a_meas_v"] ** 2, d["res_before"], d["res_after"], "a_A^2 (V^2)",
                 rms_label, "residual against amplitude", log=True)
    fig.suptitle("hrg audit residual map: " + title)
    fig.tight_layout()
    fig.savefig(out + "/residual_map.png", dpi=90)

    fig, ax = plt.subplots(3, 1, figsize=(12, 9), sharex=True)
    ax[0].plot(t, d["a_meas_v"], ".", ms=1.5, label="measured")
    ax[0].plot(t, d["a_before_v"], "-", lw=0.6, label="baseline")
    ax[0].plot(t, d["a_after_v"], "-", lw=0.6, label="selected model")
    ax[0].set_ylabel("a_A (V)")
    ax[0].legend()
    ax[1].plot(t, d["q_meas_v"], ".", ms=1.5, label="measured")
    ax[1].plot(t, d["q_before_v"], "-", lw=0.6, label="baseline")
    ax[1].plot(t, d["q_after_v"], "-", lw=0.6, label="selected model")
    ax[1].set_ylabel("a_B (V)")
    ax[2].plot(t, da_b, ".", ms=1.5, label="a_A residual, baseline")
    ax[2].plot(t, da_a, ".", ms=1.5, label="a_A residual, selected")
    ax[2].set_ylabel("residual (V)")
    ax[2].set_xlabel("t (s)")
    ax[2].legend()
    fig.suptitle("fit before / after: " + title)
    fig.tight_layout()
    fig.savefig(out + "/fit_before_after.png", dpi=90)


if __name__ == "__main__":
    main()
