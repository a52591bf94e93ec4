# SPDX-License-Identifier: Apache-2.0
"""enc_qei counting: the count functions against the independent model (enctools.qei.model),
the input filter, a modelled HEDS-5000 unit, the count beyond the rate rule, the channel options
(SWAP_AB, INV_A, INV_B), steps in consecutive clocks, and CTRL.EN.

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import pytest
from cocotb.triggers import ClockCycles, RisingEdge, Timer
from hedsmodel import QUAD, EncoderUnit, Profile, random_walk, walk, with_glitches

from enctools.qei.bus import PERIOD_PS, T_NS
from enctools.qei.env import CONFIG_IDS, CONFIGS, FILTER, begin, build_param, run_feature
from enctools.qei.model import FUNCS, QeiModel
from enctools.qei.stimulus import (BURST, ceilings, durations, illegal_jumps, near, rejected_pulses,
                                   steps_from, walk_with_jumps)
from enctools.regmap import enum, get_field, pack, regmap, units
from enctools.tb import cocotb_test


@cocotb_test()
async def func_walks(dut):
    """Every CTRL.FUNC against the model: long random walks, dither, illegal jumps."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    for func in FUNCS:
        start_count = rng.choice([0, 5, model.max - 3, rng.getrandbits(env.count_w)])
        compare = (start_count + rng.randint(-3, 3)) & model.max
        await env.setup(model, func=func, count=start_count, compare=compare)
        for name, n, p_rev in (("run", 250, 0.05), ("dither", 150, 0.5)):
            wf = random_walk(rng, n, 1.05 * FILTER * T_NS + 0.1, 3 * FILTER * T_NS, p_reverse=p_rev,
                             start_pos=env.pos)
            await env.play(wf, model)
            await env.check(model, f"{func} {name}")
        wf = walk_with_jumps(rng, 150, env.pos, jumps=8)
        await env.play(wf, model)
        await env.check(model, f"{func} jumps")
        qerr = await env.bus.rd("QERR_COUNT")
        assert qerr == model.qerrs, f"{func}: QERR_COUNT {qerr}, model {model.qerrs}"
        dut._log.info("%s: count %#x, %d quadrature errors", func, model.count, qerr)


