#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Gregory table: each catalogue effect at a real gyro's strength, through
the whole loop, and what each stage of the compensation makes of it.

Per row: run the default scenario with the effect on (hrg sim), audit that
run's telemetry into a calibration file (hrg audit --calibration), run again
with the file in force (hrg sim --calibration); run it with the online
pickoff self-calibration (hrg sim --self-calibrate), and again with what that
run put in force given at power-up. Columns: raw ADB; ADB compensated by the
seed's model alone; online in the run (valid, rounds applied, `withdrawn`
when the firmware took them back); online at the
next power-up; ADB after the audit round; the clean
gyro's compensated ADB; the maximum pattern-angle readout error (firmware's
theta_A against the true pattern angle) before and after; whether the first
run reported its compensation valid.

Goals (--check, exit 1 when one is missed): after the audit round every row
<= 2x the clean compensated ADB (--goals full only) and >= 20x below raw;
readout error after calibration <= 0.01 deg on the pickoff rows; online at
the next power-up <= 2x clean on the gain, misalignment and phase rows; no
online round kept (applied and not withdrawn) on the rows without a pickoff
effect; without
calibration, no row reports a valid compensated output worse than raw.

usage: gregory_table.py --hrg PATH --scenario default.toml [--set default|variants]
                        [--rows a,b] [--seed N] [--clean-seeds 1,2,..] [--jobs N]
                        [--work DIR] [--check] [--goals full|loop] [--duration S]

--set variants: other strengths, signs and combinations (VARIANTS), same goals.
--seed N sets the scenario's top-level seed (the noise sequence) for every
run, the clean row's included. --clean-seeds runs the clean gyro at those
seeds too and prints their compensated ADB and its rms; the 2x goals then
use max(clean of this seed, that rms): the clean ADB of one seed is one draw
of a noisy statistic (0.036 to 0.53 deg/h over seeds 1 to 4).

