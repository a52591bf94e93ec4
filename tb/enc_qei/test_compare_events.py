# SPDX-License-Identifier: Apache-2.0
"""enc_qei compare, events and irq: COMPARE and cmp_out, every event set, masked, enabled onto
irq and cleared by W1C, the error counters (QERR_COUNT, GLITCH_COUNT), CMP on count loads. A lean
build has no compare unit: cmp_out stays 0 and CMP is never raised (its other events as a full
build's).

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import cocotb
import pytest
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer
from hedsmodel import QUAD, random_walk, walk

from enctools.qei.bus import PERIOD_PS, T_NS
from enctools.qei.env import (ENGINE_SHOW, CONFIG_IDS, CONFIGS, FILTER, begin, channel, engine_build,
                              engine_period, lacks, run_feature)
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import ClockWalk, durations, play_clocks
from enctools.regmap import event_bits, get_field, pack
from enctools.tb import cocotb_test


class CmpPulses:
    """Counts cmp_out pulses on every clock (each one clock long) while started."""

    def __init__(self, dut):
        self.dut, self.n = dut, 0

    async def _watch(self):
        while True:
            await RisingEdge(self.dut.clk)
            if self.dut.cmp_out.value == 1:
                self.n += 1
                await RisingEdge(self.dut.clk)
                assert self.dut.cmp_out.value == 0, "cmp_out is longer than one clock"

    def start(self):
        return cocotb.start_soon(self._watch())


@cocotb_test()
async def compare(dut):
    """COMPARE: the CMP event and one cmp_out pulse each time the count changes to it (a lean
    build: neither, however often the count passes COMPARE)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    cmp = CmpPulses(dut)

    await env.setup(model, count=100, compare=104)
    model.cmp_hits = 0
    mon = cmp.start()
    steps = ([1] * 8 + [-1] * 8) * 3 + [1] * 4 + [-1, 1] * 5
    wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
    await env.play(wf, model)
    wf = random_walk(rng, 200, 1.05 * FILTER * T_NS + 0.1, 3 * FILTER * T_NS, p_reverse=0.4,
                     start_pos=env.pos)
    await env.play(wf, model)
    await env.check(model, "compare walk")
    mon.cancel()
    assert cmp.n == model.cmp_hits, f"cmp_out pulsed {cmp.n} times, model {model.cmp_hits}"
    # (the first walk passes 104 six times; a lean build's model has no compare unit: 0 pulses)
    assert cmp.n >= 2 or env.lean, "the walk never reached COMPARE"


@cocotb_test()
async def compare_across_the_wrap(dut):
    """COMPARE a few steps away across the end of the free range (COMPARE near all ones with the
    count near 0, and the other way round): walking across the wrap both ways raises CMP and one
    cmp_out pulse each time the count steps onto COMPARE, as the model says. (The shared engine
    judges whether COMPARE is within reach of the count modulo 2^COUNT_W.)"""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    cmp = CmpPulses(dut)
    mon = cmp.start()
    hits = 0
    for compare, count in ((model.max - 1, 1), (model.max, 2), (0, model.max - 2), (1, model.max)):
        await env.setup(model, count=count, compare=compare)
        model.cmp_hits = 0
        cmp.n = 0
        d = 1 if count > compare else -1  # towards COMPARE: across the wrap
        steps = [d] * 5 + [-d] * 5 + [d] * 5
        wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
        await env.play(wf, model)
        await env.check(model, f"COMPARE {compare:#x} from {count:#x}")
        assert cmp.n == model.cmp_hits, \
            f"COMPARE {compare:#x} from {count:#x}: cmp_out pulsed {cmp.n} times, model {model.cmp_hits}"
        hits += model.cmp_hits
    mon.cancel()
    assert hits >= 8 or env.lean, f"the walks reached COMPARE {hits} times"


