# SPDX-License-Identifier: Apache-2.0
"""The benchmark's goal verdicts (MET / MISSED, INFO), of the model layer and through the RTL."""

from __future__ import annotations

import math

from .config import (GOAL_ADDED_IDEAL, GOAL_ADDED_TYP, GOAL_BAND, GOAL_NONZERO_RPM, READ_HZ,
                     SCENARIOS, SIM_STALL_S)
from .format import edges_label, fmt_pct


def goals(args, units, model, sim) -> list[str]:
    C = model["constant"]
    out = []
    band = [r for r in model["rpms"] if GOAL_BAND[0] <= r <= GOAL_BAND[1]]
    k = "MT/a_rising"
    typ = [n for n, _ in units if n != "ideal"]
    if band:
        a_typ = max((C[r][u][k]["added_max"] for r in band for u in typ if k in C[r][u]),
                    default=math.nan)
        a_id = max(C[r]["ideal"][k]["added_max"] for r in band if k in C[r]["ideal"])
        out.append(f"{'MET' if a_typ <= GOAL_ADDED_TYP else 'MISSED'} (model): the timebase adds "
                   f"at most {fmt_pct(a_typ, 4)} % to the floor of M/T A↑ on the non-ideal units "
                   f"from {band[0]:g} to {band[-1]:g} rpm (goal ≤ 0.1 %).")
        out.append(f"{'MET' if a_id <= GOAL_ADDED_IDEAL else 'MISSED'} (model): at most "
                   f"{fmt_pct(a_id, 4)} % on the ideal unit (goal ≤ 0.02 %).")
    low = [r for r in model["rpms"] if r >= GOAL_NONZERO_RPM]
    z = sum(C[r][u].get(k, {}).get("zeros", 0) for r in low for u in C[r])
    zt = sum(C[r][u].get("T/a_rising", {}).get("zeros", 0) for r in low for u in C[r])
    out.append(f"{'MET' if z == 0 else 'MISSED'} (model): {z} readings of 0 from M/T A↑ at "
               f"constant speeds ≥ {GOAL_NONZERO_RPM:g} rpm (T A↑: {zt}; M reads 0 below "
               "30 rpm by design).")
    S = model["scenario"]
    stall = args.stall_ms * 1e-3
    for sname in ("stop", "stop6"):
        if sname in S:
            t = max(S[sname][u][k]["t_to_zero_s"] for u in S[sname])
            out.append(f"{'MET' if t <= stall + 1.5 / READ_HZ else 'MISSED'} (model): after "
                       f"the stop in '{SCENARIOS[sname][1]}', M/T A↑ reads 0 within {t * 1e3:.0f} "
                       f"ms at worst (stall timeout {args.stall_ms:g} ms, counted from the last "
                       "edge, which comes before the stop).")
    if sim and not sim.get("skipped"):
        out += sim.get("goals", [])
    elif sim and sim.get("skipped"):
        out.append(f"NOT CHECKED through the RTL: {sim['skipped']}.")
    return out


def _added_goals(results, sim: str) -> list[str]:
    """M/T A-rising at constant speeds in the goal band: what the registers add, per unit kind."""
    out = []
    band = [r for r in results if r["edge"] == "a_rising" and r["kind"] == "constant"
            and GOAL_BAND[0] <= r["rpm"] <= GOAL_BAND[1]]
    for label, sel, lim in (("non-ideal", [r for r in band if r["unit"] != "ideal"], GOAL_ADDED_TYP),
                            ("ideal", [r for r in band if r["unit"] == "ideal"], GOAL_ADDED_IDEAL)):
        vals = [r["methods"]["MT"]["added_max"] for r in sel if r["methods"].get("MT", {}).get("n")]
        nomeas = [f"{r['rpm']:g}" for r in sel if not r["methods"].get("MT", {}).get("n")]
        if vals:
            worst_ = max(vals)
            out.append(f"{'MET' if worst_ <= lim else 'MISSED'} (through the RTL, {sim}): M/T "
                       f"A↑ on the {label} unit, the simulated registers add at most "
                       f"{fmt_pct(worst_, 4)} % to the floor at {len(vals)} speeds from "
                       f"{min(r['rpm'] for r in sel):g} to {max(r['rpm'] for r in sel):g} rpm "
                       f"(goal ≤ {100 * lim:g} %)"
                       + (f"; no measurement in the window at {', '.join(nomeas)} rpm" if nomeas else "")
                       + ".")
    return out


def _stop_goal(r) -> str:
    tz = r["methods"].get("MT", {}).get("t_zero_after_stop_s", math.nan)
    st = r["stop"]
    ok = tz <= SIM_STALL_S + 1.5 / READ_HZ and not st["stalled_before_timeout"] \
        and not math.isnan(st["stalled_at_s"])
    return (f"{'MET' if ok else 'MISSED'} (through the RTL): after a stop, M/T "
            f"{edges_label(r['edge'], 'any edge')} reads 0 "
            f"{1e3 * tz:.2f} ms after the stop (timeout {SIM_STALL_S * 1e3:g} ms, reads "
            f"every 1 ms); STATUS.STALLED "
            + ("never seen" if math.isnan(st["stalled_at_s"]) else
               f"seen {1e3 * (st['stalled_at_s'] - st['last_step_s']):.2f} ms "
               "after the last step") + ".")


def sim_goals(results, stops, sim: str) -> list[str]:
    """Verdicts through the RTL: the added error, the ramp and reversal (INFO), the consistency
    checks, the stops."""
    out = _added_goals(results, sim)
    nbad = sum(r["bad_edge_delta"] + r["bad_period"] + r["bad_delta"] + r["bad_dir"]
               + r["unmatched"] for r in results + stops)
    nchk = sum(sum(r["checked"].values()) for r in results + stops)
    for r in results:
        if r["kind"] in ("ramp", "reversal") and r["methods"].get("MT", {}).get("n"):
            mt = r["methods"]["MT"]
            out.append(f"INFO (through the RTL): {r['kind']}, M/T "
                       f"{edges_label(r['edge'], 'any edge')}: the registers add "
                       f"at most {fmt_pct(mt['added_max'], 4)} % "
                       f"{'of the top speed' if r['kind'] == 'reversal' else 'of the reading'}; "
                       f"of {mt['n']} readings, {mt['wrong_sign']} of the wrong sign and "
                       f"{mt['zeros']} of 0.")
    out.append(f"{'MET' if nbad == 0 else 'MISSED'} (through the RTL): {nbad} inconsistencies "
               f"between the latched registers and the model in {nchk} checks.")
    return out + [_stop_goal(r) for r in stops]
