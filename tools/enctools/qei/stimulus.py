# SPDX-License-Identifier: Apache-2.0
"""Stimulus of the enc_qei tests: waveforms of random walks (hedsmodel), clock-exact steps and
index levels (FILTER_LEN 1: one level per clock), resets, and the value lists several feature
files use (wide bit patterns, CEILINGs, the burst of steps in consecutive clocks)."""

from __future__ import annotations

from cocotb.triggers import ClockCycles, FallingEdge
from hedsmodel import walk

from enctools.qei.bus import T_NS
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
    and bit 63."""
    c = ([0] if zero else []) + [0x25, 0x0800_0040, 0x8000_8021]
    if count_w > 32:
        c += [0x8000_0800_0000_0021]
    return c


def near(values, lo, hi):
    return sorted({v for v in values if lo <= v <= hi})
