# SPDX-License-Identifier: Apache-2.0
"""QuadratureMonitor: a reference 4X decoder of A/B (and Z) signals, for checking a DUT."""

from __future__ import annotations

import cocotb
from cocotb.triggers import Edge, First, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time

from hedsmodel.waveform import STATE_TO_POS


class QuadratureMonitor:
    """Watches channels A and B and keeps the 4X position they describe.

    Without ``clk`` every change of A or B is seen (an ideal, asynchronous decoder); with ``clk``
    the channels are sampled on its rising edges, as a synchronous decoder would. A change of both
    channels between two observations is illegal: ``errors`` counts it and the position is kept.
    ``index_count`` counts rising edges of ``z`` when given. ``transitions`` holds
    (time_ps, position) after every valid transition.
    """

    def __init__(self, a, b, z=None, clk=None, position: int = 0):
        self.a, self.b, self.z, self.clk = a, b, z, clk
        self.position = position
        self.errors = 0
        self.index_count = 0
        self.transitions: list[tuple[int, int]] = []
        self._state = None
        self._task = cocotb.start_soon(self._run())
        self._z_task = cocotb.start_soon(self._run_z()) if z is not None else None

    def _sample(self) -> tuple[int, int]:
        return int(self.a.value), int(self.b.value)

    def _observe(self, state) -> None:
        if self._state is None or state == self._state:
            self._state = state
            return
        step = (STATE_TO_POS[state] - STATE_TO_POS[self._state]) % 4
        if step == 1:
            self.position += 1
        elif step == 3:
            self.position -= 1
        else:
            self.errors += 1
        if step in (1, 3):
            self.transitions.append((get_sim_time("ps"), self.position))
        self._state = state

    async def _run(self) -> None:
        await ReadOnly()
        self._state = self._sample()
        while True:
            if self.clk is not None:
                await RisingEdge(self.clk)
            else:
                await First(Edge(self.a), Edge(self.b))
            await ReadOnly()
            self._observe(self._sample())

    async def _run_z(self) -> None:
        while True:
            await RisingEdge(self.z)
            self.index_count += 1

    def stop(self) -> None:
        """Stop watching."""
        self._task.cancel()
        if self._z_task is not None:
            self._z_task.cancel()
