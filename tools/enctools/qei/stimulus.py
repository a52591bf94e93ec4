# SPDX-License-Identifier: Apache-2.0
"""Stimulus of the enc_qei tests: waveforms of random walks (hedsmodel), clock-exact steps and
index levels (FILTER_LEN 1: one level per clock), resets, and the value lists several feature
files use (wide bit patterns, CEILINGs, the burst of steps in consecutive clocks)."""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import cocotb
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer
from hedsmodel import walk

from enctools.qei.bus import PERIOD_PS, T_NS
from enctools.qei.model import QUAD

FILTER = 2  # FILTER_LEN for the walks; states last >= 1.05 FILTER clocks


# ---- waveforms --------------------------------------------------------------------------------------
def durations(rng, n, f=FILTER):
    return [rng.uniform(1.05 * f * T_NS + 0.1, 3 * f * T_NS) for _ in range(n)]


def walk_with_jumps(rng, n, start_pos, jumps, f=FILTER):
    steps, direction = [], 1
    jump_at = set(rng.sample(range(5, n), jumps))
    for i in range(n):
        if rng.random() < 0.2:
            direction = -direction
        steps.append(2 * direction if i in jump_at else direction)
    return walk(steps, durations(rng, n, f), start_pos=start_pos)


# ---- clock-exact stimulus ----------------------------------------------------------------------------
async def play_clocks(env, model, clocks) -> None:
    """Drive (A, B) and Z clock by clock: ``clocks`` lists (4X position, Z level) per clock, set at
    the falling edge before that clock's rising edge, so that with FILTER_LEN 1 (a level of one
    clock is kept) each change is sampled in exactly that clock: steps in consecutive clocks, an
    index edge in the clock of a step or right before one. Every change of (A, B) or Z is one
    sample of the model (QeiModel.sample), in order. ``env`` is the test environment (its ``pos``
    is kept; ``z`` is the Z level now)."""
    dut = env.dut
    prev = (env.pos % 4, getattr(env, "z", 0))
    for pos, z in clocks:
        await FallingEdge(dut.clk)
        dut.a_in.value, dut.b_in.value = QUAD[pos % 4]
        dut.z_in.value = z
        if (pos % 4, z) != prev and model is not None:
            model.sample(QUAD[pos % 4], z)
        prev = (pos % 4, z)
        env.pos, env.z = pos, z


def step_clocks(pos: int, steps, z=None) -> list:
    """(position, Z) per clock for ``steps`` (+1, -1 or 0 per clock) from 4X position ``pos``;
    ``z``: the Z level per clock (default 0)."""
    out = []
    for i, s in enumerate(steps):
        pos += s
        out.append((pos, z[i] if z is not None else 0))
    return out


async def steps_from(env, model, start, steps):
    """Write COUNT = start (the model too), then play ``steps`` clock by clock (+1, -1 or 0 per
    clock) and let the pipeline settle: the setup of every consecutive-clock step check."""
    await env.bus.set_count(start)
    model.write_count(start)
    await env.settle(4)
    await play_clocks(env, model, step_clocks(env.pos, steps))
    await env.settle(4)


async def illegal_jumps(env, n: int) -> None:
    """n illegal jumps (both channels in one sample: n quadrature errors), 6 clocks apart."""
    await env.play(walk([2] * n, [6 * T_NS] * n, start_pos=env.pos), None)


async def rejected_pulses(env, n: int) -> None:
    """n lone pulses of 1.5 clocks on A (one or two samples), 8 clocks apart: each rejected by a
    FILTER_LEN of 3 or more (one GLITCH each), the position unchanged."""
    dut = env.dut
    for _ in range(n):
        a = QUAD[env.pos % 4][0]
        dut.a_in.value = 1 - a
        await Timer(int(1.5 * PERIOD_PS) + 3, unit="ps")
        dut.a_in.value = a
        await Timer(8 * PERIOD_PS, unit="ps")
    await env.settle()


async def aimed_races(dut, ref, other, prepare, stimulus, access, judge, lead: int,
                      tries: int = 80) -> list[int]:
    """Races between a bus access and a stimulus, timed by their effects inside the design (white
    box): ``ref()`` and ``other()`` tell whether the access's and the stimulus's pulse is high,
    sampled after every rising edge, and d is the clock of other's first pulse less ref's. Each
    trial: ``prepare()``, then the access 20 clocks on and the stimulus ``lead`` clocks after the
    access's start; ``judge(d, answer)`` asserts on the access's answer. Each trial aims d at the
    next of -3 .. 3 from what the last one measured (a bus with random back-pressure moves the
    access), until d has been -1, 0 and 1 (at most ``tries`` trials). Returns the d met."""
    got = set()
    aims = (-3, -2, -1, 0, 1, 2, 3)
    for n in range(tries):
        await prepare()
        at = {}

        async def watch():
            for k in range(80):
                await RisingEdge(dut.clk)
                await ReadOnly()
                for name, high in (("ref", ref), ("other", other)):
                    if name not in at and high():
                        at[name] = k

        async def delayed():
            await ClockCycles(dut.clk, lead + 20)
            await stimulus()

        w, s = cocotb.start_soon(watch()), cocotb.start_soon(delayed())
        await ClockCycles(dut.clk, 20)
        answer = await access()
        await s
        await w
        d = at["other"] - at["ref"]
        got.add(d)
        await judge(d, answer)
        if n >= len(aims) and {-1, 0, 1} <= got:
            break
        lead = max(-20, min(20, lead + aims[(n + 1) % len(aims)] - d))
    assert {-1, 0, 1} <= got, f"the races came {sorted(got)} clocks apart, not -1, 0 and 1"
    return sorted(got)


