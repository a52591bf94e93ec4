# SPDX-License-Identifier: Apache-2.0
"""QuadratureDriver: play a :class:`hedsmodel.Waveform` (and an index channel) onto DUT inputs."""

from __future__ import annotations

import cocotb
from cocotb.triggers import Timer
from cocotb.utils import get_sim_time


async def _play_events(signals, events, clock_period_ps: int | None) -> None:
    """Drive ``events`` [(t_ns, level, level, ...)] onto ``signals``, from now. An event that would
    land on the very picosecond of a clock edge (rising edges on multiples of
    ``clock_period_ps``) is moved 1 ps later, so which sample sees it is never a simulator race."""
    start_ps = get_sim_time("ps")
    now_ps = 0
    for t_ns, *levels in events:
        t_ps = int(round(t_ns * 1000.0))
        if clock_period_ps and (start_ps + t_ps) % clock_period_ps == 0:
            t_ps += 1
        if t_ps > now_ps:
            await Timer(t_ps - now_ps, unit="ps")
            now_ps = t_ps
        for sig, level in zip(signals, levels):
            sig.value = level


async def play(dut, wf, a_name: str = "a_in", b_name: str = "b_in",
               clock_period_ps: int | None = None) -> None:
    """Drive waveform ``wf`` onto ``dut.<a_name>``/``dut.<b_name>``, starting now; returns after
    the last event. Shorthand for ``QuadratureDriver(...).play(wf)``."""
    await _play_events((getattr(dut, a_name), getattr(dut, b_name)), wf.events, clock_period_ps)


class QuadratureDriver:
    """Drives encoder channels A, B (and optionally Z) of a DUT.

    ``clock_period_ps``: the period of a clock whose rising edges fall on its multiples (as
    :func:`start_clock` makes); events are then kept 1 ps clear of its edges. Times in the
    waveform are real numbers (ns), so edges land at every phase of the sampling clock.
    """

    def __init__(self, a, b, z=None, clock_period_ps: int | None = None):
        self.a, self.b, self.z = a, b, z
        self.clock_period_ps = clock_period_ps

    async def play(self, wf, index=None) -> None:
        """Play ``wf`` (a :class:`hedsmodel.Waveform`) and, if given, ``index`` [(t_ns, level)] on
        Z, both from now; returns when both have ended."""
        task = None
        if index is not None:
            if self.z is None:
                raise ValueError("QuadratureDriver: an index waveform needs the z signal")
            task = cocotb.start_soon(_play_events((self.z,), index, self.clock_period_ps))
        await _play_events((self.a, self.b), wf.events, self.clock_period_ps)
        if task is not None:
            await task

    def start(self, wf, index=None):
        """Start :meth:`play` in the background; returns the cocotb Task."""
        return cocotb.start_soon(self.play(wf, index=index))

    def set_state(self, a: int, b: int, z: int | None = None) -> None:
        """Put the channels at a level now (e.g. the initial state before a test)."""
        self.a.value, self.b.value = a, b
        if z is not None and self.z is not None:
            self.z.value = z