@cocotb_test()
async def events_and_irq(dut):
    """Every count-side event: set, masked, enabled onto irq, cleared alone by W1C (the events
    of the units a build has)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=model.max, compare=2, filter_len=3)
    await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none"))
    await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1))

    async def make(name):
        if name == "OVERFLOW":
            await bus.set_count(model.max)
            await env.applied()
            await env.play(walk([1], [45.0], start_pos=env.pos), None)
        elif name == "UNDERFLOW":
            await bus.set_count(0)
            await env.applied()
            await env.play(walk([-1], [45.0], start_pos=env.pos), None)
        elif name == "DIR_CHANGE":
            await env.play(walk([1, -1], [45.0, 45.0], start_pos=env.pos), None)
        elif name == "CMP":
            await bus.set_count(2)
        elif name == "QERR":
            await env.play(walk([2], [45.0], start_pos=env.pos), None)
        elif name == "GLITCH":
            dut.a_in.value = 1 - QUAD[env.pos % 4][0]
            await Timer(int(1.5 * PERIOD_PS) + 3, unit="ps")  # 1 or 2 samples < FILTER_LEN 3
            dut.a_in.value = QUAD[env.pos % 4][0]
        elif name == "INDEX":
            dut.z_in.value = 1
            await env.settle(8)
            dut.z_in.value = 0
        elif name == "PROBE":
            dut.probe_in.value = 1
            await env.settle(8)
            dut.probe_in.value = 0
        elif name == "SNAP_READY":
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
        elif name == "PERIOD_READY":
            await bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, N=1))
            await env.applied()
            await env.play(walk([1, 1], [45.0, 45.0], start_pos=env.pos), None)
            await bus.wr("PERIOD_CTRL", 0)
        elif name == "STALL":
            await bus.wr("STALL_TIMEOUT", 20)
            await env.applied()
            await env.settle(30)
            await bus.wr("STALL_TIMEOUT", 0)
        await env.applied()  # (the shared engine: what a write did shows up to its latency later)
        await env.settle()

    names = ["OVERFLOW", "UNDERFLOW", "DIR_CHANGE", "CMP", "QERR", "GLITCH", "INDEX", "PROBE",
             "SNAP_READY", "PERIOD_READY", "STALL"]
    if env.lean:  # (no compare, probe, period or stall unit)
        names = [n for n in names if n not in ("CMP", "PROBE", "PERIOD_READY", "STALL")]
    if lacks("TIMING"):  # (the counting profile: no snapshots, period or stall)
        names = [n for n in names if n not in ("SNAP_READY", "PERIOD_READY", "STALL")]
    for name in names:
        await bus.wr("IRQ_EN", 0)
        await bus.events()
        await env.applied()
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=3, CMP_EN=1))
        await make(name)
        word = await bus.rd("EVENTS")
        assert word & event_bits(name), f"{name} not raised (EVENTS {word:#x})"
        await env.settle(3)
        assert dut.irq.value == 0, f"irq high with IRQ_EN = 0 ({name})"
        await bus.wr("IRQ_EN", event_bits(*(n for n in names if n != name)) & ~word)
        await env.settle(3)
        assert dut.irq.value == 0, f"irq high with {name} masked"
        await bus.wr("IRQ_EN", event_bits(name))
        await env.settle(3)
        assert dut.irq.value == 1, f"irq low with {name} pending and enabled"
        # set a second event, then clear only the first: the second stays
        other = "CMP" if name != "CMP" and not env.lean else "INDEX" if name != "INDEX" else "QERR"
        await make(other)
        both = await bus.rd("EVENTS")
        assert both & event_bits(other), f"{other} not raised"
        await bus.wr("EVENTS", event_bits(name))
        after = await bus.rd("EVENTS")
        assert not after & event_bits(name), f"W1C did not clear {name}"
        assert after & event_bits(other), f"W1C of {name} also cleared {other}"
        await env.settle(3)
        assert dut.irq.value == 0, f"irq still high after clearing {name}"
        await bus.wr("EVENTS", 0)  # writing 0 clears nothing
        assert await bus.rd("EVENTS") == after
        if name in ("OVERFLOW",):
            model.count = 0
    assert await bus.rd("GLITCH_COUNT") >= 1


# the core's one-clock event pulses (white box, per-channel build) by the model's event names
CORE_EVENTS = {"OVERFLOW": "ev_overflow", "UNDERFLOW": "ev_underflow", "INDEX": "ev_index",
               "CMP": "ev_cmp", "DIR_CHANGE": "ev_dir_change", "QERR": "ev_qerr"}


@cocotb_test(skip=lacks("RANGE") or engine_build())
async def events_each_clock(dut):
    """OVERFLOW, UNDERFLOW, INDEX, CMP and DIR_CHANGE compared with the model clock by clock, not
    per segment: a walk at the count-rate bound (FILTER_LEN 1, a state every 1 .. 3 clocks,
    reversals) across both ends of a small modulo and then limit range, with COMPARE inside it and
    an index preset on every pulse of Z. Every event the model raises at a pin change is one pulse
    of the core's event (white box: the per-channel core's ev_* outputs, before EVENTS) a fixed
    number of clocks later (fixed per event, the same in both ranges), and there is no other
    pulse; EVENTS then holds their union."""
    env, rng = await begin(dut)
    bus = env.bus
    core = channel(dut).u_core
    pulses = {name: getattr(core, sig) for name, sig in CORE_EVENTS.items()}
    model = QeiModel(env.count_w)  # (one model: the direction of the last step carries over)
    lags = {}  # event -> clocks from the pin change to its pulse
    for mode in ("modulo", "limit"):
        ceiling = rng.randint(12, 40)
        await env.setup(model, func="x4", rng_mode=mode, filter_len=1,
                        count=rng.randint(0, ceiling), ceiling=ceiling,
                        compare=rng.randint(1, ceiling - 1))
        preset = rng.randint(0, ceiling)
        await bus.set64("PRESET", preset)
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
        model.preset, model.idx_action, model.idx_edge, model.idx_arm = preset, "preset", "rising", True
        await env.applied()
        await bus.events()
        model.take_events()
        want, got = [], []  # (clock, event): the model's at each pin change, the core's pulses
        sample = model.sample

        def logged(state, z=0, sample=sample):
            sample(state, z)
            want.extend((int(get_sim_time("ns") // T_NS), e) for e in model.take_events())
        model.sample = logged

        async def watch():
            while True:
                await RisingEdge(dut.clk)
                await ReadOnly()
                got.extend((int(get_sim_time("ns") // T_NS), e) for e, h in pulses.items()
                           if int(h.value))
        watcher = cocotb.start_soon(watch())
        # (a turn longer than twice the range: between two index presets the count can reach
        # either end from any PRESET)
        rev = rng.randint(2 * ceiling + 8, 2 * ceiling + 30)
        walker = ClockWalk(dut, [model], rng, positions=[env.pos], shortest=1, longest=3,
                           p_reverse=0.25, zfuns=[lambda p, rev=rev: int(p % rev < 2)])
        need = {"OVERFLOW", "UNDERFLOW", "INDEX", "CMP", "DIR_CHANGE"}
        for chunk in range(12):  # (3,000 clocks, more until the walk has raised every event)
            if chunk >= 6 and need <= {e for _, e in want}:
                break
            await walker.run(500)
        await env.settle(8)
        watcher.cancel()
        env.pos = walker.pos[0]
        model.sample = sample
        kinds = {e for _, e in want}
        assert need <= kinds, \
            f"{mode}: the walk raised only {sorted(kinds)}"
        for kind in sorted(kinds):
            w = sorted(t for t, e in want if e == kind)
            g = sorted(t for t, e in got if e == kind)
            assert g, f"{mode}: the model raised {len(w)} {kind}, the core no pulse"
            lag = g[0] - w[0]  # (each event its own pipeline depth, the same in both ranges)
            assert 1 <= lag <= 8, f"{mode}: first {kind} pulse {lag} clocks after the model's"
            assert lags.setdefault(kind, lag) == lag, \
                f"{mode}: {kind} pulses {lag} clocks after the pin change, {lags[kind]} in modulo"
            extra = sorted(set(g) - {t + lag for t in w})[:6]
            missing = sorted({t + lag for t in w} - set(g))[:6]
            assert g == [t + lag for t in w], \
                f"{mode}: {kind}: the core's pulses and the model's events (+{lag} clocks) " \
                f"differ: pulses at clocks {extra} the model did not raise, events of clocks " \
                f"{[t - lag for t in missing]} with no pulse ({len(g)} pulses, {len(w)} events)"
        stray = {e for _, e in got} - kinds
        assert not stray, f"{mode}: pulses of {sorted(stray)}, which the model never raised"
        dut._log.info("%s: %d events, each a pulse this many clocks after its pin change: %s",
                      mode, len(want), lags)
        ev = await bus.events()
        assert ev - {"SNAP_READY"} == kinds, f"{mode}: EVENTS {sorted(ev)}, model {sorted(kinds)}"
        await bus.wr("INDEX_CTRL", 0)


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
    await env.applied()
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


@cocotb_test(timeout_time=6, timeout_unit="ms")  # 2 ms of 65,540 pulses: 3x, for mutation
async def error_counters_saturate(dut):
    """QERR_COUNT's top bit and its saturation at 0xFFFF ("Number of QERR events, saturating at
    0xFFFF"): 32,770 illegal jumps read 32,770 (bit 15 set), 32,770 more read 0xFFFF, not the sum
    modulo 2^16; a write clears it."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    n = 32770
    await env.setup(model, func="x4", filter_len=1, count=0)
    for want in (n, 0xFFFF):
        await env.drv.play(walk([2] * n, [3 * T_NS] * n, start_pos=env.pos))
        env.pos += 2 * n
        await env.settle(10)
        got = await bus.rd("QERR_COUNT")
        assert got == want, f"QERR_COUNT {got:#x} after {want if want == n else 2 * n} illegal jumps, not {want:#x}"
    await bus.wr("QERR_COUNT", 0)
    await env.applied()
    await env.settle(10)
    assert await bus.rd("QERR_COUNT") == 0, "QERR_COUNT not cleared by a write"
    await bus.events()


