# SPDX-License-Identifier: Apache-2.0
"""enc_qei timebase and timing unit: TIMEBASE and TB_PRESCALE, PERIOD capture (N edges,
direction change, overflow, held values), STALL_TIMEOUT (a rewrite too) and STATUS.STALLED. A
lean build has the timebase but no period capture or stall unit: it runs the timebase's tests
only.

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import cocotb
import pytest
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer
from hedsmodel import QUAD, walk

from enctools.qei.bus import PERIOD_PS, T_NS
from enctools.qei.env import (ENGINE_IRQ, CONFIG_IDS, CONFIGS, Timebase, begin, build_param,
                              engine_period, lacks, run_feature)
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import durations, play_clocks, step_clocks
from enctools.regmap import event_bits, field, pack, regmap
from enctools.tb import cocotb_test


@cocotb_test(skip=lacks("TIMING"))
async def prescaler_and_snap_in(dut):
    """TIMEBASE advances once every PRESCALE + 1 clocks: snap_in rising edges G clocks apart give
    SNAP_TIME values G / (PRESCALE + 1) apart (floor or ceiling); snap_in held high snaps once."""
    env, rng = await begin(dut)
    bus = env.bus
    ts_w = int(dut.TS_W.value)
    ts_mask = (1 << ts_w) - 1
    cyc = 0

    async def count_clocks():
        nonlocal cyc
        while True:
            await RisingEdge(dut.clk)
            cyc += 1

    counter = cocotb.start_soon(count_clocks())
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=1))

    async def snap(hold):
        await FallingEdge(dut.clk)
        dut.snap_in.value = 1
        at = cyc
        await ClockCycles(dut.clk, hold)
        await FallingEdge(dut.clk)
        dut.snap_in.value = 0
        await env.settle(2)
        return at, await bus.rd("SNAP_TIME")

    for pre in (0, 1, 2, 9, 255):
        await bus.wr("TB_PRESCALE", pre)
        await env.settle(5)
        c0, t0 = await snap(rng.randint(1, 4))
        await ClockCycles(dut.clk, rng.randint(100, 700))
        await bus.events()
        await env.applied()
        c1, t1 = await snap(rng.randint(1, 4))
        assert "SNAP_READY" in await bus.events()
        gap = c1 - c0
        diff = (t1 - t0) & ts_mask
        lo, hi = gap // (pre + 1), -(-gap // (pre + 1))
        assert lo <= diff <= hi, f"PRESCALE {pre}: {gap} clocks gave {diff} ticks, not {lo}..{hi}"
        # the timebase itself: two reads G clocks apart
        tb0 = await bus.rd("TIMEBASE")
        assert 0 <= (tb0 - t1) & ts_mask <= (80 + env.lag) // (pre + 1) + 1  # (snap()'s wait)
    counter.cancel()
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def period_capture(dut):
    """PERIOD over N edges at constant speed (measurements of an even and of an odd number of
    clocks), the direction-change flag, PERIOD_READY, and the overflow flag and PERIOD_OVF event,
    taken through IRQ_EN, irq and its W1C, the flag cleared by the next clean measurement (TS_W =
    16 builds only: 65,536 ticks)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    lsb = regmap()["PERIOD_CTRL"].fields
    # (measurements of an even and an odd number of clocks: 28, 12, 40; 9, 15)
    for edge, n, d in (("any", 4, 7), ("any", 1, 12), ("a_rising", 2, 5), ("any", 1, 9), ("any", 3, 5)):
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE=edge, N=n))
        await env.applied()
        # states of exactly d clocks: every edge interval is d clocks
        steps = [1] * 40
        wf = walk(steps, [d * T_NS] * 40, start_pos=env.pos)
        await env.play(wf, None)
        ctrl = await bus.rd("PERIOD_CTRL")
        period = await bus.rd("PERIOD")
        per_edge = d * (4 if edge == "a_rising" else 1)
        assert period == n * per_edge, f"{edge} N={n} states {d}: PERIOD {period}, expected {n * per_edge}"
        assert not ctrl >> lsb["OVERFLOW"].lsb & 1 and not ctrl >> lsb["DIR_CHANGE"].lsb & 1
        assert "PERIOD_READY" in await bus.events()
        # a clean measurement after a reversal: DIR_CHANGE clear again
        wf = walk([1, 1, -1, -1, -1] + [-1] * 12 + [1] * 20, [d * T_NS] * 37, start_pos=env.pos)
        await env.play(wf, None)
        ctrl = await bus.rd("PERIOD_CTRL")
        assert not ctrl >> lsb["DIR_CHANGE"].lsb & 1, "DIR_CHANGE stuck after a clean measurement"
    # direction change caught: N = 8 any edges around a reversal, read right after that capture
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=8))
    await env.applied()
    wf = walk([1] * 3, [6 * T_NS] * 3, start_pos=env.pos)
    await env.play(wf, None)  # first edges: start the measurement
    wf = walk([1, 1, -1, -1, -1, -1, -1, -1], [6 * T_NS] * 8, start_pos=env.pos)
    await bus.events()
    await env.play(wf, None)
    ctrl = await bus.rd("PERIOD_CTRL")
    assert ctrl >> lsb["DIR_CHANGE"].lsb & 1, "a reversal inside the measurement did not set DIR_CHANGE"
    if int(dut.TS_W.value) == 16:
        # PERIOD_OVF through IRQ_EN and irq: masked, then enabled alone; a W1C of another event
        # keeps it, its own W1C clears it and irq falls
        ovf = event_bits("PERIOD_OVF")
        await bus.wr("IRQ_EN", ~ovf & 0xFFFF)
        await bus.events()
        await env.applied()
        await env.settle(65540)
        word = await bus.rd("EVENTS")
        assert word & ovf, f"no PERIOD_OVF after 65,540 ticks (EVENTS {word:#x})"
        await env.settle(3)
        assert dut.irq.value == int(bool(word & ~ovf & 0xFFFF)), "irq follows the masked PERIOD_OVF"
        await bus.wr("EVENTS", word & ~ovf)  # every other event: PERIOD_OVF stays
        await bus.wr("IRQ_EN", ovf)
        await env.applied()
        await env.settle(3)
        assert await bus.rd("EVENTS") & ovf, "a W1C of the other events cleared PERIOD_OVF"
        assert dut.irq.value == 1, "irq low with PERIOD_OVF pending and enabled"
        await bus.wr("EVENTS", ovf)
        await env.applied()
        await env.settle(3)
        assert not await bus.rd("EVENTS") & ovf, "the W1C of PERIOD_OVF did not clear it"
        assert dut.irq.value == 0, "irq still high after PERIOD_OVF was cleared"
        await bus.wr("IRQ_EN", 0)
        wf = walk([1] * 9, [6 * T_NS] * 9, start_pos=env.pos)
        await env.play(wf, None)
        ctrl = await bus.rd("PERIOD_CTRL")
        assert ctrl >> lsb["OVERFLOW"].lsb & 1, "OVERFLOW flag not set"
        assert await bus.rd("PERIOD") == 0xFFFF
        # OVERFLOW describes the value in PERIOD: the next clean measurement (N = 8 edges 6
        # clocks apart) clears it
        await env.play(walk([1] * 17, [6 * T_NS] * 17, start_pos=env.pos), None)
        ctrl, period = await bus.rd("PERIOD_CTRL"), await bus.rd("PERIOD")
        assert not ctrl >> lsb["OVERFLOW"].lsb & 1 and period == 8 * 6, \
            f"a clean measurement after an overflow: PERIOD_CTRL {ctrl:#x}, PERIOD {period}"
    else:
        dut._log.info("TS_W = %d: period overflow is checked in the TS_W = 16 build", int(dut.TS_W.value))
    await bus.wr("PERIOD_CTRL", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def period_n_lowered_mid_measurement(dut):
    """PERIOD_CTRL.N lowered from 8 to 2 after the measurement in progress has counted 5 edges
    (states of 10 clocks, EDGE any): it ends at its next edge (PERIOD_READY within 4 edges, not
    after the edge counter wraps), and the next PERIOD spans the new N (20 ticks). Then N raised
    from 2 to 6 the same way: PERIOD 60."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0, filter_len=1)
    d = 10

    async def forward(n: int) -> None:  # n steps up, states of d clocks
        await env.play(walk([1] * n, [d * T_NS] * n, start_pos=env.pos), None)

    for first, second in ((8, 2), (2, 6)):
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=first))
        await env.applied()
        await forward(first + 6)
        await forward(5)  # 5 edges into one measurement
        await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=second))
        await env.applied()
        await bus.events()
        await forward(4)
        await env.settle()
        if second < first:
            assert "PERIOD_READY" in await bus.events(), \
                f"N {first} -> {second} after 5 edges: no PERIOD_READY in the next 4 edges"
        await forward(2 * second + 2)
        await env.settle()
        period = await bus.rd("PERIOD")
        assert period == second * d, f"N {first} -> {second}: PERIOD {period}, expected {second * d}"
    await bus.wr("PERIOD_CTRL", 0)
    await env.applied()
    await bus.events()


async def stalled(bus) -> bool:
    """STATUS.STALLED as the channel's STATUS reads now."""
    return bool(await bus.rd("STATUS") & field("STATUS", "STALLED").mask)


@cocotb_test(skip=lacks("PERIOD"))
async def stall_and_recovery(dut):
    """STALL_TIMEOUT: the stall event and STATUS.STALLED after that many ticks without a count
    edge, not before; cleared by the next edge; once per stop."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0)
    await bus.wr("TB_PRESCALE", 1)  # a tick every 2 clocks
    await bus.wr("STALL_TIMEOUT", 150)  # 300 clocks
    for rep in range(2):
        wf = walk([1] * 10, durations(rng, 10), start_pos=env.pos)
        await env.play(wf, None)
        await bus.events()
        await ClockCycles(dut.clk, 180)
        assert "STALL" not in await bus.events(), "stall before the timeout"
        assert not await stalled(bus)
        await ClockCycles(dut.clk, 200)
        assert "STALL" in await bus.events(), "no stall after the timeout"
        assert await stalled(bus)
        await ClockCycles(dut.clk, 400)
        assert "STALL" not in await bus.events(), "the stall event repeated during one stop"
        await env.play(walk([-1], [30.0], start_pos=env.pos), None)
        assert not await stalled(bus), "STALLED not cleared by an edge"
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("TB_PRESCALE", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def stall_timeout_rewrite(dut):
    """A channel stalled (STATUS.STALLED, STALL raised): writing STALL_TIMEOUT with the value it
    has changes nothing (STALLED stays, no second STALL); a different value clears STALLED and
    restarts the timeout, so that with the shaft still STALL comes again that many ticks later,
    not before (the RDL)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0)
    t1, t2 = 200, 700 + env.lag
    await bus.wr("STALL_TIMEOUT", t1)
    await env.applied()
    await env.play(walk([1] * 4, durations(rng, 4), start_pos=env.pos), None)
    await ClockCycles(dut.clk, t1 + 50)
    await env.settle()
    assert await stalled(bus), "no stall after the timeout"
    await bus.events()
    await bus.wr("STALL_TIMEOUT", t1)  # the value it has
    await env.applied()
    await env.settle()
    assert await stalled(bus), "STALL_TIMEOUT written with its own value cleared STALLED"
    assert "STALL" not in await bus.events(), "STALL_TIMEOUT written with its own value: STALL again"
    await bus.wr("STALL_TIMEOUT", t2)  # a new value
    await env.applied()
    await env.settle()
    assert not await stalled(bus), "a new STALL_TIMEOUT did not clear STALLED"
    assert "STALL" not in await bus.events(), "a new STALL_TIMEOUT raised STALL at once"
    await ClockCycles(dut.clk, t2 - 2 * env.lag - 100)
    assert "STALL" not in await bus.events() and not await stalled(bus), \
        "STALL again before the new timeout"
    await ClockCycles(dut.clk, 2 * env.lag + 200)
    await env.settle()
    assert "STALL" in await bus.events() and await stalled(bus), \
        f"no STALL {t2} ticks after the new STALL_TIMEOUT"
    await bus.wr("STALL_TIMEOUT", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def stall_timeout_zero_is_off(dut):
    """STALL_TIMEOUT 0 is off (the RDL): from reset, a stop longer than the timebase's wrap on a
    TS_W 16 build (3,000 clocks at TS_W 32) raises no STALL and leaves STATUS.STALLED 0; written
    0 while stalled (a new value), it clears STALLED and no STALL comes again."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0)
    stop = (1 << 16) + 500 if int(dut.TS_W.value) == 16 else 3000
    await env.play(walk([1] * 4, durations(rng, 4), start_pos=env.pos), None)
    await bus.events()
    await ClockCycles(dut.clk, stop)
    await env.settle()
    assert not await stalled(bus), f"STALL_TIMEOUT 0 (reset): STALLED after {stop} clocks"
    assert "STALL" not in await bus.events(), f"STALL_TIMEOUT 0 (reset): STALL within {stop} clocks"
    await bus.wr("STALL_TIMEOUT", 100)
    await env.applied()
    await ClockCycles(dut.clk, 150)
    await env.settle()
    assert await stalled(bus) and "STALL" in await bus.events(), "no stall 150 ticks after a timeout of 100"
    await bus.wr("STALL_TIMEOUT", 0)
    await env.applied()
    await env.settle()
    assert not await stalled(bus), "STALL_TIMEOUT written 0 while stalled: STALLED stays"
    await ClockCycles(dut.clk, 3000)
    await env.settle()
    assert not await stalled(bus) and "STALL" not in await bus.events(), \
        "STALL_TIMEOUT written 0 while stalled: a stall followed"


@cocotb_test(skip=lacks("PERIOD"))
async def stall_ends_on_function_steps(dut):
    """What restarts the stall timeout is a step of the count function while CTRL.EN = 1, whether
    the range applies it or not (STALL_TIMEOUT's text). STALL_TIMEOUT 600 ticks (PRESCALE 0),
    motion every 200 clocks for 1,600: limit at CEILING pushed up (every step blocked), no
    STALL; x4 with B dithering, no STALL; x1a with the same dither (steps x1a does not count),
    STALL; EN = 0 with the shaft turning, STALL."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    t = 600
    for what, mode, func, en, want in (("limit at CEILING, pushed up", "limit", "x4", 1, False),
                                       ("x4, B dithering", "free", "x4", 1, False),
                                       ("x1a, B dithering", "free", "x1a", 1, True),
                                       ("EN 0, turning", "free", "x4", 0, True)):
        if mode == "limit" and env.lean:
            continue
        await env.setup(model, rng_mode=mode, func=func, en=en, count=0x40, ceiling=0x40)
        while env.pos % 4 != 1:  # (at state 1 -> 2 and back B alone changes)
            await env.play(walk([1], [30.0], start_pos=env.pos), None)
        await bus.wr("STALL_TIMEOUT", t)
        await env.applied()
        await bus.events()
        steps = [1] * 8 if mode == "limit" or not en else [1, -1] * 4
        await env.play(walk(steps, [200 * T_NS] * len(steps), start_pos=env.pos), None)
        stall = "STALL" in await bus.events()
        await bus.wr("STALL_TIMEOUT", 0)
        await env.applied()
        assert stall == want, f"{what}: STALL {'raised' if stall else 'not raised'} with a step " \
                              f"every 200 clocks and STALL_TIMEOUT {t}"


@cocotb_test(skip=lacks("PERIOD"))
async def period_n_zero(dut):
    """PERIOD_CTRL.N 0 acts as 1: PERIOD over one edge interval."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0, filter_len=1)
    d = 23
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=0))
    await env.applied()
    await env.play(walk([1] * 6, [d * T_NS] * 6, start_pos=env.pos), None)
    period = await bus.rd("PERIOD")
    assert period == d, f"N 0: PERIOD {period}, one edge interval is {d}"
    await bus.wr("PERIOD_CTRL", 0)
    await bus.events()


@cocotb_test(skip=lacks("PERIOD"))
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


# The clocks from a step (its pins set at a falling edge, FILTER_LEN 1) to irq with IRQ_EN = STALL
# on a per-channel build: STALL_TIMEOUT x (PRESCALE + 1) + STALL_IRQ, within the prescaler's phase
# (+- PRESCALE); the shared engine raises irq at most P + ENGINE_IRQ clocks later than that.
STALL_IRQ = 9


async def step_forward(env) -> None:
    """One step forward, set at the next falling edge (sampled at the rising edge after it)."""
    await FallingEdge(env.dut.clk)
    env.pos += 1
    env.dut.a_in.value, env.dut.b_in.value = QUAD[env.pos % 4]


async def clocks_to_stall(env, t: int, pre: int) -> int:
    """STALL_TIMEOUT t at TB_PRESCALE pre (any stall of the settings over, events cleared): a step,
    and the clocks from it to irq."""
    dut, bus = env.dut, env.bus
    await bus.wr("TB_PRESCALE", pre)
    await bus.wr("STALL_TIMEOUT", t)
    await env.applied()
    await Timer((t * (pre + 1) + 40) * PERIOD_PS, unit="ps")  # any stall of the wait is over
    await RisingEdge(dut.clk)
    await bus.events()
    n = await step_to_irq(env, t * (pre + 1) + 200 + env.lag, f"STALL_TIMEOUT {t} PRESCALE {pre}")
    await bus.events()
    return n


async def step_to_irq(env, limit: int, what: str) -> int:
    """irq low (events cleared, IRQ_EN = STALL): a step, and the clocks from it to irq (at most
    ``limit``)."""
    dut = env.dut
    await env.settle(3)
    assert dut.irq.value == 0
    await step_forward(env)
    n = 0
    while dut.irq.value == 0:
        await RisingEdge(dut.clk)
        n += 1
        assert n < limit, f"{what}: no stall"
    return n


def check_stall(env, t: int, pre: int, n: int) -> None:
    d = n - t * (pre + 1) - STALL_IRQ
    late = engine_period(int(env.dut.CHANNELS.value)) + ENGINE_IRQ if env.engine else 0
    assert -pre <= d <= pre + late, \
        f"STALL_TIMEOUT {t:#x} PRESCALE {pre}: irq {n} clocks after the step, not " \
        f"{t * (pre + 1) + STALL_IRQ}" + (f" (+- {pre})" if pre else "") + \
        (f" to {late} later" if late else "")


@cocotb_test(skip=lacks("PERIOD"))
async def stall_timeout_exact(dut):
    """The stall comes exactly STALL_TIMEOUT ticks after the last step: the clocks from a step to
    irq (IRQ_EN = STALL) are STALL_TIMEOUT x (PRESCALE + 1) + STALL_IRQ, within the prescaler's
    phase, and differ between two timeouts by exactly their difference (PRESCALE 0), or by it x
    (PRESCALE + 1) within the prescaler's phase (the shared engine: irq up to P + ENGINE_IRQ
    later)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await bus.wr("IRQ_EN", event_bits("STALL"))
    clocks = {}
    for pre, t in ((0, 0x40), (0, 0x2F), (0, 0x1F0), (0, 0x2A5), (0, 0x35A), (0, 0x0CB), (0, 0x104),
                   (0, 0x20), (0, 0x200), (0, 0x1005), (0, 4), (0, 3), (0, 2), (0, 1), (2, 0x40), (2, 0x13),
                   (2, 0x6D)):
        clocks[(pre, t)] = n = await clocks_to_stall(env, t, pre)
        check_stall(env, t, pre, n)
    for (pre, t), n in clocks.items():
        n0 = clocks[(pre, 0x40)]
        d = n - n0 - (t - 0x40) * (pre + 1)
        assert abs(d) <= pre or env.engine, \
            f"STALL_TIMEOUT {t} PRESCALE {pre}: {n} clocks to the stall, {n0} at 0x40"
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test(skip=lacks("PERIOD"))
async def stall_with_a_slow_prescaler(dut):
    """STALL_TIMEOUT 3 at TB_PRESCALE 255 (a tick every 256 clocks): the stall comes at the third
    tick after a step. Steps 505 clocks apart hold one or two ticks between them, never three,
    whatever the prescaler's phase: no STALL. Then pauses of 790 clocks (three ticks or more):
    a STALL in each. A stall raised as soon as the tick count reached STALL_TIMEOUT - 1 (not at the
    tick that makes it STALL_TIMEOUT) comes 1 to 256 clocks early, inside the 505."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await bus.wr("TB_PRESCALE", 255)
    await bus.wr("STALL_TIMEOUT", 3)
    await env.applied()
    await step_forward(env)
    await env.settle(3)
    await bus.events()  # (a stall of the rest before the first step)
    for i in range(8):
        await ClockCycles(dut.clk, 505)
        await step_forward(env)
    await env.settle(3)
    ev = await bus.events()
    assert "STALL" not in ev, \
        f"STALL with steps 505 clocks apart (two ticks at most; EVENTS {sorted(ev)})"
    for i in range(3):
        await ClockCycles(dut.clk, 790)
        await env.settle(3)
        ev = await bus.events()
        assert "STALL" in ev, \
            f"pause {i}: no STALL 790 clocks after a step (three ticks; EVENTS {sorted(ev)})"
        await step_forward(env)
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("TB_PRESCALE", 0)
    await env.applied()
    await bus.events()


@cocotb_test(skip=lacks("PERIOD"))
async def stall_ended_by_a_step(dut):
    """A stall that the next step ends soon after: STALL_TIMEOUT t at PRESCALE 0 (t above what
    the shared engine's lane times itself), a step, and the next one g clocks later, g from
    t - 40 to t + 2 P + 40 (P: the engine's period; 0 per channel), so that with the engine the
    stall and the step that ends it often fall between two of its reads of the channel, where it
    must find the stall from the step's time. EVENTS.STALL is set when g > t + 2 and not when
    g < t - 2; STATUS.STALLED is clear after the step."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    p = engine_period(int(dut.CHANNELS.value)) if env.engine else 0
    seen = {True: 0, False: 0}
    for t in (0x1F0, 0x2A5, 0x1005):
        await bus.wr("STALL_TIMEOUT", t)
        await env.applied()
        for trial in range(8):
            g = rng.choice((rng.randint(t - 40, t - 3), rng.randint(t + 3, t + 2 * p + 40)))
            await step_forward(env)
            await env.settle()  # less than t: no stall; the events of the trial before read out
            await bus.events()
            await step_forward(env)
            await ClockCycles(dut.clk, g - 1)
            await step_forward(env)
            await env.settle()
            got = "STALL" in await bus.events()
            assert got == (g > t), f"STALL_TIMEOUT {t:#x}, the next step {g} clocks later: " \
                f"EVENTS.STALL {int(got)}"
            assert not await stalled(bus), "STALLED after the step"
            seen[g > t] += 1
    dut._log.info("stalls ended by a step: %d, steps before the timeout: %d", seen[True], seen[False])
    await bus.wr("STALL_TIMEOUT", 0)


@cocotb_test(skip=lacks("TIMING"))
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


@cocotb_test(skip=lacks("PERIOD"))
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


@cocotb_test(skip=lacks("PERIOD"))
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
        await env.applied()
        await play_clocks(env, None, step_clocks(env.pos, [1] * (3 * n + 6)))
        await env.settle()
        period = await bus.rd("PERIOD")
        assert period == n, f"N={n}, an edge every clock: PERIOD {period}, expected {n}"
        await bus.wr("PERIOD_CTRL", 0)


@cocotb_test(skip=lacks("PERIOD"))
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


@cocotb_test(skip=lacks("PERIOD"))
async def period_end_at_every_timebase_phase(dut):
    """PERIOD of 0x500 ticks (more than 2^10) whose end edge comes at eight phases of the
    timebase's low 12 bits, 0x200 apart (the edge's timebase bits 11:10 take every value twice):
    exact every time, no OVERFLOW, no PERIOD_OVF. The shared engine rebuilds an end edge's time
    from the timebase's low bits; a fault there shows only at some phases of the timebase."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    lsb = regmap()["PERIOD_CTRL"].fields
    clock = Timebase(dut)
    d = 0x500
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
    await env.applied()
    for r in range(0, 0x1000, 0x200):
        await bus.events()
        await clock.phase(0x1000, r)
        await env.play(walk([1, 1], [d * T_NS, d * T_NS], start_pos=env.pos), None)
        period = await bus.rd("PERIOD")
        ctrl = await bus.rd("PERIOD_CTRL")
        events = await bus.events()
        assert period == d, f"phase {r:#x}: PERIOD {period:#x}, expected {d:#x}"
        assert not ctrl >> lsb["OVERFLOW"].lsb & 1, f"phase {r:#x}: PERIOD_CTRL.OVERFLOW set"
        assert "PERIOD_OVF" not in events, f"phase {r:#x}: PERIOD_OVF raised"
    await bus.wr("PERIOD_CTRL", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def stall_timeout_high_bits(dut):
    """STALL_TIMEOUT with bit 14 set (0x4005 ticks, PRESCALE 0): the stall comes exactly 0x4005 -
    0x40 clocks later than at 0x40, counted from a step to irq (IRQ_EN = STALL; the shared engine:
    each within P + ENGINE_IRQ clocks after the per-channel build's)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await bus.wr("IRQ_EN", event_bits("STALL"))
    clocks = {}
    for t in (0x40, 0x4005):
        clocks[t] = await clocks_to_stall(env, t, 0)
        check_stall(env, t, 0, clocks[t])
    assert env.engine or clocks[0x4005] - clocks[0x40] == 0x4005 - 0x40, \
        f"{clocks[0x4005]} clocks to the stall at 0x4005, {clocks[0x40]} at 0x40"
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test(skip=lacks("PERIOD"))
async def period_held_until_next_capture(dut):
    """After PERIOD_CTRL.EN is cleared and set again, PERIOD keeps the last measurement (0x1A9
    ticks: bits 0, 3, 5, 7, 8) through the first edge, which only starts a new measurement; the
    next edge captures the new one."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    d = 0x1A9
    ctrl = pack("PERIOD_CTRL", EN=1, EDGE="any", N=1)
    await bus.wr("PERIOD_CTRL", ctrl)
    await env.play(walk([1, 1], [d * T_NS, d * T_NS], start_pos=env.pos), None)
    assert await bus.rd("PERIOD") == d
    await bus.wr("PERIOD_CTRL", 0)
    await bus.wr("PERIOD_CTRL", ctrl)
    # a start edge 0x40 clocks from now, the end edge e clocks after it; PERIOD read between them
    e = 0x300
    play = cocotb.start_soon(env.play(walk([1, 1], [0x40 * T_NS, e * T_NS], start_pos=env.pos), None))
    await ClockCycles(dut.clk, 0x40 + 30)
    for gap in (1, 2, 0):
        period = await bus.rd("PERIOD")
        assert period == d, f"PERIOD {period:#x} after a start edge, expected {d:#x} (held)"
        if gap:
            await ClockCycles(dut.clk, gap)
    await play
    period = await bus.rd("PERIOD")
    assert period == e, f"PERIOD {period:#x} after the end edge, expected {e:#x}"

@cocotb_test(skip=lacks("TIMING"))
async def prescale_high_bits(dut):
    """TB_PRESCALE with a high bit set (0x8003, 0x4005, 0x2007, 0x1009: more than 4,000 clocks per
    tick): TIMEBASE advances at most once over 400 clocks. And a new PRESCALE restarts the
    prescaler: from 0x3FF (a tick just taken) to 0, TIMEBASE advances every clock from a few
    clocks after the write (not after the old count of up to 1,024 clocks)."""
    env, rng = await begin(dut)
    bus = env.bus
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    for pre in (0x8003, 0x4005, 0x2007, 0x1009):
        await bus.wr("TB_PRESCALE", pre)
        await ClockCycles(dut.clk, 8)
        t0 = await bus.rd("TIMEBASE")
        await ClockCycles(dut.clk, 400)
        t1 = await bus.rd("TIMEBASE")
        assert (t1 - t0) & ts_mask <= 1, \
            f"PRESCALE {pre:#x}: TIMEBASE {t0:#x} -> {t1:#x} in 400 clocks"
    await bus.wr("TB_PRESCALE", 0x3FF)
    t0 = await bus.rd("TIMEBASE")
    while await bus.rd("TIMEBASE") == t0:  # a tick: the prescaler counts 0x3FF down again
        await ClockCycles(dut.clk, 5)
    await bus.wr("TB_PRESCALE", 0)
    await ClockCycles(dut.clk, 8)
    t0 = await bus.rd("TIMEBASE")
    await ClockCycles(dut.clk, 100)
    t1 = await bus.rd("TIMEBASE")
    assert (t1 - t0) & ts_mask >= 100, \
        f"PRESCALE 0x3ff -> 0: TIMEBASE {t0:#x} -> {t1:#x} in 100 clocks and a read"
    await bus.wr("TB_PRESCALE", 0)


@cocotb_test(skip=lacks("PERIOD") or build_param("TS_W", 16) != 16)
async def timing_across_the_timebase_wrap(dut):
    """TS_W 16: the timebase wraps from 0xFFFF to 0 (TIMEBASE read 0x200 clocks apart across the
    wrap: the later value is the smaller, their difference modulo 2^16 the clocks between), and
    the values timed across the wrap stay exact: PERIOD of an edge pair 0x100 clocks apart whose
    first edge comes 0x80, 0x10 and 1 tick before the wrap; the stall of a STALL_TIMEOUT of 128
    ticks that runs over the wrap (irq as stall_timeout_exact times it)."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0, filter_len=1)
    clock = Timebase(dut)
    await clock.phase(1 << 16, 0xFF00)
    t0 = await bus.rd("TIMEBASE")
    await ClockCycles(dut.clk, 0x200)
    t1 = await bus.rd("TIMEBASE")
    assert t1 < t0 and 0x200 <= (t1 - t0) & 0xFFFF <= 0x200 + 16, \
        f"TIMEBASE {t0:#06x}, then {t1:#06x} 0x200 clocks and a read later"
    d = 0x100
    await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
    await env.applied()
    for before in (0x80, 0x10, 1):
        await clock.phase(1 << 16, (-before - 8) & 0xFFFF)  # (the first edge: about 8 clocks on)
        await env.play(walk([1, 1], [8 * T_NS, d * T_NS], start_pos=env.pos), None)
        period = await bus.rd("PERIOD")
        assert period == d, f"first edge {before:#x} ticks before the wrap: PERIOD {period:#x}, not {d:#x}"
    await bus.wr("PERIOD_CTRL", 0)
    t = 0x80
    await bus.wr("IRQ_EN", event_bits("STALL"))
    await bus.wr("STALL_TIMEOUT", t)
    await env.applied()
    await clock.phase(1 << 16, 0xFFD0)
    await bus.events()
    n = await step_to_irq(env, t + 200 + env.lag, f"STALL_TIMEOUT {t:#x} over the wrap")
    check_stall(env, t, 0, n)
    await bus.wr("STALL_TIMEOUT", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test(skip=not lacks("TIMING"))
async def timing_unit_left_out(dut):
    """CAPS.TIMING 0 (the counting profile): TIMEBASE .. STALL_TIMEOUT read 0 and ignore writes,
    PROBE_TIME reads 0, STATUS.STALLED stays 0 and STALL, SNAP_READY, PERIOD_READY and
    PERIOD_OVF never fire (CAPS.TIMING's text), with every one of those registers written all
    ones, GSNAP_CTRL's timer and snap_in on, the shaft turning and a probe edge."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0)
    rm = regmap()
    span = [n for n, r in sorted(rm.items(), key=lambda x: x[1].offset)
            if rm["TIMEBASE"].offset <= r.offset <= rm["STALL_TIMEOUT"].offset]
    for name in span + ["GSNAP_PERIOD"]:
        await bus.wr(name, 0xFFFFFFFF)
    await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1, IN_EN=1, PERIOD_EN=1))
    await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1))
    await env.applied()
    await bus.events()
    for _ in range(3):
        dut.snap_in.value = 1
        await ClockCycles(dut.clk, 5)
        dut.snap_in.value = 0
        await env.play(walk([1] * 5 + [-1] * 3, durations(rng, 8), start_pos=env.pos), None)
    dut.probe_in.value = 1
    await ClockCycles(dut.clk, 10)
    dut.probe_in.value = 0
    await ClockCycles(dut.clk, 400)
    await env.settle()
    for name in span + ["PROBE_TIME"]:
        got = await bus.rd(name)
        assert got == 0, f"no timing unit: {name} reads {got:#x}"
    assert not await stalled(bus), "no timing unit: STATUS.STALLED"
    ev = await bus.events()
    assert "PROBE" in ev, "no PROBE event (the probe latch is in the counting profile)"
    late = ev & {"STALL", "SNAP_READY", "PERIOD_READY", "PERIOD_OVF"}
    assert not late, f"no timing unit: events {sorted(late)}"
    await bus.wr("GSNAP_CTRL", 0)
    await bus.wr("PROBE_CTRL", 0)


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_timing(config):
    run_feature(__name__, *config)
