# SPDX-License-Identifier: Apache-2.0
"""The outcome of a mutation run: results.json (to write the report again), the table on the
terminal, doc/results/mutation.md, and the exit status."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..paths import RESULTS, TOP
from . import generate as gen
from .data import (KILLS, REVIEWED, Corner, Group, Module, Mutant, load_reviewed, tag_of,
                   unsnap)
from .modules import MODULES

RESULTS_MD = RESULTS / "mutation.md"


def save_results(root: Path, modules, corners, mutants, run: dict, notes: list[str]) -> None:
    """The run's outcome (build/mutate/<work>/results.json), for `--report`."""
    data = {"run": run, "modules": modules, "snapshot": str(gen.snapshot_root().relative_to(TOP)),
            "notes": notes,
            "corners": [{"module": c.module, "params": c.params, "defaults": c.defaults,
                         "index": c.index, "baseline_s": c.baseline_s,
                         "groups": [g.__dict__ for g in c.groups]} for c in corners],
            "mutants": [{"corner": corners.index(m.corner), "number": m.number,
                         "command": m.command, "path": str(m.path), "result": m.result,
                         "seconds": m.seconds, "failed_test": m.failed_test, "eq_note": m.eq_note,
                         "opts": m.opts} for m in mutants]}
    (root / "results.json").write_text(json.dumps(data, indent=1))


def load_results(paths: list[Path]):
    """Corners, mutants, modules, runs and notes of one or more results.json files. A corner (a
    module's parameter set) in several of them is taken from the last one that has mutants there
    (a corner run again after tests were added replaces its earlier run); a module's corners may
    come from different runs (--corner)."""
    modules, corners, mutants, runs, notes = [], [], [], [], []
    datas = []
    for path in paths:
        if not path.exists():
            sys.exit(f"mutate --report: no {path}; run make mutate first")
        datas.append(json.loads(path.read_text()))
    # (module, corner) -> (the run it is taken from, that run has mutants there): a run that
    # generated none at a corner (a --mutation whose cell is not there) does not replace one that did
    last: dict = {}
    for i, data in enumerate(datas):
        with_mutants = {m["corner"] for m in data["mutants"]}
        for j, c in enumerate(data["corners"]):
            key = (c["module"], tag_of(c["params"], c["defaults"]))
            if j in with_mutants or not last.get(key, (0, False))[1]:
                last[key] = (i, j in with_mutants)
    for i, data in enumerate(datas):
        gen.set_snapshot(Path(data["snapshot"]))
        cs = []
        for c in data["corners"]:
            spec = MODULES.get(c["module"]) or Module("", ())
            cs.append(Corner(c["module"], spec.file, c["params"], c["defaults"],
                             [Group(**g) for g in c["groups"]], c["index"], spec, c["baseline_s"]))
        keep = [last[(c.module, c.tag)][0] == i for c in cs]
        mutants += [Mutant(cs[m["corner"]], m["number"], m["command"], Path(m["path"]),
                           m["result"], m["seconds"], m["failed_test"], m["eq_note"], m["opts"])
                    for m in data["mutants"] if keep[m["corner"]]]
        modules += [c.module for c, k in zip(cs, keep) if k and c.module not in modules]
        corners += [c for c, k in zip(cs, keep) if k]
        runs.append(data["run"])
        notes += data.get("notes", [])
    modules = [m for m in MODULES if m in modules] + [m for m in modules if m not in MODULES]
    corners.sort(key=lambda c: (modules.index(c.module), c.index))
    return modules, corners, mutants, runs, notes


def _load_text(r: dict) -> str:
    ld = r.get("load", [])
    return f"load average {ld[0]} at the start, {ld[3]} at the end (1-min)" if len(ld) == 6 else ""