@cocotb_test(timeout_time=6, timeout_unit="ms")  # 2 ms of 65,540 pulses: 3x, for mutation
async def glitch_count_saturates(dut):
    """GLITCH_COUNT's top bit and its saturation at 0xFFFF ("Number of clocks with a rejected A/B
    level (GLITCH events), saturating at 0xFFFF"): with FILTER_LEN 2, 32,770 lone one-clock pulses on A or B (each one rejected
    level, the count unchanged) read 32,770 (bit 15 set), 32,770 more read 0xFFFF, not the sum
    modulo 2^16; QERR_COUNT stays 0; a write clears GLITCH_COUNT."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    n = 32770
    await env.setup(model, func="x4", filter_len=2, count=0)
    await bus.wr("GLITCH_COUNT", 0)
    await env.applied()
    before = await bus.count()
    for want in (n, 0xFFFF):
        # the present state for 2 clocks, a step for 1 clock (rejected), back: 3 clocks a pulse
        wf = walk([1, -1] * n, [2 * T_NS, T_NS] * n, start_pos=env.pos)
        await FallingEdge(dut.clk)  # (levels of whole clocks)
        await env.drv.play(wf)
        await env.settle(10)
        got = await bus.rd("GLITCH_COUNT")
        assert got == want, \
            f"GLITCH_COUNT {got:#x} after {want if want == n else 2 * n} rejected pulses, not {want:#x}"
    assert await bus.count() == before, "a rejected pulse moved COUNT"
    assert await bus.rd("QERR_COUNT") == 0, "a rejected pulse counted as a quadrature error"
    await bus.wr("GLITCH_COUNT", 0)
    await env.applied()
    await env.settle(10)
    assert await bus.rd("GLITCH_COUNT") == 0, "GLITCH_COUNT not cleared by a write"
    await bus.events()


@cocotb_test(skip=lacks("RANGE"))
async def cmp_on_load(dut):
    """A COUNT load that makes the count equal COMPARE raises CMP and pulses cmp_out once, for one
    clock: a COUNT write and an index preset, from another count and from COMPARE itself (the
    count already had the value), with CTRL.EN = 1 and 0; a load of another value raises neither.
    COUNT and EVENTS as the model's, cmp_out pulses = the model's compare hits."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    cmp = 0x0000_0005_89AB_CDEF & model.max
    high = []  # the clocks in which cmp_out is high

    async def watch():
        n = 0
        while True:
            await RisingEdge(dut.clk)
            n += 1
            if dut.cmp_out.value == 1:
                high.append(n)

    mon = cocotb.start_soon(watch())
    for en in (1, 0):
        await env.setup(model, count=cmp - 7, compare=cmp, filter_len=1, en=en)
        await bus.set64("PRESET", cmp)
        model.preset = cmp
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
        model.idx_action, model.idx_oneshot, model.idx_edge = "preset", False, "rising"
        model.idx_gate, model.idx_arm = None, True
        # (load, count before it, value written: None for an index preset of PRESET = COMPARE)
        for load, before, value in (("write", cmp - 1, cmp), ("write", cmp, cmp),
                                    ("write", cmp + 1, cmp + 2), ("preset", cmp + 1, None),
                                    ("preset", cmp, None)):
            await bus.set_count(before)
            model.write_count(before)
            await env.applied()
            await env.settle(4)
            await env.check(model, f"EN {en}: COUNT write of {before:#x}")
            del high[:]
            hits = model.cmp_hits
            if value is not None:
                await bus.set_count(value)
                model.write_count(value)
                await env.applied()
            else:  # an index pulse (FILTER_LEN 1: Z high for 3 clocks)
                await play_clocks(env, model, [(env.pos, 1)] * 3 + [(env.pos, 0)])
            await env.settle()
            what = f"EN {en}: {load} to {model.count:#x} from {before:#x}, COMPARE {cmp:#x}"
            await env.check(model, what)
            pulses = [n for n in high if n - 1 not in high]
            assert len(pulses) == model.cmp_hits - hits, \
                f"{what}: {len(pulses)} cmp_out pulses, model {model.cmp_hits - hits}"
            assert len(high) == len(pulses), f"{what}: cmp_out high longer than one clock"
        await bus.wr("INDEX_CTRL", 0)
        model.idx_action = "none"
    mon.cancel()