@cocotb_test()
async def filter_lengths(dut):
    """Run-time FILTER_LEN: exact counting at the rate rule, lone pulses rejected and counted."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for f in (1, 3, 7, 16):
        await env.setup(model, func="x4", filter_len=f, count=rng.getrandbits(16))
        wf = random_walk(rng, 60, 1.05 * f * T_NS + 0.1, 4 * f * T_NS + 3 * T_NS, p_reverse=0.3,
                         start_pos=env.pos)
        if f >= 3:
            # lone pulses of f - 1.3 clocks (f - 2 or f - 1 samples: always seen, always rejected),
            # at least f + 1 clocks from any transition (the count-rate rule)
            wf = with_glitches(wf, rng, 10, (f - 1.3) * T_NS, guard_ns=(f + 1.05) * T_NS)
        await env.drv.play(wf)
        # feed the model only the accepted states (a lone pulse returns to the same position)
        last = QUAD[env.pos % 4]
        for (_, a, b), p in zip(wf.events[1:], wf.positions[1:]):
            st = QUAD[p % 4]
            if st != last:
                model.sample(st)
                last = st
        env.pos = wf.positions[-1]
        await env.settle(3 * f + 10)
        got = await bus.count()
        assert got == model.count, f"FILTER_LEN {f}: count {got}, model {model.count}"
        glitches = await bus.rd("GLITCH_COUNT")
        pulses = (len(wf.events) - 61) // 2
        if f >= 3:
            assert glitches == pulses, f"FILTER_LEN {f}: GLITCH_COUNT {glitches}, {pulses} pulses"
        else:
            assert glitches == 0
        ev = await bus.events()
        assert "QERR" not in ev
        assert ("GLITCH" in ev) == (f >= 3 and pulses > 0)
        model.take_events()


@cocotb_test()
async def heds_unit_profile(dut):
    """A modelled HEDS-5000 unit (typical errors) accelerating, reversing and stopping: x4 count
    equals the model's position, no error flagged. Clock 2 MHz, so states last >= 10 clocks."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, func="x4", count=0)
    import numpy as np

    unit = EncoderUnit.typical(np.random.default_rng(rng.getrandbits(32)))
    profile = Profile(start_deg=0).ramp(0, 3000, 0.0015).ramp(3000, -1500, 0.002).stop(0.0003)
    wf = unit.waveform(profile)
    # the clock is 100 MHz here: slow the waveform 25x in time so states last >= 10 clocks
    scale = 25.0
    from hedsmodel import Waveform

    slow = Waveform()
    p0 = wf.positions[0]
    for (t, a, b), p in zip(wf.events, wf.positions):
        slow.append(t / scale, p, (a, b))
    assert slow.min_state_ns() > 2.1 * FILTER * T_NS, slow.min_state_ns()
    # start from the unit's first state: re-reference there
    first = (wf.events[0][1], wf.events[0][2])
    dut.a_in.value, dut.b_in.value = first
    await env.settle(10)
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x1a", FILTER_LEN=FILTER))
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=FILTER))
    await env.settle(10)
    await bus.set_count(0)
    await bus.events()
    await env.drv.play(slow)
    await env.settle()
    got = await bus.count()
    exp = (wf.positions[-1] - p0) & model.max
    assert got == exp, f"count {got:#x}, model position change {exp:#x}"
    ev = await bus.events()
    assert not ev & {"QERR", "GLITCH"}, f"errors flagged on a clean unit: {ev}"
    dut._log.info("HEDS-5000 profile: %d transitions, final count %d", len(wf.events) - 1,
                  got if got < 1 << 31 else got - (1 << env.count_w))


@cocotb_test()
async def beyond_rate_rule(dut):
    """Outside the count-rate rule (states shorter than a clock, pulses shorter than the filter)
    the count is exact or QERR / GLITCH is raised: never a silent loss."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    flagged = 0
    for f in (1, 3):
        for seg in range(12):
            await env.setup(model, func="x4", filter_len=f, count=0)
            wf = random_walk(rng, 80, 0.3 * T_NS, (1.3 * f + 0.5) * T_NS, p_reverse=0.3,
                             start_pos=env.pos)
            await env.drv.play(wf)
            moved = wf.positions[-1] - env.pos
            env.pos = wf.positions[-1]
            await env.settle(3 * f + 12)
            got = await bus.count()
            ev = await bus.events()
            exact = got == moved & model.max
            if not exact:
                assert ev & {"QERR", "GLITCH"}, \
                    f"FILTER_LEN {f}: count {got:#x} != position change {moved}, nothing flagged ({ev})"
                flagged += 1
            # re-synchronise the model with the position the peripheral now holds
    assert flagged >= 3, "the stimulus never broke the rule; the test tested nothing"
    dut._log.info("%d of 24 fast segments miscounted, every one flagged", flagged)


@cocotb_test()
async def filter_len_clamp(dut):
    """CTRL.FILTER_LEN 0 acts as 1: states of 1.05 clocks count exactly, and lone pulses of 1.3
    clocks (one or two samples) are levels, not rejections (GLITCH_COUNT 0; as 2 it would reject
    those of one sample). 17, 24 and 31 act as 16: lone pulses of 14.7 clocks (14 or 15 samples:
    as 15 it would take those of 15) are rejected, each one GLITCH, and states of 17.5 .. 70
    clocks count exactly."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for f, lo, hi, width, guard in ((0, 1.05, 6.0, 1.3, 1.1), (17, 17.5, 70.0, 14.7, 17.05),
                                    (24, 17.5, 70.0, 14.7, 17.05), (31, 17.5, 70.0, 14.7, 17.05)):
        await env.setup(model, func="x4", filter_len=f, count=0)
        wf = random_walk(rng, 40 if f else 300, lo * T_NS + 0.1, hi * T_NS, p_reverse=0.3,
                         start_pos=env.pos)
        n = len(wf.events)
        wf = with_glitches(wf, rng, 6, width * T_NS, guard_ns=guard * T_NS)
        inserted = (len(wf.events) - n) // 2
        assert inserted >= 4, f"FILTER_LEN {f}: {inserted} pulses placed"
        pulses = inserted if f else 0  # (FILTER_LEN 0 = 1: every pulse is taken)
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


