# SPDX-License-Identifier: Apache-2.0
"""cocotb module of the mutation flow: many mutants in one simulation.

The design holds every mutant of one module at one corner (Yosys ``mutate -ctrl``, the method of
YosysHQ's mcy): mutant k acts while the register ``mut_ctl.sel`` (a root module the mutation
hook adds, enctools.mutation.plugin) equals k; 0 is the unmutated Yosys round trip. This module
runs the cocotb tests of the group's modules (``MUT_LOOP_SUITE``: [[module, testcase], ...],
discovered as cocotb discovers them: the Test objects of each module and the Tests of its
TestGenerators, filtered by the testcase names as the cocotb runner filters them) against the
mutants in ``MUT_LOOP_IDS``, in one simulator process:

- the unmutated design runs every test first (``MUT_LOOP_BASELINE=1``), or (``lazy``) a test runs
  on it the first time that test kills a mutant: only a kill needs the proof that its test passes
  unmutated. A failure there marks the run broken (the flow, not the tests, would be wrong).
- each mutant runs the tests until the first failure, which kills it. Tests that have killed go
  first (most kills per simulated microsecond of their run first), then ``MUT_LOOP_ORDER``, then
  the rest in discovery order. A survivor runs them all.
- each test runs under its own name's seed, as in ``make test`` (cocotb's rule: the regression
  seed plus the SHA-1 of the test's full name; ``random`` and ``cocotb.RANDOM_SEED`` are set to
  it), with its own expect_fail / expect_error, judged here as cocotb judges them.
- a simulated-time limit per test (``cocotb.triggers.with_timeout``): the test's own timeout, else
  ``MUT_LOOP_LIMITS`` (per test, from the first run's unmutated times), else 10 x the unmutated
  run's time + 1 ms (non-lazy), else ``MUT_LOOP_LIMIT_NS``. A mutant that hits it is killed by
  "timeout" (the flow checks that the test takes at most half the limit on the unmutated design:
  a tighter limit could not tell a slow mutant from a wrong one).
- ``MUT_LOOP_CAP``: a mutant still alive after that share of the tests stops, "capped" (the flow
  checks it for equivalence, and resumes it in a new process after the tests it passed:
  ``MUT_LOOP_RESUME``). ``MUT_LOOP_VERIFIED``: tests shown to pass unmutated in an earlier process.

cocotb runs the module's Test objects ("slots", registered below) one after the other; each slot
asks the loop which (mutant, test) comes next, selects the mutant, runs the test's coroutine under
the limit, records the outcome itself and finishes normally (the slots left over pass at once). A task the test started that raises
makes cocotb end the slot; the slot records that as a failure of the test.

Progress and verdicts go to ``MUT_LOOP_RESULTS`` (JSON, rewritten at the start and end of every
test) and a heartbeat to ``MUT_LOOP_RESULTS.beat`` (the simulated time, at most twice per CPU
second). The flow (enctools.mutation.run) reads both: a simulator whose simulated time stops
while it burns CPU is stopped, and the mutant is judged without it (a combinational loop, or a
rerun with more CPU time).
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import random
import re
import time
from asyncio import CancelledError

import cocotb
import pytest
from cocotb.handle import Immediate
from cocotb.regression import Test, TestGenerator
from cocotb.simtime import convert, get_sim_time
from cocotb.triggers import SimTimeoutError, Timer, with_timeout

ENV = os.environ
SUITE = json.loads(ENV.get("MUT_LOOP_SUITE") or "[]")
IDS = [int(x) for x in ENV.get("MUT_LOOP_IDS", "").split(",") if x.strip()]
RESULTS = ENV.get("MUT_LOOP_RESULTS", "")
BASELINE = ENV.get("MUT_LOOP_BASELINE", "1")  # "1", "lazy" or "0"
LAZY = BASELINE == "lazy"
LIMITS = json.loads(ENV.get("MUT_LOOP_LIMITS") or "{}")  # test fullname -> ns
LIMIT_NS = float(ENV.get("MUT_LOOP_LIMIT_NS") or 0)
ORDER = [s for s in ENV.get("MUT_LOOP_ORDER", "").split(",") if s]
CAP = float(ENV.get("MUT_LOOP_CAP") or 0)  # alive after this share of the tests: "capped"
RESUME = json.loads(ENV.get("MUT_LOOP_RESUME") or "{}")  # mutant -> tests it passed before
VERIFIED = [s for s in ENV.get("MUT_LOOP_VERIFIED", "").split(",") if s]
BEAT_PS = 20_000_011  # heartbeat period (20 us, off the clock grid)

# the regression seed: cocotb.RANDOM_SEED holds it while test modules are imported (discovery)
REGRESSION_SEED = getattr(cocotb, "RANDOM_SEED", 0)
FAILURES = (AssertionError, pytest.fail.Exception)  # what expect_fail accepts, as in cocotb


def _end_test_type() -> type:
    """The exception cocotb.end_test() raises (taken from the public function itself)."""
    try:
        cocotb.end_test()
    except BaseException as e:  # noqa: BLE001
        return type(e)
    raise RuntimeError("cocotb.end_test() did not raise")


END_TEST = _end_test_type()


def test_seed(t: Test) -> int:
    """The seed cocotb gives test ``t`` in a regression."""
    return REGRESSION_SEED + int(hashlib.sha1(t.fullname.encode()).hexdigest(), 16)


def module_tests(name: str) -> list[Test]:
    """The Tests of a cocotb module, as cocotb's discovery finds them."""
    mod = importlib.import_module(name)
    out: list[Test] = []
    for obj in vars(mod).values():
        if isinstance(obj, Test):
            out.append(obj)
        elif isinstance(obj, TestGenerator):
            out += list(obj.generate_tests())
    return out


