#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Simulation speed: how fast the cocotb regression's typical load runs on each simulator.

Plays the same random walk (N transitions, states of S..2S clocks, edges off the clock grid) into
tb/hdl/enc_quad_probe.v (conditioner + x4 + x2 + x1) at 12 MHz, once per simulator, and prints
simulated clocks and encoder transitions per wall-clock second of the run itself (the build is
timed separately). cocotb's Python driver is part of the measurement: that is what a test pays.

    scripts/sim_speed.py [--transitions 20000] [--state-clocks 4] [--sims icarus verilator]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path



def positive(kind):
    def parse(text: str):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number")
        if v <= 0:
            raise argparse.ArgumentTypeError(f"{text} must be positive")
        return v
    return parse


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--transitions", type=positive(int), default=20000)
    ap.add_argument("--state-clocks", type=positive(float), default=4.0,
                    help="shortest state in clocks (states last S..2S; default 4)")
    ap.add_argument("--sim", nargs="+", choices=("icarus", "verilator"),
                    default=["icarus", "verilator"], help="simulators to measure (default both)")
    args = ap.parse_args()

    import os
    from .harness import run

    rows = []
    for sim in args.sim:
        os.environ["SIM"] = sim
        print(f"sim_speed: {sim}: building and running {args.transitions} transitions ...", flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "speed.json"
            cfg = {"transitions": args.transitions, "state_clocks": args.state_clocks, "seed": 1}
            t0 = time.perf_counter()
            run("enc_quad_probe", "enctools.benches.sim_speed", name="sim_speed", parameters={"FILTER_LEN": 3},
                tb_sources=("enc_quad_probe.v",), testcase="speed", quiet=True,
                extra_env={"ENC_SPEED": json.dumps(cfg), "ENC_RESULTS": str(out)})
            total = time.perf_counter() - t0
            r = json.loads(out.read_text())
        rows.append((sim, total - r["wall_s"], r["wall_s"], r["clocks"] / r["wall_s"],
                     r["transitions"] / r["wall_s"]))

    print("\n| simulator | build + start (s) | run (s) | simulated clocks / s | transitions / s |")
    print("|---|---:|---:|---:|---:|")
    for sim, build, wall, cps, tps in rows:
        print(f"| {sim} | {build:.1f} | {wall:.1f} | {cps:,.0f} | {tps:,.0f} |")
    print(f"\n{args.transitions:,} transitions, states {args.state_clocks:g}..{2 * args.state_clocks:g} "
          f"clocks at 12 MHz, enc_quad_probe (FILTER_LEN 3), cocotb {__import__('cocotb').__version__}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