@cocotb_test()
async def sub_clock_a_pulse_unseen(dut):
    """An A pulse between two clock edges (high from 0.3 to 0.7 of a clock period after a rising
    edge, B steady at 1) is never sampled: pulse_dir (FILTER_LEN 1 and 3) and x4 count nothing for
    it, nor do increase (FILTER_LEN 1) and decrease (FILTER_LEN 2), and no QERR or GLITCH is
    raised (CTRL.FILTER_LEN's text: such a pulse is not seen at all). The same pulse made 1.5
    clocks long is sampled: pulse_dir and decrease count it (FILTER_LEN 1)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    while QUAD[env.pos % 4] != (0, 1):  # A low, B high (pulse_dir: up)
        await env.play(walk([1], [3 * T_NS], start_pos=env.pos), None)

    async def pulses(n: int, clocks: float) -> None:
        for _ in range(n):
            await RisingEdge(dut.clk)
            await Timer(int(0.3 * PERIOD_PS), unit="ps")
            dut.a_in.value = 1
            await Timer(int(clocks * PERIOD_PS), unit="ps")
            dut.a_in.value = 0
            await ClockCycles(dut.clk, rng.randint(4, 9))

    for func, f, clocks, counted in (("pulse_dir", 1, 0.4, 0), ("pulse_dir", 3, 0.4, 0),
                                     ("increase", 1, 0.4, 0), ("decrease", 2, 0.4, 0),
                                     ("x4", 1, 0.4, 0), ("pulse_dir", 1, 1.5, 1),
                                     ("decrease", 1, 1.5, -1)):
        await env.setup(model, func=func, filter_len=f, count=0)
        await bus.events()
        n = rng.randint(3, 6)
        await pulses(n, clocks)
        await env.settle(12)
        what = f"{func}, FILTER_LEN {f}: {n} A pulses of {clocks} clocks"
        assert await bus.count() == counted * n & model.max, f"{what}: COUNT {await bus.count()}"
        ev = await bus.events()
        assert not {"QERR", "GLITCH"} & ev, f"{what}: events {sorted(ev)}"
        assert await bus.rd("GLITCH_COUNT") == 0, f"{what}: GLITCH_COUNT"


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


@cocotb_test()
async def steps_in_consecutive_clocks(dut):
    """Every RANGE, CEILINGs of 0, small ones and ones with high bits: from counts at, just above
    and just below CEILING, at 0 and at the top, steps in consecutive clocks both ways (an up step
    right after a down step, a wrap right after a wrap, ...): COUNT, EVENTS and STATUS.STOPPED
    equal the model's after each burst. (A lean build's count is free-running: free only.)"""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    top = model.max
    for mode in ("free",) if env.lean else ("modulo", "limit", "non_recycle", "free"):
        for ceiling in (ceilings(env.count_w) if mode != "free" else [top]):
            await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
            starts = near([ceiling + d for d in (-1, 0, 1, 2)] + [0, top], 0, top)
            for start in starts:
                await steps_from(env, model, start, BURST)
                what = f"{mode} CEILING {ceiling:#x} from {start:#x}, steps in consecutive clocks"
                await env.check(model, what)
                stopped = get_field("STATUS", "STOPPED", await bus.rd("STATUS"))
                assert stopped == int(model.stopped), f"{what}: STATUS.STOPPED {stopped}"


@cocotb_test()
async def en_off_gates_steps_only(dut):
    """CTRL.EN = 0 gates count steps only: steps leave COUNT as it is (no event of theirs), a COUNT
    write loads, an armed index preset loads PRESET and, one-shot, disarms (INDEX_CTRL.ARM and
    STATUS.INDEX_ARMED read 0; the next index pulse loads nothing). COUNT and EVENTS as the
    model's after each part."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    zf = lambda p: int(5 <= p % 40 <= 7)  # noqa: E731  an index pulse over positions 5..7 of 40
    await env.setup(model, count=1000, en=0)
    wf = walk([1] * 13 + [-1] * 4, durations(rng, 17), start_pos=env.pos)  # no index pulse
    await env.play(wf, model)
    await env.check(model, "EN 0, steps")
    value = 0x0000_0003_C3A5_5A3C & model.max
    await bus.set_count(value)
    model.write_count(value)
    await env.settle()
    await env.check(model, "EN 0, COUNT write")
    preset = 0x0000_0001_2345_6789 & model.max
    await bus.set64("PRESET", preset)
    model.preset = preset
    await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", ONESHOT=1, EDGE="rising", ARM=1))
    model.idx_action, model.idx_oneshot, model.idx_edge = "preset", True, "rising"
    model.idx_gate, model.idx_arm = None, True
    for k in range(2):  # forward over one index pulse: it presets; the second one does not
        wf = walk([1] * 40, durations(rng, 40), start_pos=env.pos)
        await env.play(wf, model, zfun=zf)
        assert model.idx_hits == k + 1
        await env.check(model, f"EN 0, index pulse {k + 1} of a one-shot preset")
        arm = get_field("INDEX_CTRL", "ARM", await bus.rd("INDEX_CTRL"))
        armed = get_field("STATUS", "INDEX_ARMED", await bus.rd("STATUS"))
        assert arm == armed == 0, \
            f"EN 0: INDEX_CTRL.ARM {arm}, STATUS.INDEX_ARMED {armed} after a one-shot preset"
        value = (value + 0x111) & model.max
        await bus.set_count(value)
        model.write_count(value)
        await env.settle()
        await env.check(model, f"EN 0, COUNT write after index pulse {k + 1}")


