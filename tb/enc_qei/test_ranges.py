# SPDX-License-Identifier: Apache-2.0
"""enc_qei range modes (free, modulo, limit, non_recycle) and CEILING: across the bounds both
ways, CEILINGs with every bit pattern, bounded ranges at the count-rate bound, step pairs and
bursts of steps in consecutive clocks at the bounds. A lean build's count is free-running (RANGE
reads free, CEILING is absent): it runs the free range's tests only.

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import random

import cocotb
import pytest
from cocotb.triggers import ClockCycles, FallingEdge
from hedsmodel import QUAD, random_walk, walk

from enctools.qei.bus import T_NS, signed
from enctools.qei.env import CONFIG_IDS, CONFIGS, Timebase, begin, engine_period, lacks, run_feature
from enctools.qei.model import RANGES, QeiModel
from enctools.qei.stimulus import BURST, WIDE, durations, near, slice_compare_cases, steps_from
from enctools.regmap import get_field, pack, regmap
from enctools.tb import cocotb_test


@cocotb_test()
async def range_modes(dut):
    """Each RANGE across its boundaries, both ways; non_recycle stops until COUNT is written."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    for mode in ("free",) if env.lean else RANGES:
        ceiling = rng.randint(5, 12) if mode != "free" else model.max
        start_count = 2 if mode != "free" else model.max - 2
        await env.setup(model, func="x4", rng_mode=mode, count=start_count, ceiling=ceiling)
        # up across the top, down across 0, up again, in small checked pieces
        for direction, n in ((1, 20), (-1, 40), (1, 9), (-1, 3), (1, 30)):
            done = 0
            while done < n:
                k = min(n - done, rng.randint(1, 5))
                wf = walk([direction] * k, durations(rng, k), start_pos=env.pos)
                await env.play(wf, model)
                await env.check(model, f"{mode} dir {direction}")
                status = await bus.rd("STATUS")
                stopped = status >> regmap()["STATUS"].fields["STOPPED"].lsb & 1
                assert stopped == int(model.stopped), f"{mode}: STATUS.STOPPED {stopped}"
                done += k
            if mode == "non_recycle" and model.stopped:
                value = rng.randint(1, ceiling - 1)
                await bus.set_count(value)
                model.write_count(value)
                await env.settle()
                await env.check(model, "non_recycle after COUNT write")
        dut._log.info("%s ok (ceiling %d)", mode, ceiling)


@cocotb_test(skip=lacks("RANGE"))
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


@cocotb_test(skip=lacks("RANGE"))
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
        await env.applied()  # (the shared engine: PRESET and INDEX_CTRL act before the walk)
        wf = random_walk(rng, 400, 1.05 * T_NS + 0.1, 2.1 * T_NS, p_reverse=0.5, start_pos=env.pos)
        await env.play(wf, model, zfun=lambda p: int(p % 7 == 0))
        await env.check(model, f"{mode} CEILING {ceiling:#x} PRESET {preset:#x} fast")
        await bus.wr("INDEX_CTRL", 0)
        model.idx_action = "none"


# the CEILINGs of the step-pair test: 0, 1 (every count but 0 is at it), small, high bits
def _pair_ceilings(count_w):
    return [0, 1, 0x8000_8021]


@cocotb_test(skip=lacks("RANGE"))
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
            for start in near([ceiling + d for d in (-1, 0, 1, 2)] + [0, 1], 0, top):
                for pair in ((-1, +1), (+1, -1), (+1, +1)):
                    await steps_from(env, model, start, pair)
                    what = f"{mode} CEILING {ceiling:#x} from {start:#x}, steps {pair}"
                    await env.check(model, what)
                    stopped = get_field("STATUS", "STOPPED", await bus.rd("STATUS"))
                    assert stopped == int(model.stopped), f"{what}: STATUS.STOPPED {stopped}"


