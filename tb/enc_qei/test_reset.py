# SPDX-License-Identifier: Apache-2.0
"""enc_qei reset: rst while the shaft turns, in each input state, on a rejection clock, one-clock
resets around a step, a step soon after reset, irq low through a reset, every register's reset
value read from the first clocks after a reset.

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import pytest
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer
from hedsmodel import QUAD, random_walk, walk

from enctools.qei.env import (CONFIG_IDS, CONFIGS, ENGINE_SHOW, begin, engine_period, lacks,
                              run_feature)
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import durations, illegal_jumps, pulse_rst
from enctools.regmap import built_mask, field, pack, regmap, units
from enctools.tb import cocotb_test


FILTER_RESET = regmap()["CTRL"].fields["FILTER_LEN"].reset  # CTRL.FILTER_LEN after reset (3)


@cocotb_test()
async def reset_mid_motion(dut):
    """rst while the shaft turns: every register back to reset; then counts from the new reference."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=12345, compare=7)
    await bus.wr("PRESET_LO", 99)
    await bus.wr("IRQ_EN", 0xFFF)
    wf = random_walk(rng, 200, 25.0, 40.0, p_reverse=0.1, start_pos=env.pos)
    task = env.drv.start(wf)
    await Timer(3000, unit="ns")
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    await FallingEdge(dut.clk)
    dut.rst.value = 0
    await task
    env.pos = wf.positions[-1]
    await env.settle(20)
    have = units(await bus.rd("CAPS"))
    for name, reg in regmap().items():
        if reg.coherent or name in ("TIMEBASE", "STATUS", "EVENTS", "GLITCH_COUNT", "QERR_COUNT"):
            continue
        exp = sum((f.reset or 0) << f.lsb for f in reg.fields.values() if f.kind != "in" or
                  f.reset is not None) if name not in ("CAPS",) else None
        if exp is None:
            continue
        got = await bus.rd(name)
        mask = 0
        for f in reg.fields.values():
            if f.reset is not None:
                mask |= built_mask(f, env.count_w, int(dut.TS_W.value), have)
        assert got & mask == exp & mask, f"{name} after rst: {got:#x}, reset {exp & mask:#x}"
    # counting resumes from the reference taken after rst
    model2 = QeiModel(env.count_w)
    model2.reference(QUAD[env.pos % 4])
    c0 = await bus.count()
    wf = random_walk(rng, 100, 25.0, 40.0, p_reverse=0.2, start_pos=env.pos)
    await env.play(wf, model2)
    assert await bus.count() == (c0 + model2.count) & model2.max


@cocotb_test()
async def reset_in_each_state(dut):
    """rst with the shaft standing in each of the four states (inputs held through the reset):
    the peripheral takes that state as its reference: count 0, no QERR, no GLITCH; then it counts
    exactly from there. (`valid` must not rise a clock before the conditioner shows the inputs,
    or the first state is taken as a step.)"""
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


@cocotb_test()
async def irq_low_in_reset(dut):
    """irq is 0 in every clock of a reset and after it, even with events pending and enabled
    when rst comes."""
    env, rng = await begin(dut)
    bus = env.bus
    await bus.wr("IRQ_EN", 0xFFF)
    if lacks("TIMING"):  # (the counting profile: an illegal jump, QERR pending)
        await illegal_jumps(env, 1)
    else:
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


@cocotb_test(skip=lacks("RANGE"))
async def cmp_out_low_in_reset(dut):
    """cmp_out is 0 from the first clock of a reset on and after it (compare is off after reset:
    CTRL.CMP_EN 0), with a step onto an armed COMPARE reaching the pins in any clock from 4
    before rst to 9 after it; with the step well before the reset, cmp_out pulses first (so the
    compare was armed)."""
    env, rng = await begin(dut)
    bus = env.bus
    for off in range(-4, 10):  # rst rises `off` clocks after the step reaches the pins
        await env.setup(QeiModel(env.count_w), count=5, compare=6, filter_len=1)
        a, b = QUAD[(env.pos + 1) % 4]
        trace = []  # per clock: rst as the edge sampled it, cmp_out after the edge
        for k in range(-6, 24):
            await FallingEdge(dut.clk)
            if k == 0:
                dut.a_in.value, dut.b_in.value = a, b
            if k == off:
                dut.rst.value = 1
            if k == off + 2:
                dut.rst.value = 0
            await RisingEdge(dut.clk)
            await ReadOnly()
            trace.append((k, int(dut.rst.value), int(dut.cmp_out.value)))
        env.pos += 1
        first = next(i for i, (_, r, _) in enumerate(trace) if r)
        late = [k for k, _, c in trace[first:] if c]
        assert not late, f"rst {off} clocks after the step: cmp_out high in clocks {late} (of the step)"
        if off == 9:
            assert any(c for _, _, c in trace[:first]), "the step onto COMPARE gave no cmp_out"
        await env.settle(20)
    assert await bus.rd("CTRL") & field("CTRL", "CMP_EN").mask == 0, "CMP_EN not 0 after reset"


