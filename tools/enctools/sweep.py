#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The dense count-limit sweep (`make sweep`): frequency x FILTER_LEN 1..4 x phase error.

For each FILTER_LEN (one build of tb/hdl/enc_quad_probe.v at the 12 MHz clock) the cocotb test
`sweep_points` in tb/common/sweeps.py plays modelled HEDS-5000 units (the hedsmodel package, python/) into the counting
circuits and compares the accumulated counts with the waveform's true position:

- a grid: units with phase error 0 .. 70 e° (no other error, so the narrowest state is 90 - ΔS and
  the narrowest level 180 e°) at frequencies from 25 kHz (3000 rpm) through the note's 200 kHz to
  well past the count limit: each point exact, or flagged (error / glitch pulses), or -- never
  seen, and reported loudly -- wrong without a flag;
- boundaries: for each (FILTER_LEN, phase error), and for a few units drawn at the note's table
  means, a 0.25 % grid walked up from 0.98 x the predicted limit to the first miscount. The
  prediction is scripts/error_budget.py count-limit with the unit's measured errors (and the same
  rule applied to the narrowest state and level directly; the smaller of the two is the limit).

Writes doc/results/sweep_results.md (the table, included by the README) and sim/figures/count_limit.png
(exact / flagged points vs frequency, the predicted boundary, the measured one). Runs on
Verilator by default (SIM=icarus works, about ten times slower). Prints one line per point.
Usage: scripts/sweep.py [--sim icarus|verilator] [--jobs N] [--quick] [--seed N]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .paths import TOP
TABLE = TOP / "doc" / "results" / "sweep_results.md"
RAW = TOP / "sim" / "build" / "sweep_raw.json"   # every point, for --replot (not committed)
FIGURE = TOP / "sim" / "figures" / "count_limit.png"

FILTER_LENS = (1, 2, 3, 4)
PHASES = (0, 10, 20, 30, 40, 50, 60, 70)
TYPICAL_SEEDS = (11, 12, 13)
LOW_FREQS = ((25e3, 400), (1e5, 1000), (2e5, 2000), (5e5, 2000))   # (Hz, transitions)
DETUNE = 1.0013


def default_sim() -> str:
    sim = os.environ.get("SIM")
    if sim:
        return sim
    venv_verilator = list((TOP / ".venv" / "lib").glob("python3*/site-packages/verilator/bin/verilator"))
    return "verilator" if venv_verilator or shutil.which("verilator") else "icarus"


def job_for(fl: int, quick: bool) -> dict:
    """The points and boundary walks for one FILTER_LEN."""
    import numpy as np

    from hedsmodel import EncoderUnit
    from .benches.sweeps import unit_dict

    phases = PHASES[::2] if quick else PHASES
    step_mhz = 0.2 if quick else 0.1
    # x DETUNE: a round frequency is a whole number of clocks per cycle (1.5 MHz = 8), which
    # samples every cycle at the same clock phase; detuned, each run meets every phase
    highs = [round(0.6 + step_mhz * i, 3) * 1e6 * DETUNE for i in range(int(2.8 / step_mhz) + 1)]
    points = []
    for phase in phases:
        unit = unit_dict(EncoderUnit(phase_error_deg=float(phase)))
        freqs = [(f, n) for f, n in LOW_FREQS] + [(f, 2000) for f in highs]
        for i, (f, n) in enumerate(freqs):
            points.append({"unit": unit, "tag": f"grid phase {phase}", "f_hz": f, "transitions": n,
                           "direction": 1 if i % 2 == 0 else -1, "phase": phase})
    boundary = [{"unit": unit_dict(EncoderUnit(phase_error_deg=float(p))), "tag": f"phase {p}",
                 "phase": p, "kind": "phase"} for p in phases]
    boundary += [{"unit": unit_dict(EncoderUnit.typical(np.random.default_rng(s))),
                  "tag": f"typical unit {s}", "kind": "typical"}
                 for s in (TYPICAL_SEEDS[:1] if quick else TYPICAL_SEEDS)]
    return {"points": points, "boundary": boundary,
            "boundary_args": {"lo": 0.98, "hi": 1.25, "step": 0.005 if quick else 0.0025,
                              "transitions": 4000, "strict": False}}


def run_filter_len(fl: int, sim: str, quick: bool, seed: str | None, tmp: Path) -> dict:
    from .harness import run

    spec, out = tmp / f"job_F{fl}.json", tmp / f"out_F{fl}.json"
    spec.write_text(json.dumps(job_for(fl, quick)))
    env = {"ENC_SWEEP_POINTS": str(spec), "ENC_SWEEP_OUT": str(out), "COCOTB_LOG_LEVEL": "WARNING"}
    if seed is not None:
        os.environ["SEED"] = seed
    try:
        run("enc_quad_probe", "enctools.benches.sweeps", name=f"sweep_F{fl}", parameters={"FILTER_LEN": fl},
            tb_sources=("enc_quad_probe.v",), testcase="sweep_points", extra_env=env)
    except RuntimeError as e:  # a failing cocotb test; the results file says what happened
        print(f"sweep F={fl}: simulation reported failure ({e})", flush=True)
    if not out.exists():
        raise SystemExit(f"sweep F={fl}: no results written (see the simulator output above)")
    return json.loads(out.read_text())


