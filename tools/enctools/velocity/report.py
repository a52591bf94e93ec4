# SPDX-License-Identifier: Apache-2.0
"""doc/results/velocity_methods.md: the Markdown report, section by section (the model layer's
tables, the simulated layer's lines from sim_report, the goals, the recommendation)."""

from __future__ import annotations

import math
from pathlib import Path

from .config import CPR, FILTER_LEN, LABEL, LATENCY_CLOCKS, PRESCALE_RPMS, SCENARIOS, VARIANTS
from .format import fmt_pct, worst
from .goals import goals
from .plan import timebase


def _intro(args, wall_s: float) -> list:
    tb = timebase(args)
    L = []
    L += ["<!-- written by scripts/velocity_bench.py (make velocity); do not edit by hand -->", "",
          "# Velocity methods on a HEDS-5000: what each reads, and what enc_qei adds", "",
          f"Modelled HEDS-5000 units (hedsmodel; 500 cycles/rev, x4 = 2,000 counts/rev) read at "
          f"1 kHz by the estimators of `hedsmodel.velocity` / `sw/enc_qei_velocity.c`. Timebase "
          f"{args.clk_mhz:g} MHz / (PRESCALE {args.prescale} + 1) = {tb.tick_s * 1e9:g} ns tick, "
          f"TS_W 32; the model timestamps edges {LATENCY_CLOCKS} clocks after the pins (FILTER_LEN "
          f"{FILTER_LEN}; the RTL's own offset is measured in the simulated layer; a constant, "
          "so it cancels); "
          f"estimator stall timeout {args.stall_ms:g} ms. Seed {args.seed}"
          f"{', --quick' if args.quick else ''}; {wall_s / 60:.1f} min on {args.jobs} "
          f"job(s). Relative errors in % of the true shaft speed: *rms* and *max* over the "
          f"readings of a run (one revolution per speed, at most "
          f"{2 if args.quick else 60} s, from the third read and one read after the third A-rising edge); "
          "*floor* = the same estimator on the model's exact edge times (the encoder's own "
          "error); *added* = max |latched − floor| / true speed (what the timebase adds); "
          "*zeros* = readings of exactly 0 while turning.", ""]
    L += ["Methods: **M** = SNAP_DELTA / Δ SNAP_TIME (unit time); **T** = edges / PERIOD "
          "(N = 1, period of one selected edge); **M/T** = SNAP_EDGE_DELTA / Δ SNAP_EDGE_TIME "
          "(timestamp, hostmot2). *any edge* = every x4 transition (A and B, rising and falling); "
          "*A↑* = A rising only (one per cycle). T and M/T carry the standstill rule (no new edge: "
          "at most one edge's counts over the time since the last edge) and the stall timeout; "
          "M has neither.", ""]
    return L


def _units(units, usum) -> list:
    L = []
    L += ["## Units", "", "| unit | state-width error ΔS (e°) | phase error (e°) | pulse-width error (e°) "
          "| cycle error (e°) | eccentricity TIR (mm) |", "|---|---:|---:|---:|---:|---:|"]
    for n, _ in units:
        s = usum[n]
        L.append(f"| {n} | {s['state_error_deg']:.1f} | {s['phase_error_deg']:.1f} | "
                 f"{s['pulse_error_deg']:.1f} | {s['cycle_error_deg']:.2f} | {s['ecc_mm']:.4f} |")
    L += ["", "Each unit's code-wheel line errors repeat every revolution (line k and line k + 500 "
          "are the same line), as its eccentricity does; its radial and axial shaft play is "
          "drawn anew for every cycle.", ""]
    return L


