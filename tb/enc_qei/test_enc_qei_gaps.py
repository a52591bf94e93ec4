# SPDX-License-Identifier: Apache-2.0
"""enc_qei: the checks `make mutate` (issue 14) showed test_enc_qei.py did not make.

Each cocotb test here closes a gap that Yosys mutants of the enc_qei modules passed through (the
mutants are named in doc/mutation.md). Deterministic stimulus (fixed values, chosen to set the bits
and reach the states the mutants change), the same bus models and helpers as test_enc_qei.py, the
same two configurations (enc_qei_wb COUNT_W 32 / TS_W 32, enc_qei_axil COUNT_W 64 / TS_W 16).
"""

from __future__ import annotations

import random

import cocotb
import pytest
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer

from enctools.tb import cocotb_test

from enctools.harness import run
from hedsmodel import QUAD, random_walk, walk, with_glitches
from enctools.qei.model import QeiModel
from enctools.regmap import event_bits, pack, regmap, size_mask
from enctools.qei.bus import (PERIOD_PS, T_NS, play_clocks,
                    step_clocks)
from test_enc_qei import begin, durations


def _field(reg, name, word):
    f = regmap()[reg].fields[name]
    return word >> f.lsb & ((1 << f.width) - 1)


# ---- timing unit -----------------------------------------------------------------------------------
@cocotb_test()
async def unit_timer_period(dut):
    """SNAP_PERIOD = P: the unit timer snaps every P ticks (0 and 1: every tick), at PRESCALE 0
    and 1: SNAP_TIME values read 2.5 periods apart differ by a multiple of P, and SNAP_TIME is never
    more than a period behind TIMEBASE. P values set each of the low 13 bits somewhere."""
    env, rng = await begin(dut)
    bus = env.bus
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    for pre, p in ((0, 0), (0, 1), (0, 2), (0, 3), (0, 0x5A), (0, 0x1A5), (1, 0xC3),
                   (0, 0x2C3), (0, 0x200), (0, 0x6F0), (0, 0x80F), (0, 0x1003)):
        step = max(p, 1)
        await bus.wr("TB_PRESCALE", pre)
        await bus.wr("SNAP_PERIOD", p)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1))
        times = []
        for wait in (step + 5, 2 * step + step // 2 + 7):
            await Timer(wait * (pre + 1) * PERIOD_PS, unit="ps")
            t = await bus.rd("SNAP_TIME")
            tb = await bus.rd("TIMEBASE")
            assert (tb - t) & ts_mask <= step + 40, \
                f"SNAP_PERIOD {p} PRESCALE {pre}: SNAP_TIME {t} a period behind TIMEBASE {tb}"
            times.append(t)
        d = (times[1] - times[0]) & ts_mask
        assert d % step == 0 and d >= 2 * step, \
            f"SNAP_PERIOD {p} PRESCALE {pre}: snapshots {d} ticks apart, not a multiple of {step}"
        await bus.wr("SNAP_CTRL", 0)
    await bus.wr("TB_PRESCALE", 0)


@cocotb_test()
async def period_large_n(dut):
    """PERIOD_CTRL.N up to 255: PERIOD = N x the edge interval (any edge, states of 3 clocks)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    for n in (17, 100, 255, 0xAA):
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=n))
        steps = 2 * n + 8
        await env.play(walk([1] * steps, [3 * T_NS] * steps, start_pos=env.pos), None)
        period = await bus.rd("PERIOD")
        assert period == 3 * n, f"N={n}: PERIOD {period}, expected {3 * n}"
        await bus.wr("PERIOD_CTRL", 0)


@cocotb_test()
async def snapshot_wide_values(dut):
    """SNAP_COUNT of counts with every bit pattern (the high half too): a snapshot holds them;
    SNAP_TIME and SNAP_EDGE_TIME of an edge taken 4,200 to 12,600 clocks after reset (timebase
    bits 12 and 13) lie between the TIMEBASE read before the edge and the one after the snapshot."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    for k, value in enumerate((0x5555_5555_5555_5555, 0xAAAA_AAAA_AAAA_AAAA,
                               0xFFFF_FFFF_FFFF_FFFF, 0x0123_4567_89AB_CDEF)):
        value &= model.max
        await env.setup(model, count=value, en=0)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
        await env.settle(4)
        for gap in (1, 2, 0):  # held while nothing else snaps (reads an odd and an even clock apart)
            got = await bus.rd("SNAP_COUNT_LO") | await bus.rd("SNAP_COUNT_HI") << 32
            assert got == value, f"SNAP_COUNT {got:#x}, count {value:#x}"
            if gap:
                await ClockCycles(dut.clk, gap)
        if k:
            await Timer(4200 * PERIOD_PS, unit="ps")
        before = await bus.rd("TIMEBASE")
        await env.play(walk([1], [3 * T_NS], start_pos=env.pos), None)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        t_snap, t_edge = await bus.rd("SNAP_TIME"), await bus.rd("SNAP_EDGE_TIME")
        after = await bus.rd("TIMEBASE")
        span = (after - before) & ts_mask
        assert (t_edge - before) & ts_mask <= (t_snap - before) & ts_mask <= span, \
            f"TIMEBASE {before:#x}, SNAP_EDGE_TIME {t_edge:#x}, SNAP_TIME {t_snap:#x}, TIMEBASE {after:#x}"