--jobs N: rows run in N worker threads, each driving its own hrg processes
(default: every core); the rows are independent runs, so the table is the same
for every N and printed in the same order. --duration S is passed to every
hrg sim; without it each row runs at its own length (row_run_s): the
scenario's, or LONG_RUN_S for the rows with a pickoff gain mismatch or a
nonlinear damping, and for a thermal damping whose damping swing (nu beta
A_T) the scenario's run does not resolve to 7 of the audit's sigmas; each
held against the clean gyro run at the same length and seed. A row whose
raw ADB / 20 lies below the clean gyro's compensated ADB at its length (the
20x-below-raw goal under the clean gyro's own noise) runs again at
LONG_RUN_S (rerun_reason), and its `run` column says so.
"""
import argparse
import concurrent.futures as cf
import csv
import json
import math
import os
import re
import subprocess
import sys
import tomllib

# name -> ({section: {key: value}}, pickoff row?)
ROWS = {
    "none": ({}, False),
    "pickoff_gain_mismatch": ({"effects.pickoff_gain_mismatch": {"enabled": "true", "gain": "0.01"}}, True),
    "pickoff_misalignment": ({"effects.pickoff_misalignment": {"enabled": "true", "angle_deg": "0.5"}}, True),
    "pickoff_phase_mismatch": ({"effects.pickoff_phase_mismatch": {"enabled": "true", "phase_deg": "1.0"}}, True),
    "drive_feedthrough": ({"effects.drive_feedthrough": {
        "enabled": "true", "x_v_per_v": "1e-3", "y_v_per_v": "5e-4",
        "x_phase_deg": "30.0", "y_phase_deg": "30.0"}}, False),
    "thermal_damping": ({"effects.thermal_damping": {"enabled": "true", "rel_per_c": "0.004"},
                         "temperature": {"kind": '"sine"', "amplitude_c": "1.0", "freq_hz": "0.005",
                                         "mean_c": "25.0", "value_c": None}}, False),
    "thermal_frequency": ({"effects.thermal_frequency": {"enabled": "true", "ppm_per_c": "5.0"},
                           "temperature": {"kind": '"sine"', "amplitude_c": "1.0", "freq_hz": "0.005",
                                           "mean_c": "25.0", "value_c": None}}, False),
    "duffing_stiffness": ({"effects.duffing_stiffness": {"enabled": "true", "hz_per_v2": "2e-3"}}, False),
    "nonlinear_damping": ({"effects.nonlinear_damping": {"enabled": "true", "rel_per_v2": "0.05"}}, False),
    "electrostatic_spring": ({"effects.electrostatic_spring": {"enabled": "true", "hz_per_v2": "-1.11e-4"}}, False),
    "gap_harmonics": ({"electrodes": {"eps_p": "0.02", "eps_q": "0.01"}}, False),
    "pickoff_combination": ({
        "effects.pickoff_gain_mismatch": {"enabled": "true", "gain": "0.01"},
        "effects.pickoff_misalignment": {"enabled": "true", "angle_deg": "0.3"},
        "effects.pickoff_phase_mismatch": {"enabled": "true", "phase_deg": "0.5"}}, True),
    "thermal_combination": ({
        "effects.thermal_frequency": {"enabled": "true", "ppm_per_c": "5.0"},
        "effects.thermal_damping": {"enabled": "true", "rel_per_c": "0.004"},
        "temperature": {"kind": '"sine"', "amplitude_c": "2.0", "freq_hz": "0.005",
                        "mean_c": "25.0", "value_c": None}}, False),
}



def _sine_temperature(amplitude_c, freq_hz):
    return {"kind": '"sine"', "amplitude_c": amplitude_c, "freq_hz": freq_hz,
            "mean_c": "25.0", "value_c": None}


# Other strengths, signs and combinations a real gyro could have (--set
# variants): the same goals must hold, so the loop cannot depend on the
# strengths and signs of the rows above.
VARIANTS = {
    "none": ({}, False),
    "gain_neg": ({"effects.pickoff_gain_mismatch": {"enabled": "true", "gain": "-0.02"}}, True),
    "misalignment_neg": ({"effects.pickoff_misalignment": {"enabled": "true", "angle_deg": "-1.0"}}, True),
    "phase_neg": ({"effects.pickoff_phase_mismatch": {"enabled": "true", "phase_deg": "-0.5"}}, True),
    "feedthrough_other": ({"effects.drive_feedthrough": {
        "enabled": "true", "x_v_per_v": "5e-4", "y_v_per_v": "1.5e-3",
        "x_phase_deg": "-120.0", "y_phase_deg": "75.0"}}, False),
    "thermal_damping_neg": ({"effects.thermal_damping": {"enabled": "true", "rel_per_c": "-0.004"},
                             "temperature": _sine_temperature("1.5", "0.003")}, False),
    "thermal_frequency_neg": ({"effects.thermal_frequency": {"enabled": "true", "ppm_per_c": "-8.0"},
                               "temperature": _sine_temperature("1.5", "0.003")}, False),
    "duffing_neg": ({"effects.duffing_stiffness": {"enabled": "true", "hz_per_v2": "-3e-3"}}, False),
    "nonlinear_damping_0.1": ({"effects.nonlinear_damping": {"enabled": "true", "rel_per_v2": "0.1"}}, False),
    "gap_p_only": ({"electrodes": {"eps_p": "0.03", "eps_q": "0.0"}}, False),
    "gain_feedthrough": ({
        "effects.pickoff_gain_mismatch": {"enabled": "true", "gain": "-0.01"},
        "effects.drive_feedthrough": {"enabled": "true", "x_v_per_v": "8e-4", "y_v_per_v": "8e-4",
                                      "x_phase_deg": "60.0", "y_phase_deg": "-30.0"}}, True),
    "gap_thermal": ({
        "electrodes": {"eps_p": "-0.015", "eps_q": "0.02"},
        "effects.thermal_damping": {"enabled": "true", "rel_per_c": "0.004"},
        "temperature": _sine_temperature("1.0", "0.005")}, False),
    "pickoff_combination_neg": ({
        "effects.pickoff_gain_mismatch": {"enabled": "true", "gain": "-0.015"},
        "effects.pickoff_misalignment": {"enabled": "true", "angle_deg": "-0.4"},
        "effects.pickoff_phase_mismatch": {"enabled": "true", "phase_deg": "0.8"}}, True),
}

SETS = {"default": ROWS, "variants": VARIANTS}

# The run length at which the audit sees the effects that show only in how
# a free decay changes within its window, well enough for the output. From
# 1800 s the windows are 5 s long instead of 1 s (tools/gregory/README.md):
# - a pickoff gain mismatch shows only in windows taken while the pattern
#   turns, with information growing as the cube of each window's length: the
#   365 s scenario gives sigma ~1.9e-5 (33 windows of 1 s), while the output
#   moves ~0.25 deg/h per 1e-5 and needs ~1e-5; 1800 s gives ~1.3e-6;
# - a pickoff misalignment is read from the same turning windows (the level
#   pattern's sin 4theta part): on the 4.2 kHz resonator the output moves
#   ~1 deg/h per 1e-3 deg, against a sigma ~5e-4 deg on the 365 s run, as
#   much as the clean gyro's own noise there (0.03 to 0.7 deg/h by seed):
#   even the true map does not reach 2x a low draw of it; 1800 s gives
#   ~1e-4 deg (the audit) and ~1.8e-5 (the firmware's own reading, which
#   the file weighs in);
# - a nonlinear damping shows as the decay rate against the energy, which
#   falls ~0.7 % in a 1 s window and ~3 % in a 5 s one: sigma ~0.03 /V^2 at
#   365 s (found from ~0.2 /V^2), ~0.0025 /V^2 at 1800 s. Uncorrected it
#   biases the output (-6.4 deg/h per 1/V^2 of sin 4theta at 365 s), because
#   the windows' energy follows cos 4theta and its common damping change is
#   taken for anisotropy.
LONG_RUN_S = 1800.0
LONG_RUN_EFFECTS = ("effects.pickoff_gain_mismatch", "effects.pickoff_misalignment",
                    "effects.nonlinear_damping")
# The gap rows stay at the scenario's length: the audit's gap harmonic does
# not sharpen with the run (sigma ~1.3e-3 at 365 s, 1.7e-3 to 2.7e-3 and
# biased at 1800 s; tools/gregory/README.md, "The gap rows' length").

# A thermal damping beta shows as the change nu beta dT of the damping (nu =
# pi f / Q) that the temperature swing makes, read by the audit from the free
# decays' rates against the temperature. On the scenario's run (~44 windows
# of 1 s, 1.8 cycles of a 5 mHz sine) its sigma of nu beta A_T (A_T the
# swing's amplitude) is ~1.6e-6 1/s on either resonator of the table (beta
# +-0.00052 /degC at the seed's nu 3.14e-3 1/s, +-0.00092 at 1.65e-3; seeds
# 1-4, 1 uV/sqrt(Hz)), and it grows with the pickoff noise. The audit accepts
# a finding from 5 sigma: a row whose swing the scenario's run resolves to
# fewer than 7 (two more for the draw's own scatter) runs LONG_RUN_S, where
# the 5 s windows give ~13x the precision (tools/gregory/README.md, "Another
# resonator"): half the seed's nu halves the swing of the same beta.
THERMAL_SWING_SIGMA_PER_S = 1.6e-6
THERMAL_SWING_NOISE_V_RMS = 2.2e-4
THERMAL_SIGMAS_NEEDED = 7.0


def _scenario_value(scenario, section, key):
    """scenario[section][key] of a parsed scenario; missing: an error naming it."""
    table = scenario
    for part in section.split("."):
        table = table.get(part, {})
    if key not in table:
        raise SystemExit("scenario has no %s in [%s] (needed for the thermal damping row's "
                         "length)" % (key, section))
    return table[key]


def temperature_swing_c(scenario):
    """The temperature's amplitude about its middle over the run (degC): a
    sine's amplitude, half the span of steps or ramps, 0 when constant; None
    for a table file (not read here)."""
    temp = scenario.get("temperature", {})
    kind = temp.get("kind", "constant")
    if kind == "constant":
        return 0.0
    if kind == "sine":
        return abs(float(_scenario_value(scenario, "temperature", "amplitude_c")))
    if kind in ("steps", "ramps"):
        v = _scenario_value(scenario, "temperature", "value_c")
        return 0.5 * (max(v) - min(v))
    return None


def thermal_damping_sigmas(text):
    """The audit's expected significance of the thermal damping on the
    scenario's own run (None: no thermal damping, or a swing not known)."""
    s = tomllib.loads(text)
    td = s.get("effects", {}).get("thermal_damping", {})
    if not td.get("enabled", False):
        return None
    swing_c = temperature_swing_c(s)
    if swing_c is None:
        return None
    nu_per_s = (math.pi * _scenario_value(s, "resonator", "f_hz") /
                _scenario_value(s, "resonator", "q"))
    beta_per_c = abs(_scenario_value(s, "effects.thermal_damping", "rel_per_c"))
    noise_v = math.hypot(_scenario_value(s, "adc", "noise_x_v_rms"),
                         _scenario_value(s, "adc", "noise_y_v_rms")) / math.sqrt(2.0)
    sigma_per_s = THERMAL_SWING_SIGMA_PER_S * noise_v / THERMAL_SWING_NOISE_V_RMS
    return nu_per_s * beta_per_c * swing_c / sigma_per_s


