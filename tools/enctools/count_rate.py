#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Count-rate benchmark: the shortest state width (in clock periods) at which the conditioner +
decoders still count exactly, for FILTER_LEN = 1..4, against the contract's bound max(1, F/2).

For each F it plays random walks of N transitions (states uniform [S, 2S] clocks, edges off the
clock grid, 30% reversals) for several seeds, at S = bound x ratio for ratios going down from
1.10, and reports the smallest S at which every seed at that S and above was exact; then it
plays the same walks at 0.8 x the bound and reports how many missed, each of which must be
flagged. Exact means the 4X and 2X counts equal the true position and the 1X count stays in its
hysteresis band.
With --dut qei the same walks go through the peripheral: enc_qei_wb, FUNC x4, CTRL.FILTER_LEN set
at run time, COUNT read over Wishbone; exact means COUNT equals the true 4X position, and a miss
must have set QERR or GLITCH. With --dut engine the walks go through the shared engine
(enc_qei_wb, ENGINE = 1, 16 lean channels): each point plays every seed's walk on all 16 channels
at once (channel 0 the seed's, the others their own), and every channel is judged alone. Runs on
Verilator by default (SIM=icarus also works, slower). Prints a progress line per point and a
markdown table (also written to doc/results/count_rate.md).

    scripts/count_rate.py [--transitions 20000] [--seeds 3] [--filters 1 2 3 4] [--sim verilator]
                          [--seed 1000] [--jobs 2] [--dut probe|qei|engine|both|all]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .paths import TOP

RATIOS = (1.10, 1.07, 1.05, 1.03, 1.02, 1.01, 1.00, 0.99, 0.98, 0.97, 0.95, 0.92, 0.90)
FLAG_RATIO = 0.80  # well below the bound: every inexact walk must be flagged (QERR / GLITCH)


def positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number")
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text} must be at least 1")
    return v


def filter_len(text: str) -> int:
    v = positive_int(text)
    if v > 16:
        raise argparse.ArgumentTypeError(f"FILTER_LEN {v} is outside 1 .. 16")
    return v


DUTS = {  # --dut: what the table calls it
    "probe": "conditioner + decoders (tb/hdl/enc_quad_probe.v)",
    "qei": "enc_qei_wb (FUNC x4, COUNT over Wishbone)",
    "engine": "enc_qei_wb, shared engine, 16 channels at once (FUNC x4, COUNT over Wishbone)",
}
ENGINE_CHANNELS = 16