@cocotb_test()
async def stall_timeout_exact(dut):
    """The stall comes exactly STALL_TIMEOUT ticks after the last step: the clocks from a step to
    irq (IRQ_EN = STALL) differ between two timeouts by exactly their difference (PRESCALE 0), or
    by it x (PRESCALE + 1) within the prescaler's phase."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await bus.wr("IRQ_EN", event_bits("STALL"))
    clocks = {}
    for pre, t in ((0, 0x40), (0, 0x2F), (0, 0x1F0), (0, 0x2A5), (0, 0x35A), (0, 0x0CB), (0, 0x104),
                   (0, 0x20), (0, 0x200), (0, 0x1005), (0, 4), (0, 3), (0, 2), (0, 1), (2, 0x40), (2, 0x13),
                   (2, 0x6D)):
        await bus.wr("TB_PRESCALE", pre)
        await bus.wr("STALL_TIMEOUT", t)
        await Timer((t * (pre + 1) + 40) * PERIOD_PS, unit="ps")  # any stall of the wait is over
        await RisingEdge(dut.clk)
        await bus.events()
        await env.settle(3)
        assert dut.irq.value == 0
        await FallingEdge(dut.clk)
        env.pos += 1
        dut.a_in.value, dut.b_in.value = QUAD[env.pos % 4]
        n = 0
        while dut.irq.value == 0:
            await RisingEdge(dut.clk)
            n += 1
            assert n < t * (pre + 1) + 200, f"STALL_TIMEOUT {t} PRESCALE {pre}: no stall"
        clocks[(pre, t)] = n
        await bus.events()
    for (pre, t), n in clocks.items():
        n0 = clocks[(pre, 0x40)]
        d = n - n0 - (t - 0x40) * (pre + 1)
        assert abs(d) <= pre, f"STALL_TIMEOUT {t} PRESCALE {pre}: {n} clocks to the stall, {n0} at 0x40"
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test()
async def prescaler_long(dut):
    """TIMEBASE at PRESCALE values that set bits 0 .. 8, over 8 to 150 ticks (2,400 clocks or
    more): snap_in rising edges G clocks apart give SNAP_TIME values G / (PRESCALE + 1) apart
    (floor or ceiling)."""
    env, rng = await begin(dut)
    bus = env.bus
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=1))

    async def snap():
        await FallingEdge(dut.clk)
        dut.snap_in.value = 1
        at = round(get_sim_time("ns") / T_NS)
        await ClockCycles(dut.clk, 2)
        await FallingEdge(dut.clk)
        dut.snap_in.value = 0
        await env.settle(3)
        return at, await bus.rd("SNAP_TIME")

    for k, pre in enumerate((0x25, 0x2A, 0x3F, 0x30, 0x71, 0x1F0, 0x0F)):
        await bus.wr("TB_PRESCALE", pre)
        await env.settle(5)
        c0, t0 = await snap()
        ticks = max(8, 2400 // (pre + 1))
        await Timer((ticks * (pre + 1) + 7 * k) * PERIOD_PS, unit="ps")
        c1, t1 = await snap()
        gap, diff = c1 - c0, (t1 - t0) & ts_mask
        lo, hi = gap // (pre + 1), -(-gap // (pre + 1))
        assert lo <= diff <= hi, f"PRESCALE {pre}: {gap} clocks gave {diff} ticks, not {lo}..{hi}"
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test()
async def error_counters_wide(dut):
    """QERR_COUNT and GLITCH_COUNT past 1,024 (bits 10 and up): 1,100 illegal jumps and 1,100
    lone one-clock pulses are each counted."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    n = 1100
    await env.setup(model, func="x4", filter_len=1, count=0)
    await env.drv.play(walk([2] * n, [3 * T_NS] * n, start_pos=env.pos))
    env.pos += 2 * n
    await env.settle(10)
    assert await bus.rd("QERR_COUNT") == n, "QERR_COUNT after 1,100 illegal jumps"
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=2))
    await env.settle(10)
    await bus.wr("GLITCH_COUNT", 0)
    a = QUAD[env.pos % 4][0]
    for _ in range(n):
        await FallingEdge(dut.clk)
        dut.a_in.value = 1 - a
        await FallingEdge(dut.clk)
        dut.a_in.value = a
        await ClockCycles(dut.clk, 2)
    await env.settle(10)
    assert await bus.rd("GLITCH_COUNT") == n, "GLITCH_COUNT after 1,100 lone pulses"
    await bus.events()


