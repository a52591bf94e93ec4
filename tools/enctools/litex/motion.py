# SPDX-License-Identifier: Apache-2.0
"""A deterministic motion per encoder channel, in Migen for the simulated SoC and in numpy for the
test that checks what the firmware printed.

Each channel is a fixed-point integrator clocked by sys: ``acc`` (count steps per clock², VFRAC
fraction bits) is a piecewise-constant function of the clock number ``t`` (0 at the first clock
after reset), and in every clock ``vel += acc`` and ``pos += vel >> (VFRAC - FRAC)`` (the step
of the clock, FRAC fraction bits, rounded down). The shaft position in count steps is
``x = pos >> FRAC`` (floor); the encoder outputs are the quadrature state of ``x``
(forward = A leads B: x mod 4 = 0, 1, 2, 3 gives (A, B) = 00, 10, 11, 01) and an index ``z`` that
is high while ``x mod CPR == 0`` (one state per CPR steps). A one-clock ``acc`` of v gives a
velocity step to v. The Python model does the same integer arithmetic, so the position and the
speed at any clock are known exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

FRAC = 32          # fraction bits of pos and of its step per clock
VFRAC = 48         # fraction bits of vel and acc
POS_W = 64         # pos register bits (signed): 32 integer bits
VEL_W = 64
CPR_LOG2 = 10      # index every 1024 count steps (256 cycles of x4)


@dataclass
class Motion:
    """One channel: ``x0`` the position at reset (count steps), ``steps`` the (clock, acc) pairs
    (acc in 2^-VFRAC count steps per clock², in force from that clock on; 0 before the first)."""

    name: str
    x0: int = 0
    steps: list = field(default_factory=list)

    def acc_at(self, n: int) -> np.ndarray:
        """acc in each clock 0 .. n-1."""
        acc = np.zeros(n, dtype=np.int64)
        for clock, value in self.steps:
            if clock < n:
                acc[clock:] = value
        return acc

    def trace(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(pos, step) in clocks 0 .. n-1, FRAC fraction bits: vel[t+1] = vel[t] + acc[t],
        step[t] = vel[t] >> (VFRAC - FRAC), pos[t+1] = pos[t] + step[t]. The step is the speed in
        count steps per clock."""
        acc = self.acc_at(n)
        vel = np.zeros(n, dtype=np.int64)
        vel[1:] = np.cumsum(acc[:-1])
        step = vel >> (VFRAC - FRAC)
        pos = np.empty(n, dtype=np.int64)
        pos[0] = self.x0 << FRAC
        pos[1:] = pos[0] + np.cumsum(step[:-1])
        return pos, step


def profiles(f_clk: float, t0_ms: float = 4.0) -> list[Motion]:
    """The four motions of the simulated SoC: ramps, constant speeds, a reversal, index pulses.
    Speeds in count steps per second, times in ms from reset; still until ``t0_ms`` (the firmware
    sets up meanwhile). Every channel starts on state 00 (x0 a multiple of 4) off its index, so
    the peripheral's reset state is the encoder's. The steady channel's 3,137,618.034 count/s (a
    step every 15.9 clocks; 3137.618 steps per 1 kHz period, a golden-ratio fraction, so the
    snapshots fall at evenly spread phases of the steps) pins the delay from the pins to the
    count to one clock."""

    def clk(ms):
        return int(round(ms * 1e-3 * f_clk))

    def v(counts_per_s):          # a velocity as fixed point counts per clock
        return int(round(counts_per_s / f_clk * (1 << VFRAC)))

    def a(counts_per_s, ms):      # the acc that changes the speed by counts_per_s in ms
        return int(round(v(counts_per_s) / clk(ms)))

    t0 = t0_ms
    ramp = Motion("ramp", x0=8, steps=[
        (clk(t0), a(60_000, 20)), (clk(t0 + 20), 0),                      # 0 -> 60k counts/s
        (clk(t0 + 40), a(-60_000, 20)), (clk(t0 + 60), 0)])                # 60k -> 0, then still
    steady = Motion("steady", x0=100, steps=[
        (clk(t0), v(3_137_618.034)), (clk(t0) + 1, 0)])                    # a step to 3.1M
    reverse = Motion("reversal", x0=-300, steps=[
        (clk(t0), v(30_000)), (clk(t0) + 1, 0),                            # a step to 30k
        (clk(t0 + 20), a(-60_000, 30)), (clk(t0 + 50), 0)])                # through 0 to -30k
    slow = Motion("slow", x0=4, steps=[
        (clk(t0), v(1_500)), (clk(t0) + 1, 0),                             # A rises every 2.7 ms
        (clk(t0 + 50), a(-101_500, 10)), (clk(t0 + 60), 0)])               # ramp to -100k
    return [ramp, steady, reverse, slow]


def quadrature(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, Z) of positions x."""
    q = x & 3
    return ((q == 1) | (q == 2)).astype(np.int8), (q >= 2).astype(np.int8), \
        ((x & ((1 << CPR_LOG2) - 1)) == 0).astype(np.int8)


class MotionGen:
    """The Migen side: ``MotionGen(motions).module()`` builds a module with ``a``, ``b``, ``z``
    outputs (one bit per channel) driven by the motions."""

    def __init__(self, motions: list[Motion]):
        self.motions = motions

    def module(self):
        from migen import Cat, If, Module, Signal

        motions = self.motions
        m = Module()
        n = len(motions)
        m.a, m.b, m.z = Signal(n), Signal(n), Signal(n)
        t = Signal(32)
        m.sync += If(t != (1 << 32) - 1, t.eq(t + 1))
        for k, mo in enumerate(motions):
            acc = Signal((VEL_W, True))
            vel = Signal((VEL_W, True))
            step = Signal((VEL_W - (VFRAC - FRAC), True))
            pos = Signal((POS_W, True), reset=mo.x0 << FRAC)
            # acc as a function of t: the last step whose clock has come
            expr = acc.eq(0)
            for clock, value in mo.steps:
                expr = If(t >= clock, acc.eq(value)).Else(expr)
            m.comb += expr
            m.comb += step.eq(vel[VFRAC - FRAC:])   # the top bits, as a signed number
            m.sync += [vel.eq(vel + acc), pos.eq(pos + step)]
            x = pos[FRAC:]
            m.comb += [
                m.a[k].eq(x[0] ^ x[1]),
                m.b[k].eq(x[1]),
                m.z[k].eq(x[:CPR_LOG2] == 0),
            ]
        return m