@cocotb_test(skip=lacks("RANGE"))
async def steps_at_patterned_ceilings(dut):
    """CEILINGs with bit patterns from a fixed seed (deterministic: random.Random(1414), the same
    list every run), each range, counts one step and one or five units of a 16-bit slice away:
    the slice comparators of the at-CEILING flags with every carry pattern, under steps in
    consecutive clocks (the BURST of steps_in_consecutive_clocks). Then the WIDE CEILINGs and
    their complements (every bit of CEILING - 2, CEILING - 1 and CEILING both 0 and 1 among them,
    so that no bit of a flag's comparator is left at one value) in every range, from one and two
    steps below CEILING and one above: the +1 candidate of a flag (CEILING - 2's comparator) is
    read only by a step in the clock right after a step."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    top = model.max
    pick = random.Random(1414)
    cases = []
    for i in range(12):
        mode = ("modulo", "limit", "non_recycle")[i % 3]
        sl = pick.randrange(0, max(1, env.count_w // 16))
        ceiling = pick.getrandbits(env.count_w) >> pick.randrange(0, env.count_w)
        cases.append((mode, ceiling, (-1, 1, 2, -(1 << 16 * sl), 1 << 16 * sl, 5 << 16 * sl, -(5 << 16 * sl))))
    for ceiling in WIDE + tuple(~v for v in WIDE):
        for mode in ("modulo", "limit", "non_recycle"):
            cases.append((mode, ceiling & top, (-2, -1, 1)))
    for mode, ceiling, ds in cases:
        await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
        for d in ds:
            start = ceiling + d
            if not 0 <= start <= top:
                continue
            await steps_from(env, model, start, BURST)
            await env.check(model, f"{mode} CEILING {ceiling:#x} from {start:#x}, steps in consecutive clocks")


@cocotb_test(skip=lacks("RANGE"))
async def non_recycle_stop_holds(dut):
    """non_recycle stopped at CEILING (and at 0): a RANGE change to free, modulo or limit does not
    release it (steps both ways count nothing and raise no OVERFLOW / UNDERFLOW, STATUS.STOPPED
    stays 1; SNAP_DELTA still counts them), nor does an index preset; a COUNT write does, and the
    new range counts from there. COUNT, EVENTS, STOPPED vs the model."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus

    timing = not lacks("TIMING")

    async def stopped(what, want):
        await env.settle()
        got = get_field("STATUS", "STOPPED", await bus.rd("STATUS"))
        assert got == want == int(model.stopped), f"{what}: STATUS.STOPPED {got}, model {model.stopped}"

    for other in ("free", "modulo", "limit"):
        for start, d in ((7, 1), (3, -1)):  # up to CEILING 10, down to 0
            await env.setup(model, rng_mode="non_recycle", filter_len=1, count=start, ceiling=10)
            steps = [d] * 8
            await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
            await env.check(model, f"non_recycle from {start}")
            await stopped(f"non_recycle from {start}", 1)
            ctrl = pack("CTRL", EN=1, FUNC="x4", RANGE=other, FILTER_LEN=1)
            await bus.wr("CTRL", ctrl)
            model.range = other
            await env.applied()
            if timing:  # (the stopped counter's steps are still motion: SNAP_DELTA counts them)
                await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
                await env.settle(4)
                await bus.events()  # (SNAP_READY: not the model's)
            steps = [1, 1, -1, -1, -1, 1]
            await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
            await env.check(model, f"stopped, then RANGE {other}")
            await stopped(f"stopped, then RANGE {other}", 1)
            if timing:
                await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
                await env.settle(4)
                delta = signed(await bus.rd("SNAP_DELTA"))
                assert delta == sum(steps), f"stopped, RANGE {other}: SNAP_DELTA {delta}, motion {sum(steps)}"
                await bus.events()
            # an index preset loads PRESET but does not release it
            await bus.set64("PRESET", 4)
            model.preset = 4
            await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
            model.idx_action, model.idx_oneshot, model.idx_edge = "preset", False, "rising"
            model.idx_gate, model.idx_arm = None, True
            await env.applied()
            zf = lambda p, p0=env.pos: int(p == p0 + 1)  # noqa: E731  Z high over one state
            steps = [1, 1, -1, -1]
            await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model,
                           zfun=zf)
            assert model.idx_hits >= 1, "no index pulse reached the model"
            model.idx_hits = 0
            await bus.wr("INDEX_CTRL", 0)
            model.idx_action = "none"
            await env.check(model, f"stopped, RANGE {other}, an index preset")
            await stopped(f"stopped, RANGE {other}, an index preset", 1)
            assert await bus.count() == 4, f"stopped, RANGE {other}: the index preset did not load PRESET"
            await bus.set_count(5)
            model.write_count(5)
            await env.applied()
            await stopped("COUNT written", 0)
            steps = [1, 1, -1]
            await env.play(walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos), model)
            await env.check(model, f"COUNT written, RANGE {other}")
    assert model.count == 6, f"the last walk counted to {model.count}, not 6"