# ---- conditioner (enc_conditioner_rt) -------------------------------------------------------------------
@cocotb_test()
async def filter_len_clamp(dut):
    """CTRL.FILTER_LEN 0 acts as 1 (states of 1.05 clocks count exactly), 31 as 16 (a level of
    14.7 clocks is rejected, states of 17.5 .. 70 clocks count exactly)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for f, lo, hi, pulses in ((0, 1.05, 2.0, 0), (31, 17.5, 70.0, 4)):
        await env.setup(model, func="x4", filter_len=f, count=0)
        wf = random_walk(rng, 40 if f else 300, lo * T_NS + 0.1, hi * T_NS, p_reverse=0.3,
                         start_pos=env.pos)
        n = len(wf.events)
        if pulses:
            wf = with_glitches(wf, rng, pulses, 14.7 * T_NS, guard_ns=17.05 * T_NS)
            pulses = (len(wf.events) - n) // 2
            assert pulses >= 2
        await env.drv.play(wf)
        last = QUAD[env.pos % 4]
        for (_, a, b), p in zip(wf.events[1:], wf.positions[1:]):
            st = QUAD[p % 4]
            if st != last:
                model.sample(st)
                last = st
        env.pos = wf.positions[-1]
        await env.settle(60)
        got = await bus.count()
        assert got == model.count, f"FILTER_LEN {f}: count {got}, model {model.count}"
        assert await bus.rd("GLITCH_COUNT") == pulses, f"FILTER_LEN {f}: GLITCH_COUNT"
        ev = await bus.events()
        assert "QERR" not in ev, f"FILTER_LEN {f}: QERR"
        model.take_events()


async def pulse_rst(dut, clocks=1):
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    await ClockCycles(dut.clk, clocks)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


@cocotb_test()
async def reset_in_each_state(dut):
    """rst with the shaft standing in each of the four states (inputs held through the reset):
    the peripheral takes that state as its reference: count 0, no QERR, no GLITCH; then it counts
    exactly from there. (Written as the reproducer of a bug make mutate led to: `valid` rose one
    clock before the conditioner showed the inputs; fixed in enc_conditioner_rt, d197bf9.)"""
    env, rng = await begin(dut)
    bus = env.bus
    for pos in (2, 1, 3, 0, 2):
        a, b = QUAD[pos % 4]
        dut.a_in.value, dut.b_in.value = a, b
        await ClockCycles(dut.clk, 40)
        await pulse_rst(dut, 2)
        env.pos = pos
        await env.settle(40)
        assert await bus.count() == 0, f"state {a}{b} through rst: count moved"
        ev = await bus.events()
        assert not ev & {"QERR", "GLITCH"}, f"state {a}{b} through rst: {ev}"
        model = QeiModel(env.count_w)
        model.reference(QUAD[env.pos % 4])
        wf = walk([1, 1, -1, 1, 1, 1], durations(rng, 6, 3), start_pos=env.pos)
        await env.play(wf, model)
        assert await bus.count() == model.count, f"state {a}{b}: count after rst"


@cocotb_test()
async def reset_on_rejection_clock(dut):
    """A one-clock rst at every clock around the rejection of a lone 2-clock pulse (FILTER_LEN 3,
    the reset value): the reset clears the pending rejection, no GLITCH afterwards."""
    env, rng = await begin(dut)
    bus = env.bus
    for k in range(0, 9):
        await FallingEdge(dut.clk)
        dut.a_in.value = 1 - QUAD[env.pos % 4][0]
        await ClockCycles(dut.clk, 2)
        await FallingEdge(dut.clk)
        dut.a_in.value = QUAD[env.pos % 4][0]
        await ClockCycles(dut.clk, k)
        await pulse_rst(dut, 1)
        await env.settle(30)
        ev = await bus.events()
        assert "GLITCH" not in ev, f"GLITCH after a reset {k} clocks after the pulse"
        assert await bus.rd("GLITCH_COUNT") == 0


@cocotb_test()
async def step_soon_after_reset(dut):
    """A step whose conditioned level arrives a few clocks after `valid` rose (FILTER_LEN 3, the
    reset value: the input changes between the 2nd and 3rd rising edge after rst falls) is
    counted: the decoders leave reset as soon as the filter has settled, not later."""
    env, rng = await begin(dut)
    bus = env.bus
    for direction in (1, -1, 1):
        base = env.pos - env.pos % 4
        dut.a_in.value, dut.b_in.value = QUAD[base % 4]
        await ClockCycles(dut.clk, 10)
        await pulse_rst(dut, 2)
        await RisingEdge(dut.clk)
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        env.pos = base + direction
        dut.a_in.value, dut.b_in.value = QUAD[env.pos % 4]
        await env.settle(30)
        got = await bus.count()
        assert got == direction & ((1 << env.count_w) - 1), \
            f"step {direction:+d} 1.5 clocks after rst: COUNT {got:#x}"
        assert not (await bus.events()) & {"QERR", "GLITCH"}


# ---- core: channel options -------------------------------------------------------------------------------
@cocotb_test()
async def swap_and_invert(dut):
    """CTRL.SWAP_AB, INV_A, INV_B, INV_Z in every combination: STATUS.A/B/Z show the channels as
    the decoders see them, and a forward walk counts up or down by the parity of the three A/B
    options (each reverses the direction), with no QERR."""
    env, rng = await begin(dut)
    bus = env.bus
    st = regmap()["STATUS"].fields
    for combo in range(16):
        swap, inv_a, inv_b, inv_z = (combo >> 0 & 1, combo >> 1 & 1, combo >> 2 & 1, combo >> 3 & 1)
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=2, SWAP_AB=swap, INV_A=inv_a,
                                  INV_B=inv_b, INV_Z=inv_z))
        await env.settle(8)
        await bus.set_count(0)
        await bus.events()
        for k in range(3):
            a, b = QUAD[env.pos % 4]
            status = await bus.rd("STATUS")
            exp = ((b if swap else a) ^ inv_a, (a if swap else b) ^ inv_b, inv_z)
            got = tuple(status >> st[n].lsb & 1 for n in ("A", "B", "Z"))
            assert got == exp, f"combo {combo:04b}: STATUS A/B/Z {got}, expected {exp}"
            steps = [1] * (3 + 2 * k)
            await env.play(walk(steps, [3 * T_NS] * len(steps), start_pos=env.pos), None)
        n = 3 + 5 + 7
        exp_count = (n if (swap + inv_a + inv_b) % 2 == 0 else -n) & ((1 << env.count_w) - 1)
        got = await bus.count()
        assert got == exp_count, f"combo {combo:04b}: COUNT {got:#x}, expected {exp_count:#x}"
        assert "QERR" not in await bus.events(), f"combo {combo:04b}: QERR"
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=3))


# ---- core: wide values -------------------------------------------------------------------------------------
WIDE = (0x5A5A_A5A5_C3C3_3C3C, 0xA5A5_5A5A_3C3C_C3C3, 0x8000_0001_8000_0001, 0x7FFE_FFFF_0FF0_F00F)


@cocotb_test()
async def latches_wide(dut):
    """PROBE_LATCH and INDEX_LATCH of counts with every bit pattern (the high word too)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for value in WIDE + tuple(~v for v in WIDE):
        value &= model.max
        await env.setup(model, count=value)
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE="rising"))
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="latch", EDGE="rising", ARM=1))
        dut.probe_in.value = 1
        dut.z_in.value = 1
        await env.settle(10)
        dut.probe_in.value = 0
        dut.z_in.value = 0
        await env.settle(10)
        for gap in (1, 2, 0):  # held: the same value at reads an odd and an even clock apart
            probe = await bus.rd("PROBE_LATCH_LO") | await bus.rd("PROBE_LATCH_HI") << 32
            index = await bus.rd("INDEX_LATCH_LO") | await bus.rd("INDEX_LATCH_HI") << 32
            assert probe == value, f"PROBE_LATCH {probe:#x}, count {value:#x}"
            assert index == value, f"INDEX_LATCH {index:#x}, count {value:#x}"
            await ClockCycles(dut.clk, gap) if gap else None
        await bus.wr("PROBE_CTRL", 0)
        await bus.wr("INDEX_CTRL", 0)


