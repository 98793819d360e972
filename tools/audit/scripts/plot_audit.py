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


def main():
    csv, out, title = sys.argv[1], sys.argv[2], sys.argv[3]
    d = np.genfromtxt(csv, delimiter=",", names=True)
    t = d["t_s"]
    th4 = np.mod(4.0 * d["theta_deg"], 360.0)

    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    ax[0, 0].plot(t, d["res_before"], ".", ms=1.5, label="baseline")
    ax[0, 0].plot(t, d["res_after"], ".", ms=1.5, label="selected model")
    ax[0, 0].set_xlabel("t (s)")
    ax[0, 0].set_ylabel("block residual rms (noise units)")
    ax[0, 0].set_yscale("log")
    ax[0, 0].legend()
    ax[0, 0].set_title("residual against time (free decays)")
    da_b = d["a_meas_v"] - d["a_before_v"]
    da_a = d["a_meas_v"] - d["a_after_v"]
    ax[0, 1].plot(th4, da_b, ".", ms=1.5, label="baseline")
    ax[0, 1].plot(th4, da_a, ".", ms=1.5, label="selected model")
    ax[0, 1].set_xlabel("4 theta (deg)")
    ax[0, 1].set_ylabel("amplitude residual (V)")
    ax[0, 1].legend()
    ax[0, 1].set_title("amplitude residual against pattern angle")
    dq_b = d["q_meas_v"] - d["q_before_v"]
    dq_a = d["q_meas_v"] - d["q_after_v"]
    ax[1, 0].plot(th4, dq_b, ".", ms=1.5, label="baseline")
    ax[1, 0].plot(th4, dq_a, ".", ms=1.5, label="selected model")
    ax[1, 0].set_xlabel("4 theta (deg)")
    ax[1, 0].set_ylabel("quadrature a_B residual (V)")
    ax[1, 0].legend()
    ax[1, 0].set_title("quadrature residual against pattern angle")
    ax[1, 1].plot(d["a_meas_v"] ** 2, d["res_before"], ".", ms=1.5, label="baseline")
    ax[1, 1].plot(d["a_meas_v"] ** 2, d["res_after"], ".", ms=1.5, label="selected model")
    ax[1, 1].set_xlabel("a_A^2 (V^2)")
    ax[1, 1].set_ylabel("block residual rms (noise units)")
    ax[1, 1].set_yscale("log")
    ax[1, 1].legend()
    ax[1, 1].set_title("residual against amplitude")
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