@cocotb_test()
async def en_off_keeps_the_rest(dut):
    """CTRL.EN = 0 gates the steps only; the rest keeps working (the RDL's EN): illegal jumps
    raise QERR and count in QERR_COUNT, rejected pulses raise GLITCH and count in GLITCH_COUNT,
    TIMEBASE advances, a probe edge latches the count into PROBE_LATCH with PROBE_TIME between
    the TIMEBASE reads around it and raises PROBE, and a COUNT write onto COMPARE raises CMP
    (the units a build has); COUNT stays the value written."""
    env, rng = await begin(dut)
    bus = env.bus
    have = units(await bus.rd("CAPS"))
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    model = QeiModel(env.count_w)
    count = 0x0000_0002_8000_0123 & model.max
    await env.setup(model, count=count, en=0, filter_len=3,
                    compare=None if "RANGE" not in have else count + 7)
    n_q, n_g = rng.randint(3, 9), rng.randint(3, 9)
    await illegal_jumps(env, n_q)
    await rejected_pulses(env, n_g)
    q, g = await bus.rd("QERR_COUNT"), await bus.rd("GLITCH_COUNT")
    assert q == n_q, f"EN 0: QERR_COUNT {q} after {n_q} illegal jumps"
    assert g == n_g, f"EN 0: GLITCH_COUNT {g} after {n_g} rejected pulses"
    ev = await bus.events()
    assert {"QERR", "GLITCH"} <= ev, f"EN 0: EVENTS {sorted(ev)} without QERR and GLITCH"
    assert await bus.count() == count, "EN 0: COUNT moved"
    t0 = await bus.rd("TIMEBASE")
    await Timer(50 * T_NS, unit="ns")
    t1 = await bus.rd("TIMEBASE")
    assert (t1 - t0) & ts_mask >= 50 or "TIMING" not in have, \
        f"EN 0: TIMEBASE {t0:#x} -> {t1:#x} in 50 clocks"
    if "PROBE" in have:
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1))
        await env.applied()
        before = await bus.rd("TIMEBASE")
        dut.probe_in.value = 1
        await env.settle(8)
        dut.probe_in.value = 0
        after = await bus.rd("TIMEBASE")
        latch = await bus.get64("PROBE_LATCH")
        t_probe = await bus.rd("PROBE_TIME")
        assert latch == count, f"EN 0: PROBE_LATCH {latch:#x}, count {count:#x}"
        assert 0 < (t_probe - before) & ts_mask < (after - before) & ts_mask or \
            "TIMING" not in have, \
            f"EN 0: PROBE_TIME {t_probe:#x} not between TIMEBASE {before:#x} and {after:#x}"
        assert "PROBE" in await bus.events(), "EN 0: a probe edge raised no PROBE"
    if "RANGE" in have:
        await bus.set_count(count + 7)
        await env.applied()
        await env.settle()
        assert "CMP" in await bus.events(), "EN 0: a COUNT write onto COMPARE raised no CMP"
    await bus.wr("PROBE_CTRL", 0)