@cocotb_test()
async def ceiling_wide(dut):
    """RANGE modulo and limit with CEILINGs of varied bit patterns: across the top both ways, and
    from counts just above and below it in each 16-bit slice (the slices are compared apart)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    ceilings = WIDE + tuple(~v for v in WIDE[:2])
    for i, ceiling in enumerate(ceilings):
        mode = ("modulo", "limit")[i % 2]
        ceiling &= model.max
        starts = [ceiling - 2]
        for sl in range(0, env.count_w, 16):  # one slice above / below, the others equal
            for d in (1 << sl, -(1 << sl)):
                c = ceiling + d
                if 0 <= c <= model.max and c != ceiling:
                    starts.append(c)
        for start in starts:
            await env.setup(model, rng_mode=mode, count=start, ceiling=ceiling)
            for steps in ([1, 1, 1, 1], [-1, -1, -1, -1, -1]):
                wf = walk(steps, [3 * T_NS] * len(steps), start_pos=env.pos)
                await env.play(wf, model)
                await env.check(model, f"{mode} CEILING {ceiling:#x} from {start:#x}")


@cocotb_test()
async def bounded_range_fast(dut):
    """RANGE modulo and limit at the count-rate bound (FILTER_LEN 1, states of 1.05 .. 2.1 clocks,
    many reversals: steps in consecutive clocks both ways), CEILINGs with high bits, counts on
    both sides of slice boundaries: COUNT and events equal the model's."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    for mode, ceiling, start in (("modulo", 0x1_0000_0040, 0x1_0000_0020), ("limit", 0x2_0001_0010, 0x2_0000_FFF8),
                                 ("modulo", 0x30, 0x2E), ("limit", 0x1_0018, 0xFFF0),
                                 ("limit", 0xFFF0, 0x1_0008), ("modulo", 0x1_FFF0, 0x2_0004),
                                 ("modulo", 0, 0), ("limit", 0, 0), ("modulo", 0x8000_8001, 3)):
        ceiling &= model.max
        start &= model.max
        await env.setup(model, rng_mode=mode, filter_len=1, count=start, ceiling=ceiling)
        wf = random_walk(rng, 600, 1.05 * T_NS + 0.1, 2.1 * T_NS, p_reverse=0.5, start_pos=env.pos)
        await env.play(wf, model)
        await env.check(model, f"{mode} CEILING {ceiling:#x} from {start:#x} fast")
    # index presets near CEILING (in other 16-bit slices too), steps right after them
    for mode, ceiling, preset in (("limit", 0x0800_1234, 0x0800_1230), ("modulo", 0x0800_1234, 0x0801_0000),
                                  ("limit", 0x1_0000, 0xFFFF), ("modulo", 0x0C00_0000, 0x0BFF_FFFE)):
        ceiling &= model.max
        preset &= model.max
        await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
        await bus.set64("PRESET", preset)
        model.preset = preset
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
        model.idx_action, model.idx_oneshot, model.idx_edge = "preset", False, "rising"
        model.idx_gate, model.idx_arm = None, True
        wf = random_walk(rng, 400, 1.05 * T_NS + 0.1, 2.1 * T_NS, p_reverse=0.5, start_pos=env.pos)
        await env.play(wf, model, zfun=lambda p: int(p % 7 == 0))
        await env.check(model, f"{mode} CEILING {ceiling:#x} PRESET {preset:#x} fast")
        await bus.wr("INDEX_CTRL", 0)
        model.idx_action = "none"


# ---- steps in consecutive clocks, at loads and wraps -------------------------------------------------
# The count keeps at-CEILING and at-zero flags in registers, computed from the next count's
# candidates (Fmax): a step in the clock right after another step, a wrap or a load uses a flag that
# was computed in the clock before, not recomputed from a quiet count. These tests put steps in
# consecutive clocks (FILTER_LEN 1, one level per clock, qei_tb.play_clocks) right at those points.
# (Ceilings: 0, small ones, a high half that equals the count's with bit 27 set, bit 31 and bit 63.)
def _ceilings(count_w, zero=True):
    c = ([0] if zero else []) + [0x25, 0x0800_0040, 0x8000_8021]
    if count_w > 32:
        c += [0x8000_0800_0000_0021]
    return c


def _near(values, lo, hi):
    return sorted({v for v in values if lo <= v <= hi})


# per clock: +1, -1 or 0 (no step); pairs in consecutive clocks, each way, with quiet clocks between
BURST = (-1, +1, 0, 0, +1, +1, 0, 0, -1, -1, 0, 0, +1, -1, 0, 0, -1, +1, +1, 0, 0, +1, -1, -1, 0)


async def steps_from(env, model, start, steps):
    """Write COUNT = start (the model too), then play ``steps`` clock by clock (+1, -1 or 0 per
    clock) and let the pipeline settle: the setup of every consecutive-clock step check below."""
    await env.bus.set_count(start)
    model.write_count(start)
    await env.settle(4)
    await play_clocks(env, model, step_clocks(env.pos, steps))
    await env.settle(4)


@cocotb_test()
async def steps_in_consecutive_clocks(dut):
    """Every RANGE, CEILINGs of 0, small ones and ones with high bits: from counts at, just above
    and just below CEILING, at 0 and at the top, steps in consecutive clocks both ways (an up step
    right after a down step, a wrap right after a wrap, ...): COUNT, EVENTS and STATUS.STOPPED
    equal the model's after each burst."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    top = model.max
    for mode in ("modulo", "limit", "non_recycle", "free"):
        for ceiling in (_ceilings(env.count_w) if mode != "free" else [top]):
            await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
            starts = _near([ceiling + d for d in (-1, 0, 1, 2)] + [0, top], 0, top)
            for start in starts:
                await steps_from(env, model, start, BURST)
                what = f"{mode} CEILING {ceiling:#x} from {start:#x}, steps in consecutive clocks"
                await env.check(model, what)
                stopped = _field("STATUS", "STOPPED", await bus.rd("STATUS"))
                assert stopped == int(model.stopped), f"{what}: STATUS.STOPPED {stopped}"


# the CEILINGs of the step-pair test: 0, 1 (every count but 0 is at it), small, high bits
def _pair_ceilings(count_w):
    return [0, 1, 0x8000_8021]


@cocotb_test()
async def step_pairs_at_bounds(dut):
    """Two steps in consecutive clocks (down-up, up-down, up-up) from counts at, just above and
    just below CEILING and at 0 / 1, every bounded range, CEILING 0 and 1 too: COUNT, EVENTS and
    STATUS.STOPPED after each pair (an event missed in one pair cannot hide behind the same event
    of a later one)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    top = model.max
    for mode in ("limit", "non_recycle", "modulo"):
        for ceiling in _pair_ceilings(env.count_w):
            await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
            for start in _near([ceiling + d for d in (-1, 0, 1, 2)] + [0, 1], 0, top):
                for pair in ((-1, +1), (+1, -1), (+1, +1)):
                    await steps_from(env, model, start, pair)
                    what = f"{mode} CEILING {ceiling:#x} from {start:#x}, steps {pair}"
                    await env.check(model, what)
                    stopped = _field("STATUS", "STOPPED", await bus.rd("STATUS"))
                    assert stopped == int(model.stopped), f"{what}: STATUS.STOPPED {stopped}"