@cocotb_test()
async def dir_change_after_reset(dut):
    """EVENTS.DIR_CHANGE after reset (its text): the previous direction is up, so a first step
    down raises DIR_CHANGE and a first step up does not; whichever way the steps before the
    reset went."""
    env, rng = await begin(dut)
    bus = env.bus
    for before in (1, -1):
        for first in (1, -1, -1, 1):
            await env.play(walk([before] * 3, [30.0] * 3, start_pos=env.pos), None)
            await pulse_rst(dut, 2)
            await env.settle(20)
            await env.play(walk([first], [30.0], start_pos=env.pos), None)
            ev = await bus.events()
            assert ("DIR_CHANGE" in ev) == (first < 0), \
                f"steps {before:+d} before the reset, a first step {first:+d} after it: EVENTS {sorted(ev)}"


@cocotb_test()
async def status_after_reset(dut):
    """STATUS right after a reset: DIR (the direction of the last step) reads 1 (up) however
    the steps before the reset went, from the first read on; VALID (the filter settled, FILTER_LEN
    + 2 clocks after rst) reads 0 in a read requested in the clock rst falls, then 1, never back
    to 0: for each d, one reset after a step down and one read requested d clocks after it, d = 0
    .. 12 on a per_channel build (1 from FILTER_LEN + 2 = 5), d = 0 .. P + 56 on the shared
    engine (1 from P + 44 + 5: CAPS.ENGINE shared (1)). On AXI4-Lite, whose master's random
    back-pressure moves the clock a read samples, only the 1 from there on is checked."""
    env, rng = await begin(dut)
    bus = env.bus
    settled = FILTER_RESET + 2 + (engine_period(int(dut.CHANNELS.value)) + ENGINE_SHOW
                                  if env.engine else 0)
    valid = []
    for d in range(settled + 8):
        await env.play(walk([-1], [30.0], start_pos=env.pos), None)
        if d % 8 == 0:  # (the step down shows in DIR: the reset has something to undo)
            assert not await bus.rd("STATUS") & field("STATUS", "DIR").mask, "DIR 1 after a step down"
        await pulse_rst(dut, 2)
        if d:
            await ClockCycles(dut.clk, d)
        status = await bus.rd("STATUS")
        assert status & field("STATUS", "DIR").mask, f"STATUS {status:#x} read {d} clocks after rst: DIR 0"
        valid.append(int(bool(status & field("STATUS", "VALID").mask)))
        await env.settle(20)
    dut._log.info("STATUS.VALID in reads d = 0, 1, ... clocks after rst: %s", "".join(map(str, valid)))
    if bus.kind == "wb":  # (AXI4-Lite: random back-pressure moves the clock a read samples)
        assert valid[0] == 0, "STATUS.VALID 1 in a read requested in the clock rst fell"
        assert valid == sorted(valid), f"STATUS.VALID went back to 0 (reads d = 0, 1, ...: {valid})"
    assert all(valid[settled:]), f"STATUS.VALID 0 in a read {valid.index(0, settled)} clocks after rst"


@cocotb_test(timeout_time=12, timeout_unit="ms")  # about 3.6 ms on the engine: 3x, for mutation
async def reset_values_right_after_reset(dut):
    """Every channel register reads its RDL reset value (of the build's units) from the first
    clock after rst falls: for each d and each register, one reset and one read requested about d
    clocks after it, d = 0 .. P + 7 on the shared engine (P: the clocks between two reads of a
    channel; the engine answers the reset values until its first write-back of the channel, in
    its second visit) and 0 .. 7 on a per_channel build. Before each reset the register is
    written another value where it has configuration fields, and a snapshot is taken
    (SNAP_READY pending, SNAP_TIME set), and both are given time to be stored: a read answered
    from the state before the reset, or from a reset value with a wrong bit, shows."""
    env, rng = await begin(dut)
    bus = env.bus
    caps = await bus.rd("CAPS")
    count_w, ts_w, have = caps & 0xFF, caps >> 8 & 0xFF, units(caps)
    span = engine_period(int(dut.CHANNELS.value)) + 8 if env.engine else 8
    regs = []
    for r in sorted(regmap().values(), key=lambda r: r.offset):
        with_reset = [f for f in r.fields.values() if f.reset is not None]
        if r.group != "chan" or not with_reset:
            continue
        exp = sum((f.reset << f.lsb) & built_mask(f, count_w, ts_w, have) for f in with_reset)
        writable = not r.coherent and any(f.kind == "cfg" for f in r.fields.values())
        regs.append((r.name, exp, sum(f.mask for f in with_reset), writable))
    for d in range(span):
        for name, exp, mask, writable in regs:
            if writable:
                await bus.wr(name, ~exp & 0xFFFFFFFF)
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
            await env.settle(4)  # (the engine's latency: the write and the snapshot stored)
            await pulse_rst(dut, 2)
            if d:
                await ClockCycles(dut.clk, d)
            got = await bus.rd(name)
            assert got & mask == exp, \
                f"{name} read {d} clocks after rst: {got & mask:#x}, reset value {exp:#x}"


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_reset(config):
    run_feature(__name__, *config)