def fmt_khz(f: float) -> str:
    return "—" if f is None or (isinstance(f, float) and math.isnan(f)) else f"{f / 1e3:,.1f}"


def write_table(results: dict, sim: str, seconds: float, path: Path) -> list[str]:
    """doc/results/sweep_results.md; returns the list of problems (silent losses, exactness failures)."""
    problems = []
    lines = [
        "<!-- written by scripts/sweep.py (make sweep); do not edit by hand -->",
        "",
        f"Count limit of enc_conditioner + decoders at the 12 MHz clock (T = 83.333 ns), measured "
        f"on {sim} in {seconds / 60:.1f} min. *Predicted*: `scripts/error_budget.py count-limit` "
        "with the unit's measured state-width error ΔS and pulse-width error ΔP (states >= 1.05 T, "
        "levels >= 1.05 F T); *direct*: the same rule on the narrowest state and level in the "
        "waveform; the limit is the smaller. *Measured*: highest frequency of a 0.25 % grid "
        "(4000 transitions per point) below the first miscount. Ratio = measured / limit.",
        "",
        "| F | unit | ΔS (e°) | ΔP (e°) | predicted (kHz) | binds | direct (kHz) | measured (kHz) "
        "| first miscount (kHz) | ratio |",
        "|---|---|---:|---:|---:|---|---:|---:|---:|---:|",
    ]
    for fl in sorted(results):
        for b in results[fl]["boundaries"]:
            lines.append(
                f"| {fl} | {b['tag']} | {b['state_error_deg']:.1f} | {b['pulse_error_deg']:.1f} | "
                f"{fmt_khz(b['f_pred_hz'])} | {b['binding']} | {fmt_khz(b['f_direct_hz'])} | "
                f"{fmt_khz(b['measured_hz'])} | {fmt_khz(b['first_bad_hz'])} | {b['ratio']:.4f} |")
    n_pts = n_exact = n_flag = n_inside = n_inside_exact = 0
    for fl in sorted(results):
        every = results[fl]["points"] + [r for b in results[fl]["boundaries"] for r in b["results"]]
        for r in every:
            n_pts += 1
            n_exact += r["exact"]
            n_flag += (not r["exact"]) and r["flags"] > 0
            n_inside += r["f_hz"] <= r["f_limit_hz"]
            n_inside_exact += r["f_hz"] <= r["f_limit_hz"] and r["exact"]
            if r["silent4"] or r["silent2"] or r["silent1"]:
                problems.append(f"F={fl} {r['tag']} {r['f_hz']:.0f} Hz: wrong count without a flag")
            if r["f_hz"] <= r["f_limit_hz"] and not r["exact"]:
                problems.append(f"F={fl} {r['tag']} {r['f_hz']:.0f} Hz: inside the limit, not exact")
    phase_rows = [b for fl in results for b in results[fl]["boundaries"] if b["tag"].startswith("phase")]
    worst = max(abs(b["ratio"] - 1) for b in phase_rows) if phase_rows else math.nan
    lines += [
        "",
        f"{n_pts} simulated points: {n_exact} exact, {n_flag} flagged, "
        f"{n_pts - n_exact - n_flag} wrong without a flag; "
        f"{n_inside} points at or under the limit, "
        + ("all exact. " if n_inside_exact == n_inside else
           f"**{n_inside - n_inside_exact} of them not exact**. ")
        +
        f"Phase-error units: measured boundary {100 * worst:.2f} % from the prediction at worst "
        "(the contract's 1.05 margin is the expected gap: a state or level shorter than 1.05 "
        "clocks but longer than 1 is still always sampled). Typical units (every factor of the "
        "note's Tables 2 and 3 at its mean) have a soft cliff: only a few of their states are as "
        "narrow as the narrowest, so past the limit a miss is a matter of chance, and the note's "
        "ΔS (largest deviation either way) is conservative for the narrowest state. A point's "
        "4000 transitions are two revolutions of the 500-line wheel: the wheel's line errors "
        "repeat every revolution (each line passes twice, as on a real wheel), the shaft's "
        "radial and axial play is drawn anew for every cycle.",
        "",
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines))
    return problems


