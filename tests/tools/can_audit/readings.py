#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The firmware's own readings through CAN against telemetry.csv.

`hrg sim --can-log` with a calibration in force -> `hrg can-decode`: the
decoded recording's pump_edge_* / damping_check_* / self_cal_* keys are the ones hrg sim
writes into telemetry.csv, within the CAN resolution (firmware/can/README.md,
HRG_CAL_READINGS); `hrg audit REC --calibration OUT.toml` on both writes the
same feedthrough, combined with the switch-off step check's reading, within
what that resolution moves it.

usage: readings.py HRG SCENARIO CALIBRATION|- DURATION_S WORKDIR [--keys-only] [--thermal]
       [--pickoff]
CALIBRATION '-': none in force.
--keys-only: the keys alone (a calibration that removes the feedthrough
leaves the audit nothing to find, and the file nothing to combine).
--thermal: the run must have the damping model check's thermal reading.
--pickoff: the run must have the pickoff self-calibration's map.
Exit status 0 when they agree; prints every key and value compared.
"""
import os
import re
import sys

from compare import run  # the same runner and exit-status rule as the audit comparison

RES_FT = 2e-8  # V/V, the feedthrough signals' resolution
RES_SIGMA = 1e-9  # V/V, their sigma's
SET_PERIOD_S = 1.0  # one set of 10 pages at 10 Hz, held from its first page
RES_MAP = 4e-9  # the pickoff map's parts (-, rad)
RES_MAP_SIGMA = 2e-9  # their sigmas'
PREFIXES = ("pump_edge_", "damping_check_", "self_cal_")
PARTS = ("x_re", "x_im", "y_re", "y_im")


def header(path):
    keys = {}
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            k, _, v = line[1:].strip().partition("=")
            keys[k] = v
    return keys


# Each key's tolerance between the two recordings: half the signal's
# resolution (both halves of a sum for the in-force parts), the age of the
# last complete set for the time in force.
def tolerance(key):
    if key == "pump_edge_edges":
        return 0
    if key == "pump_edge_in_force_s":
        return 2 * SET_PERIOD_S + 0.01
    if key in ("pump_edge_sigma_v_per_v", "pump_edge_scatter_v_per_v"):
        return 0.5 * RES_SIGMA * (1 + 1e-9)
    if key.startswith("pump_edge_"):
        return 0.5 * RES_FT * (1 + 1e-9)
    if key == "damping_check_thermal_damping_per_c":
        return 0.5e-7 * (1 + 1e-9)
    if key == "damping_check_thermal_damping_sigma_per_c":
        return 0.5e-8 * (1 + 1e-9)
    if key.startswith("self_cal_"):
        return 0.5 * (RES_MAP_SIGMA if "sigma" in key else RES_MAP) * (1 + 1e-9)
    raise SystemExit(f"no tolerance for {key}")


def compare_keys(csv_keys, can_keys, thermal, bad, pickoff=False):
    wanted = sorted(k for k in csv_keys if k.startswith(PREFIXES))
    if not any(k.startswith("pump_edge_") for k in wanted):
        bad.append("telemetry.csv has no pump_edge_* keys: the run measured no switch-off")
    if thermal and "damping_check_thermal_damping_per_c" not in wanted:
        bad.append("telemetry.csv has no damping_check_* keys: the run has no thermal reading")
    if pickoff and "self_cal_gain" not in wanted:
        bad.append("telemetry.csv has no self_cal_* keys: the run has no pickoff map")
    for k in wanted:
        if k not in can_keys:
            bad.append(f"{k} missing from the decoded recording")
            continue
        x, y, tol = float(csv_keys[k]), float(can_keys[k]), tolerance(k)
        print(f"  {k}: {x:.9g} (csv) {y:.9g} (CAN) tol {tol:.3g}")
        if abs(x - y) > tol:
            bad.append(f"{k} differs by {abs(x - y):.3g} > {tol:.3g}")
    extra = [k for k in can_keys if k.startswith(PREFIXES) and k not in csv_keys]
    if extra:
        bad.append(f"the decoded recording has keys telemetry.csv has not: {extra}")


def calibration(path):
    """The file's feedthrough values and its combination comment's tuples."""
    values, text = {}, open(path).read()
    for p in PARTS:
        m = re.search(rf"^feedthrough_{p}_v_per_v = (\S+)$", text, re.M)
        values[p] = float(m.group(1))
    num = r"\(([^)]*)\) \+- (\S+) V/V"
    m = re.search(r"^# drive_feedthrough \(x re, x im, y re, y im\): weighted by inverse "
                  rf"variance .*the audit's {num}, the firmware's {num}", text, re.M)
    if m is None:
        return values, None

    def tup(i):
        return [float(v) for v in m.group(i).split(",")], float(m.group(i + 1))

    return values, (tup(1), tup(3))


def compare_files(csv_cal, can_cal, bad):
    v_csv, c_csv = calibration(csv_cal)
    v_can, c_can = calibration(can_cal)
    if c_csv is None or c_can is None:
        bad.append("a file does not weigh the switch-off step check's reading with the audit's "
                   f"(csv: {c_csv is not None}, CAN: {c_can is not None})")
        return
    (a_csv, sa), (f_csv, sf) = c_csv
    (a_can, _), (f_can, _) = c_can
    # The firmware's reading is the in-force part plus the residual: each
    # within half a resolution; the audit's own differs as the two
    # recordings do (compare.py). The combined value moves by their weights.
    w_f = sa * sa / (sa * sa + sf * sf)
    for i, p in enumerate(PARTS):
        print_tol = 1e-5 * abs(f_csv[i]) + 1e-5 * abs(a_csv[i])  # the comment's %.6g
        tol = w_f * RES_FT + (1 - w_f) * abs(a_csv[i] - a_can[i]) + print_tol
        d_fw = abs(f_csv[i] - f_can[i])
        d = abs(v_csv[p] - v_can[p])
        print(f"  feedthrough_{p}: {v_csv[p]:.9g} (csv) {v_can[p]:.9g} (CAN) tol {tol:.3g}; "
              f"the check's {f_csv[i]:.6g} / {f_can[i]:.6g}")
        if d_fw > RES_FT + print_tol:
            bad.append(f"the check's {p} differs by {d_fw:.3g} > {RES_FT + print_tol:.3g}")
        if d > tol:
            bad.append(f"feedthrough_{p} differs by {d:.3g} > {tol:.3g}")


def main():
    flags = sys.argv[6:]
    keys_only, thermal, pickoff = ("--keys-only" in flags, "--thermal" in flags,
                                   "--pickoff" in flags)
    if len(sys.argv) < 6 or len(flags) != keys_only + thermal + pickoff:
        raise SystemExit(__doc__)
    hrg, scenario, cal, duration, work = sys.argv[1:6]
    os.makedirs(work, exist_ok=True)
    log = os.path.join(work, "run.log")
    sim = [hrg, "sim", "--scenario", scenario, "--duration", duration,
           "--out", os.path.join(work, "sim"), "--can-log", log, "--no-plots", "--quiet"]
    run(sim + (["--calibration", cal] if cal != "-" else []))
    decoded = os.path.join(work, "can.csv")
    dec = run([hrg, "can-decode", log, "-o", decoded])
    sys.stdout.write(dec)
    csv = os.path.join(work, "sim", "telemetry.csv")
    bad = []
    compare_keys(header(csv), header(decoded), thermal, bad, pickoff)
    files = (os.path.join(work, "csv.toml"), os.path.join(work, "can.toml"))
    if not keys_only:
        for rec, out in zip((csv, decoded), files):
            run([hrg, "audit", rec, "--calibration", out])
        compare_files(*files, bad)
    for b in bad:
        print("DIFFERS: " + b)
    raise SystemExit(1 if bad else 0)


if __name__ == "__main__":
    main()