# The 20x-below-raw goal needs after <= raw / 20, and after the audit round a
# row is at best a draw of the clean gyro's figure at the same length: where raw / 20
# lies below the clean gyro's compensated ADB there, even the clean gyro's
# own figure misses it, and the run cannot tell a good calibration from a
# bad one. The clean gyro's ADB
# is the noise floor of a 4 theta fit over the parks; from LONG_RUN_S the 5 s
# windows bring it down ~10x (0.67 -> 0.054 deg/h on the 4.2 kHz resonator,
# seed 1; ~T^-3/2). A 1 deg pickoff phase there lowers the raw drift to 6.55
# deg/h (18.4 without it): raw / 20 0.33 against a clean 0.67 at 365 s.
# Such a row runs again at LONG_RUN_S (rerun_reason). The raw drift of an
# effect is the run's own (the phase's part of it has no a priori figure:
# +5 deg/h on the seed's resonator, -12 here), so the rule is read from the
# row's first run.
RAW_OVER_AFTER = 20.0


def rerun_reason(run_s, raw_adb, clean_adb, duration):
    """Why a row run at run_s (None: the scenario's) runs again at
    LONG_RUN_S: its raw / 20 (deg/h) lies below the clean gyro's compensated
    ADB at that length (clean_adb, the goals' reference); None when it does
    not, when it ran LONG_RUN_S already, or when --duration (duration, not
    None) fixed every row's length."""
    if duration is not None or run_s == LONG_RUN_S:
        return None
    goal = raw_adb / RAW_OVER_AFTER
    if goal >= clean_adb:
        return None
    return "%s: raw/20 %.3g < clean %.3g" % (run_text(run_s), goal, clean_adb)