def write_figure(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from enctools.benches.sweeps import CLK_HZ, MARGIN

    fls = sorted(results)
    fig, axes = plt.subplots(1, len(fls), figsize=(3.2 * len(fls), 4.2), dpi=120, sharey=True)
    axes = np.atleast_1d(axes)
    for ax, fl in zip(axes, fls):
        pts = [p for p in results[fl]["points"]]
        for ok, colour, marker, label in ((True, "#55a868", "o", "exact"),
                                          (False, "#c44e52", "x", "flagged")):
            sel = [p for p in pts if bool(p["exact"]) == ok]
            ax.scatter([p["f_hz"] / 1e6 for p in sel], [p["phase_error_deg"] for p in sel],
                       s=9, c=colour, marker=marker, lw=0.8, label=label)
        silent = [p for p in pts if p["silent4"] or p["silent2"] or p["silent1"]]
        if silent:
            ax.scatter([p["f_hz"] / 1e6 for p in silent], [p["phase_error_deg"] for p in silent],
                       s=40, facecolors="none", edgecolors="k", label="wrong, no flag")
        ph = np.linspace(0, 75, 200)
        f_state = (90 - ph) / 360 * CLK_HZ / MARGIN
        f_level = 180 / 360 * CLK_HZ / (MARGIN * fl)
        ax.plot(np.minimum(f_state, f_level) / 1e6, ph, "k-", lw=1.2, label="predicted limit")
        ax.plot(MARGIN * np.minimum(f_state, f_level) / 1e6, ph, "k--", lw=0.8,
                label="without the 1.05 margin")
        rows = [b for b in results[fl]["boundaries"] if b["tag"].startswith("phase")]
        ax.plot([b["measured_hz"] / 1e6 for b in rows], [b["phase"] if "phase" in b else
                                                         float(b["tag"].split()[1]) for b in rows],
                "D", ms=4, mfc="#4c72b0", mec="k", mew=0.5, label="measured boundary")
        ax.axvline(0.2, color="0.5", ls=":", lw=1)
        ax.text(0.23, 77, "note's 200 kHz", fontsize=7, color="0.35", va="top")
        ax.set_xlim(0, 3.6)
        ax.set_ylim(-3, 79)
        ax.set_title(f"FILTER_LEN = {fl}", fontsize=10)
        ax.set_xlabel("encoder output frequency (MHz)")
        ax.grid(True, lw=0.3, alpha=0.5)
    axes[0].set_ylabel("phase error = state-width error ΔS (e°)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    fig.suptitle("enc_conditioner + x4/x2/x1 decoders at 12 MHz: exact counts vs frequency "
                 "(points from 25 kHz = 3000 rpm up)", fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="sweep.py", description=__doc__.split("\n")[0])
    ap.add_argument("--sim", default=default_sim(), choices=("icarus", "verilator"))
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2") or 2),
                    help="FILTER_LENs simulated in parallel (default $JOBS or 2)")
    ap.add_argument("--filter-lens", default=",".join(map(str, FILTER_LENS)),
                    help="comma-separated FILTER_LEN values (default 1,2,3,4)")
    ap.add_argument("--quick", action="store_true", help="coarser grid (a smoke run)")
    ap.add_argument("--seed", default=os.environ.get("SEED") or None, help="cocotb random seed")
    ap.add_argument("--table", type=Path, default=TABLE)
    ap.add_argument("--figure", type=Path, default=FIGURE)
    ap.add_argument("--replot", action="store_true",
                    help=f"no simulation: redraw table and figure from {RAW.relative_to(TOP)}")
    args = ap.parse_args(argv)
    if args.replot:
        raw = json.loads(RAW.read_text())
        results = {int(k): v for k, v in raw["results"].items()}
        problems = write_table(results, raw["sim"], raw["seconds"], args.table)
        write_figure(results, args.figure)
        print(args.table.read_text())
        return 1 if problems else 0
    os.environ["SIM"] = args.sim
    fls = [int(x) for x in args.filter_lens.split(",")]
    print(f"sweep: {args.sim}, FILTER_LEN {fls}, {args.jobs} in parallel"
          f"{' (quick)' if args.quick else ''}; one line per simulated point", flush=True)
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(max(1, args.jobs)) as pool:
        futures = {fl: pool.submit(run_filter_len, fl, args.sim, args.quick, args.seed, Path(tmp))
                   for fl in fls}
        results = {fl: fut.result() for fl, fut in futures.items()}
    seconds = time.monotonic() - t0
    RAW.parent.mkdir(parents=True, exist_ok=True)
    RAW.write_text(json.dumps({"sim": args.sim, "seconds": seconds, "results": results}))
    problems = write_table(results, args.sim, seconds, args.table)
    write_figure(results, args.figure)
    print(f"\nsweep: done in {seconds / 60:.1f} min; wrote {args.table} and {args.figure}\n")
    print(args.table.read_text())
    for p in problems:
        print(f"sweep: PROBLEM: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
