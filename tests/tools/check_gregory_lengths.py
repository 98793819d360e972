#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Gregory table's run length per row (gregory_table.row_run_s).

- default scenario (the seed's resonator, nu 3.14e-3 1/s): every row keeps
  its length, the scenario's or LONG_RUN_S for a pickoff gain mismatch or a
  nonlinear damping; the thermal damping rows stay at the scenario's (the
  audit reads their damping swing to ~7.9 sigma there, seeds 1-4 7.5-8.8);
- another resonator (tools/gregory/other-resonator.toml, nu 1.65e-3 1/s):
  the thermal damping +-1 degC (and its variants at +-1.5 degC, with a gap)
  runs LONG_RUN_S, the swing read to ~4.1 sigma on the 365 s run (measured
  1.6 to 6.7 at seeds 1-4, accepted at none but seed 3); the thermal
  combination at +-2 degC stays at the scenario's;
- the rule follows the physics: half the strength on the seed's resonator,
  or twice its pickoff noise, halves the swing's significance and runs long.

Usage: check_gregory_lengths.py SOURCE_DIR
"""
import os
import sys

src = sys.argv[1]
sys.path.insert(0, os.path.join(src, "tools", "gregory"))
import gregory_table as gt  # noqa: E402

LONG = gt.LONG_RUN_S
# The rows that run long on the other resonator only.
OTHER_LONG = {"thermal_damping", "thermal_damping_neg", "gap_thermal"}


def length(base, edits):
    return gt.row_run_s(edits, gt.row_text(base, edits), None)


def main():
    default = open(os.path.join(src, "sim_target", "scenarios", "default.toml")).read()
    other = open(os.path.join(src, "tools", "gregory", "other-resonator.toml")).read()
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    for set_name, rows in gt.SETS.items():
        for name, (edits, _) in rows.items():
            own = LONG if any(e in edits for e in gt.LONG_RUN_EFFECTS) else None
            check(length(default, edits) == own,
                  f"default scenario, {set_name} {name}: {gt.run_text(own)}")
            want = LONG if name in OTHER_LONG else own
            check(length(other, edits) == want,
                  f"other resonator, {set_name} {name}: {gt.run_text(want)}")
    half = {"effects.thermal_damping": {"enabled": "true", "rel_per_c": "0.002"},
            "temperature": gt.ROWS["thermal_damping"][0]["temperature"]}
    check(length(default, half) == LONG, "default scenario, thermal damping 0.002 /degC: 1800 s")
    noisy = dict(gt.ROWS["thermal_damping"][0],
                 adc={"noise_x_v_rms": "4.4e-4", "noise_y_v_rms": "4.4e-4"})
    check(length(default, noisy) == LONG,
          "default scenario, thermal damping at twice the pickoff noise: 1800 s")
    if failures:
        raise SystemExit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