@cocotb_test()
async def steps_at_patterned_ceilings(dut):
    """CEILINGs with bit patterns from a fixed seed (deterministic: random.Random(1414), the same
    list every run), each range, counts one step and one or five units of a 16-bit slice away:
    the slice comparators of the at-CEILING flags with every carry pattern, under steps in
    consecutive clocks (the BURST of steps_in_consecutive_clocks)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    top = model.max
    pick = random.Random(1414)
    for i in range(12):
        mode = ("modulo", "limit", "non_recycle")[i % 3]
        sl = pick.randrange(0, env.count_w // 16)
        ceiling = pick.getrandbits(env.count_w) >> pick.randrange(0, env.count_w)
        await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
        for d in (-1, 1, 2, -(1 << 16 * sl), 1 << 16 * sl, 5 << 16 * sl, -(5 << 16 * sl)):
            start = ceiling + d
            if not 0 <= start <= top:
                continue
            await steps_from(env, model, start, BURST)
            await env.check(model, f"{mode} CEILING {ceiling:#x} from {start:#x}, steps in consecutive clocks")


@cocotb_test()
async def free_range_ignores_ceiling(dut):
    """RANGE free with CEILING set below the top (free ignores it): steps in consecutive clocks
    across CEILING, and at 0 and the top: COUNT and EVENTS as the model's (no wrap at CEILING)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    top = model.max
    for ceiling in (0, 0x25, 0x8000_8021):
        await env.setup(model, rng_mode="free", filter_len=1, count=0, ceiling=ceiling)
        for start in _near([ceiling - 1, ceiling, ceiling + 1, 0, top], 0, top):
            await steps_from(env, model, start, BURST)
            await env.check(model, f"free, CEILING {ceiling:#x}, from {start:#x}")