def _which_method(units, C, rpms, typ) -> list:
    L = []
    L += ["## Which method at which speed", "",
          "rms error (%) of each method, latched by the modelled peripheral, worst of the "
          f"{len(typ)} non-ideal units (the ideal unit in brackets where it is not ~0); zeros = "
          "readings of 0 at that constant speed, all units. **Bold**: the best method at that "
          "speed (and any within 5 % of it).", "",
          "| rpm | " + " | ".join(LABEL[v] for v in VARIANTS) + " | zeros M | zeros M/T A↑ |",
          "|---:|" + "---:|" * (len(VARIANTS) + 2)]
    for rpm in rpms:
        rows = C[rpm]
        cells = []
        vals = {v: worst(rows, f"{v[0]}/{v[1]}", "rms", typ) if typ else
                worst(rows, f"{v[0]}/{v[1]}", "rms") for v in VARIANTS}
        best = min((x for x in vals.values() if not math.isnan(x)), default=math.nan)
        for v in VARIANTS:
            c = fmt_pct(vals[v], 2)
            ideal = rows.get("ideal", {}).get(f"{v[0]}/{v[1]}", {}).get("rms", math.nan)
            if not math.isnan(ideal) and ideal > 1e-4:
                c += f" ({fmt_pct(ideal, 2)})"
            cells.append(f"**{c}**" if vals[v] <= 1.05 * best else c)
        zm = sum(r.get("M/any", {}).get("zeros", 0) for r in rows.values())
        zmt = sum(r.get("MT/a_rising", {}).get("zeros", 0) for r in rows.values())
        n = sum(r.get("MT/a_rising", {}).get("n", 0) for r in rows.values())
        L.append(f"| {rpm:g} | " + " | ".join(cells) + f" | {zm}/{n} | {zmt}/{n} |")
    L.append("")
    return L


def _state_width(units, usum, C, rpms) -> list:
    """Why timing between unlike edges is a poor source: the state-width error."""
    L = []
    L += ["## Why timing between unlike edges is a poor velocity source", "",
          "An x4 encoder's four edges per cycle are not equally spaced: the state-width error ΔS "
          "(tens of electrical degrees on a typical HEDS-5000, from the pulse-width and phase "
          "errors) makes one state up to (90 + ΔS) e° long and another (90 − ΔS) e°. Timing "
          "between consecutive edges of *any* type measures one state, so a reading is off by "
          "up to ΔS / (90° − ΔS) -- at every speed, since it is geometry, not timing. A-rising edges are one "
          "whole cycle apart: only the line-placement error of the code wheel (~0.7 e° rms per "
          "cycle in the model; the units table's cycle error is the note's Figure 3 maximum, "
          "eccentricity included) and the once-per-revolution eccentricity remain. M/T with any edge averages the states over "
          "the read period, so its error falls as more states fit in a read (≈ ΔS / 90° divided "
          "by the states per read).", "",
          "| unit | ΔS (e°) | ΔS / (90° − ΔS) (%) | T any edge max (%) | T A↑ max (%) | M/T any max at 30 rpm (%) "
          "| M/T A↑ max at 30 rpm (%) |", "|---|---:|---:|---:|---:|---:|---:|"]
    r30 = min(rpms, key=lambda r: abs(r - 30))
    for n, _ in units:
        s = usum[n]
        t_any = max(C[r][n].get("T/any", {}).get("floor_max", 0) for r in rpms)
        t_a = max(C[r][n].get("T/a_rising", {}).get("floor_max", 0) for r in rpms)
        L.append(f"| {n} | {s['state_error_deg']:.1f} | {fmt_pct(s['state_error_deg'] / (90 - s['state_error_deg']), 1)} | "
                 f"{fmt_pct(t_any, 2)} | {fmt_pct(t_a, 2)} | "
                 f"{fmt_pct(C[r30][n].get('MT/any', {}).get('floor_max'), 2)} | "
                 f"{fmt_pct(C[r30][n].get('MT/a_rising', {}).get('floor_max'), 2)} |")
    L.append("")
    return L


def _floor_added(C, rpms, typ) -> list:
    """M/T on A-rising edges: the encoder's floor and what the hardware adds."""
    L = []
    L += ["## Timestamp method, A-rising edges: the encoder's floor and what the hardware adds", "",
          "| rpm | floor rms, worst unit (%) | floor max, worst unit (%) | added max, non-ideal (%) "
          "| added max, ideal (%) | latched max, worst unit (%) | zeros |",
          "|---:|---:|---:|---:|---:|---:|---:|"]
    for rpm in rpms:
        rows = C[rpm]
        k = "MT/a_rising"
        zeros = sum(r.get(k, {}).get("zeros", 0) for r in rows.values())
        L.append(f"| {rpm:g} | {fmt_pct(worst(rows, k, 'floor_rms'))} | "
                 f"{fmt_pct(worst(rows, k, 'floor_max'))} | "
                 f"{fmt_pct(worst(rows, k, 'added_max', typ))} | "
                 f"{fmt_pct(rows.get('ideal', {}).get(k, {}).get('added_max'))} | "
                 f"{fmt_pct(worst(rows, k, 'max'))} | {zeros} |")
    L.append("")
    return L