@cocotb_test(skip=lacks("RANGE"))
async def cmp_on_load_shows(dut):
    """A COUNT write that loads COMPARE (CMP_EN = 1): cmp_out pulses in the clock of the load, and
    every read of EVENTS requested ENGINE_SHOW + P clocks or more after that clock shows CMP (the
    shared engine's bound for a value, CAPS.ENGINE; a per-channel build: 3 clocks)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    cmp = 0x0000_0002_4000_0011 & model.max
    tb = dut.u_qei.timebase
    bound = engine_period(int(dut.CHANNELS.value)) + ENGINE_SHOW if env.engine else 3
    pulse = [None]

    async def watch():
        while True:
            await RisingEdge(dut.clk)
            if dut.cmp_out.value == 1 and pulse[0] is None:
                pulse[0] = int(tb.value)

    mon = cocotb.start_soon(watch())
    await env.setup(model, count=cmp - 1, compare=cmp, filter_len=1)
    worst = 0
    for trial in range(8):
        await bus.set_count(cmp - 1 - trial)
        await env.settle()
        await bus.events()
        await env.applied()
        pulse[0] = None
        await bus.set_count(cmp)
        for _ in range(4 * env.lag + 20):
            if pulse[0] is not None:
                break
            await RisingEdge(dut.clk)
        assert pulse[0] is not None, f"trial {trial}: no cmp_out pulse after a COUNT write of COMPARE"
        while True:
            start = int(tb.value)
            if await bus.rd("EVENTS") & event_bits("CMP"):
                break
            assert start - pulse[0] < bound, \
                f"trial {trial}: EVENTS read {start - pulse[0]} clocks after the load (cmp_out) " \
                f"without CMP (bound {bound})"
        worst = max(worst, int(tb.value) - pulse[0])
        await ClockCycles(dut.clk, rng.randrange(50))
    mon.cancel()
    dut._log.info("CMP of a load shown at most %d clocks after cmp_out (bound %d)", worst, bound)


@cocotb_test(skip=lacks("RANGE"))
async def compare_enable(dut):
    """CTRL.CMP_EN: with 0 (the reset value) a walk through COMPARE and a COUNT write of it raise
    no CMP and no cmp_out pulse; setting CMP_EN while the count equals COMPARE raises nothing; with
    1 the next step onto COMPARE and a load of it do. Clearing CMP_EN stops it again."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    pulses = 0

    async def count_pulses():
        nonlocal pulses
        while True:
            await RisingEdge(dut.clk)
            pulses += int(dut.cmp_out.value)

    assert get_field("CTRL", "CMP_EN", await bus.rd("CTRL")) == 0, "CTRL.CMP_EN is not 0 after reset"
    mon = cocotb.start_soon(count_pulses())
    cmp = 0x10
    await env.setup(model, count=cmp - 3, filter_len=1)  # compare=None: CMP_EN = 0
    await bus.set64("COMPARE", cmp)
    await env.applied()
    steps = [1] * 6 + [-1] * 6 + [1] * 3  # through COMPARE both ways, ending on it
    await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
    await bus.set_count(cmp)
    model.write_count(cmp)
    await env.settle()
    await env.check(model, "CMP_EN = 0: walk through COMPARE and a COUNT write of it")
    assert pulses == 0, f"cmp_out pulsed {pulses} times with CMP_EN = 0"
    ctrl = pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1, CMP_EN=1)
    await bus.wr("CTRL", ctrl)
    await env.settle()  # (the shared engine: the write acts within its latency too)
    await env.check(model, "CMP_EN set while the count equals COMPARE")  # (model: compare None)
    assert pulses == 0, "setting CMP_EN on COMPARE pulsed cmp_out"
    model.compare, model.cmp_hits = cmp, 0
    steps = [1, -1, -1, 1]  # off COMPARE and back onto it twice
    await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
    await bus.set_count(cmp)
    model.write_count(cmp)
    await env.settle()
    await env.check(model, "CMP_EN = 1: steps onto COMPARE and a load of it")
    assert pulses == model.cmp_hits == 3, f"cmp_out pulsed {pulses} times, model {model.cmp_hits}"
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1, CMP_EN=0))
    await env.applied()
    model.compare = None
    await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
    await env.settle()
    await env.check(model, "CMP_EN cleared again")
    assert pulses == 3, "cmp_out pulsed after CMP_EN was cleared"
    mon.cancel()


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_compare_events(config):
    run_feature(__name__, *config)