def run_points(dut: str, f: int, points: list[dict]) -> list[dict]:
    from .harness import run

    env = {"ENC_POINTS": json.dumps([dict(pt, f=f) for pt in points])}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "results.json"
        env["ENC_RESULTS"] = str(out)
        if dut == "probe":
            run("enc_quad_probe", "enctools.benches.count_rate_probe", name=f"count_rate_bench_f{f}",
                parameters={"FILTER_LEN": f}, tb_sources=("enc_quad_probe.v",), testcase="sweep",
                extra_env=env, quiet=True)
        elif dut == "qei":
            run("enc_qei_wb", "enctools.benches.count_rate_qei", name=f"count_rate_bench_qei_f{f}", testcase="sweep",
                extra_env=env, quiet=True)
        else:
            from .regmap import enum

            run("enc_qei_wb", "enctools.benches.count_rate_qei", name=f"count_rate_bench_engine_f{f}",
                parameters={"CHANNELS": ENGINE_CHANNELS, "PROFILE": enum("CAPS", "PROFILE")["lean"],
                            "ENGINE": 1}, testcase="sweep", extra_env=env, quiet=True)
        return json.loads(out.read_text())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--transitions", type=positive_int, default=20000,
                    help="transitions per walk (default 20000)")
    ap.add_argument("--seeds", type=positive_int, default=3, help="walks per point (default 3)")
    ap.add_argument("--filters", type=filter_len, nargs="+", default=[1, 2, 3, 4],
                    help="FILTER_LEN values (default 1 2 3 4)")
    ap.add_argument("--sim", choices=("icarus", "verilator"), default="verilator",
                    help="simulator (default verilator)")
    ap.add_argument("--seed", type=int, default=1000,
                    help="base seed: walk k of FILTER_LEN F uses seed*F + k (default 1000)")
    ap.add_argument("--jobs", type=positive_int, default=2, help="FILTER_LEN values run in parallel")
    ap.add_argument("--dut", choices=("probe", "qei", "engine", "both", "all"), default="both",
                    help="the bare circuits, the enc_qei peripheral, its shared engine with 16 "
                         "channels, both of the first two (default), or all three")
    args = ap.parse_args()
    os.environ["SIM"] = args.sim

    t0 = time.time()
    duts = {"both": ["probe", "qei"], "all": list(DUTS)}.get(args.dut, [args.dut])

    def walks_at(dut: str, f: int, s: float) -> tuple[list[dict], list[dict]]:
        """Every seed's walk at states of S clocks: the results, and the misses nothing flagged."""
        results = run_points(dut, f, [{"s": s, "n": args.transitions, "seed": args.seed * f + k}
                                      for k in range(args.seeds)])
        return results, [r for r in results if not r["exact"] and not r["flagged"]]

    def one_filter(job):
        dut, f = job
        bound = max(1.0, f / 2)
        smallest_exact = None
        failed_at = None
        for ratio in RATIOS:
            s = round(bound * ratio, 4)
            results, silent = walks_at(dut, f, s)
            exact = all(r["exact"] for r in results)
            walks = f"{args.seeds} x {ENGINE_CHANNELS}" if dut == "engine" else f"{args.seeds}"
            print(f"count_rate: {dut} F={f} S={s:.3f} clocks ({ratio:.2f} x bound): "
                  f"{'exact' if exact else 'NOT exact'} over {walks} x {args.transitions} transitions"
                  f"{', SILENT MISCOUNT' if silent else ''}  [{time.time() - t0:.0f} s]", flush=True)
            if silent:
                raise SystemExit(f"count_rate: silent miscount: {silent[0]}")
            if not exact:
                failed_at = s
                break
            smallest_exact = s
        # well below the bound: how many walks miss, and that each one that does is flagged
        s = round(bound * FLAG_RATIO, 4)
        results, silent = walks_at(dut, f, s)
        inexact = [r for r in results if not r["exact"]]
        print(f"count_rate: {dut} F={f} S={s:.3f} clocks ({FLAG_RATIO:.2f} x bound): "
              f"{len(inexact)} of {len(results)} walks inexact, {len(inexact) - len(silent)} of them "
              f"flagged  [{time.time() - t0:.0f} s]", flush=True)
        if silent:
            raise SystemExit(f"count_rate: silent miscount: {silent[0]}")
        return dut, f, bound, smallest_exact, failed_at, (len(inexact), len(results))

    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(one_filter, [(d, f) for d in duts for f in args.filters]))

    header = ["| circuit | FILTER_LEN | bound max(1, F/2) (clocks) | smallest exact S (clocks) | ratio to bound | "
              f"first failing S | at {FLAG_RATIO:.2f} x bound: walks inexact, all flagged |",
              "|---|---:|---:|---:|---:|---:|---|"]
    new = {}
    ok = True
    for dut, f, bound, s, failed, (n_inexact, n_walks) in rows:
        ratio = s / bound if s else float("nan")
        ok &= s is not None and abs(ratio - 1) <= 0.05
        new.setdefault(DUTS[dut], []).append(
            f"| {DUTS[dut]} | {f} | {bound:.2f} | {s if s else '-'} | {ratio:.2f} | "
            f"{failed if failed else 'none down to ' + str(round(bound * RATIOS[-1], 3))} | "
            f"{n_inexact} of {n_walks} |")
    table = "\n".join(header + [row for name in DUTS.values() for row in new.get(name, [])])
    note = (f"\n{args.seeds} seeds x {args.transitions:,} transitions per point, states uniform "
            f"[S, 2S] clock periods, edges off the clock grid, simulator {os.environ['SIM']}"
            + (f"; the shared engine: each seed's walk and {ENGINE_CHANNELS - 1} others on its "
               f"{ENGINE_CHANNELS} channels at once, each channel judged alone" if "engine" in duts else "")
            + ". No point below the bound miscounted silently (the run stops if one does).\n")
    print(table + note)
    (TOP / "doc" / "results" / "count_rate.md").write_text(table + "\n" + note)
    print("count_rate: every F within 5% of its bound" if ok else "count_rate: some F NOT within 5% of its bound")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
