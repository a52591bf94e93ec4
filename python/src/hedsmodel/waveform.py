# SPDX-License-Identifier: Apache-2.0
"""Quadrature waveforms as event lists, and generators of them (no cocotb here).

A waveform is a list of events ``(t_ns, a, b)``: from time ``t_ns`` (float, nanoseconds, relative to
the start of playback) the channels are at levels ``a`` and ``b``. The first event is the initial
state at ``t_ns = 0``. Times are real numbers, not clock multiples, so edges land at every phase of
the sampling clock; :func:`play` rounds them to the simulator's 1 ps precision.

Forward rotation (A leads B by 90 degrees): 00 -> 10 -> 11 -> 01 -> 00, as in the module contracts.
A 4X position ``p`` maps to the state ``QUAD[p % 4]``.

The HEDS-5000 model (:mod:`hedsmodel.unit`) produces waveforms in this same format; the cocotb
driver :class:`cocotbext.quadrature.QuadratureDriver` plays them onto a DUT.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field


QUAD = ((0, 0), (1, 0), (1, 1), (0, 1))  # forward sequence of (A, B)
STATE_TO_POS = {ab: p for p, ab in enumerate(QUAD)}


def state_of(pos: int) -> tuple[int, int]:
    return QUAD[pos % 4]


@dataclass
class Waveform:
    """Events plus the 4X position after each one (``None`` where a glitch or an illegal jump
    makes the position meaningless until the next clean state)."""

    events: list = field(default_factory=list)  # [(t_ns, a, b)]
    positions: list = field(default_factory=list)  # 4X position in force from each event

    @property
    def duration_ns(self) -> float:
        return self.events[-1][0] if self.events else 0.0

    @property
    def final_position(self) -> int:
        return self.positions[-1]

    def append(self, t_ns: float, pos: int | None, ab: tuple[int, int] | None = None) -> None:
        a, b = ab if ab is not None else state_of(pos)
        assert not self.events or t_ns >= self.events[-1][0], "events must be in time order"
        self.events.append((t_ns, a, b))
        self.positions.append(pos)

    def min_state_ns(self) -> float:
        """Shortest time between two consecutive events (the narrowest state driven)."""
        ts = [e[0] for e in self.events]
        return min(b - a for a, b in zip(ts, ts[1:])) if len(ts) > 1 else float("inf")


def walk(steps, durations_ns, start_pos: int = 0, t0_ns: float = 0.0) -> Waveform:
    """A waveform that starts at ``start_pos`` and takes ``steps[i]`` (+1 forward, -1 reverse, 0 stay)
    after the current state has lasted ``durations_ns[i]``."""
    wf = Waveform()
    pos, t = start_pos, t0_ns
    wf.append(t, pos)
    for step, dur in zip(steps, durations_ns):
        t += dur
        if step:
            pos += step
            wf.append(t, pos)
    return wf


def random_walk(rng: random.Random, n: int, s_min_ns: float, s_max_ns: float,
                p_reverse: float = 0.2, start_pos: int = 0) -> Waveform:
    """``n`` valid transitions, each state lasting uniform[s_min, s_max] ns, reversing direction
    with probability ``p_reverse`` at each transition."""
    direction = 1
    steps, durs = [], []
    for _ in range(n):
        if rng.random() < p_reverse:
            direction = -direction
        steps.append(direction)
        durs.append(rng.uniform(s_min_ns, s_max_ns))
    return walk(steps, durs, start_pos=start_pos)


def with_glitches(wf: Waveform, rng: random.Random, count: int, width_ns: float,
                  guard_ns: float) -> Waveform:
    """Insert ``count`` lone pulses of ``width_ns`` on one channel (random A or B) in the middle of
    states longer than ``width_ns + 2 * guard_ns``. The position is unchanged by a glitch."""
    ev, pos = wf.events, wf.positions
    candidates = [i for i in range(len(ev) - 1) if ev[i + 1][0] - ev[i][0] > width_ns + 2 * guard_ns]
    chosen = set(rng.sample(candidates, min(count, len(candidates))))
    out = Waveform()
    for i, (t, a, b) in enumerate(ev):
        out.append(t, pos[i], (a, b))
        if i in chosen:
            start = rng.uniform(t + guard_ns, ev[i + 1][0] - guard_ns - width_ns)
            if rng.random() < 0.5:
                out.append(start, pos[i], (1 - a, b))
            else:
                out.append(start, pos[i], (a, 1 - b))
            out.append(start + width_ns, pos[i], (a, b))
    return out