def _prescale(args, units, model) -> list:
    L = []
    P = model["prescale"]
    if P:
        L += ["## Timebase resolution: hardware-added error of M/T A↑ vs prescaler", "",
              f"Max added error (%), {units[0][0]} unit / {units[1][0] if len(units) > 1 else '-'}, "
              f"at a {args.clk_mhz:g} MHz clock.", "",
              "| PRESCALE | tick | " + " | ".join(f"{r:g} rpm" for r in PRESCALE_RPMS) + " |",
              "|---:|---:|" + "---:|" * len(PRESCALE_RPMS)]
        for p in sorted(P):
            tick = (p + 1) / (args.clk_mhz * 1e6)
            cells = []
            for r in PRESCALE_RPMS:
                rows = P[p].get(r, {})
                vals = [rows[u]["MT/a_rising"]["added_max"] for u, _ in units[:2]
                        if u in rows and "MT/a_rising" in rows[u]]
                cells.append(" / ".join(fmt_pct(v) for v in vals))
            L.append(f"| {p} | {tick * 1e9:g} ns | " + " | ".join(cells) + " |")
        L += ["", "The added error is about one tick over the time between the two timestamps "
              "(≥ one read period, 1 ms, when edges are dense; one cycle when they are sparse): "
              "keep the tick ≤ 100 ns (PRESCALE ≤ 9 at 100 MHz) for ≤ 0.01 %.", ""]
    return L


def _scenarios(units, model) -> list:
    """Ramp and reversal: errors, wrong sign, zeros; stops: time to 0."""
    L = []
    S = model["scenario"]
    if S:
        L += ["## Ramp, reversal and stop", ""]
        for sname in ("ramp", "reversal"):
            if sname not in S:
                continue
            L += [f"**{SCENARIOS[sname][1]}**: rms / max error (%) where |true| ≥ 30 rpm "
                  "(against the speed at the read; the methods' lag included), readings of the "
                  "wrong sign and of 0 where |true| ≥ 6 rpm. Wrong sign counts only readings "
                  "after the encoder's last count step went the right way: between a turn and "
                  "the first step back a reading keeps the old sign, decaying, as the encoder "
                  "has not said anything yet.", "",
                  "| unit | " + " | ".join(LABEL[v] for v in VARIANTS) + " |",
                  "|---|" + "---|" * len(VARIANTS)]
            for n, _ in units:
                r = S[sname][n]
                cells = []
                for v in VARIANTS:
                    m = r.get(f"{v[0]}/{v[1]}", {})
                    cells.append(f"{fmt_pct(m.get('rms'), 2)} / {fmt_pct(m.get('max'), 2)}; "
                                 f"sign {m.get('wrong_sign', 0)}, 0s {m.get('zeros_moving', 0)}"
                                 f"/{m.get('n_moving', 0)}")
                L.append(f"| {n} | " + " | ".join(cells) + " |")
            L.append("")
        for sname in ("stop", "stop6"):
            if sname not in S:
                continue
            L += [f"**{SCENARIOS[sname][1]}**: time from the stop until the reading is 0 for good "
                  f"(s) [from the last edge of any type]; zero readings while turning.", "",
                  "| unit | " + " | ".join(LABEL[v] for v in VARIANTS) + " |",
                  "|---|" + "---|" * len(VARIANTS)]
            for n, _ in units:
                r = S[sname][n]
                cells = []
                for v in VARIANTS:
                    m = r.get(f"{v[0]}/{v[1]}", {})
                    cells.append(f"{m.get('t_to_zero_s', math.nan):.3f} "
                                 f"[{m.get('since_last_edge_s', math.nan):.3f}]; 0s "
                                 f"{m.get('zeros_moving', 0)}/{m.get('n_moving', 0)}")
                L.append(f"| {n} | " + " | ".join(cells) + " |")
            L.append("")
    return L