@cocotb_test()
async def free_range_ignores_ceiling(dut):
    """RANGE free with CEILING set below the top (free ignores it): steps in consecutive clocks
    across CEILING, and at 0 and the top: COUNT and EVENTS as the model's (no wrap at CEILING)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    top = model.max
    for ceiling in (0, 0x25, 0x8000_8021):
        await env.setup(model, rng_mode="free", filter_len=1, count=0, ceiling=ceiling)
        for start in near([ceiling - 1, ceiling, ceiling + 1, 0, top], 0, top):
            await steps_from(env, model, start, BURST)
            await env.check(model, f"free, CEILING {ceiling:#x}, from {start:#x}")


@cocotb_test(skip=lacks("RANGE"))
async def single_bit_ceilings(dut):
    """CEILING = 2^k and 2^k + 1 for every bit k above 0, in modulo and limit: steps in
    consecutive clocks from 0 up and back down across 0 (the "CEILING <= 1" flag of the next
    count's candidates must see every bit of CEILING)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    for mode in ("modulo", "limit"):
        await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=0x25)
        for k in range(1, env.count_w):
            for ceiling in (1 << k, 1 << k | 1):
                await env.bus.set64("CEILING", ceiling)
                model.ceiling = ceiling
                await steps_from(env, model, 0, (+1, +1, -1, -1, -1, 0, +1, 0))
                await env.check(model, f"{mode} CEILING {ceiling:#x}, steps from 0")


