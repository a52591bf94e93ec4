# SPDX-License-Identifier: Apache-2.0
"""cocotb-side helpers shared by every test: the test decorator, seeds, the usual test start.

- ``cocotb_test(**kw)``: use instead of ``cocotb.test(**kw)``. The test is a cocotb test as
  usual, and is also recorded (module, name, plain function, options), so that a tool can run a
  module's tests again by themselves, as mutation testing does, without cocotb's internals.
- ``start(dut, period_ps, ...)``: clock, seed logged, inputs driven, reset; returns the test's RNG.
- ``current_seed()``: the seed cocotb gives the running test (regression seed + its full name).
- ``until(t_ps)``: wait until an absolute simulation time (a bench playing a timed plan).

Encoder stimulus comes from the installed packages ``hedsmodel`` (waveforms, the HEDS-5000 model)
and ``cocotbext.quadrature`` (driver, monitor, clock).
"""

from __future__ import annotations

import hashlib
import importlib
import random
from dataclasses import dataclass, field

import cocotb
from cocotb.triggers import FallingEdge, Timer
from cocotb.utils import get_sim_time

from cocotbext.quadrature import reset, start_clock

# The regression seed: cocotb.RANDOM_SEED holds it while test modules are imported (during
# discovery); from a test's start on it holds that test's seed. (None outside a simulation, where
# pytest imports the test files to collect them.)
REGRESSION_SEED: int | None = getattr(cocotb, "RANDOM_SEED", None)


@dataclass
class TestDef:
    """A cocotb test as written: its plain function and the options given to cocotb.test."""

    func: object
    module: str
    name: str
    options: dict = field(default_factory=dict)

    @property
    def fullname(self) -> str:
        return f"{self.module}.{self.name}"

    @property
    def seed(self) -> int:
        """The seed cocotb gives this test in a regression (the same in any run of it)."""
        return REGRESSION_SEED + int(hashlib.sha1(self.fullname.encode()).hexdigest(), 16)


_registry: dict[str, list[TestDef]] = {}


def cocotb_test(**options):
    """``cocotb.test(**options)`` that also records the test (see the module docstring)."""
    def deco(func):
        name = options.get("name") or func.__name__
        _registry.setdefault(func.__module__, []).append(TestDef(func, func.__module__, name, options))
        return cocotb.test(**options)(func)
    return deco


def module_tests(module: str) -> list[TestDef]:
    """The tests a module declares with :func:`cocotb_test`, in file order (imports it)."""
    importlib.import_module(module)
    tests = _registry.get(module, [])
    if not tests:
        raise LookupError(f"{module}: no tests declared with enctools.tb.cocotb_test")
    return list(tests)


def current_seed() -> int:
    return cocotb.RANDOM_SEED


def log_seed(dut) -> int:
    """Log the seeds of the running cocotb test and return the per-test seed."""
    seed = current_seed()
    dut._log.info("test seed = %d, regression seed = %d (reproduce with: make test SEED=%d)",
                  seed, REGRESSION_SEED, REGRESSION_SEED)
    return seed


async def reset_dut(dut, clocks: int = 2) -> None:
    """Hold ``dut.rst`` for ``clocks`` rising edges of ``dut.clk``, release after a falling edge."""
    await reset(dut.rst, dut.clk, clocks)


async def until(t_ps: float) -> None:
    """Wait until simulation time ``t_ps`` (ps; at once when it has passed)."""
    now = get_sim_time("ps")
    if t_ps > now:
        await Timer(int(round(t_ps - now)), unit="ps")


async def start(dut, period_ps: int, inputs: dict | None = None, do_reset: bool = True,
                has_rst: bool = True) -> random.Random:
    """The usual start of a test: a clock on ``dut.clk`` with rising edges on multiples of
    ``period_ps``, the seed logged, ``inputs`` (name -> value) driven, then a reset
    (``do_reset``), or ``rst`` held high up to the next falling edge (without ``has_rst``, just that
    edge). Returns an RNG seeded with the test's seed."""
    await start_clock(dut.clk, period_ps)
    seed = log_seed(dut)
    for name, value in (inputs or {}).items():
        getattr(dut, name).value = value
    if has_rst and do_reset:
        await reset_dut(dut)
    else:
        if has_rst:
            dut.rst.value = 1
        await FallingEdge(dut.clk)
    return random.Random(seed)
