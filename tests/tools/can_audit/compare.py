#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The board user's path against the simulator's own recording.

`hrg sim --can-log` -> `hrg can-decode` -> `hrg audit` must give the verdict,
the findings and the parameters that `hrg audit` gives on the same run's
telemetry.csv: the CAN telemetry carries what the audit needs (envelopes
against a reference the log rebuilds exactly, the row time, the drive as
applied, pump, temperature and the table's rate).

usage: compare.py HRG SCENARIO|- DURATION_S WORKDIR
  SCENARIO '-' is the main job (the default resonator under the rate-table
  sweep, no effect: the null case).
Exit status 0 when they agree; prints both audits' figures and the bus load.
"""
import json
import os
import subprocess
import sys


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode not in (0, 1):  # hrg sim exits 1 for its own checks on short runs
        sys.stdout.write(p.stdout + p.stderr)
        raise SystemExit(f"failed ({p.returncode}): {' '.join(cmd)}")
    return p.stdout


def audit(hrg, recording, json_path):
    out = run([hrg, "audit", recording, "--json", json_path])
    with open(json_path) as f:
        return json.load(f), out.splitlines()[0]


def findings(a):
    return {f["effect"]: f for f in a["findings"]}


def main():
    if len(sys.argv) != 5:
        raise SystemExit(__doc__)
    hrg, scenario, duration, work = sys.argv[1:]
    os.makedirs(work, exist_ok=True)
    log = os.path.join(work, "run.log")
    sim = [hrg, "sim", "--duration", duration, "--out", os.path.join(work, "sim"),
           "--can-log", log, "--no-plots", "--quiet"]
    if scenario != "-":
        sim += ["--scenario", scenario]
    run(sim)
    decoded = os.path.join(work, "can.csv")
    dec = run([hrg, "can-decode", log, "-o", decoded])
    sys.stdout.write(dec)
    if "no frame lost" not in dec:
        raise SystemExit("the simulated bus lost frames")
    a_csv, v_csv = audit(hrg, os.path.join(work, "sim", "telemetry.csv"),
                         os.path.join(work, "csv.json"))
    a_can, v_can = audit(hrg, decoded, os.path.join(work, "can.json"))
    print("telemetry.csv: " + v_csv)
    print("CAN log:       " + v_can)
    bad = []
    if a_csv["verdict"] != a_can["verdict"]:
        bad.append(f"verdict {a_csv['verdict']} (csv) vs {a_can['verdict']} (CAN)")
    f_csv, f_can = findings(a_csv), findings(a_can)
    if set(f_csv) != set(f_can):
        bad.append(f"findings {sorted(f_csv)} (csv) vs {sorted(f_can)} (CAN)")
    # Each finding's parameters agree within their stated 1-sigma uncertainty.
    for effect in sorted(set(f_csv) & set(f_can)):
        for key, x in f_csv[effect]["params"].items():
            y = f_can[effect]["params"][key]
            sigma = max(f_csv[effect]["uncertainty"][key], f_can[effect]["uncertainty"][key])
            print(f"  {effect}.{key}: {x:.6g} (csv) {y:.6g} (CAN) +/- {sigma:.3g}")
            if abs(x - y) > sigma:
                bad.append(f"{effect}.{key} differs by {abs(x - y):.3g} > {sigma:.3g}")
    # The baseline's parameters carry no stated uncertainty: each candidate's
    # 1-sigma is the scale of what the data resolve; the resonator's own
    # figures agree to the fraction the two recordings' quantization allows.
    tol = {"f_hz": 1e-6, "nu_per_s": 2e-3, "dmu": 2e-3, "split_hz": 2e-3, "angular_gain": 1e-4}
    for key, rel in tol.items():
        x = a_csv["baseline"]["params"][key]
        y = a_can["baseline"]["params"][key]
        scale = abs(x) if key != "f_hz" else 1.0
        print(f"  baseline.{key}: {x:.9g} (csv) {y:.9g} (CAN)")
        if abs(x - y) > rel * scale:
            bad.append(f"baseline {key} {x} vs {y}")
    if bad:
        print("DISAGREE: " + "; ".join(bad))
        return 1
    print("agree: same verdict, findings and parameters")
    return 0


if __name__ == "__main__":
    sys.exit(main())
