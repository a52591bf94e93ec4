# SPDX-License-Identifier: Apache-2.0
"""Clock and reset helpers that keep the driver's edges off the clock grid."""

from __future__ import annotations

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time


async def start_clock(clk, period_ps: int) -> None:
    """Start a cocotb Clock on ``clk`` whose rising edges fall on multiples of ``period_ps`` in
    absolute simulation time (each cocotb test starts its own clock, at whatever time the previous
    test ended), which is what :class:`QuadratureDriver`'s ``clock_period_ps`` assumes."""
    if not isinstance(period_ps, int) or period_ps < 2:
        raise ValueError(f"start_clock: period_ps must be an integer >= 2, not {period_ps!r}")
    now = get_sim_time("ps")
    if now % period_ps:
        await Timer(period_ps - now % period_ps, unit="ps")
    # cocotb wants the high time given for an odd period (12 MHz = 83333 ps)
    cocotb.start_soon(Clock(clk, period_ps, unit="ps", period_high=period_ps // 2).start())


async def reset(rst, clk, clocks: int = 2, active_high: bool = True) -> None:
    """Hold ``rst`` active for ``clocks`` rising edges of ``clk``, then release it after a falling
    edge. (The first edge may not be one: a previous test's clock can have stopped high.)"""
    if clocks < 1:
        raise ValueError(f"reset: clocks must be >= 1, not {clocks}")
    rst.value = 1 if active_high else 0
    for _ in range(clocks):
        await RisingEdge(clk)
    await FallingEdge(clk)
    rst.value = 0 if active_high else 1
