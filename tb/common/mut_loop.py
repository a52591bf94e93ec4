# SPDX-License-Identifier: Apache-2.0
"""cocotb module of `make mutate` (scripts/mutate.py): many mutants in one simulation.

scripts/mutate.py builds one design per module and parameter corner that holds all N mutants of
the module (Yosys `mutate -ctrl`, the method of YosysHQ's mcy): mutant k is active while the
control register `mut_ctl.sel` (a root module tb/common/harness.py adds in this mode) equals k;
0 is the unmutated Yosys round trip. This module runs the cocotb tests of one test module
(MUT_LOOP_MODULE, the one the pytest test would have run) against mutant 0 and then against
every mutant in MUT_LOOP_IDS, one test after the other, in one simulator process:

- mutant 0 (the baseline) runs every test; a failure there marks the run broken (the flow is
  wrong, not the tests) and nothing else runs. Its per-test wall time is the tests' cost.
- each mutant runs the tests until the first failure (fail-fast): that test kills it. Tests that
  have killed mutants in this run go first, most kills per second of baseline first; the others
  keep the given order (ENC_QEI_MUT_TESTS, or the module's own order). A survivor runs them all.
- every test is the regression's own Test object, run with its own name, so cocotb seeds it as in
  `make test` (the seed hashes the test's full name), with its own expect_fail / expect_error,
  and cocotb itself judges it (the verdict is read from cocotb's result recording, not guessed).
  Each test resets the DUT at its start, as in a normal run of several tests.
- a simulated-time limit per test (the test's own, or MUT_LOOP_TIMEOUT_NS, or 10 x the baseline's
  time + 1 ms): a mutant that never answers fails by timeout (counted as killed, marked so).

Progress and verdicts go to MUT_LOOP_RESULTS (JSON, rewritten after every test): scripts/mutate.py
reads it, and if the simulator hangs in wall-clock time (a mutant's combinational loop), kills the
process, marks the running mutant "timeout" and starts a new one for the rest.

cocotb has no public way to run tests chosen at run time, so the module registers (1 + #mutants) x
#tests slots and gives each slot its test when cocotb starts it (cocotb 2.1 calls the test function
before it reads the timeout and computes the seed from module and name; requirements.txt pins it).
"""

from __future__ import annotations

import importlib
import json
import os
import time

import cocotb
import pytest
from cocotb._decorators import Test, TestGenerator
from cocotb.handle import Immediate
from cocotb.simtime import get_sim_time

MODULE = os.environ.get("MUT_LOOP_MODULE", "")
IDS = [int(x) for x in os.environ.get("MUT_LOOP_IDS", "").split(",") if x.strip()]
RESULTS = os.environ.get("MUT_LOOP_RESULTS", "")
TESTCASE = [s for s in os.environ.get("MUT_LOOP_TESTCASE", "").split(",") if s]
# "1": mutant 0 runs every test first; "lazy": a test is run on mutant 0 the first time it kills a
# mutant (only tests that kill need to be shown to pass on the unmutated design); "0": neither
BASELINE = os.environ.get("MUT_LOOP_BASELINE", "1")
LAZY = BASELINE == "lazy"
# a mutant still alive after CAP_S seconds stops here as "capped" (scripts/mutate.py checks it for
# equivalence first, then resumes it: RESUME = {mutant: [tests it passed]})
CAP_S = float(os.environ.get("MUT_LOOP_CAP_S") or 0)
RESUME = (json.loads(open(os.environ["MUT_LOOP_RESUME"]).read())
          if os.environ.get("MUT_LOOP_RESUME") else {})


def module_tests(name: str) -> list[Test]:
    """The Test objects of a cocotb test module, as cocotb's discovery finds them (a Test, or the
    Tests of a TestGenerator), in file order; the module may give its own list (mut_loop_tests)."""
    mod = importlib.import_module(name)
    if hasattr(mod, "mut_loop_tests"):
        return list(mod.mut_loop_tests())
    out: list[Test] = []
    for obj in vars(mod).values():
        out += ([obj] if isinstance(obj, Test) else
                list(obj.generate_tests()) if isinstance(obj, TestGenerator) else [])
    return out


