#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Runs `hrg sim` on a scenario file and checks the run against the file.

  check_scenario_run.py library HRG SCENARIO OUTDIR
      scenario-check passes; a 10 s run simulates the file's resonator (the
      report's true decay rate is pi f / Q, its split pi * split_hz), its rate
      and temperature profiles row by row, for exactly 10 s.
  check_scenario_run.py option NAME HRG SCENARIO OUTDIR
      one run option of `hrg sim` with --scenario: it takes effect (static-base,
      bias-angles, duration, real-time) or is refused with the reason
      (refuse-static-base, refuse-bias-angles on a scenario with its own rate
      profile).
Exit status 0 when every check holds; the failed checks are printed.
"""
import csv
import json
import math
import subprocess
import sys
import tomllib

EARTH_RATE_RAD_S = 7.2921150e-5
failures = []


def check(ok, what):
    print(("ok:     " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)


def run_sim(hrg, scenario, out, *opts):
    cmd = [hrg, "sim", "--scenario", scenario, "--out", out, "--no-plots", "--quiet", *opts]
    p = subprocess.run(cmd, capture_output=True, text=True)
    print("$ " + " ".join(cmd) + f"  -> exit {p.returncode}")
    return p


def load_run(out):
    with open(out + "/report.json") as f:
        report = json.load(f)
    with open(out + "/telemetry.csv") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return report, rows


def profile(section, unit, scale, fallback):
    """The scenario's profile as a function of t (SI), for the kinds this
    check can evaluate (None otherwise); the Earth term included for rates."""
    if section is None:
        return lambda t: fallback
    kind = section.get("kind", "constant")
    earth = 0.0
    if "earth_latitude_deg" in section:
        earth = EARTH_RATE_RAD_S * math.sin(math.radians(section["earth_latitude_deg"]))
    if kind == "constant":
        v = section.get("value_" + unit, fallback / scale) * scale + earth
        return lambda t: v
    if kind == "ramps":
        ts, vs = section["t_s"], [v * scale for v in section["value_" + unit]]

        def ramps(t):
            if t <= ts[0]:
                return vs[0] + earth
            for i in range(1, len(ts)):
                if t <= ts[i]:
                    a = (t - ts[i - 1]) / (ts[i] - ts[i - 1])
                    return vs[i - 1] + a * (vs[i] - vs[i - 1]) + earth
            return vs[-1] + earth

        return ramps
    return None


def check_columns(rows, column, fn, scale, tol, what):
    if fn is None:
        print(f"skip:   {what} (profile kind not evaluated here)")
        return
    worst = max(abs(float(r[column]) - fn(float(r["t_s"])) / scale) for r in rows)
    check(worst <= tol, f"{what}: worst row differs by {worst:.3g} (limit {tol:g})")


# The recording's temp_c is the firmware's reading of the board's sensor:
# quantised to its 1 mdegC (half an LSB) and read every 10 ms (held; the
# row's stamp may lie up to one more frame past the read).
TEMP_LSB_C = 1e-3
TEMP_HOLD_S = 0.012


def check_measured_temperature(rows, fn):
    what = "temp_c follows [temperature] as the sensor reads it"
    if fn is None:
        print(f"skip:   {what} (profile kind not evaluated here)")
        return
    worst = 0.0
    for r in rows:
        t = float(r["t_s"])
        moved = max(abs(fn(t) - fn(t - d)) for d in (0.25 * TEMP_HOLD_S, 0.5 * TEMP_HOLD_S, TEMP_HOLD_S))
        excess = abs(float(r["temp_c"]) - fn(t)) - (0.5 * TEMP_LSB_C + moved + 1e-9)
        worst = max(worst, excess)
    check(worst <= 0.0, f"{what}: worst row exceeds half an LSB plus the hold by {worst:.3g} degC")


def check_library(hrg, scenario, out):
    p = subprocess.run([hrg, "scenario-check", scenario], capture_output=True, text=True)
    check(p.returncode == 0, "scenario-check passes: " + (p.stdout + p.stderr).strip())
    with open(scenario, "rb") as f:
        sc = tomllib.load(f)
    duration = 10.0
    p = run_sim(hrg, scenario, out, "--duration", str(duration))
    check(p.returncode in (0, 1), f"the run completes (0 passed, 1 failed its own checks): {p.stderr.strip()}")
    if p.returncode not in (0, 1):
        return
    report, rows = load_run(out)
    res = sc.get("resonator", {})
    f_hz, q = res.get("f_hz", 5000.0), res.get("q", 5.0e6)
    ident = report["identification"]
    nu = ident["nu_per_s"]["truth"]
    check(abs(nu - math.pi * f_hz / q) <= 1e-7 * nu, f"true nu {nu:.6g} 1/s = pi f / Q = {math.pi * f_hz / q:.6g}")
    dw = math.hypot(ident["dw_c_rad_s"]["truth"], ident["dw_s_rad_s"]["truth"])
    split = math.pi * res.get("split_hz", 5.0e-4)
    check(abs(dw - split) <= 1e-7 * split, f"true half split {dw:.6g} rad/s = pi split_hz = {split:.6g}")
    check(abs(report["duration_s"] - duration) < 1e-9, f"duration {report['duration_s']} s")
    t_last = float(rows[-1]["t_s"])
    check(duration - 0.02 < t_last <= duration, f"last telemetry row at {t_last} s")
    rate = profile(sc.get("rate"), "dps", math.pi / 180.0, 0.0)
    check_columns(rows, "rate_dps", rate, math.pi / 180.0, 1e-9, "rate_dps follows [rate]")
    temp = profile(sc.get("temperature"), "c", 1.0, res.get("temp_ref_c", 25.0))
    check_measured_temperature(rows, temp)


def check_option(name, hrg, scenario, out):
    if name == "static-base":
        # 60 s: past lock (about 35 s) and past the 45 s at which the rate
        # table's schedule would start turning.
        p = run_sim(hrg, scenario, out, "--static-base", "--duration", "60")
        check(p.returncode in (0, 1), "the run completes")
        report, rows = load_run(out)
        check("static base" in report["scenario"], "report: " + report["scenario"])
        earth_dps = math.degrees(EARTH_RATE_RAD_S * math.sin(math.radians(55.75)))
        worst = max(abs(float(r["rate_dps"]) - earth_dps) for r in rows)
        check(worst < 1e-9, f"rate_dps is the scenario's constant Earth rate {earth_dps:.6g} deg/s on every row (worst {worst:.3g})")
        turning = sum(1 for r in rows if r["pattern_cmd"] == "1")
        check(turning > 0, f"the firmware turns the pattern itself ({turning} rows with pattern_cmd = 1)")
    elif name == "bias-angles":
        p = run_sim(hrg, scenario, out, "--bias-angles", "4", "--duration", "170")
        check(p.returncode in (0, 1), "the run completes")
        report, _ = load_run(out)
        n = report["drift"]["parked_angles"]
        check(n == 4, f"4 parked angles (got {n})")
        parks = report["drift"]["parks"]
        if len(parks) == 4:
            steps = [(b["theta_deg"] - a["theta_deg"] + 45.0) % 90.0 - 45.0 for a, b in zip(parks, parks[1:])]
            check(all(abs(abs(s) - 22.5) < 2.0 for s in steps), f"theta steps of 90/4 deg: {steps}")
    elif name == "duration":
        p = run_sim(hrg, scenario, out, "--duration", "45")
        check(p.returncode in (0, 1), "the run completes")
        report, rows = load_run(out)
        check(abs(report["duration_s"] - 45.0) < 1e-9, f"duration {report['duration_s']} s")
        t_last = float(rows[-1]["t_s"])
        check(44.98 < t_last <= 45.0, f"last telemetry row at {t_last} s")
    elif name == "real-time":
        p = run_sim(hrg, scenario, out, "--real-time", "--duration", "1")
        check(p.returncode in (0, 1), "the run completes")
        report, _ = load_run(out)
        check(report["executive"]["pacing"] == "real_time", "pacing " + report["executive"]["pacing"])
        check(report["wall_s"] >= 0.99, f"1 simulated s take {report['wall_s']:.3f} s of wall time")
        check(report["scenario"].startswith("scenario "), "report: " + report["scenario"])
    elif name in ("refuse-static-base", "refuse-bias-angles"):
        opt = ["--static-base"] if name == "refuse-static-base" else ["--bias-angles", "8"]
        p = run_sim(hrg, scenario, out, *opt, "--duration", "5")
        check(p.returncode == 2, "refused with exit status 2")
        check("own rate profile" in p.stderr and opt[0] in p.stderr, "the reason names the profile and the option: " + p.stderr.strip())
    else:
        check(False, "unknown option check " + name)


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "library":
        check_library(*sys.argv[2:])
    elif len(sys.argv) == 6 and sys.argv[1] == "option":
        check_option(*sys.argv[2:])
    else:
        print(__doc__)
        return 2
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
