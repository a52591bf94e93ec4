# SPDX-License-Identifier: Apache-2.0
"""The simulated layer's part of the table: which RTL was simulated, one row per case, the stop,
and the goal verdicts (goals.sim_goals); the points the figure marks."""

from __future__ import annotations

import math

from ..paths import TOP
from .config import FILTER_LEN, SIM_STALL_S, SIM_STOP_RPM, SIM_UNITS
from .format import edges_label, fmt_pct
from .goals import sim_goals


def rtl_revision(rev: str | None = None) -> str:
    """The git revision of rtl/ that was simulated (and whether rtl/ had uncommitted changes)."""
    import subprocess

    try:
        last = subprocess.run(["git", "log", "-1", "--format=%h", rev or "HEAD", "--", "rtl"],
                              cwd=TOP, capture_output=True, text=True, check=True).stdout.strip()
        dirty = "" if rev else subprocess.run(
            ["git", "status", "--porcelain", "--", "rtl"], cwd=TOP, capture_output=True,
            text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "an unknown revision (no git)"
    return (f"rtl/ as of commit {last} (its last change" + (f" up to {rev[:7]}, --rtl-rev)" if rev
                                                             else ")")
            + (", with uncommitted changes in the working tree" if dirty else ""))


def _intro(args, units, n_cases: int, wall: float, sim: str) -> list:
    return [f"Simulated: {rtl_revision(getattr(args, 'rtl_rev', None))}. "
            f"{n_cases} cases simulated on {sim} in {wall:.0f} s ({args.jobs} process(es)): "
            f"the units *{'*, *'.join(n for n, _ in units[:SIM_UNITS])}* at each speed, a few 1 kHz "
            "reads each (the first initialises, the first new edge is a reference). *Added*: max "
            "|reading from the simulated registers − the same estimator on the model's exact times "
            "of the same edges| / true speed (the reversal: / its top speed), over the reads with a "
            "measurement; *wrong sign* = M/T readings against the shaft's direction where |speed| ≥ "
            "6 rpm and the last count step already went that way. *Checks*: SNAP_EDGE_DELTA against the model's count between the matched edges, "
            "PERIOD against the model's time between them (±2 ticks), PERIOD_CTRL.DIR_CHANGE "
            "against a direction change among the model's steps they span, SNAP_DELTA against the "
            "model's steps "
            "between the latching clocks (reads with no step within 4 clocks of a latch); "
            "*unmatched* = SNAP_EDGE_TIME values matching no model edge; *edge latency* = median "
            "SNAP_EDGE_TIME minus the pin time of its edge, in ticks (the synchroniser, the "
            f"FILTER_LEN = {FILTER_LEN} filter and the pipeline, plus half a clock of sampling; "
            "the same for every edge, so it cancels in every difference); *PERIOD newer* = reads where "
            "PERIOD (live, read a few clocks after the snapshot) already held the next edge's "
            "measurement, which the floor then uses too. (The latch instant is known "
            "only through SNAP_TIME, so M's added error is 0 by construction; what tests M is the "
            "SNAP_DELTA check, i.e. that count and time are latched in the same clock.)", ""]


def _case_rows(results) -> list:
    L = ["| unit | rpm | edges | reads | M/T added max (%) | T added max (%) | M added max (%) "
         "| M/T error max (%) | zeros M/T | wrong sign M/T | checks failed (edge Δ / period / "
         "dir flag / Δ, of checked) | unmatched | edge latency (ticks) | PERIOD newer |",
         "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|"]
    for r in results:
        m = r["methods"]
        mt, t, mm = m.get("MT", {}), m.get("T", {}), m.get("M", {})
        ck = r["checked"]
        label = {"constant": f"{r['rpm']:g}", "ramp": "ramp 600 → 3000 in 8 ms",
                 "reversal": "150 → −150 in 16 ms"}[r["kind"]]
        L.append(f"| {r['unit']} | {label} | {edges_label(r['edge'])} | "
                 f"{r['reads']} | {fmt_pct(mt.get('added_max'), 4)} ({mt.get('n', 0)}) | "
                 f"{fmt_pct(t.get('added_max'), 4)} | {fmt_pct(mm.get('added_max'), 4)} | "
                 f"{fmt_pct(mt.get('err_max'), 3)} | {mt.get('zeros', 0)} | "
                 f"{mt.get('wrong_sign', 0)} | "
                 f"{r['bad_edge_delta']}/{ck['edge_delta']}, {r['bad_period']}/{ck['period']}, "
                 f"{r['bad_dir']}/{ck['dir_flag']}, {r['bad_delta']}/{ck['delta']} | "
                 f"{r['unmatched']} | {r['latency_ticks']:.1f} | {r['period_newer']} |")
    return L + [""]


def _stop_rows(stops) -> list:
    if not stops:
        return []
    L = [f"**Stop** ({stops[0]['unit']}): {SIM_STOP_RPM:g} rpm for 3 ms, then standing, with "
         f"STALL_TIMEOUT and the estimators' timeout at {SIM_STALL_S * 1e3:g} ms. Time from "
         "the stop to the reading that stays 0, and when STATUS.STALLED was first seen "
         "(ms after the last count step; reads are 1 ms apart).", "",
         "| edges | M/T → 0 (ms after stop) | T → 0 | M → 0 | STALLED seen (ms after last step) "
         "| STALLED before the timeout | zeros while turning (M/T) |",
         "|---|---:|---:|---:|---:|---|---:|"]
    for r in stops:
        m, st = r["methods"], r["stop"]

        def f(k, m=m):
            v = m.get(k, {}).get("t_zero_after_stop_s", math.nan)
            return "—" if math.isnan(v) else f"{1e3 * v:.2f}"
        L.append(f"| {edges_label(r['edge'])} | {f('MT')} | {f('T')} | "
                 f"{f('M')} | {1e3 * (st['stalled_at_s'] - st['last_step_s']):.2f} | "
                 f"{'yes (wrong)' if st['stalled_before_timeout'] else 'no'} | "
                 f"{m.get('MT', {}).get('moving_zeros', 0)} |")
    return L + [""]


def sim_report(args, units, results, wall, sim, errors) -> dict:
    """Markdown lines, goal verdicts and plot points of the simulated layer."""
    L = _intro(args, units, len(results), wall, sim)
    if errors:
        L += [f"**Simulation errors**: {'; '.join(errors.values())}", ""]
    stops = [r for r in results if r["kind"] == "stop"]
    moving = [r for r in results if r["kind"] != "stop"]
    L += _case_rows(moving) + _stop_rows(stops)
    points = [{"rpm": r["rpm"], "unit": r["unit"], "added_max": r["methods"]["MT"]["added_max"]}
              for r in moving if r["edge"] == "a_rising" and r["methods"].get("MT", {}).get("n")
              and r["kind"] == "constant"]
    return {"lines": L, "goals": sim_goals(moving, stops, sim), "points": points,
            "results": moving, "wall_s": wall}