def row_run_s(edits, text, duration):
    """A row's hrg sim --duration: the one asked for, else the length its
    effect needs (None: the scenario's own). edits: the row's keys; text:
    its scenario."""
    if duration is not None:
        return duration
    if any(e in edits for e in LONG_RUN_EFFECTS):
        return LONG_RUN_S
    z = thermal_damping_sigmas(text)
    if z is not None and z < THERMAL_SIGMAS_NEEDED:
        return LONG_RUN_S
    return None


# The rows whose effect the online self-calibration identifies (gain and
# misalignment from the level of E, the phase from the level of the
# quadrature): online at the next power-up <= 2x clean is asserted there.
SELF_CAL_ROWS = {"pickoff_gain_mismatch", "pickoff_misalignment", "pickoff_phase_mismatch",
                 "gain_neg", "misalignment_neg", "phase_neg"}


def set_key(text, section, key, value):
    """Sets `key = value` inside [section] of a TOML text (added when absent)."""
    lines = text.split("\n")
    head = "[" + section + "]"
    try:
        start = next(i for i, l in enumerate(lines) if l.strip() == head)
    except StopIteration:
        raise SystemExit("scenario has no [%s]" % section)
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("[")), len(lines))
    pat = re.compile(r"^\s*" + re.escape(key) + r"\s*=")
    for i in range(start + 1, end):
        if pat.match(lines[i]):
            if value is None:
                del lines[i]
            else:
                lines[i] = "%s = %s" % (key, value)
            return "\n".join(lines)
    if value is None:
        return "\n".join(lines)
    lines.insert(start + 1, "%s = %s" % (key, value))
    return "\n".join(lines)


