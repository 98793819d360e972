#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The audit round through CAN on a Gregory table row with a thermal damping.

The row's scenario and length are the table's (tools/gregory/gregory_table.py:
row_text, row_run_s). `hrg sim --can-log` -> `hrg can-decode` -> `hrg audit
REC --calibration OUT.toml` on the decoded recording -> `hrg sim
--calibration OUT.toml`: the decoded header carries the damping model check's
thermal reading as telemetry.csv does (readings.py), the file weighs it with
the audit's own finding (its combination comment), within 5 of its sigmas of
the row's truth and within the CAN resolution of the file written from
telemetry.csv; the second run is within 2x the clean gyro at the same length
and 20x below raw, its compensation reported valid.

usage: thermal_round.py HRG SCENARIO ROW WORKDIR
Exit status 0 when every check holds; prints the figures.
"""
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "tools", "gregory"))
import gregory_table as gt  # noqa: E402
from compare import run  # noqa: E402
from readings import compare_keys, header  # noqa: E402

NUM = r"(\S+) \+- (\S+) /degC"
COMBINED = re.compile(r"^# thermal_damping \(the firmware's: its damping model check\): .*"
                      rf"the audit's {NUM}, the firmware's {NUM} -> {NUM}$", re.M)
RES_BETA = 0.5e-7  # /degC, half the CAN resolution of the check's reading (readings.py)


def file_value(path):
    """The calibration file's thermal damping and its combination comment's
    (audit, sigma, firmware, sigma, combined, sigma), None when not combined."""
    text = open(path).read()
    value = float(re.search(r"^thermal_damping_per_c = (\S+)$", text, re.M).group(1))
    m = COMBINED.search(text)
    return value, None if m is None else [float(v) for v in m.groups()]


def main():
    if len(sys.argv) != 5:
        raise SystemExit(__doc__)
    hrg, scenario, row, work = sys.argv[1:]
    edits = gt.ROWS[row][0]
    truth = float(edits["effects.thermal_damping"]["rel_per_c"])
    text = gt.row_text(open(scenario).read(), edits)
    length = gt.row_run_s(edits, text, None)
    print(f"{row}: the table runs it at {gt.run_text(length)}")
    os.makedirs(work, exist_ok=True)
    scen, log = os.path.join(work, "scenario.toml"), os.path.join(work, "run.log")
    open(scen, "w").write(text)
    first = gt.run_sim(hrg, scen, os.path.join(work, "sim"), duration=length, can_log=log)
    decoded = os.path.join(work, "can.csv")
    sys.stdout.write(run([hrg, "can-decode", log, "-o", decoded]))
    bad = []
    compare_keys(header(os.path.join(work, "sim", "telemetry.csv")), header(decoded), True, bad)
    files = {}
    for name, rec in (("can", decoded), ("csv", os.path.join(work, "sim", "telemetry.csv"))):
        files[name] = os.path.join(work, name + ".toml")
        run([hrg, "audit", rec, "--calibration", files[name]])
    value, comb = file_value(files["can"])
    value_csv, _ = file_value(files["csv"])
    if comb is None:
        bad.append("the file from CAN does not weigh the damping check's reading with the audit's")
    else:
        audit, s_audit, fw, s_fw, combined, s_comb = comb
        print(f"  the audit's {audit:.6g} +- {s_audit:.2g}, the firmware's {fw:.6g} +- {s_fw:.2g}"
              f" -> {combined:.6g} +- {s_comb:.2g} /degC (truth {truth:g}; from telemetry.csv"
              f" {value_csv:.9g})")
        if abs(value - truth) > 5.0 * s_comb:
            bad.append(f"thermal damping {value:.6g} more than 5 sigma from {truth:g}")
        # The two files' values move by the check's CAN rounding and by the
        # audit's difference between the recordings (within its sigma,
        # compare.py), each at its weight.
        w_fw = s_audit**2 / (s_audit**2 + s_fw**2)
        if abs(value - value_csv) > w_fw * RES_BETA + (1.0 - w_fw) * s_audit:
            bad.append(f"CAN's file {value:.9g} vs telemetry.csv's {value_csv:.9g}")
    after = gt.run_sim(hrg, scen, os.path.join(work, "run1"), files["can"], duration=length)
    clean = gt.run_clean(hrg, scenario, work, None, length)
    print(f"  ADB deg/h: raw {first['raw']:.3g}, seed model {gt.adb(first['comp'])}, after the "
          f"round through CAN {gt.adb(after['comp'])} (valid: {after['valid']}), clean {clean:.3g}")
    if not after["comp"] <= 2.0 * clean:
        bad.append(f"after {after['comp']:.3g} > 2x clean {clean:.3g}")
    if not 20.0 * after["comp"] <= first["raw"]:
        bad.append(f"after {after['comp']:.3g} not 20x below raw {first['raw']:.3g}")
    if not after["valid"]:
        bad.append("the compensation with the file is not valid")
    for b in bad:
        print("FAILS: " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