def _sim_section(sim) -> list:
    L = []
    L += ["## Through the RTL (enc_qei_wb over Wishbone, cocotb)", ""]
    if sim is None:
        L += ["Not run (`--sim none`).", ""]
    elif sim.get("skipped"):
        L += [f"**Not run**: {sim['skipped']}. The numbers above are the model layer only "
              "(an ideal peripheral with the contract's timing).", ""]
    else:
        L += sim["lines"]
    return L


def _recommendation(args, units, usum, C, rpms, typ) -> list:
    k = "MT/a_rising"
    fl_lo = [C[r][u][k]["floor_rms"] for r in rpms if r < 100 for u in typ if k in C[r][u]]
    fl_hi = [C[r][u][k]["floor_rms"] for r in rpms if r >= 1000 for u in typ if k in C[r][u]]
    ecc = [usum[u]["ecc_mm"] for u in typ]
    rng_txt = (lambda v: f"{fmt_pct(min(v), 2)}–{fmt_pct(max(v), 2)} %" if v else "—")
    mt_any_ok = [r for r in rpms if all(
        C[r][u].get("MT/any", {}).get("rms", math.inf)
        <= 1.25 * C[r][u].get(k, {}).get("rms", 0) for u in typ)]
    L = ["## Recommendation", "",
          "- Use **M/T on A-rising edges** (SNAP_CTRL.EDGE = a_rising, SNAP_EDGE_DELTA / Δ "
          "SNAP_EDGE_TIME) at every speed. Its error is the encoder's own: below 100 rpm, where "
          "a reading spans one or a few cycles, the cycle error of its two edges ("
          f"{rng_txt(fl_lo)} rms on the non-ideal units); above 1,000 rpm, where it spans many "
          "cycles, the once-per-revolution speed ripple of the code wheel's eccentricity "
          f"({rng_txt(fl_hi)} rms for {min(ecc) if ecc else 0:.3f}–{max(ecc) if ecc else 0:.3f} "
          "mm TIR; being tied to the shaft angle, a host could calibrate it out against the "
          "index). The standstill rule keeps it off 0 down to one cycle per stall timeout "
          f"({60 / (CPR * args.stall_ms * 1e-3):.2g} rpm with {args.stall_ms:g} ms), and a stop "
          "reads 0 one stall timeout after the last edge.",
          "- **Any-edge timing** inherits the state-width error, ΔS / (90° − ΔS) per edge pair "
          "(tens of %): T on any edge never recovers; M/T on any edge only when many states fit "
          "in one read (within 25 % of A↑ from "
          f"{min(mt_any_ok):g} rpm)." if mt_any_ok else "(never within 25 % of A↑ here).",
          "- **M** (unit time) is exact on average but quantised to one count per read period "
          "(30 rpm at 1 kHz): it reads 0 or 30 rpm below 30 rpm and ±1 count above; use it only "
          "where the count per read is large (it matches M/T A↑ near 12,000 rpm).",
          "- **T** on A-rising edges equals M/T at low speed (one cycle per reading) and needs no "
          "snapshot; at high speed it sees one cycle's error unaveraged: prefer M/T there.", ""]
    return L


def write_table(args, units, usum, model, sim, path: Path, wall_s: float) -> list[str]:
    """The Markdown report; returns the list of goal verdict lines."""
    typ = [n for n, _ in units if n != "ideal"]
    rpms = model["rpms"]
    C = model["constant"]
    verdicts = goals(args, units, model, sim)
    L = (_intro(args, wall_s) + _units(units, usum) + _which_method(units, C, rpms, typ)
         + _state_width(units, usum, C, rpms) + _floor_added(C, rpms, typ)
         + _prescale(args, units, model) + _scenarios(units, model) + _sim_section(sim)
         + ["## Goals", ""] + [f"- {v}" for v in verdicts] + [""]
         + _recommendation(args, units, usum, C, rpms, typ))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(L))
    return verdicts