async def pulse_rst(dut, clocks=1):
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    await ClockCycles(dut.clk, clocks)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


# ---- values -------------------------------------------------------------------------------------------
# counts, CEILINGs and latches with every bit pattern (the high word too)
WIDE = (0x5A5A_A5A5_C3C3_3C3C, 0xA5A5_5A5A_3C3C_C3C3, 0x8000_0001_8000_0001, 0x7FFE_FFFF_0FF0_F00F)

# Steps in consecutive clocks, at loads and wraps: the count keeps at-CEILING and at-zero flags in
# registers, computed from the next count's candidates (Fmax): a step in the clock right after
# another step, a wrap or a load uses a flag that was computed in the clock before, not recomputed
# from a quiet count. The tests that use these put steps in consecutive clocks (FILTER_LEN 1, one
# level per clock, play_clocks) right at those points.
# per clock: +1, -1 or 0 (no step); pairs in consecutive clocks, each way, with quiet clocks between
BURST = (-1, +1, 0, 0, +1, +1, 0, 0, -1, -1, 0, 0, +1, -1, 0, 0, -1, +1, +1, 0, 0, +1, -1, -1, 0)


def slice_compare_cases(count_w: int) -> list:
    """(CEILING, values) pairs for the count's slice-by-slice compare with CEILING (16-bit slices,
    a >= b from each slice's > and >=): for every bit of every slice above the lowest, with the
    slice's bit 0 set or not, a CEILING of that bit (lower slices 5, so CEILING - 1 keeps the
    slice), and values below it in that slice, one below it in the lower slices, equal, and above
    it; only those that fit COUNT_W bits."""
    out = []
    for k in range(1, (count_w + 15) // 16):
        for bit in range(16):
            for low in (0x0001, 0x0000):
                ceiling = (1 << bit | low) << 16 * k | 5
                if ceiling >> count_w:
                    continue
                values = (((1 << bit) - 1 | low) << 16 * k | 5, ceiling - 1, ceiling,
                          ((1 << bit) + 1 | low) << 16 * k)
                out.append((ceiling, [v for v in values if not v >> count_w]))
    return out


def ceilings(count_w, zero=True):
    """CEILINGs of 0, small ones, a high half that equals the count's with bit 27 set, bit 31
    and bit 63, each cut to COUNT_W bits (a narrow build: 0x40 and 0x8021 at COUNT_W 16)."""
    c = ([0] if zero else []) + [0x25, 0x0800_0040, 0x8000_8021]
    if count_w > 32:
        c += [0x8000_0800_0000_0021]
    return list(dict.fromkeys(v & ((1 << count_w) - 1) for v in c))


def near(values, lo, hi):
    return sorted({v for v in values if lo <= v <= hi})


# ---- clock-exact walks on every channel, with what a snapshot of any clock holds ------------------------
@dataclass
class Mark:
    """A channel's state after one sampled change: ``t`` the timebase (unwrapped, TB_PRESCALE 0)
    at the falling edge that set the pins, the model's count and motion (QeiModel.delta, every
    step while EN) after it, whether it was a step (any edge) and an A-rising edge."""

    t: int
    count: int
    motion: int
    step: bool
    a_rise: bool


class Timeline:
    """One channel's marks, and the snapshot registers of any clock. SNAP_PIPE: a change whose pins
    were set at timebase t is in a snapshot whose SNAP_TIME is t + SNAP_PIPE or later (FILTER_LEN
    1); EDGE_PIPE: an edge's SNAP_EDGE_TIME is t + EDGE_PIPE. The same on every build (the shared
    engine shows a snapshot later, never other values)."""

    SNAP_PIPE = 6
    EDGE_PIPE = 6

    def __init__(self, count: int):
        self.marks = [Mark(-(1 << 62), count, 0, False, False)]
        self.times = [self.marks[0].t]

    def add(self, mark: Mark) -> None:
        self.marks.append(mark)
        self.times.append(mark.t)

    def _last(self, t: int) -> int:
        return bisect.bisect_right(self.times, t - self.SNAP_PIPE) - 1

    def at(self, t: int) -> Mark:
        """The last mark a snapshot at (unwrapped) timebase t holds."""
        return self.marks[self._last(t)]

    def edge(self, t: int, a_rising: bool, switch: int | None = None, old_a: bool = False,
             floor: int | None = None) -> Mark | None:
        """The last selected edge (SNAP_CTRL.EDGE: A rising edges if ``a_rising``, else every step)
        a snapshot at timebase t holds. With ``switch`` (an EDGE change), the edges stamped
        (SNAP_EDGE_TIME) before it were chosen by ``old_a`` instead. None when there is none, or
        when it would be stamped before ``floor``."""
        for i in range(self._last(t), 0, -1):
            m = self.marks[i]
            e = m.t + self.EDGE_PIPE
            if floor is not None and e < floor:
                return None
            if m.a_rise if (a_rising if switch is None or e >= switch else old_a) else m.step:
                return m
        return None


class ClockWalk:
    """Random walks on channels 0 .. len(models) - 1 of a build at once, clock by clock (FILTER_LEN
    1: a level set at a falling edge is sampled at the next rising edge): each channel holds a
    state for a random number of clocks in [shortest, longest], steps back with probability
    ``p_reverse``, and its Z level is zfuns[k](position) (None: Z low). Every change is fed to the
    channel's model in order and marked on its Timeline with the timebase of its clock
    (TB_PRESCALE 0), so that a snapshot can be checked against the clock its SNAP_TIME names.
    Walk k drives bit bits[k] of the vectors a_in, b_in, z_in (default: bit k), starting from
    positions[k], which must be the state its A and B pins hold; run() may be called again to go
    on walking after a pause."""

    def __init__(self, dut, models, rng, positions=None, shortest=1, longest=4, p_reverse=0.2,
                 zfuns=None, bits=None):
        self.dut, self.models, self.rng = dut, models, rng
        n = len(models)
        self.bits = list(bits if bits is not None else range(n))
        self.pos = list(positions or [0] * n)
        z_pins = int(dut.z_in.value)
        self.z = [z_pins >> bit & 1 for bit in self.bits]
        self.shortest, self.longest, self.p_reverse = shortest, longest, p_reverse
        self.zfuns = zfuns or [None] * n
        self.dirs = [1] * n
        self.lines = [Timeline(m.count) for m in models]
        self.ts_mask = (1 << int(dut.TS_W.value)) - 1
        self.tb = dut.u_qei.timebase
        self.last_tb = int(self.tb.value)
        self.t = self.last_tb  # the timebase unwrapped

    def _overlay(self, a: int, b: int, z: int, k: int) -> tuple[int, int, int]:
        """The pin vectors a, b, z with walk k's bit set to its state (its position's A and B, its
        Z)."""
        bit, (sa, sb) = self.bits[k], QUAD[self.pos[k] % 4]
        keep = ~(1 << bit)
        return a & keep | sa << bit, b & keep | sb << bit, z & keep | self.z[k] << bit

    def now(self) -> int:
        """The timebase now, unwrapped (it must be read at least once per wrap of the timebase:
        run() reads it every clock)."""
        tb = int(self.tb.value)
        self.t += (tb - self.last_tb) & self.ts_mask
        self.last_tb = tb
        return self.t

    def unwrap(self, tb: int) -> int:
        """A timebase value read from a register (less than one wrap of the timebase ago)."""
        return self.now() - ((self.last_tb - tb) & self.ts_mask)

    async def run(self, clocks: int) -> None:
        dut, rng, n = self.dut, self.rng, len(self.models)
        hold = [rng.randint(self.shortest, self.longest) for _ in range(n)]
        a = int(dut.a_in.value)
        b = int(dut.b_in.value)
        z = int(dut.z_in.value)
        # the walked bits from the walk's own state: a run started in the timestep of the last
        # run's final write reads the pins before that write lands
        for k in range(n):
            a, b, z = self._overlay(a, b, z, k)
        for _ in range(clocks):
            await FallingEdge(dut.clk)
            self.now()
            for k in range(n):
                hold[k] -= 1
                if hold[k] > 0:
                    continue
                hold[k] = rng.randint(self.shortest, self.longest)
                if rng.random() < self.p_reverse:
                    self.dirs[k] = -self.dirs[k]
                old = QUAD[self.pos[k] % 4]
                self.pos[k] += self.dirs[k]
                new = QUAD[self.pos[k] % 4]
                zk = self.zfuns[k](self.pos[k]) if self.zfuns[k] else 0
                self.z[k] = zk
                a, b, z = self._overlay(a, b, z, k)
                model = self.models[k]
                model.sample(new, zk)
                self.lines[k].add(Mark(self.t, model.count, model.delta, True,
                                       (old[0], new[0]) == (0, 1)))
            dut.a_in.value, dut.b_in.value, dut.z_in.value = a, b, z