@cocotb_test()
async def index_gate_each_state(dut):
    """INDEX_CTRL gate (GATE_EN, GATE_A, GATE_B) at each of the four states, a Z pulse in each
    state: the INDEX event and the latch only for the gate's state (model's index qualifier)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    await env.setup(model, filter_len=1, count=100)
    for gate in QUAD:
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="latch", EDGE="rising", ARM=1,
                                        GATE_EN=1, GATE_A=gate[0], GATE_B=gate[1]))
        model.idx_action, model.idx_oneshot, model.idx_edge = "latch", False, "rising"
        model.idx_gate, model.idx_arm = tuple(gate), True
        await env.settle(4)
        await bus.events()
        model.take_events()
        for k in range(4):  # one step, then a Z pulse (one clock) in the state reached
            await play_clocks(env, model, step_clocks(env.pos, (1, 0, 0, 0), (0, 0, 1, 0)))
            await env.settle(4)
            await env.check(model, f"gate {gate}, Z pulse in state {QUAD[env.pos % 4]}")
            latch = await bus.rd("INDEX_LATCH_LO") | await bus.rd("INDEX_LATCH_HI") << 32
            assert latch == model.idx_latch, \
                f"gate {gate}, Z in {QUAD[env.pos % 4]}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
    await bus.wr("INDEX_CTRL", 0)


@cocotb_test()
async def index_at_steps(dut):
    """An index preset in the clock right before steps in consecutive clocks (PRESET at, just above
    and just below CEILING, also in another 16-bit slice), and an index latch in the very clock of
    a wrap (down from 0 to CEILING, up from CEILING to 0) or of a step: COUNT, EVENTS and
    INDEX_LATCH equal the model's, in every bounded range."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    top = model.max
    for action in ("preset", "latch"):
        for mode in ("modulo", "limit", "non_recycle"):
            for ceiling in _ceilings(env.count_w, zero=False):
                await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
                await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE="rising", ARM=1))
                model.idx_action, model.idx_oneshot, model.idx_edge = action, False, "rising"
                model.idx_gate, model.idx_arm = None, True
                lo16 = ceiling & ~0xFFFF  # the same upper slices, a lower low slice
                values = _near([ceiling - 1, ceiling, ceiling + 1, 0] + ([lo16 | 0x10] if action ==
                               "preset" else []), 0, top)
                for value in values:
                    if action == "preset":
                        await bus.set64("PRESET", value)
                        model.preset = value
                        await bus.set_count(ceiling // 2)
                        model.write_count(ceiling // 2)
                    else:
                        await bus.set_count(value)
                        model.write_count(value)
                    await env.settle(4)
                    # Z rises alone, then steps from the next clock on; then Z rises with a step
                    for steps, z in (((0, +1, +1, -1, 0), (1, 1, 0, 0, 0)),
                                     ((0, -1, -1, +1, 0), (1, 1, 0, 0, 0)),
                                     ((-1, +1, 0), (1, 0, 0)), ((+1, -1, 0), (1, 0, 0)),
                                     ((-1, -1, 0), (1, 0, 0)), ((+1, +1, 0), (1, 0, 0))):
                        await play_clocks(env, model, step_clocks(env.pos, steps, z))
                        what = f"{mode} CEILING {ceiling:#x} {action} at {value:#x}, steps {steps}"
                        if action == "latch":  # each latch (the next Z edge overwrites it)
                            await env.settle(4)
                            latch = (await bus.rd("INDEX_LATCH_LO")
                                     | await bus.rd("INDEX_LATCH_HI") << 32)
                            assert latch == model.idx_latch, \
                                f"{what}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
                    await env.settle(4)
                    await env.check(model, what)
                    if action == "preset" and ceiling == 0x25:
                        # a preset in the clock of a down step from 1 / from 0, then a step in the
                        # next clock (the load wins: the flags must be the preset value's)
                        for before, steps in ((1, (-1, -1, 0)), (0, (-1, +1, 0)), (1, (-1, +1, 0))):
                            await bus.set_count(before)
                            model.write_count(before)
                            await env.settle(4)
                            await play_clocks(env, model, step_clocks(env.pos, steps, (1, 0, 0)))
                            await env.settle(4)
                            await env.check(model, f"{what}; preset with a down step from {before}")
                await bus.wr("INDEX_CTRL", 0)
                model.idx_action = "none"


@cocotb_test()
async def unit_timer_prescaled(dut):
    """The unit timer at PRESCALE 2 .. 5 (ticks 3 .. 6 clocks apart: clocks without a tick between
    the ticks): SNAP_PERIOD = P gives a SNAP_READY exactly P x (PRESCALE + 1) clocks after the
    previous one, and SNAP_TIME values exactly P ticks apart."""
    env, rng = await begin(dut)
    bus = env.bus
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    await bus.wr("IRQ_EN", event_bits("SNAP_READY"))
    for pre, p in ((2, 0x2D), (3, 0x24), (3, 0x28), (4, 0x1E), (5, 0x1C), (3, 0x2C), (5, 0x25)):
        await bus.wr("TB_PRESCALE", pre)
        await bus.wr("SNAP_PERIOD", p)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1))
        seen = []
        for k in range(4):
            await bus.events()  # clear SNAP_READY; the next one raises irq
            n = 0
            while dut.irq.value == 0:
                await RisingEdge(dut.clk)
                n += 1
                assert n < 4 * p * (pre + 1) + 100, f"PRESCALE {pre} SNAP_PERIOD {p}: no snapshot"
            at = round(get_sim_time("ns") / T_NS)
            t = await bus.rd("SNAP_TIME")
            seen.append((at, t))
        for (c0, t0), (c1, t1) in zip(seen[1:], seen[2:]):  # (the first one: timer phase unknown)
            assert c1 - c0 == p * (pre + 1), \
                f"PRESCALE {pre} SNAP_PERIOD {p}: snapshots {c1 - c0} clocks apart, not {p * (pre + 1)}"
            assert (t1 - t0) & ts_mask == p, \
                f"PRESCALE {pre} SNAP_PERIOD {p}: SNAP_TIME {t0:#x} then {t1:#x}, not {p} ticks apart"
        await bus.wr("SNAP_CTRL", 0)
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test()
async def snapshot_deltas_held(dut):
    """SNAP_DELTA and SNAP_EDGE_DELTA hold their values between snapshots: each read three times,
    an odd and an even number of clocks apart, after walks forward, back and turning between two
    snapshots (positive and negative deltas, EDGE any and A rising): always the applied steps since
    the previous snapshot, and the count change between the last selected edges of the two."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    for edge in ("any", "a_rising"):
        await env.setup(model, count=1000, filter_len=1)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE=edge))
        await env.settle(4)
        last_edge = None  # 4X position of the last selected edge up to the previous snapshot
        # each a walk between two snapshots; the mixed ones turn within it (an accumulator that
        # counts down from a positive value, up from a negative one)
        for steps in ([1] * 9, [-1] * 14, [1] * 5, [-1] * 3, [1] * 22, [-1] * 30,
                      [1] * 7 + [-1] * 3, [-1] * 6 + [1] * 2, [1] * 3 + [-1] * 8):
            n = sum(steps)
            wf = walk(steps, [3 * T_NS] * len(steps), start_pos=env.pos)
            await env.play(wf, model)
            rises = [p for q, p in zip(wf.positions, wf.positions[1:])
                     if edge == "any" or (QUAD[q % 4][0], QUAD[p % 4][0]) == (0, 1)]
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE=edge))
            await env.settle(4)
            for gap in (1, 2, 0):
                delta = await bus.rd("SNAP_DELTA")
                edge_delta = await bus.rd("SNAP_EDGE_DELTA")
                assert delta == n & 0xFFFFFFFF, f"EDGE {edge}: SNAP_DELTA {delta:#x} after {n} steps"
                if rises and last_edge is not None:
                    exp = (rises[-1] - last_edge) & 0xFFFFFFFF
                    assert edge_delta == exp, \
                        f"EDGE {edge}: SNAP_EDGE_DELTA {edge_delta:#x}, expected {exp:#x} after {n} steps"
                if gap:
                    await ClockCycles(dut.clk, gap)
            if rises:
                last_edge = rises[-1]
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test()
async def period_above_2k_ticks(dut):
    """PERIOD of edge intervals of 2,652 ticks (bits 2 .. 11 in the tick counter and PERIOD; the
    other tests measure 765 ticks at most, or the 2^16 overflow at TS_W 16): exact, and held
    (read an odd and an even number of clocks apart); and of 314 ticks at PRESCALE 1 and 3 (the
    tick counter holds between ticks): within one tick."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    for pre in (1, 3):  # ticks PRESCALE + 1 clocks apart: clocks without a tick in between
        await bus.wr("TB_PRESCALE", pre)
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
        clocks = 0x13A * (pre + 1) + 1
        await env.play(walk([1, 1, 1], [clocks * T_NS] * 3, start_pos=env.pos), None)
        period = await bus.rd("PERIOD")
        assert abs(period - 0x13A) <= 1, f"PRESCALE {pre}: PERIOD {period:#x}, expected 0x13a (+-1)"
        await bus.wr("PERIOD_CTRL", 0)
    await bus.wr("TB_PRESCALE", 0)
    d = 0x0A5C
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
    await env.play(walk([1, 1], [d * T_NS, d * T_NS], start_pos=env.pos), None)
    for gap in (1, 2, 0):  # held: the same value at reads an odd and an even clock apart
        period = await bus.rd("PERIOD")
        assert period == d, f"PERIOD {period:#x}, expected {d:#x}"
        if gap:
            await ClockCycles(dut.clk, gap)
    await bus.wr("PERIOD_CTRL", 0)


@cocotb_test()
async def period_consecutive_edges(dut):
    """PERIOD_CTRL.N 2 .. 17 with an edge in every clock (FILTER_LEN 1, one state per clock: the
    edge after a measurement's start edge, and the one after the next-to-last, come in the very
    next clock): PERIOD = N ticks, N edges of one clock each."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    for n in (2, 3, 5, 10, 12, 15, 17):
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=n))
        await play_clocks(env, None, step_clocks(env.pos, [1] * (3 * n + 6)))
        await env.settle()
        period = await bus.rd("PERIOD")
        assert period == n, f"N={n}, an edge every clock: PERIOD {period}, expected {n}"
        await bus.wr("PERIOD_CTRL", 0)


@cocotb_test()
async def period_held_after_disable(dut):
    """PERIOD keeps the last measurement after PERIOD_CTRL.EN is cleared: a period of 0x2A5C ticks
    (bit 13 set, within TS_W 16), read an odd and an even number of clocks apart, before and after
    the clear."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    d = 0x2A5C
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
    await env.play(walk([1, 1], [d * T_NS, d * T_NS], start_pos=env.pos), None)
    for enabled in (True, False):
        if not enabled:
            await bus.wr("PERIOD_CTRL", 0)
        for gap in (1, 2, 3, 0):
            period = await bus.rd("PERIOD")
            assert period == d, f"EN {int(enabled)}: PERIOD {period:#x}, expected {d:#x}"
            if gap:
                await ClockCycles(dut.clk, gap)


