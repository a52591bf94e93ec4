# SPDX-License-Identifier: Apache-2.0
"""The command line of `make velocity` (scripts/velocity_bench.py): options with one-line errors,
then the model layer, the simulated layer, the table and the figure."""

from __future__ import annotations

import argparse
import math
import time

from ..paths import TOP
from .config import FIGURE, TABLE
from .figure import write_figure
from .model import run_model
from .plan import make_units, unit_summary
from .report import write_table
from .simulate import rtl_has_timing, run_sim


class Parser(argparse.ArgumentParser):
    def error(self, message):   # one line, no usage dump
        self.exit(2, f"velocity_bench: {message}\n")


def _num(kind, lo=None, hi=None, lo_open=False):
    def conv(text):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if kind is int else 'a number'}")
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{text!r} is not finite")
        if lo is not None and (v <= lo if lo_open else v < lo):
            raise argparse.ArgumentTypeError(f"{text} must be {'>' if lo_open else '>='} {lo}")
        if hi is not None and v > hi:
            raise argparse.ArgumentTypeError(f"{text} must be <= {hi}")
        return v
    return conv


def _parser() -> Parser:
    p = Parser(description="Velocity-method accuracy on modelled HEDS-5000 units (make velocity).")
    p.add_argument("--rpm-min", type=_num(float, 0, 60000, lo_open=True), default=1.0,
                   help="lowest constant speed, rpm (default 1)")
    p.add_argument("--rpm-max", type=_num(float, 0, 60000, lo_open=True), default=12000.0,
                   help="highest constant speed, rpm (default 12000)")
    p.add_argument("--points", type=_num(int, 2, 60), default=12,
                   help="log-spaced speeds (6 and 30 rpm are added when in range; default 12)")
    p.add_argument("--units", type=_num(int, 0, 12), default=4,
                   help="non-ideal units: half typical (table means), half drawn (default 4)")
    p.add_argument("--seed", type=_num(int, 0, 2**63 - 1), default=2026,
                   help="seed for the units and read phases (default 2026)")
    p.add_argument("--quick", action="store_true", help="short runs (about a minute)")
    p.add_argument("--jobs", type=_num(int, 1, 64), default=2, help="worker processes")
    p.add_argument("--sim", choices=("auto", "none", "icarus", "verilator"), default="auto",
                   help="simulated layer through enc_qei (auto: Verilator if present, else Icarus)")
    p.add_argument("--rtl-rev", default=None, metavar="REV",
                   help="simulate rtl/ (and its RDL) as of this git revision instead of the "
                        "working tree")
    p.add_argument("--sim-reads", type=_num(int, 3, 200), default=6,
                   help="1 kHz reads per speed in the simulated layer (default 6)")
    p.add_argument("--prescale", type=_num(int, 0, 65535), default=0,
                   help="TB_PRESCALE.PRESCALE: timebase tick = (P+1) clocks (default 0)")
    p.add_argument("--clk-mhz", type=_num(float, 1, 1000), default=100.0,
                   help="peripheral clock, MHz (default 100)")
    p.add_argument("--calib", choices=("on", "off", "only"), default="on",
                   help="the calibrated methods (doc/results/velocity_calibration.md): after the "
                        "rest (on), not at all (off), or alone (only)")
    p.add_argument("--stall-ms", type=_num(float, 0, 10000, lo_open=True), default=200.0,
                   help="stall timeout of the estimators, ms (default 200)")
    return p


def parse_args(argv=None):
    p = _parser()
    a = p.parse_args(argv)
    if a.rtl_rev is not None:
        from ..rtlcopy import revision

        try:
            a.rtl_rev = revision(a.rtl_rev)
        except ValueError as e:
            p.error(f"--rtl-rev {e}")
    if a.rpm_min >= a.rpm_max:
        p.error(f"--rpm-min ({a.rpm_min:g}) must be below --rpm-max ({a.rpm_max:g})")
    tick = (a.prescale + 1) / (a.clk_mhz * 1e6)
    if a.stall_ms * 1e-3 >= 2**32 * tick:
        p.error(f"--stall-ms {a.stall_ms:g} exceeds the 32-bit timebase's wrap "
                f"({2**32 * tick:.3g} s at this clock and prescaler)")
    if tick > 1e-4:
        p.error(f"timebase tick {tick * 1e6:g} us is too coarse for 1 kHz reads "
                "(lower --prescale or raise --clk-mhz)")
    return a


def main(argv=None) -> int:
    args = parse_args(argv)
    t_start = time.perf_counter()
    units = make_units(args)
    usum = {n: unit_summary(u) for n, u in units}
    for n, _ in units:
        s = usum[n]
        print(f"unit {n}: state-width error {s['state_error_deg']:.1f} e°, phase "
              f"{s['phase_error_deg']:.1f} e°, eccentricity {s['ecc_mm']:.4f} mm TIR", flush=True)
    if args.calib == "only":
        return _calibration(args, units)
    model = run_model(args, units)
    print(f"model layer: {model['wall_s']:.1f} s", flush=True)
    sim = None
    if args.sim != "none":
        ok, why = rtl_has_timing()
        if not ok:
            sim = {"skipped": f"enc_qei's timing registers are not in the RTL yet ({why})"}
            print(f"sim layer skipped: {sim['skipped']}", flush=True)
        else:
            sim = run_sim(args, units, model["rpms"])
    wall = time.perf_counter() - t_start
    verdicts = write_table(args, units, usum, model, sim, TABLE, wall)
    write_figure(args, units, model, sim, FIGURE)
    print(f"wrote {TABLE.relative_to(TOP)} and {FIGURE.relative_to(TOP)} in {wall / 60:.1f} min")
    for v in verdicts:
        print("  " + v)
    return _calibration(args, units) if args.calib == "on" else 0


def _calibration(args, units) -> int:
    """The calibrated methods (enctools.velocity.calib), their table and plot."""
    from .calib import run_calibration
    from .calib_report import FIGURE as CFIG, TABLE as CTAB, write_calibration

    res = run_calibration(args, units)
    goals = write_calibration(args, units, res, CTAB, CFIG, res["wall_s"])
    print(f"wrote {CTAB.relative_to(TOP)} and {CFIG.relative_to(TOP)} in "
          f"{res['wall_s'] / 60:.1f} min")
    for g in goals:
        print("  " + g)
    return 0