def selected(module: str, testcase: str | None) -> list[Test]:
    tests = module_tests(module)
    if testcase:  # as the cocotb runner's testcase filter (and its testcase mode: skip ignored)
        names = [s.strip() for s in testcase.split(",") if s.strip()]
        regex = r"\.(" + "|".join(rf".*{re.escape(n)}" for n in names) + ")$"
        chosen = [t for t in tests if re.search(regex, t.fullname)]
        if not chosen:
            raise RuntimeError(f"mutation loop: no cocotb test {names} in {module}")
    else:
        chosen = [t for t in tests if not t.skip]
    return sorted(chosen, key=lambda t: t.stage)


def suite_tests() -> list[Test]:
    out: dict[str, Test] = {}
    for module, testcase in SUITE:
        for t in selected(module, testcase):
            out.setdefault(t.fullname, t)
    return list(out.values())


def score(t: Test, exc: BaseException | None) -> str:
    """passed / failed / skipped, by cocotb's rules for expect_fail and expect_error."""
    if isinstance(exc, END_TEST):
        exc = None  # cocotb.end_test(): ended as if it passed
    if exc is None:
        return "failed" if (t.expect_error or t.expect_fail) else "passed"
    if isinstance(exc, pytest.skip.Exception):
        return "skipped"
    if isinstance(exc, pytest.xfail.Exception):
        return "passed"
    if t.expect_error:
        types = tuple(e for e in t.expect_error if isinstance(e, type))
        matchers = [e for e in t.expect_error if not isinstance(e, type)]
        ok = isinstance(exc, types) or any(m.matches(exc) for m in matchers)
        return "passed" if ok else "failed"
    if t.expect_fail:
        return "passed" if isinstance(exc, FAILURES) else "failed"
    return "failed"