FUNC_ALL = (1 << len(FUNCS)) - 1  # enc_qei's FUNC_MASK default: every count function


@cocotb_test(skip=build_param("FUNC_MASK", FUNC_ALL) == FUNC_ALL)
async def func_mask_builds(dut):
    """A build with some count functions (enc_qei parameter FUNC_MASK; CTRL.FUNC's text): with one,
    FUNC reads it whatever is written and counts with it; with several, FUNC reads back what was
    written, a built function counts as the model's and one left out counts nothing (no step, no
    QERR, on a walk with illegal jumps)."""
    env, rng = await begin(dut)
    bus = env.bus
    mask = int(dut.FUNC_MASK.value)
    built = [f for f in FUNCS if mask >> enum("CTRL", "FUNC")[f] & 1]
    for func in FUNCS:
        model = QeiModel(env.count_w)
        await env.setup(model, func=built[0] if len(built) == 1 else func, count=100)
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC=func, FILTER_LEN=FILTER))
        await env.applied()
        got = get_field("CTRL", "FUNC", await bus.rd("CTRL"))
        want = enum("CTRL", "FUNC")[built[0] if len(built) == 1 else func]
        assert got == want, f"FUNC_MASK {mask:#x}: FUNC written {func}, reads {got}, not {want}"
        await bus.events()
        wf = walk_with_jumps(rng, 60, env.pos, 3)
        await env.play(wf, model if func in built or len(built) == 1 else None)
        count, ev = await bus.count(), await bus.events()
        if func in built or len(built) == 1:
            assert count == model.count, f"FUNC_MASK {mask:#x}, FUNC {func}: COUNT {count}, model {model.count}"
        else:
            assert count == 100 and "QERR" not in ev, \
                f"FUNC_MASK {mask:#x}, FUNC {func} left out: COUNT {count} (100), EVENTS {sorted(ev)}"


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_counting(config):
    run_feature(__name__, *config)


@pytest.mark.parametrize("mask", (1 << 3, 1 << 0 | 1 << 3 | 1 << 5), ids=("x1a", "x4-x1a-pulse_dir"))
def test_counting_func_mask(mask):
    from enctools.harness import run

    run("enc_qei_wb", __name__, name=f"enc_qei_wb_func_mask_{mask}", parameters={"FUNC_MASK": mask},
        testcase="func_mask_builds")