@cocotb_test(skip=lacks("RANGE"))
async def ceiling_slice_compares(dut):
    """COUNT loaded just below or above CEILING in one 16-bit slice above the lowest (the count
    compares with CEILING slice by slice: a >= b from the slices' > and >=), in modulo, then one
    step up and one down: below it counts on, at or above it wraps (every bit of every upper
    slice of CEILING must reach the compare, with the slice's bit 0 set or not)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    await env.setup(model, rng_mode="modulo", filter_len=1, count=0)
    for ceiling, counts in slice_compare_cases(env.count_w):
        await env.bus.set64("CEILING", ceiling)
        model.ceiling = ceiling
        for count in counts:
            await steps_from(env, model, count, (+1, -1))
            await env.check(model, f"CEILING {ceiling:#x}, COUNT {count:#x}, +1 -1")


# (TIMING: the phase of the engine's visits is found from the timebase, which the counting
# profile leaves out; the full and lean builds run it)
@cocotb_test(skip=lacks("RANGE", "TIMING"))
async def range_change_across_the_wrap(dut):
    """CTRL.RANGE written from free to limit or modulo (CEILING 1000, COUNT_W 8: 127) while the count crosses the
    end of the free range: from 2 four steps down and two up, or from all ones - 1 six steps up,
    3 clocks apart, starting i clocks after the CTRL write starts. With the shared engine every
    write starts at one phase of its visits and i runs over 2 P + 24 clocks, so the new range is
    applied before, between and after the steps, in the window right after a crossing too (its
    range ends then come from a count on the other side of the end); a per-channel build applies
    it at once (i over 8 clocks). COUNT and EVENTS (DIR_CHANGE aside) must be those of the range
    changing at one of the seven points between the steps: a count just below 2^COUNT_W is at or
    above CEILING, one just above 0 below it."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    ceiling = min(1000, model.max // 2)  # (COUNT_W 8: 127)
    cases = (("limit", 2, (-1, -1, -1, -1, 1, 1)), ("modulo", 2, (-1, -1, -1, -1, 1, 1)),
             ("limit", -2, (1,) * 6), ("modulo", -2, (1,) * 6))
    clock = Timebase(dut)
    p = engine_period(int(dut.CHANNELS.value)) if env.engine else 1
    span = 2 * p + 24 if env.engine else 8
    r0 = rng.randrange(p)
    for i in range(span):
        mode, start, steps = cases[i % len(cases)]
        start &= model.max
        await env.setup(model, rng_mode="free", filter_len=1, count=start, ceiling=ceiling)
        await clock.phase(p, r0)

        async def play() -> None:
            for _ in range(i):
                await FallingEdge(dut.clk)
            for s in steps:
                env.pos += s
                dut.a_in.value, dut.b_in.value = QUAD[env.pos % 4]
                await ClockCycles(dut.clk, 3)

        task = cocotb.start_soon(play())
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", RANGE=mode, FILTER_LEN=1))
        await task
        await env.settle()
        await env.applied()
        got = (await bus.count(), await bus.events() - {"DIR_CHANGE"})
        outcomes = []
        for k in range(len(steps) + 1):  # the range changes after step k
            m = QeiModel(env.count_w)
            m.count, m.ceiling = start, ceiling
            for n, s in enumerate(steps):
                m.range = "free" if n < k else mode
                m.apply(s)
            outcomes.append((m.count, m.events - {"DIR_CHANGE"}))
        assert got in outcomes, \
            f"{mode} from {start:#x}, steps {steps} {i} clocks after the CTRL write: COUNT {got[0]:#x}, " \
            f"EVENTS {sorted(got[1])}; the range changing between two steps gives one of " \
            + ", ".join(f"({c:#x}, {sorted(e)})" for c, e in outcomes)
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1))


@cocotb_test(skip=lacks("RANGE"))
async def ranges_beside_index_options(dut):
    """RANGE modulo and limit with CEILING 20 and 21 while INDEX_CTRL holds options without an
    action (ONESHOT; the gate on A and B; EDGE falling with ARM): up across CEILING and down across
    0, COUNT and EVENTS as the model's. The channel's configuration travels as one word; a bit of
    CEILING taken wrong while an unrelated bit of it is set shows only at CEILING's own ends."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    for opts in (dict(ONESHOT=1), dict(GATE_EN=1, GATE_A=1, GATE_B=1), dict(EDGE="falling", ARM=1)):
        for mode, ceiling in (("modulo", 20), ("limit", 21), ("modulo", 21), ("limit", 20)):
            await env.setup(model, rng_mode=mode, count=ceiling - 3, ceiling=ceiling, filter_len=1)
            await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none", **opts))
            await env.applied()
            for direction, n in ((1, 6), (-1, 28), (1, 5)):
                wf = walk([direction] * n, [3 * T_NS] * n, start_pos=env.pos)
                await env.play(wf, model)
                await env.check(model, f"INDEX_CTRL {opts}, {mode} CEILING {ceiling}, {n} steps "
                                       f"{'up' if direction > 0 else 'down'}")
            await bus.wr("INDEX_CTRL", 0)

# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_ranges(config):
    run_feature(__name__, *config)