def table_rows(modules, corners, mutants, reviewed) -> tuple[tuple, list[tuple]]:
    head = ("module", "corners", "generated", "killed", "survived", "equivalent", "score")
    rows = []
    tot = dict(gen=0, killed=0, surv=0, unrev=0, equiv=0, unres=0)
    for mod in modules:
        ms = [m for m in mutants if m.corner.module == mod]
        killed = sum(m.result in KILLS for m in ms)
        timeouts = sum(m.result == "timeout" for m in ms)
        loops = sum(m.result == "loop" for m in ms)
        equiv = sum(m.result == "equivalent" for m in ms)
        surv = [m for m in ms if m.result == "survived"]
        unres = sum(m.result == "unresolved" for m in ms)
        unrev = sum(m.mutant_id() not in reviewed for m in surv)
        score = killed / (len(ms) - equiv) if len(ms) - equiv else 1.0
        extra = ", ".join(x for x in (f"{timeouts} timeout" if timeouts else "",
                                      f"{loops} loop" if loops else "") if x)
        surv_txt = f"{len(surv)}" + (f" ({unrev} not reviewed)" if unrev else
                                     " (reviewed)" if surv else "")
        if unres:
            surv_txt += f", {unres} unresolved"
        rows.append((mod, str(sum(c.module == mod for c in corners)), str(len(ms)),
                     f"{killed}" + (f" ({extra})" if extra else ""), surv_txt, str(equiv),
                     f"{100 * score:.1f} %"))
        for k, v in (("gen", len(ms)), ("killed", killed), ("surv", len(surv)), ("unrev", unrev),
                     ("equiv", equiv), ("unres", unres)):
            tot[k] += v
    surv_txt = str(tot["surv"]) + (f" ({tot['unrev']} not reviewed)" if tot["unrev"] else "")
    if tot["unres"]:
        surv_txt += f", {tot['unres']} unresolved"
    rows.append(("total", str(len(corners)), str(tot["gen"]), str(tot["killed"]), surv_txt,
                 str(tot["equiv"]), f"{100 * tot['killed'] / max(1, tot['gen'] - tot['equiv']):.1f} %"))
    return head, rows


def shared_ids(mutants) -> list[str]:
    """The ids that two different mutations have (see Mutant.mutant_id: two calls of one function
    on one line can give them), in the order met."""
    by_id: dict[str, set] = {}
    for m in mutants:
        by_id.setdefault(m.mutant_id(), set()).add(unsnap(m.command.split(" -src ")[0]))
    return [i for i, cmds in by_id.items() if len(cmds) > 1]


def report(modules, corners, mutants, seed: int, run: dict, notes: list[str],
           write_md: bool = True, table: str = "mutation", command: str = "make mutate") -> int:
    reviewed = load_reviewed()
    head, rows = table_rows(modules, corners, mutants, reviewed)
    lines = [head] + rows
    widths = [max(len(r[i]) for r in lines) for i in range(len(head))]
    print()
    for i, r in enumerate(lines):
        print("  ".join(v.ljust(w) if j == 0 else v.rjust(w) for j, (v, w) in enumerate(zip(r, widths))))
        if i == 0:
            print("  ".join("-" * w for w in widths))
    load_txt = _load_text(run)
    if run.get("parts"):
        load_txt = f"in {len(run['parts'])} runs: " + "; ".join(
            f"{r['elapsed'] / 60:.1f} min wall, {r.get('cpu', 0) / 60:.1f} CPU-min, {_load_text(r)}, "
            f"{r.get('date', '')}" for r in run["parts"])
    n = sum(1 for _ in mutants)
    print(f"\nseed {seed}, {n} mutants, {run['jobs']} jobs, {run['elapsed'] / 60:.1f} min wall, "
          f"{run.get('cpu', 0) / 60:.1f} CPU-min; {load_txt}")
    notes = list(notes) + [f"mutants with different mutations share the id {i}: a reviewed reason "
                           "would cover both" for i in shared_ids(mutants)]
    for note in notes:
        print(f"note: {note}")
    surv = [m for m in mutants if m.result == "survived"]
    unreviewed = [m for m in surv if m.mutant_id() not in reviewed]
    unresolved = [m for m in mutants if m.result == "unresolved"]
    for m in unreviewed:
        print(f"UNREVIEWED SURVIVOR {m.mutant_id()} {m.corner.module} {m.corner.label}: "
              f"{m.describe()} ({m.eq_note}); mutant {gen.rel(m.path) if m.path else '-'}")
    for m in unresolved:
        print(f"UNRESOLVED {m.mutant_id()} {m.corner.module} {m.corner.label}: {m.describe()} "
              f"in {m.failed_test}: {m.eq_note}")
    if write_md:
        write_results_md(head, rows, corners, mutants, reviewed, seed, run, load_txt, n,
                         RESULTS / f"{table}.md", command, notes)
    status = 0
    if unreviewed:
        print(f"mutate: {len(unreviewed)} survivor(s) neither equivalent nor reviewed "
              f"(add a test, or a reason in {REVIEWED.relative_to(TOP)})", file=sys.stderr)
        status = 1
    if unresolved:
        print(f"mutate: {len(unresolved)} mutant(s) unresolved (see above)", file=sys.stderr)
        status = 1
    return status


