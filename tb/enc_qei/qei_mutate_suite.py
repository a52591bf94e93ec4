# SPDX-License-Identifier: Apache-2.0
"""cocotb test module for `make mutate` (scripts/mutate.py): the enc_qei cocotb tests, a chosen
subset in a chosen order, stopping at the first failure.

The tests are the regression's own cocotb tests (the same Test objects, imported from their
modules: same code, same names, so the same per-test seeds as in `make test`); nothing here adds a
check. Two things differ from a normal run, both for speed only:

- ENC_QEI_MUT_TESTS = "module.test,module.test,...": run these, in this order (cheapest and most
  killing first). Unset or empty: every test of DEFAULT_MODULES in file order.
- fail-fast: once a test has failed, the remaining ones are skipped (pytest.skip, so cocotb
  records them as skipped and the run still fails). A mutant is killed by its first failing test.
  (A test marked expect_fail that fails as expected passes, and does not stop the run.)
- a simulated-time limit per test (TIMEOUT_US, 1.4 x the longest test's time): a mutant that
  never answers a bus cycle fails in seconds instead of running into scripts/mutate.py's
  wall-clock timeout.

Used only through tb/enc_qei/mutate_enc_qei.py (not collected by `make test`). In the mutation
mode of scripts/mutate.py (many mutants in one simulation, tb/common/mut_loop.py) this module only
gives the list (mut_loop_tests); mut_loop runs it per mutant.
"""

from __future__ import annotations

import copy
import functools
import importlib
import os

import pytest
from cocotb._decorators import Test, TestGenerator

DEFAULT_MODULES = ("test_enc_qei", "test_enc_qei_gaps")
TIMEOUT_US = 1000  # simulated time per test; the longest (period_capture at TS_W 16) needs ~700 us

_failed: list[str] = []


def _fail_fast(t: Test) -> Test:
    orig = t.func

    @functools.wraps(orig)
    async def func(dut, *args, **kwargs):
        if _failed:
            pytest.skip(f"fail-fast: {_failed[0]} failed")
        try:
            await orig(dut, *args, **kwargs)
        except BaseException as e:  # an assertion, a timeout, or a cancel by a failing task
            if not isinstance(e, pytest.skip.Exception) and not t.expect_fail:
                _failed.append(t.fullname)
            raise

    w = copy.copy(t)
    w.func = func
    if w.timeout is None:  # a mutant that stops the bus must not hang the run (longest test: 0.7 ms)
        w.timeout = (TIMEOUT_US, "us")
    return w


def _module_tests(name: str) -> dict[str, Test]:
    mod = importlib.import_module(name)
    tests: dict[str, Test] = {}
    for obj in vars(mod).values():  # as cocotb's discovery: a Test, or a TestGenerator's Tests
        for t in ([obj] if isinstance(obj, Test) else
                  obj.generate_tests() if isinstance(obj, TestGenerator) else []):
            tests[t.name] = t
    return tests


def _selected() -> list[Test]:
    spec = [s.strip() for s in os.environ.get("ENC_QEI_MUT_TESTS", "").split(",") if s.strip()]
    if not spec:
        return [t for m in DEFAULT_MODULES for t in _module_tests(m).values()]
    out, cache = [], {}
    for s in spec:
        mod, _, name = s.rpartition(".")
        if mod not in cache:
            cache[mod] = _module_tests(mod)
        if name not in cache[mod]:
            raise RuntimeError(f"ENC_QEI_MUT_TESTS: no cocotb test {name!r} in {mod}")
        out.append(cache[mod][name])
    return out


def mut_loop_tests() -> list[Test]:
    """The selected tests for tb/common/mut_loop.py (many mutants in one simulation: it does the
    fail-fast itself), each with the TIMEOUT_US limit unless it has its own."""
    out = []
    for t in _selected():
        w = copy.copy(t)
        if w.timeout is None:
            w.timeout = (TIMEOUT_US, "us")
        out.append(w)
    return out


def _register() -> None:
    """cocotb discovers the Test objects of this module's namespace, in insertion order (no loop
    variable may stay behind at module level: it would be discovered too)."""
    for i, t in enumerate(_selected()):
        globals()[f"_t{i:02d}_{t.name}"] = _fail_fast(t)


if not os.environ.get("MUT_LOOP_MODULE"):  # mut_loop imports this module for mut_loop_tests()
    _register()
