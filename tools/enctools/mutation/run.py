# SPDX-License-Identifier: Apache-2.0
"""Running the mutants of a corner: simulator processes, their watchdog, the verdicts.

For each group of tests of a corner in turn (survivors of one go on to the next), pytest runs the
group's pytest ids with the mutation plugin (enctools.mutation.plugin): one Icarus process runs
the cocotb tests of every module of the group against the listed mutants
(enctools.mutation.loop) and writes the verdicts as it goes.

No verdict depends on a wall clock. A test that runs too long is killed by its simulated-time
limit, inside the simulation ("timeout"). A simulator that stops making progress (its simulated
time stands still while it uses CPU: a mutant with a zero-delay combinational loop spins inside
one time step) is stopped once it has used ``STALL_CPU_S`` seconds of CPU time since its last
progress, and the mutant it was running is judged without it: Yosys builds that mutant alone into
the group's design and looks for a logic loop the unmutated design has not ("loop", a kill). If
there is none, the mutant runs again alone, from the test it stopped in, with ``RERUN_CPU_S``; if
it stops again it is "unresolved", which fails the run.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

from ..paths import TOP
from . import generate as gen
from .data import Corner, Group, Mutant

STALL_CPU_S = 60  # CPU seconds without simulated-time progress before a simulator is stopped
RERUN_CPU_S = 600  # the same for the rerun of a stopped mutant alone
CLK_TCK = os.sysconf("SC_CLK_TCK")


def session_cpu(sid: int) -> float:
    """CPU seconds (user + system) of the live processes of session ``sid``."""
    total = 0
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                text = f.read()
        except OSError:
            continue
        rest = text[text.rindex(")") + 2:].split()
        if int(rest[3]) == sid:
            total += int(rest[11]) + int(rest[12])
    return total / CLK_TCK


def read_json(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None  # not written yet, or being replaced: the next poll reads it


class Sim:
    """One simulator process (a pytest run of one group) and what it reported."""

    def __init__(self, build: Path, group: Group, env: dict, budget: float):
        self.build, self.group, self.env, self.budget = build, group, env, budget
        self.vdir = build / "verdicts"
        self.data: dict = {}
        self.stalled = False
        self.log = build / "pytest.log"

    def results_file(self) -> Path | None:
        files = sorted(self.vdir.glob("*.json"))
        return files[0] if files else None

    def run(self, on_data) -> None:
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
               "-p", "enctools.mutation.plugin", "-rfE", *self.group.nodeids]
        with open(self.log, "w") as log:
            # a session of its own: the watchdog reads its CPU time and can end all of it
            proc = subprocess.Popen(cmd, cwd=TOP, env=self.env, stdout=log,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            gen.RUNNING.add(proc)
            last_cpu, last_sim, last_mtime = 0.0, -1.0, 0
            while proc.poll() is None:
                time.sleep(0.5)
                cpu = session_cpu(proc.pid)
                progress = False
                f = self.results_file()
                if f is not None:
                    mtime = f.stat().st_mtime_ns if f.exists() else 0
                    if mtime != last_mtime:
                        last_mtime, progress = mtime, True
                        data = read_json(f)
                        if data:
                            self.data = data
                            on_data(data)
                    beat = read_json(Path(str(f) + ".beat"))
                    if beat and beat["sim_ns"] > last_sim:
                        last_sim, progress = beat["sim_ns"], True
                if progress or cpu < last_cpu:
                    last_cpu = cpu
                elif cpu - last_cpu > self.budget:
                    self.stalled = True
                    os.killpg(proc.pid, 9)
                    proc.wait()
            gen.RUNNING.discard(proc)
        f = self.results_file()
        if f is not None:
            self.data = read_json(f) or self.data


def base_env(root: Path, c: Corner, build: Path, seed: int) -> dict:
    d = gen.corner_dir(root, c)
    env = dict(os.environ)
    for k in [k for k in env if k.startswith("MUT_")] + ["WAVES", "ENC_WAVES"]:
        env.pop(k, None)
    env.update(ENC_RTL_SNAPSHOT=str(gen.snapshot_root()), ENC_RTL_OVERRIDE=f"{c.file}={d / 'mut.v'}",
               ENC_BUILD_ROOT=str(d / "build"), MUT_LOOP_DIR=str(build / "verdicts"),
               SIM="icarus", SEED=str(seed), PYTHONDONTWRITEBYTECODE="1")
    return env


def short(test: str) -> str:
    return test.replace("enctools.benches.", "").replace("enctools.tb.", "")


def run_corner(root: Path, c: Corner, mutants: list[Mutant], seed: int, say, early_equiv,
               width: int = 1) -> None:
    """Every mutant of the corner against its groups of tests. Sets m.result for the killed
    (killed / timeout / loop), the unresolved, and those found equivalent early (capped); the
    survivors keep "-". A flow error goes to c.error.

    The first process of a group runs every mutant (and the unmutated design); the mutants it
    leaves (capped, or not started) run again in up to ``width`` processes at once, each with a
    share of them, so that a corner run alone uses every worker."""
    d = gen.corner_dir(root, c)
    by_num = {m.number: m for m in mutants}
    kills: Counter = Counter()  # test -> mutants it killed in this corner
    reported: set[int] = set()
    lock = threading.Lock()
    for gi, g in enumerate(c.groups):
        queue = [m.number for m in mutants if m.result == "-"]
        if not queue:
            break
        lazy = c.suite.lazy
        limits: dict = {}
        verified: set[str] = set()
        base_ns: dict[str, float] = {}  # test -> simulated time on the unmutated design
        timeouts: list[tuple[int, str, float]] = []  # (mutant, test, limit) of the timeout kills
        resume: dict[int, list] = {}
        stopped: set[int] = set()  # stopped once by the watchdog
        solo: list[int] = []
        first, attempt = True, 0

        def start(ids: list[int], budget: float, name: str) -> Sim:
            build = d / f"sim{gi}" / name
            shutil.rmtree(build, ignore_errors=True)
            (build / "verdicts").mkdir(parents=True)
            env = base_env(root, c, build, seed)
            order = [t for t, _ in kills.most_common()] + list(c.spec.priority)
            env.update(MUT_RUN_TAG=name, MUT_LOOP_IDS=",".join(map(str, ids)), MUT_GROUP_KEY=g.key,
                       MUT_LOOP_SUITE=json.dumps(g.members), MUT_LOOP_ORDER=",".join(order),
                       MUT_LOOP_BASELINE="lazy" if lazy else ("1" if first else "0"),
                       MUT_LOOP_LIMITS=json.dumps(limits), MUT_LOOP_VERIFIED=",".join(sorted(verified)),
                       MUT_LOOP_LIMIT_NS=str(c.suite.limit_ns or ""),
                       MUT_LOOP_CAP=str(c.suite.cap) if (first and gi == 0) else "",
                       MUT_LOOP_RESUME=json.dumps({str(k): resume[k] for k in ids if k in resume}))
            return Sim(build, g, env, budget)

        def live(data: dict, ids: list[int]) -> None:  # a kill's progress line, as it happens
            with lock:
                for k in ids:
                    r = data["results"].get(str(k), {})
                    m = by_num[k]
                    if r.get("result") in ("killed", "timeout") and m.result == "-":
                        m.result, m.failed_test = r["result"], short(r["killed_by"])
                        m.seconds += r.get("cpu_s", 0)
                        kills[r["killed_by"]] += 1
                        reported.add(k)
                        say(m)

        def absorb(sim: Sim, ids: list[int]) -> bool:
            """Takes in what one process found; False (and c.error) on a flow error."""
            data = sim.data
            where = gen.rel(sim.log)
            if not data:
                c.error = f"{g.label}: no verdicts from the mutation loop (see {where})"
                return False
            if data.get("broken"):
                c.error = f"{g.label}: {data['broken']} (see {where})"
                return False
            r0 = data["results"].get("0")
            if r0 and r0.get("result") == "passed":
                c.baseline_s += r0.get("cpu_s", 0)
            limits.update(data.get("limits", {}))
            verified.update(data.get("verified", []))
            base_ns.update(data.get("base_ns", {}))
            timeouts.extend((int(k), r["killed_by"], r.get("limit_ns", 0))
                            for k, r in data["results"].items() if r.get("result") == "timeout")
            cur = data.get("current")
            if sim.stalled and cur in (0, None):
                c.error = (f"{g.label}: the simulation makes no progress "
                           + (f"on the unmutated design in {data.get('test')}" if cur == 0 else
                              "outside any test") + f" (see {where})")
                return False
            for k in ids:
                m, r = by_num[k], data["results"].get(str(k))
                if r is None:
                    queue.append(k)  # not started (a mutant before it stopped the process)
                    continue
                if k not in reported:
                    m.seconds += r.get("cpu_s", 0)
                res = r.get("result")
                if res in ("killed", "timeout"):
                    if k not in reported:
                        m.result, m.failed_test = res, short(r["killed_by"])
                        kills[r["killed_by"]] += 1
                        reported.add(k)
                        say(m)
                elif res == "unresolved":
                    m.result, m.failed_test = "unresolved", short(r["killed_by"])
                    m.eq_note = r.get("message", "")
                    say(m)
                elif res == "capped":  # alive after the cap: equivalent? (a proof ends it)
                    if early_equiv(m, len(r.get("passed", []))):
                        reported.add(k)
                    else:
                        resume[k] = r.get("passed", [])
                        queue.append(k)
                elif res == "running" and sim.stalled and cur == k:
                    test = short(data.get("test") or "?")
                    loop, note = gen.has_new_loop(root, m, g)
                    if loop:
                        m.result, m.failed_test = "loop", f"{test} (combinational loop: {note})"
                        say(m)
                    elif k in stopped:
                        m.result, m.failed_test = "unresolved", test
                        m.eq_note = (f"no simulated-time progress in {RERUN_CPU_S} CPU seconds, "
                                     f"alone; no logic loop ({note})")
                        say(m)
                    else:
                        stopped.add(k)
                        resume[k] = r.get("passed", [])
                        solo.append(k)
                elif res != "survived":
                    c.error = (f"{g.label}: no verdict for mutant {k} ({res}; see {where})")
                    return False
            return True

        while queue or solo or (first and not lazy):
            attempt += 1
            if solo:
                batches, budget = [[solo.pop(0)]], RERUN_CPU_S
            else:
                # the first process runs them all; the rest share them out, one process a worker
                n = 1 if first else max(1, min(width, len(queue)))
                batches, budget, queue = [queue[i::n] for i in range(n)], STALL_CPU_S, []
            sims = [start(ids, budget, f"run{attempt}" + (f"_{i}" if len(batches) > 1 else ""))
                    for i, ids in enumerate(batches)]
            threads = [threading.Thread(target=s.run, args=(lambda data, ids=ids: live(data, ids),))
                       for s, ids in zip(sims, batches)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            for s, ids in zip(sims, batches):
                if not absorb(s, ids):
                    return
            first = False
        # a timeout kills only if the test ends well within its limit on the unmutated design
        for k, test, limit in timeouts:
            base = base_ns.get(test)
            if base is None or not limit or base > limit / 2:
                c.error = (f"{g.label}: mutant {k} killed by the time limit of {short(test)} "
                           f"({limit:.0f} ns), which takes "
                           + (f"{base:.0f} ns unmutated" if base is not None else "an unknown time")
                           + ": the limit must be at least twice the unmutated time")
                return