class Loop:
    def __init__(self, tests: list[Test]):
        self.tests = tests
        self.by_name = {t.fullname: t for t in tests}
        self.queue = ([0] if BASELINE == "1" else []) + [k for k in IDS if k != 0]
        self.verify_q: list[Test] = []  # lazy: killing tests still to run on mutant 0
        self.verified: set[str] = set(VERIFIED)
        self.kills = {t.fullname: 0 for t in tests}
        self.sim_ns = {t.fullname: 0.0 for t in tests}  # unmutated (or first known) sim time
        self.limits = dict(LIMITS)
        self.base_ns: dict[str, float] = {}  # simulated time of a test on the unmutated design
        self.limit_used = 0.0
        self.results: dict[int, dict] = {}
        self.order = self.initial_order()
        self.cur_k: int | None = None
        self.done_tests: list[str] = []
        self.running: Test | None = None
        self.t0 = self.sim0 = self.k_cpu0 = 0.0
        self.broken = ""
        self.last_beat = 0.0
        self.write()

    def initial_order(self) -> list[Test]:
        first = []
        for name in ORDER:
            for t in self.tests:
                if (t.fullname == name or t.name == name) and t not in first:
                    first.append(t)
        return first + [t for t in self.tests if t not in first]

    # ---- what to run next ---------------------------------------------------------------------
    def next(self) -> tuple[int, Test] | None:
        while True:
            if self.broken:
                return None
            if self.cur_k is None and self.verify_q:  # lazy: a killer on the unmutated design
                self.cur_k = 0
                self.results.setdefault(0, {"result": "passed", "tests": 0, "cpu_s": 0.0})
                return 0, self.verify_q[0]
            if self.cur_k is None:
                if not self.queue:
                    return None
                self.cur_k = self.queue.pop(0)
                self.done_tests = list(RESUME.get(str(self.cur_k), []))
                self.k_cpu0 = time.process_time()
                self.results[self.cur_k] = {"result": "running", "tests": 0,
                                            "passed": list(self.done_tests)}
                self.write()
            todo = [t for t in self.order if t.fullname not in self.done_tests]
            if todo:
                return self.cur_k, todo[0]
            self.finish(self.cur_k, "survived" if self.cur_k else "passed", "")

    def limit_ns(self, t: Test) -> float | None:
        if t.timeout is not None:
            value, unit = t.timeout
            return float(convert(value, unit, to="ns", round_mode="round"))
        if self.cur_k == 0 and LAZY:
            return None  # measured in full: a timeout kill is checked against it
        if t.fullname in self.limits:
            return self.limits[t.fullname]
        return LIMIT_NS or None

    def finish(self, k: int, result: str, test: str, message: str = "") -> None:
        r = self.results[k]
        r.update(result=result, killed_by=test, message=message[:300],
                 cpu_s=round(time.process_time() - self.k_cpu0, 2), tests=len(self.done_tests),
                 passed=list(self.done_tests))
        if k == 0 and result != "passed":
            self.broken = f"the unmutated design (mutant 0) fails {test}: {message[:200]}"
        if k and result in ("killed", "timeout"):
            if result == "timeout":
                r["limit_ns"] = self.limit_used
            if LAZY and test not in self.verified and all(t.fullname != test for t in self.verify_q):
                self.verify_q.append(self.by_name[test])
            self.kills[test] += 1
            killers = sorted((t for t in self.tests if self.kills[t.fullname]),
                             key=lambda t: -self.kills[t.fullname] / max(self.sim_ns[t.fullname], 1e3))
            self.order = killers + [t for t in self.order if t not in killers]
        self.cur_k = None
        self.write()

    # ---- a test's start and end ---------------------------------------------------------------
    def started(self, k: int, t: Test) -> None:
        self.running = t
        self.t0 = time.process_time()
        self.sim0 = get_sim_time("ns")
        self.write()

    def ended(self, k: int, t: Test, outcome: str, message: str = "") -> None:
        """outcome: passed, failed, skipped, timeout, or unresolved."""
        self.running = None
        sim = get_sim_time("ns") - self.sim0
        cpu = time.process_time() - self.t0
        if k == 0 or not self.sim_ns[t.fullname]:  # the unmutated time, else the first known
            self.sim_ns[t.fullname] = sim
        if k == 0:
            self.base_ns[t.fullname] = sim
        if k == 0 and not LAZY and outcome == "passed" and t.timeout is None \
                and t.fullname not in self.limits:
            self.limits[t.fullname] = round(10 * sim + 1_000_000)
        if k == 0 and LAZY:  # one killing test on the unmutated design
            r0 = self.results[0]
            self.verify_q.pop(0)
            self.cur_k = None
            r0["cpu_s"] = round(r0["cpu_s"] + cpu, 2)
            r0["tests"] += 1
            self.verified.add(t.fullname)
            if outcome not in ("passed", "skipped"):
                r0["result"] = "failed"
                self.broken = f"the unmutated design (mutant 0) fails {t.fullname}: {message[:200]}"
            self.write()
            return
        self.done_tests.append(t.fullname)
        self.results[k]["tests"] = len(self.done_tests)
        if outcome in ("failed", "timeout", "unresolved"):
            self.done_tests.pop()
            self.finish(k, {"failed": "killed"}.get(outcome, outcome), t.fullname, message)
        elif k and CAP and len(self.done_tests) >= CAP * len(self.tests) \
                and len(self.done_tests) < len(self.tests):
            self.finish(k, "capped", "")
        else:
            self.results[k]["passed"] = list(self.done_tests)
            self.write()

    # ---- files ----------------------------------------------------------------------------------
    def write(self) -> None:
        if not RESULTS:
            return
        data = {"current": self.cur_k, "test": self.running.fullname if self.running else None,
                "broken": self.broken, "results": {str(k): v for k, v in self.results.items()},
                "tests": [t.fullname for t in self.tests], "limits": self.limits,
                "sim_ns": self.sim_ns, "base_ns": self.base_ns, "kills": self.kills,
                "verified": sorted(self.verified),
                "cpu_s": round(time.process_time(), 2)}
        _replace(RESULTS, json.dumps(data))

    def beat(self) -> None:
        now = time.process_time()
        if RESULTS and now - self.last_beat >= 0.5:
            self.last_beat = now
            _replace(RESULTS + ".beat", json.dumps({"sim_ns": get_sim_time("ns"), "cpu_s": now}))