def set_seed(text, seed):
    """Sets the scenario's top-level `seed = N` (the noise sequence of every run)."""
    lines = text.split("\n")
    first_section = next((i for i, l in enumerate(lines) if l.startswith("[")), len(lines))
    pat = re.compile(r"^\s*seed\s*=")
    for i in range(first_section):
        if pat.match(lines[i]):
            lines[i] = "seed = %d" % seed
            return "\n".join(lines)
    lines.insert(first_section, "seed = %d\n" % seed)
    return "\n".join(lines)


def row_text(base_text, edits, seed=None):
    """A row's scenario: the base scenario's text with the row's keys (and the seed) set."""
    text = base_text if seed is None else set_seed(base_text, seed)
    for section, kv in edits.items():
        for k, v in kv.items():
            text = set_key(text, section, k, v)
    return text


def readout_error_deg(telemetry):
    """Largest |theta_A - true pattern angle| (mod 90 deg) over the valid output."""
    worst = 0.0
    with open(telemetry) as f:
        rows = csv.DictReader(l for l in f if not l.startswith("#"))
        for r in rows:
            if r["out_valid"] != "1" or float(r["a_a_v"]) < 0.5:
                continue
            d = float(r["theta_deg"]) - float(r["true_theta_deg"])
            d = (d + 45.0) % 90.0 - 45.0
            worst = max(worst, abs(d))
    return worst


def adb(v):
    """An ADB for the table; '-' when not measured (no park had the compensation valid)."""
    return "-" if math.isnan(v) else "%.3g" % v