def selected() -> list[Test]:
    tests = module_tests(MODULE)
    if TESTCASE:  # like cocotb's testcase mode: these, skip flag or not
        by_name = {t.name: t for t in tests}
        missing = [n for n in TESTCASE if n not in by_name]
        if missing:
            raise RuntimeError(f"mut_loop: no cocotb test {missing} in {MODULE}")
        return [by_name[n] for n in TESTCASE]
    return sorted((t for t in tests if not t.skip), key=lambda t: t.stage)


class Loop:
    def __init__(self, tests: list[Test]):
        self.tests = tests
        self.queue = ([0] if BASELINE == "1" else []) + [k for k in IDS if k != 0]
        self.verify_q: list[Test] = []  # LAZY: killing tests still to run on mutant 0
        self.verified: set[str] = set()
        self.kills = {t.fullname: 0 for t in tests}
        self.cost = {t.fullname: 0.0 for t in tests}  # baseline wall seconds
        self.sim_ns = {t.fullname: 0.0 for t in tests}  # baseline simulated ns
        self.results: dict[int, dict] = {}
        self.order = list(tests)
        self.cur_k: int | None = None
        self.done_tests: list[str] = []
        self.running: Test | None = None
        self.t0 = 0.0
        self.sim0 = 0.0
        self.k_t0 = 0.0
        self.k_wall = 0.0
        self.broken = ""
        self.write()

    # ---- what to run next ---------------------------------------------------------------------
    def next(self) -> tuple[int, Test] | None:
        while True:
            if self.broken:
                return None
            if self.cur_k is None and self.verify_q:  # LAZY: a killer on the unmutated design
                self.cur_k = 0
                self.k_t0, self.k_wall = time.monotonic(), time.time()
                self.results.setdefault(0, {"result": "passed", "tests": 0, "seconds": 0.0})
                return 0, self.verify_q[0]
            if self.cur_k is None:
                if not self.queue:
                    return None
                self.cur_k = self.queue.pop(0)
                self.done_tests = list(RESUME.get(str(self.cur_k), []))
                self.k_t0 = time.monotonic()
                self.k_wall = time.time()
                self.results[self.cur_k] = {"result": "running", "tests": 0}
                self.write()
            todo = [t for t in self.order if t.fullname not in self.done_tests]
            if todo:
                return self.cur_k, todo[0]
            self.finish(self.cur_k, "survived" if self.cur_k else "passed", "")

    def finish(self, k: int, result: str, test: str) -> None:
        r = self.results[k]
        r.update(result=result, killed_by=test, seconds=round(time.monotonic() - self.k_t0, 2),
                 tests=len(self.done_tests), passed=list(self.done_tests))
        if k == 0 and result != "passed":
            self.broken = f"the unmutated design (mutant 0) fails {test}"
        if k and result in ("killed", "timeout"):
            if LAZY and test not in self.verified and all(t.fullname != test for t in self.verify_q):
                self.verify_q += [t for t in self.tests if t.fullname == test]
            self.kills[test] += 1
            killers = sorted((t for t in self.tests if self.kills[t.fullname]),
                             key=lambda t: -self.kills[t.fullname] / max(self.cost[t.fullname], 0.02))
            self.order = killers + [t for t in self.order if t not in killers]
        self.cur_k = None
        self.write()

    def timeout_of(self, t: Test):
        if t.timeout is not None:
            return t.timeout
        if os.environ.get("MUT_LOOP_TIMEOUT_NS"):
            return (float(os.environ["MUT_LOOP_TIMEOUT_NS"]), "ns")
        if self.cur_k == 0 or not self.sim_ns[t.fullname]:
            return None  # (the wall-clock watchdog of scripts/mutate.py still applies)
        return (round(10 * self.sim_ns[t.fullname] + 1_000_000), "ns")

    # ---- cocotb's verdict ---------------------------------------------------------------------
    def verdict(self, outcome: str, exc: BaseException | None = None) -> None:
        t, k = self.running, self.cur_k
        if t is None or k is None:
            return
        self.running = None
        self.done_tests.append(t.fullname)
        if k == 0 or (outcome != "failed" and not self.cost[t.fullname]):
            self.cost[t.fullname] = time.monotonic() - self.t0
            self.sim_ns[t.fullname] = get_sim_time("ns") - self.sim0
        if k == 0 and LAZY:  # one killing test on the unmutated design
            r0 = self.results[0]
            self.verify_q.pop(0)
            self.cur_k = None
            r0["seconds"] = round(r0["seconds"] + time.monotonic() - self.t0, 2)
            r0["tests"] += 1
            if outcome == "failed":
                r0["result"] = "failed"
                self.broken = f"the unmutated design (mutant 0) fails {t.fullname}"
            self.verified.add(t.fullname)
            self.write()
            return
        self.results[k]["tests"] = len(self.done_tests)
        if outcome == "failed":
            self.done_tests.pop()
            timeout = type(exc).__name__ == "SimTimeoutError" if exc is not None else False
            self.finish(k, "timeout" if timeout else "killed", t.fullname)
        elif (k and CAP_S and time.monotonic() - self.k_t0 > CAP_S
              and len(self.done_tests) < len(self.tests)):
            self.finish(k, "capped", "")
        else:
            self.write()

    def write(self) -> None:
        if not RESULTS:
            return
        data = {"module": MODULE, "current": self.cur_k, "current_since_wall": self.k_wall,
                "broken": self.broken, "results": {str(k): v for k, v in self.results.items()},
                "tests": [t.fullname for t in self.tests],
                "baseline_cost": self.cost, "kills": self.kills}
        tmp = RESULTS + ".tmp"
        with open(tmp, "w") as f:
            json.dump(data, f)
        os.replace(tmp, RESULTS)


