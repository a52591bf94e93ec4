# SPDX-License-Identifier: Apache-2.0
"""cocotb-side helpers shared by every test folder: seed logging and the usual test start
(aligned clock, seed, inputs, reset). Encoder stimulus itself comes from the installed packages
``hedsmodel`` (waveforms, the HEDS-5000 model) and ``cocotbext.quadrature`` (driver, clock)."""

from __future__ import annotations

import random

import cocotb
from cocotb.triggers import FallingEdge

from cocotbext.quadrature import reset, start_clock


def log_seed(dut) -> int:
    """Log the seeds of the running cocotb test and return the per-test seed. cocotb derives each
    test's seed from the regression seed (COCOTB_RANDOM_SEED, our SEED) and the test's name; the
    regression seed is the one to pass back to reproduce a run."""
    test_seed = cocotb.RANDOM_SEED
    try:  # cocotb 2.1 keeps the regression seed on its (private) manager
        regression_seed = cocotb.regression._manager_inst._regression_seed
    except AttributeError:
        regression_seed = None
    dut._log.info("test seed = %d, regression seed = %s (reproduce with: make test SEED=%s)",
                  test_seed, regression_seed, regression_seed)
    return test_seed


async def reset_dut(dut, clocks: int = 2) -> None:
    """Hold ``dut.rst`` for ``clocks`` rising edges of ``dut.clk``, release after a falling edge."""
    await reset(dut.rst, dut.clk, clocks)


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