@cocotb_test()
async def snapshot_edge_delta_after_reversal(dut):
    """SNAP_CTRL.EDGE = A rising: a snapshot taken after steps back behind the last rising edge of
    A (steps counted since that edge go down from a positive value), then walks forward through
    more rising edges: each SNAP_EDGE_DELTA is the count change between the last rising edges of
    A before the two snapshots."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    await env.setup(model, count=5000, filter_len=1)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="a_rising"))
    await env.settle(4)
    last_edge = None
    for steps in ([1] * 6 + [-1], [1] * 9 + [-1] * 2, [1] * 7 + [-1], [1] * 10 + [-1] * 3,
                  [1] * 13 + [-1], [1] * 5 + [-1] * 2):
        wf = walk(steps, [3 * T_NS] * len(steps), start_pos=env.pos)
        await env.play(wf, model)
        rises = [p for q, p in zip(wf.positions, wf.positions[1:])
                 if (QUAD[q % 4][0], QUAD[p % 4][0]) == (0, 1)]
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="a_rising"))
        await env.settle(4)
        edge_delta = await bus.rd("SNAP_EDGE_DELTA")
        if rises and last_edge is not None:
            exp = (rises[-1] - last_edge) & 0xFFFFFFFF
            assert edge_delta == exp, f"after {steps}: SNAP_EDGE_DELTA {edge_delta:#x}, expected {exp:#x}"
        if rises:
            last_edge = rises[-1]
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test()
async def one_clock_reset_in_motion(dut):
    """A reset of one clock in each clock around an applied down step (and up step): afterwards
    SNAP_DELTA (a snapshot by command, the shaft still) is 0 and COUNT is 0 -- nothing of the
    step before the reset leaks into the accumulators after it."""
    env, rng = await begin(dut)
    bus = env.bus
    for direction in (-1, 1):
        for offset in range(0, 9):
            model = QeiModel(env.count_w)
            await env.setup(model, count=50, filter_len=1)
            await FallingEdge(dut.clk)
            env.pos += direction
            dut.a_in.value, dut.b_in.value = QUAD[env.pos % 4]
            await ClockCycles(dut.clk, offset)
            await FallingEdge(dut.clk)
            dut.rst.value = 1
            await FallingEdge(dut.clk)
            dut.rst.value = 0
            await env.settle(30)
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
            await env.settle(4)
            delta = await bus.rd("SNAP_DELTA")
            assert delta == 0, f"step {direction}, reset {offset} clocks after: SNAP_DELTA {delta:#x}"
            assert await bus.count() == 0, f"step {direction}, reset {offset} clocks after: COUNT not 0"


# ---- register block -----------------------------------------------------------------------------------------
def _cfg_regs():
    """Registers with a storage (cfg) field and no write side effect the walk would disturb."""
    return [r for r in sorted(regmap().values(), key=lambda r: r.offset)
            if not r.coherent and r.name != "EVENTS" and any(f.kind == "cfg" for f in r.fields.values())]


def _cfg_mask(r, count_w, ts_w):
    """The storage bits at this COUNT_W / TS_W (the bits a write sets)."""
    return sum((size_mask(f.sized_by, count_w, ts_w) << f.lsb) & f.mask
               for f in r.fields.values() if f.kind == "cfg")


def _cfg_fields(r):
    """The bits of the storage fields, sized or not (bits above the size must read 0)."""
    return sum(f.mask for f in r.fields.values() if f.kind == "cfg")


@cocotb_test()
async def register_patterns(dut):
    """Every storage register written with its own pattern, then all read back (no write lands in
    another register, no read shows another one), twice with the patterns complemented, each read
    repeated one and two clocks later (the value holds)."""
    env, rng = await begin(dut)
    bus = env.bus
    count_w, ts_w = env.count_w, int(dut.TS_W.value)
    regs = _cfg_regs()
    for flip in (0, 0xFFFFFFFF):
        want = {}
        for i, r in enumerate(regs):
            value = ((0x9E3779B9 * (i + 1)) & 0xFFFFFFFF) ^ flip
            await bus.wr(r.name, value)
            want[r.name] = value & _cfg_mask(r, count_w, ts_w)
        for r in regs:
            m = _cfg_fields(r)
            for gap in (1, 2, 0):
                got = await bus.rd(r.name) & m
                assert got == want[r.name], \
                    f"{r.name}: read {got:#010x}, wrote {want[r.name]:#010x} (flip {flip:#x})"
                if gap:
                    await ClockCycles(dut.clk, gap)
    for r in regs:  # back to the reset values
        await bus.wr(r.name, sum((f.reset or 0) << f.lsb for f in r.fields.values()) & 0xFFFFFFFF)
    await bus.events()


@cocotb_test()
async def byte_enables_all(dut):
    """Every storage register and COUNT_HI honour each byte-enable mask (contiguous lanes on
    AXI4-Lite): the lanes written take the new bytes, the others keep theirs."""
    env, rng = await begin(dut)
    bus = env.bus
    count_w, ts_w = env.count_w, int(dut.TS_W.value)
    masks = [1, 2, 4, 8, 3, 6, 12, 7, 14] + ([5, 9, 10, 13, 11] if bus.kind == "wb" else [])
    for i, r in enumerate(_cfg_regs()):
        m, fm = _cfg_mask(r, count_w, ts_w), _cfg_fields(r)
        for k, (strb, flip) in enumerate((m, f) for m in masks for f in (0, 0xFFFFFFFF)):
            lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
            old = ((0xC3A55A3C * (i + 3 * k + 1)) ^ flip) & 0xFFFFFFFF  # each bit kept as 0 and as 1
            new = ~old & 0xFFFFFFFF
            await bus.wr(r.name, old)
            await bus.wr(r.name, new, strb)
            got = await bus.rd(r.name) & fm
            exp = (old & ~lanes | new & lanes) & m
            assert got == exp, f"{r.name} strb {strb:#x}: {got:#010x}, expected {exp:#010x}"
        await bus.wr(r.name, sum((f.reset or 0) << f.lsb for f in r.fields.values()) & 0xFFFFFFFF)
    await bus.events()
    # COUNT_HI: the staged word merges the lanes into the high word latched by the last COUNT_LO read
    model = QeiModel(count_w)
    await env.setup(model, count=0, en=0)
    for k, strb in enumerate(masks):
        lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
        old = (0x5AC3A53C * (k + 1) << 32 | 0x1234_5678) & model.max
        await bus.set_count(old)
        await bus.rd("COUNT_LO")  # latches COUNT_HI
        new_hi = ~(old >> 32) & 0xFFFFFFFF
        await bus.wr("COUNT_HI", new_hi, strb)
        await bus.wr("COUNT_LO", 0x0BAD_F00D)
        hi = ((old >> 32) & ~lanes | new_hi & lanes) & 0xFFFFFFFF
        exp = (hi << 32 | 0x0BAD_F00D) & model.max
        got = await bus.count()
        assert got == exp, f"COUNT_HI strb {strb:#x}: count {got:#x}, expected {exp:#x}"


@cocotb_test()
async def probe_time_exact(dut):
    """PROBE_TIME at probe edges spread over the timebase's low bits: within the TIMEBASE values
    read just before and just after, and PROBE_LATCH the count, every time."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    for k in range(12):
        value = (0x0F0F_0F0F_5A5A_A5A5 >> k | 1 << 2 * k) & model.max
        await env.setup(model, count=value)
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE="rising"))
        await Timer((73 * k + 5) * PERIOD_PS, unit="ps")
        await FallingEdge(dut.clk)
        before = await bus.rd("TIMEBASE")
        dut.probe_in.value = 1
        await ClockCycles(dut.clk, 6)
        after = await bus.rd("TIMEBASE")
        dut.probe_in.value = 0
        await env.settle(6)
        t = await bus.rd("PROBE_TIME")
        latch = await bus.rd("PROBE_LATCH_LO") | await bus.rd("PROBE_LATCH_HI") << 32
        assert (t - before) & ts_mask <= (after - before) & ts_mask, \
            f"PROBE_TIME {t:#x} outside {before:#x}..{after:#x}"
        assert latch == value, f"PROBE_LATCH {latch:#x}, count {value:#x}"
        await bus.wr("PROBE_CTRL", 0)