def _hook(loop: Loop) -> None:
    """Read each test's verdict where cocotb records it."""
    mgr = cocotb.regression._manager_inst

    def wrap(name: str, outcome: str):
        orig = getattr(mgr, name)

        def rec(*args, **kwargs):
            if outcome == "skipped":
                loop.running = None  # an idle slot
            elif outcome == "failed":
                exc = kwargs.get("result", args[3] if len(args) > 3 else None)
                loop.verdict("failed", exc if isinstance(exc, BaseException) else None)
            else:
                loop.verdict(outcome)
            return orig(*args, **kwargs)

        setattr(mgr, name, rec)

    wrap("_record_test_passed", "passed")
    wrap("_record_test_xfail", "passed")  # expect_fail / expect_error met: a pass
    wrap("_record_test_failed", "failed")
    wrap("_record_test_init_failed", "failed")
    wrap("_record_test_skipped", "skipped")


def _register() -> None:
    tests = selected()
    loop = Loop(tests)
    _hook(loop)
    ctl = cocotb.tops.get("mut_ctl") if hasattr(cocotb, "tops") else None

    async def idle():
        pytest.skip("mut_loop: nothing left to run")

    def make_slot(i: int) -> Test:
        slot = Test(func=None, args=(), kwargs={}, name=f"slot{i:04d}", module=__name__, doc=None,
                    timeout=None, expect_fail=False, expect_error=(), skip=False, stage=0)

        def func(dut, *args, **kwargs):
            """Called by cocotb just before it starts the slot: pick the (mutant, test)."""
            nxt = loop.next()
            if nxt is None:
                slot.module, slot.name, slot.timeout = __name__, f"slot{i:04d}", None
                slot.expect_fail, slot.expect_error = False, ()
                return idle()
            k, t = nxt
            slot.module, slot.name = t.module, t.name  # cocotb seeds from these, as in make test
            slot.expect_fail, slot.expect_error = t.expect_fail, t.expect_error
            slot.timeout = loop.timeout_of(t)
            loop.running = t
            loop.t0 = time.monotonic()
            loop.sim0 = get_sim_time("ns")
            loop.write()

            async def run():
                # (here, not above: cocotb may call the function in the ReadOnly phase of the
                # previous test's end, where no value can be written)
                if ctl is None:
                    raise RuntimeError("mut_loop: no root module mut_ctl (harness.run adds it in "
                                       "mutation mode)")
                ctl.sel.value = Immediate(k)
                # the mutant is really selected (a flow that cannot select one cannot fail)
                assert int(ctl.sel.value) == k, f"mut_ctl.sel is {ctl.sel.value}, not {k}"
                await t.func(dut, *t.args, **t.kwargs)

            return run()

        slot.func = func
        return slot

    n_slots = len(tests) * len(loop.queue)
    for i in range(n_slots):
        globals()[f"_slot{i:04d}"] = make_slot(i)


if MODULE:
    _register()