def _replace(path: str, text: str) -> None:
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def _register() -> None:
    tests = suite_tests()
    loop = Loop(tests)
    ctl = cocotb.tops.get("mut_ctl")

    async def heartbeat():
        while True:
            await Timer(BEAT_PS, "ps")
            loop.beat()

    async def slot(dut):
        nxt = loop.next()
        if nxt is None:
            return  # nothing left to run: the slot passes at once
        k, t = nxt
        if ctl is None:
            raise RuntimeError("mutation loop: no root module mut_ctl (the mutation hook adds it)")
        ctl.sel.value = Immediate(k)
        # the mutant is really selected (a flow that cannot select one cannot fail)
        assert int(ctl.sel.value) == k, f"mut_ctl.sel is {ctl.sel.value}, not {k}"
        seed = test_seed(t)
        random.seed(seed)
        cocotb.RANDOM_SEED = seed
        cocotb.start_soon(heartbeat())
        limit = loop.limit_used = loop.limit_ns(t)
        loop.started(k, t)
        exc: BaseException | None = None
        try:
            coro = t.func(dut, *t.args, **t.kwargs)
            if limit:
                await with_timeout(coro, limit, "ns")
            else:
                await coro
        except CancelledError:
            # cocotb ends the slot: a task the test started raised (the test fails, as in any
            # regression; an expected failure cannot be judged without the exception)
            expected = bool(t.expect_fail or t.expect_error)
            loop.ended(k, t, "unresolved" if expected else "failed",
                       "a task started by the test raised (see the simulator log)")
            raise
        except BaseException as e:  # noqa: BLE001 -- judged below
            exc = e
        elapsed = get_sim_time("ns") - loop.sim0
        if isinstance(exc, SimTimeoutError) and limit and elapsed >= limit:
            loop.ended(k, t, "timeout", f"no end within {limit:.0f} ns of simulated time")
        else:
            loop.ended(k, t, score(t, exc), f"{type(exc).__name__}: {exc}" if exc else "")

    n_slots = len(tests) * (len(loop.queue) + 1)
    for i in range(n_slots):
        globals()[f"mut_slot{i:05d}"] = Test(
            func=slot, args=(), kwargs={}, name=f"mut_slot{i:05d}", module=__name__, doc=None,
            timeout=None, expect_fail=False, expect_error=(), skip=False, stage=0)


if SUITE:
    _register()