def run_sim(hrg, scenario, out, calibration=None, self_calibrate=False, duration=None,
            can_log=None):
    cmd = [hrg, "sim", "--scenario", scenario, "--out", out, "--no-plots", "--quiet"]
    if can_log is not None:
        cmd += ["--can-log", can_log]
    if duration is not None:
        cmd += ["--duration", repr(duration)]
    if calibration:
        cmd += ["--calibration", calibration]
    if self_calibrate:
        cmd += ["--self-calibrate"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode == 2:
        raise SystemExit("hrg sim failed: %s\n%s" % (" ".join(cmd), p.stderr))
    rep = json.load(open(os.path.join(out, "report.json")))
    d = rep["drift"]
    comp = rep.get("compensation", {})
    # Not fitted: no park had the compensation valid (not measured, not 0).
    comp_adb = d["compensated"]["adb_dph"] if d["compensated"].get("fitted", True) else math.nan
    return {"raw": d["raw"]["adb_dph"], "comp": comp_adb,
            "passed": rep["passed"], "valid": comp.get("valid", True),
            "rounds": comp.get("self_calibration", {}).get("rounds_applied", 0),
            "withdrawn": comp.get("self_calibration", {}).get("rounds_withdrawn", 0),
            "self_cal": comp.get("self_calibration", {}),
            "readout": readout_error_deg(os.path.join(out, "telemetry.csv"))}


def kept_pickoff_map(online):
    """The pickoff map a board keeps from an online run, as the firmware
    reports it (report.json compensation.self_calibration.keep_*,
    fw::app::Firmware::pickoff_map_to_keep): once a round has been applied,
    what a round would put in force at the end of the run, the whole
    estimate over every window with each part weighted by its evidence
    (est::evidence_weighted_map); the map in force when the solve failed or
    the decay test refuses the windows, and after a withdrawal of the rounds
    (their model refuted) the map before them. The rounds stop at 4, or when the
    information has not doubled, half-way through a 365 s run; the estimate
    over the whole run is the better one (tools/gregory/README.md)."""
    sc = online["self_cal"]
    return sc["keep_gain"], sc["keep_misalignment_deg"], sc["keep_phase_deg"]


def run_row(hrg, base, work, rows, name, duration=None, seed=None, tag=None):
    text = row_text(open(base).read(), rows[name][0], seed)
    d = os.path.join(work, name if tag is None else name + "_" + tag)
    os.makedirs(d, exist_ok=True)
    scen = os.path.join(d, "scenario.toml")
    open(scen, "w").write(text)
    before = run_sim(hrg, scen, os.path.join(d, "run0"), duration=duration)
    cal = os.path.join(d, "cal.toml")
    p = subprocess.run([hrg, "audit", os.path.join(d, "run0", "telemetry.csv"), "--calibration", cal],
                       capture_output=True, text=True)
    if not os.path.exists(cal):
        raise SystemExit("hrg audit wrote no calibration for %s:\n%s%s" % (name, p.stdout, p.stderr))
    verdict = next((l.split()[1] for l in p.stdout.splitlines() if l.startswith("VERDICT:")), "?")
    after = run_sim(hrg, scen, os.path.join(d, "run1"), cal, duration=duration)
    online = run_sim(hrg, scen, os.path.join(d, "online"), self_calibrate=True,
                     duration=duration)
    # What the firmware identified online, in force from the next power-up
    # (as a board keeps it): the pickoff map only.
    own = os.path.join(d, "own.toml")
    open(own, "w").write("calibration_format = 1\npickoff_y_gain = %.17g\n"
                         "pickoff_y_misalignment_deg = %.17g\npickoff_y_phase_deg = %.17g\n" %
                         kept_pickoff_map(online))
    reboot = run_sim(hrg, scen, os.path.join(d, "online_reboot"), own, duration=duration)
    return name, before, after, verdict, online, reboot


def run_clean(hrg, base, work, seed, duration=None):
    """The clean gyro's compensated ADB at one seed (None: the scenario's own)
    and run length (the spread of the statistic, the reference of a row run
    at another length)."""
    d = os.path.join(work, "clean_seed_%s_%s" % (
        "scenario" if seed is None else seed, "scenario" if duration is None else "%.0fs" % duration))
    os.makedirs(d, exist_ok=True)
    scen = os.path.join(d, "scenario.toml")
    text = open(base).read()
    open(scen, "w").write(text if seed is None else set_seed(text, seed))
    return run_sim(hrg, scen, os.path.join(d, "run0"), duration=duration)["comp"]


def run_text(duration):
    """A row's run length for the table."""
    return "scenario" if duration is None else "%.0f s" % duration


def run_column(duration, why):
    """The table's `run` column: the row's length, and why it ran again there."""
    return run_text(duration) + (" (%s)" % why if why else "")


def parse_seeds(text):
    try:
        seeds = [int(v) for v in text.split(",")]
    except ValueError:
        raise SystemExit("--clean-seeds wants integers separated by commas (got '%s')" % text)
    return seeds


def run_rows(ex, a, rows, names, length, clean_at, spread_at, clean_seeds, tag=None):
    """Runs the rows `names` at their lengths, and the clean gyro (with
    --clean-seeds, at those seeds too) at every length a row runs at that
    it has not run yet; fills clean_at and spread_at (length -> ADB, list).
    Returns name -> the row's runs."""
    # map() returns the rows in the order asked, whichever finishes first.
    res = {r[0]: r[1:] for r in ex.map(
        lambda n: run_row(a.hrg, a.scenario, a.work, rows, n, length[n], a.seed, tag), names)}
    if "none" in res:
        clean_at[length["none"]] = res["none"][0]["comp"]
    new = sorted({length[n] for n in names} - set(clean_at), key=lambda d: d or 0.0)
    clean_at.update(zip(new, ex.map(lambda d: run_clean(a.hrg, a.scenario, a.work, a.seed, d), new)))
    for d in [d for d in clean_at if d not in spread_at]:
        spread_at[d] = list(ex.map(lambda s: run_clean(a.hrg, a.scenario, a.work, s, d),
                                   clean_seeds))
    return res


def goal_reference(clean_at, spread_at, clean_seeds=None):
    """The goals' 2x reference per length: the clean run of the same seed,
    or (with --clean-seeds) not below the clean gyro's rms ADB over those
    seeds, printed when clean_seeds is given."""
    ref_at = dict(clean_at)
    for d, spread in spread_at.items():
        if not spread:
            continue
        rms = math.sqrt(sum(v * v for v in spread) / len(spread))
        if clean_seeds:
            print("clean compensated ADB over seeds %s, %s: %s deg/h, rms %.3g" % (
                ",".join(str(s) for s in clean_seeds), run_text(d),
                ", ".join("%.3g" % v for v in spread), rms))
        ref_at[d] = max(clean_at[d], rms)
    return ref_at


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hrg", required=True)
    ap.add_argument("--scenario", required=True)
    ap.add_argument("--set", choices=list(SETS), default="default")
    ap.add_argument("--rows", default=None)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--work", default="gregory-work")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--goals", choices=["full", "loop"], default="full")
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--clean-seeds", default=None)
    a = ap.parse_args()
    if a.jobs < 1:
        ap.error("--jobs must be at least 1 (got %d)" % a.jobs)
    if a.duration is not None and not a.duration > 0:
        ap.error("--duration must be positive (got %g)" % a.duration)
    rows = SETS[a.set]
    names = a.rows.split(",") if a.rows else list(rows)
    for n in names:
        if n not in rows:
            raise SystemExit("unknown row '%s' in --set %s (rows: %s)" % (n, a.set, ", ".join(rows)))
    if "none" not in names:
        names = ["none"] + names
    clean_seeds = parse_seeds(a.clean_seeds) if a.clean_seeds else []
    base = open(a.scenario).read()
    length = {n: row_run_s(rows[n][0], row_text(base, rows[n][0]), a.duration) for n in names}
    clean_at, spread_at = {}, {}
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        res = run_rows(ex, a, rows, names, length, clean_at, spread_at, clean_seeds)
        ref_at = goal_reference(clean_at, spread_at)
        # The rows whose 20x-below-raw goal lies under the clean gyro's ADB
        # at their length run again at LONG_RUN_S (rerun_reason).
        why = {n: rerun_reason(length[n], res[n][0]["raw"], ref_at[length[n]], a.duration)
               for n in names if n != "none"}
        again = [n for n in names if why.get(n)]
        for n in again:
            length[n] = LONG_RUN_S
        res.update(run_rows(ex, a, rows, again, length, clean_at, spread_at, clean_seeds, "long"))
    ref_at = goal_reference(clean_at, spread_at, clean_seeds)
    print("| effect | run | raw | seed model | (valid) | online in run | (valid, rounds) | online at next power-up | after audit round | (valid) | clean | readout before | after | audit verdict | goals |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    missed = []
    for n in names:
        b, c, verdict, o, r = res[n]
        clean, ref = clean_at[length[n]], ref_at[length[n]]
        goals = []
        if n != "none":
            if a.goals == "full" and not c["comp"] <= 2.0 * ref:
                goals.append("after %.3g > 2x clean %.3g" % (c["comp"], 2.0 * ref))
            if not c["comp"] * 20.0 <= b["raw"]:
                goals.append("after not 20x below raw")
            if not c["valid"]:
                goals.append("after: compensation not valid")
            if rows[n][1] and not c["readout"] <= 0.01:
                goals.append("readout %.3g deg > 0.01" % c["readout"])
            # The online estimate from the next power-up: <= 2x clean.
            if n in SELF_CAL_ROWS and not r["comp"] <= 2.0 * ref:
                goals.append("online %.3g > 2x clean %.3g" % (r["comp"], 2.0 * ref))
            # The rows without a pickoff effect: the self-calibration keeps
            # nothing (a round its own later evidence refutes is withdrawn).
            kept_rounds = o["rounds"] - o["withdrawn"]
            if not rows[n][1] and kept_rounds > 0:
                goals.append("online kept %d spurious rounds" % kept_rounds)
        for run in (b, c, o, r):
            if run["valid"] and run["comp"] > run["raw"]:
                goals.append("valid compensation worse than raw")
        rounds = "%d" % o["rounds"] + (" withdrawn" if o["withdrawn"] else "")
        print("| %s | %s | %.3g | %s | %s | %s | %s, %s | %s | %s | %s | %.3g | %.3g | %.3g | %s | %s |" % (
            n, run_column(length[n], why.get(n)), b["raw"], adb(b["comp"]), "yes" if b["valid"] else "NO",
            adb(o["comp"]), "yes" if o["valid"] else "NO", rounds, adb(r["comp"]), adb(c["comp"]),
            "yes" if c["valid"] else "NO", clean,
            b["readout"], c["readout"], verdict, "; ".join(goals) if goals else "met"))
        if goals:
            missed.append(n)
    print("ADB in deg/h of input rate ('-': not measured, the compensation was valid in no park); "
          "readout error in deg (max |theta_A - true|).")
    if a.check and missed:
        print("goals missed: " + ", ".join(missed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
