# SPDX-License-Identifier: Apache-2.0
"""The command line of `make demo` and `make waves` (scripts/demo.py)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..paths import TOP
from .analyse import analyze
from .config import DEFAULT_PNG, ICARUS_MAX_CLOCKS, NAME, VCD
from .gtkw import write_gtkw
from .options import OptionError, estimate_clocks, validate
from .plan import Plan, make_plan
from .report import print_report
from .simulate import simulate
from .view import demo_figure, open_waves


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=sys.modules[__package__].__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rpm", default=None, help="peak speed, rpm (default 3000)")
    ap.add_argument("--temp-c", default=None, help="temperature, degC, -40..125 (default 25)")
    ap.add_argument("--clk-hz", default=None, help="circuit clock, Hz (default 12e6)")
    ap.add_argument("--seed", default=None, help="unit seed, integer >= 0 (default 1)")
    ap.add_argument("--sim", default="auto", choices=("auto", "verilator", "icarus"),
                    help="simulator (default auto: Icarus for short runs, which needs no C++ "
                         "build; Verilator, faster per clock, for long ones)")
    ap.add_argument("--png", default=str(DEFAULT_PNG),
                    help="where to render the waveform picture ('' = none)")
    ap.add_argument("--gtkw", default=None,
                    help="where to write the GTKWave save file for this run (default "
                         "sim/waves/NAME.gtkw beside the VCD; '' = none)")
    ap.add_argument("--view", action="store_true", help="open the demo's VCD in GTKWave (make waves)")
    ap.add_argument("--name", default=NAME, help=argparse.SUPPRESS)  # build dir and VCD name (tests)
    return ap.parse_args(argv)


def _shown(path: Path):
    return path.relative_to(TOP) if path.is_relative_to(TOP) else path


def _absolute(text: str) -> Path:
    path = Path(text)
    return path if path.is_absolute() else Path.cwd() / path


def write_views(args, plan: Plan, vcd: Path) -> None:
    """The save file and the picture of this run's dump, and the line that names them."""
    vcd_mb = vcd.stat().st_size / 1e6 if vcd.exists() else 0.0
    gtkw = vcd.with_suffix(".gtkw") if args.gtkw is None else _absolute(args.gtkw) if args.gtkw else None
    shown = ""
    if gtkw is not None:
        write_gtkw(plan, vcd, gtkw)
        shown = f", save file {_shown(gtkw)}"
    if args.png:
        png = _absolute(args.png)
        demo_figure(vcd, png, plan)
        print(f"waves: {vcd.relative_to(TOP)} ({vcd_mb:.1f} MB){shown}, picture {_shown(png)}; "
              f"'make waves' opens them")
    else:
        print(f"waves: {vcd.relative_to(TOP)} ({vcd_mb:.1f} MB){shown}; 'make waves' opens it")


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.view:
        return open_waves()
    try:
        opts = validate(args.rpm, args.temp_c, args.clk_hz, args.seed)
    except OptionError as exc:
        print(f"make demo: {exc}", file=sys.stderr)
        return 2
    t0 = time.monotonic()
    plan = make_plan(opts)
    sim = args.sim
    if sim == "auto":
        sim = "icarus" if estimate_clocks(opts.rpm, plan.clk_hz) <= ICARUS_MAX_CLOCKS else "verilator"
    res = simulate(plan, sim, args.name)
    plan.t0_ps = res["t0_ps"]
    an = analyze(plan, res)
    print_report(plan, res, an)
    write_views(args, plan, VCD.with_name(f"{args.name}.vcd"))
    n_fail = sum(not ok for _, ok, _ in an["verdicts"])
    print(f"demo: {'all circuits PASS' if not n_fail else f'{n_fail} FAIL'} "
          f"(build {res['t_build']:.1f} s, simulation {res['t_sim']:.1f} s, "
          f"total {time.monotonic() - t0:.1f} s)")
    return 1 if n_fail else 0