def write_results_md(head, rows, corners, mutants, reviewed, seed, run, load_txt, n,
                     path: Path = RESULTS_MD, command: str = "make mutate",
                     notes: list[str] | None = None) -> None:
    md = ["# Mutation coverage", "",
          f"`{command}` (scripts/mutate.py; how it works: [doc/mutation.md](../mutation.md)). "
          f"Seed {seed}, {n} mutants, {run['jobs']} jobs, {run['elapsed'] / 60:.1f} min wall time, "
          f"{run.get('cpu', 0) / 60:.1f} CPU-minutes (user + system of the tools it ran), "
          f"{load_txt}, {run.get('date', '')}.", ""]
    for note in notes or []:  # (each a paragraph)
        md += [f"Note: {note.rstrip('.')}.", ""]
    md += ["| " + " | ".join(head) + " |", "|" + "|".join(["---"] + ["---:"] * (len(head) - 1)) + "|"]
    md += ["| " + " | ".join(r) + " |" for r in rows]
    md += ["", "Score = killed / (generated - equivalent). Killed counts the mutants a test failed "
           "on, those that ran into a test's simulated-time limit (timeout) and those whose "
           "simulation stopped in a combinational loop (loop). Survivors are the mutants that pass "
           "every test of their corner and are not proven equivalent; each one needs a reason in "
           "scripts/mutate_reviewed.txt.", "",
           "## Corners and tests", "",
           "Each group is one simulation: the pytest ids that share one build, all their cocotb "
           "tests. Survivors of a group go on to the next.", "",
           "| module | corner | groups of tests | unmutated runs (CPU s) |", "|---|---|---|---:|"]
    for c in corners:
        groups = "<br>".join(f"{i + 1}. {g.label}" for i, g in enumerate(c.groups))
        md.append(f"| {c.module} | {c.label} | {groups} | {c.baseline_s:.1f} |")
    md += ["", "## Survivors and equivalent mutants", ""]
    listed = [m for m in mutants if m.result in ("survived", "equivalent", "unresolved")]
    if listed:
        md += ["| module | corner | id | mutation | result | equivalence check | reason |",
               "|---|---|---|---|---|---|---|"]
        for m in listed:
            reason = (reviewed.get(m.mutant_id(), "**not reviewed**") if m.result == "survived"
                      else "")
            desc = m.describe().replace("|", "\\|")
            md.append(f"| {m.corner.module} | {m.corner.label} | {m.mutant_id()} | {desc} | "
                      f"{m.result} | {m.eq_note.replace('|', chr(92) + '|')} | "
                      f"{reason.replace('|', chr(92) + '|')} |")
    else:
        md.append("None.")
    loops = [m for m in mutants if m.result in ("loop", "timeout")]
    if loops:
        md += ["", "## Timeouts and loops", "", "| module | corner | mutation | result | test |",
               "|---|---|---|---|---|"]
        for m in loops:
            md.append(f"| {m.corner.module} | {m.corner.label} | {m.describe().replace('|', chr(92) + '|')} "
                      f"| {m.result} | {m.failed_test.replace('|', chr(92) + '|')} |")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(md) + "\n")
    print(f"table written to {path.relative_to(TOP)}")