# ---- bus adapters --------------------------------------------------------------------------------------------
@cocotb.test(timeout_time=200, timeout_unit="us")  # a lost response must not hang the run
async def concurrent_reads_and_writes(dut):
    """AXI4-Lite: reads and writes outstanding at the same time (the master's read and write
    channels run independently): every read answers its own register, every write lands.
    (Wishbone has one transaction at a time: the same traffic, in turn.)"""
    env, rng = await begin(dut)
    bus = env.bus
    ident = await bus.rd("ID")
    caps = await bus.rd("CAPS")
    for rnd in range(12):
        values = {r: (0x3C5A_96E1 * (rnd + 1) + 0x1111 * k) & 0xFFFFFFFF
                  for k, r in enumerate(("PRESET_LO", "COMPARE_LO", "IRQ_EN", "SNAP_PERIOD"))}
        reads = []
        if bus.kind == "axil":
            writes = [cocotb.start_soon(bus.wr(r, v)) for r, v in values.items()]
            reads = [cocotb.start_soon(bus.rd(n)) for n in ("ID", "CAPS", "ID", "CAPS")]
            for t in writes:
                await t
            got = [await t for t in reads]
        else:
            for r, v in values.items():
                await bus.wr(r, v)
            got = [await bus.rd(n) for n in ("ID", "CAPS", "ID", "CAPS")]
        assert got == [ident, caps, ident, caps], f"round {rnd}: reads {got}"
        for r, v in values.items():
            m = _cfg_mask(regmap()[r], env.count_w, int(dut.TS_W.value))
            assert await bus.rd(r) == v & m, f"round {rnd}: {r}"
    for r in ("PRESET_LO", "COMPARE_LO", "IRQ_EN", "SNAP_PERIOD"):
        await bus.wr(r, 0)


@cocotb_test()
async def irq_low_in_reset(dut):
    """irq is 0 in every clock of a reset and after it, even with events pending and enabled
    when rst comes."""
    env, rng = await begin(dut)
    bus = env.bus
    await bus.wr("IRQ_EN", 0xFFF)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))  # SNAP_READY pending
    await env.settle(20)
    assert dut.irq.value == 1
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    for k in range(4):
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        assert dut.irq.value == 0, f"irq high in clock {k} of the reset"
    dut.rst.value = 0
    for k in range(6):
        await FallingEdge(dut.clk)
        assert dut.irq.value == 0, f"irq high {k} clocks after the reset"


@cocotb_test()
async def wb_abandoned_cycle(dut):
    """Wishbone: a cycle the master drops (CYC low) before the answer gets no ACK or ERR
    outside it (a mapped and an unmapped offset); the next cycle works. (AXI4-Lite has no such case: nothing to do.)"""
    env, rng = await begin(dut)
    bus = env.bus
    if bus.kind != "wb":
        return
    ident = await bus.rd("ID")
    unmapped = max(r.offset for r in regmap().values()) + 4
    for hold, adr in ((1, regmap()["ID"].offset), (2, regmap()["ID"].offset), (1, unmapped),
                      (2, unmapped)):
        await FallingEdge(dut.clk)
        dut.wb_adr_i.value = adr
        dut.wb_we_i.value = 0
        dut.wb_sel_i.value = 0xF
        dut.wb_cyc_i.value = 1
        dut.wb_stb_i.value = 1
        await ClockCycles(dut.clk, hold)
        await FallingEdge(dut.clk)
        dut.wb_cyc_i.value = 0
        dut.wb_stb_i.value = 0
        for k in range(8):
            await Timer(PERIOD_PS // 10, unit="ps")  # the same clock, CYC already low
            assert dut.wb_ack_o.value == 0 and dut.wb_err_o.value == 0, \
                f"ACK/ERR {k} clocks after the master dropped CYC"
            await FallingEdge(dut.clk)
        assert await bus.rd("ID") == ident


# ---- pytest ---------------------------------------------------------------------------------------------
CONFIGS = [("enc_qei_wb", 32, 32), ("enc_qei_axil", 64, 16)]


@pytest.mark.parametrize("top,count_w,ts_w", CONFIGS, ids=[f"{t}-c{c}-t{s}" for t, c, s in CONFIGS])
def test_enc_qei_gaps(top, count_w, ts_w):
    run(top, __name__, name=f"gaps_{top}_c{count_w}_t{ts_w}",
        parameters={"COUNT_W": count_w, "TS_W": ts_w})
