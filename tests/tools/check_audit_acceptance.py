# SPDX-License-Identifier: MIT
"""The audit's acceptance rule on the firmware's own telemetry (default
scenario, 365 s, tools/audit/README.md step 7).

- pickoff phase 1 deg, seed 4: the phase is found within 5 of its sigmas of
  1 deg; the 4-theta pump pattern the firmware's loops leave under that phase
  (it reads as eps_p -0.0085 +- 0.0013, delta BIC 22, removing 0.005 % of the
  baseline's misfit) is an alternative, not a finding;
- drive feedthrough x 1e-3, y 5e-4 at 30 deg, seed 1: the feedthrough is
  found; the gap harmonics (|eps| 0.15 +- 0.015 taking up 14 % of a misfit the
  excitation segments keep at 10x their noise) are not;
- gap harmonics eps_p 0.02, eps_q 0.01, seed 1: still found, |eps| within 5
  of its sigmas of hypot(0.02, 0.01);
- drive feedthrough 8e-4 at -45 deg (x) and 110 deg (y), seed 1: its
  in-phase part turns the measured amplitude against the pump, and the
  amplitude loop then oscillates faster than the rows, which alias the pump
  on most excitation segments (|eps| 0.44 before the audit read the pattern
  angle's drift over its own span; 0.178 with those segments in and the
  feedthrough's pulls out): the feedthrough is found, no gap harmonics, and
  the JSON counts the segments left out; no electrostatic spring either
  (its ring-up at the pump's limit sat -2.08e-4 rad/s off by the pump's
  phase, which follows the measured wave: a false spring of -2.78e-7 Hz/V^2
  at delta BIC 71.8 before that pull was taken out).

Usage: check_audit_acceptance.py HRG SCENARIO WORK_DIR
"""
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "gregory"))
import gregory_table as gt  # noqa: E402


# Rows beyond the Gregory table's: name -> {section: {key: value}}.
EXTRA_ROWS = {
    "feedthrough_m45_110": {"effects.drive_feedthrough": {
        "enabled": "true", "x_v_per_v": "8e-4", "y_v_per_v": "8e-4",
        "x_phase_deg": "-45.0", "y_phase_deg": "110.0"}},
}


def audit_row(hrg, scenario, work, row, seed):
    keys = EXTRA_ROWS[row] if row in EXTRA_ROWS else gt.ROWS[row][0]
    text = gt.row_text(open(scenario).read(), keys, seed)
    d = os.path.join(work, "%s_seed%d" % (row, seed))
    os.makedirs(d, exist_ok=True)
    scen = os.path.join(d, "scenario.toml")
    open(scen, "w").write(text)
    run = os.path.join(d, "run")
    p = subprocess.run([hrg, "sim", "--scenario", scen, "--out", run, "--no-plots", "--quiet"],
                       capture_output=True, text=True)
    if p.returncode == 2:
        raise SystemExit("hrg sim failed:\n" + p.stderr)
    out = os.path.join(d, "audit.json")
    p = subprocess.run([hrg, "audit", os.path.join(run, "telemetry.csv"), "--json", out],
                       capture_output=True, text=True)
    if p.returncode != 0 or not os.path.exists(out):
        raise SystemExit("hrg audit failed:\n" + p.stdout + p.stderr)
    print(p.stdout)
    return json.load(open(out))


def finding(rep, effect):
    return next((f for f in rep["findings"] if f["effect"] == effect), None)


def main():
    hrg, scenario, work = sys.argv[1:4]
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    rep = audit_row(hrg, scenario, work, "pickoff_phase_mismatch", 4)
    f = finding(rep, "pickoff_phase_mismatch")
    check(f is not None and abs(f["params"]["phase_deg"] - 1.0) <= 5 * f["uncertainty"]["phase_deg"],
          "phase seed 4: phase mismatch found within 5 sigma of 1 deg")
    check(finding(rep, "gap_harmonics") is None, "phase seed 4: no gap harmonics finding")
    check(any(a["effect"] == "gap_harmonics" for a in rep["alternatives"]),
          "phase seed 4: the gap harmonics listed as an alternative")
    check("acceptance_rule" in rep and "always" in rep["acceptance_rule"],
          "the JSON states the acceptance rule")

    rep = audit_row(hrg, scenario, work, "drive_feedthrough", 1)
    check(finding(rep, "drive_feedthrough") is not None, "feedthrough seed 1: feedthrough found")
    check(finding(rep, "gap_harmonics") is None, "feedthrough seed 1: no gap harmonics finding")

    rep = audit_row(hrg, scenario, work, "gap_harmonics", 1)
    f = finding(rep, "gap_harmonics")
    truth = math.hypot(0.02, 0.01)
    check(f is not None and abs(f["params"]["eps"] - truth) <= 5 * f["uncertainty"]["eps"],
          "gap seed 1: |eps| found within 5 sigma of %.5f" % truth)

    rep = audit_row(hrg, scenario, work, "feedthrough_m45_110", 1)
    f = finding(rep, "drive_feedthrough")
    check(f is not None and abs(f["params"]["v_per_v"] - 8e-4) <= 0.05 * 8e-4,
          "feedthrough -45/110 deg seed 1: feedthrough found within 5 % of 8e-4 V/V")
    check(finding(rep, "gap_harmonics") is None, "feedthrough -45/110 deg seed 1: no gap harmonics")
    check(finding(rep, "electrostatic_spring") is None,
          "feedthrough -45/110 deg seed 1: no electrostatic spring")
    check(rep.get("excitation_segments_left_out", 0) > 0,
          "feedthrough -45/110 deg seed 1: the JSON counts the excitation segments left out")

    if failures:
        raise SystemExit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
