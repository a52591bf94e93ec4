# SPDX-License-Identifier: Apache-2.0
"""enc_qei index and probe: INDEX_CTRL actions (preset, latch, none), the gate, one-shot, edges,
the latches with wide values, index edges at steps and wraps; PROBE_CTRL, PROBE_LATCH and
PROBE_TIME; which configuration changes are not index edges, and that a gate change is one. A
lean build has no probe unit and a free-running count: its index tests run in the free range
(wraps at 0 and the top).

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import pytest
from cocotb.triggers import ClockCycles, FallingEdge, Timer
from hedsmodel import QUAD, walk

from enctools.qei.bus import PERIOD_PS, T_NS
from enctools.qei.env import CONFIG_IDS, CONFIGS, begin, lacks, run_feature
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import (FILTER, WIDE, ceilings, durations, near, play_clocks,
                                   slice_compare_cases, step_clocks)
from enctools.regmap import pack, regmap
from enctools.tb import cocotb_test


@cocotb_test()
async def index(dut):
    """INDEX_CTRL: preset / latch / none, gate, one-shot, rising and falling, forward and back."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    # index pulse over positions 5..7 of every 40 (a state and a half wide, like a real one)
    zf = lambda p: int(5 <= p % 40 <= 7)  # noqa: E731
    cases = [
        dict(action="preset", gate=None, edge="rising", oneshot=False),
        dict(action="preset", gate=QUAD[6 % 4], edge="rising", oneshot=False),
        dict(action="latch", gate=QUAD[6 % 4], edge="falling", oneshot=False),
        dict(action="latch", gate=None, edge="falling", oneshot=True),
        dict(action="preset", gate=QUAD[5 % 4], edge="rising", oneshot=True),
        dict(action="none", gate=QUAD[7 % 4], edge="rising", oneshot=False),
    ]
    for case in cases:
        await env.setup(model, func="x4", count=1000)
        preset = rng.randint(100, 200)
        await bus.set64("PRESET", preset)
        model.preset = preset
        # registers that do not act here hold any value (SNAP_CTRL.PERIOD_EN and CTRL.CMP_EN
        # stay 0): the shared engine keeps them in one configuration word with PRESET's low bits
        # (SNAP_PERIOD there only below 2^TIM_W, 256 at one channel: 128 .. 255 sets its top bit)
        await bus.wr("SNAP_PERIOD", rng.randint(0x80, 0xFF))
        await bus.set64("COMPARE", rng.getrandbits(32))
        gate = case["gate"]
        word = pack("INDEX_CTRL", ACTION=case["action"], ONESHOT=int(case["oneshot"]),
                    EDGE=case["edge"], GATE_EN=int(gate is not None),
                    GATE_A=gate[0] if gate else 0, GATE_B=gate[1] if gate else 0, ARM=1)
        await bus.wr("INDEX_CTRL", word)
        model.idx_action, model.idx_oneshot, model.idx_edge = case["action"], case["oneshot"], case["edge"]
        model.idx_gate, model.idx_arm = gate, True
        status = await bus.rd("STATUS")
        armed = status >> regmap()["STATUS"].fields["INDEX_ARMED"].lsb & 1
        assert armed == int(case["action"] != "none"), f"{case}: STATUS.INDEX_ARMED {armed}"
        # forward through two index pulses, back through both, dither over one
        for steps in ([1] * 90, [-1] * 90, [1, -1] * 6 + [1] * 8 + [-1, 1] * 6):
            wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
            await env.play(wf, model, zfun=zf)
            await env.check(model, f"index {case}")
            latch = await bus.get64("INDEX_LATCH")
            assert latch == model.idx_latch, f"{case}: INDEX_LATCH {latch}, model {model.idx_latch}"
            arm = (await bus.rd("INDEX_CTRL")) >> regmap()["INDEX_CTRL"].fields["ARM"].lsb & 1
            assert arm == int(model.idx_arm), f"{case}: INDEX_CTRL.ARM {arm}, model {model.idx_arm}"
        assert model.idx_hits >= 4
        dut._log.info("index %s: %d qualified index pulses", case, model.idx_hits)
        model.idx_hits = 0
    await bus.wr("INDEX_CTRL", 0)
    model.idx_action = "none"


@cocotb_test()
async def index_with_z_inverted(dut):
    """CTRL.INV_Z = 1 with an active-low index at the pins (z_in idle high, low over the pulse):
    the decoder's Z is the inverse, so INDEX_CTRL.EDGE rising is z_in falling. Preset on rising
    with a gate, latch on falling, none: COUNT, EVENTS, INDEX_LATCH and ARM as the model's fed
    the inverted Z, forward, back and dithering over the pulse."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    zf = lambda p: int(5 <= p % 40 <= 7)  # noqa: E731  (the decoder's Z; the pins carry 1 - zf)
    dut.z_in.value = 1 - zf(env.pos)
    for action, gate, edge in (("preset", QUAD[6 % 4], "rising"), ("latch", None, "falling"),
                               ("none", None, "rising")):
        await env.setup(model, func="x4", count=1000)
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=FILTER, INV_Z=1))
        preset = rng.randint(100, 200)
        await bus.set64("PRESET", preset)
        model.preset = preset
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE=edge,
                                        GATE_EN=int(gate is not None), GATE_A=gate[0] if gate else 0,
                                        GATE_B=gate[1] if gate else 0, ARM=1))
        model.idx_action, model.idx_oneshot, model.idx_edge = action, False, edge
        model.idx_gate, model.idx_arm = gate, True
        await env.applied()
        for steps in ([1] * 90, [-1] * 90, [1, -1] * 6 + [1] * 8 + [-1, 1] * 6):
            wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
            pins = [(t, 1 - zf(p)) for (t, _, _), p in zip(wf.events, wf.positions)]
            await env.drv.play(wf, index=pins)
            for (_, a, b), p in zip(wf.events, wf.positions):
                model.sample((a, b), zf(p))
            env.pos = wf.positions[-1]
            await env.settle()
            what = f"INV_Z, {action} on {edge}" + (f" gated {gate}" if gate else "")
            await env.check(model, what)
            latch = await bus.get64("INDEX_LATCH")
            assert latch == model.idx_latch, f"{what}: INDEX_LATCH {latch}, model {model.idx_latch}"
        assert model.idx_hits >= 4, f"INV_Z, {action}: {model.idx_hits} qualified index pulses"
        model.idx_hits = 0
    await bus.wr("INDEX_CTRL", 0)
    await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=FILTER))
    dut.z_in.value = 0


@cocotb_test()
async def index_gate_same_position(dut):
    """With the gate, a preset index gives the same position forward and backward."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0)
    preset = 500 & model.max  # (COUNT_W 8: 0xF4)
    await bus.set64("PRESET", preset)
    gate = QUAD[6 % 4]
    await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", GATE_EN=1, GATE_A=gate[0],
                                    GATE_B=gate[1], ARM=1))
    await env.applied()
    zf = lambda p: int(5 <= p <= 7)  # noqa: E731
    for direction in (1, -1, 1, -1):
        target = 12 if direction > 0 else 0
        steps = [direction] * abs(target - env.pos)
        wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
        await env.play(wf, None, zfun=zf)
        got = await bus.count()
        # the count equals PRESET at position 6, whichever way it was crossed
        assert got == (preset + target - 6) & model.max, f"direction {direction}: count {got}"


@cocotb_test(skip=lacks("PROBE"))
async def probe(dut):
    """PROBE_CTRL: the count and the timebase at the chosen edge; ONCE clears EN. Without the
    timing unit (CAPS.TIMING 0, the counting profile) PROBE_TIME reads 0."""
    env, rng = await begin(dut)
    timing = not lacks("TIMING")
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0)
    lsb_en = regmap()["PROBE_CTRL"].fields["EN"].lsb
    for edge, once in (("rising", 0), ("falling", 0), ("rising", 1)):
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE=edge, ONCE=once))
        for k in range(3):
            steps = [rng.choice([1, -1])] * rng.randint(3, 10)
            wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
            await env.play(wf, model)
            before = await bus.rd("TIMEBASE")
            lead = (edge == "falling")
            dut.probe_in.value = 1
            await Timer(rng.randint(60, 90) * 1000 + 3, unit="ps")
            dut.probe_in.value = 0
            await env.settle()
            after = await bus.rd("TIMEBASE")
            latch = await bus.rd("PROBE_LATCH_LO") | await bus.rd("PROBE_LATCH_HI") << 32
            t = await bus.rd("PROBE_TIME")
            ev = await bus.events()
            if once and k > 0:
                assert "PROBE" not in ev, "a ONCE probe latched twice"
                continue
            assert "PROBE" in ev, f"no PROBE event ({edge}, once={once})"
            assert latch == model.count, f"PROBE_LATCH {latch}, count {model.count}"
            if timing:
                assert before < t < after, f"PROBE_TIME {t} outside {before}..{after} (lead {lead})"
            else:
                assert before == t == after == 0, f"no timing unit: TIMEBASE {before}, {after}, PROBE_TIME {t}"
            en = (await bus.rd("PROBE_CTRL")) >> lsb_en & 1
            assert en == (0 if once else 1), f"PROBE_CTRL.EN {en} after a latch (once={once})"
    await bus.wr("PROBE_CTRL", 0)


@cocotb_test()
async def latches_wide(dut):
    """PROBE_LATCH and INDEX_LATCH of counts with every bit pattern (the high word too; a lean
    build: INDEX_LATCH)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    probe = not lacks("PROBE")
    for value in WIDE + tuple(~v for v in WIDE):
        value &= model.max
        await env.setup(model, count=value)
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE="rising"))
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="latch", EDGE="rising", ARM=1))
        await env.applied()
        dut.probe_in.value = 1
        dut.z_in.value = 1
        await env.settle(10)
        dut.probe_in.value = 0
        dut.z_in.value = 0
        await env.settle(10)
        for gap in (1, 2, 0):  # held: the same value at reads an odd and an even clock apart
            if probe:
                got = await bus.rd("PROBE_LATCH_LO") | await bus.rd("PROBE_LATCH_HI") << 32
                assert got == value, f"PROBE_LATCH {got:#x}, count {value:#x}"
            index = await bus.get64("INDEX_LATCH")
            assert index == value, f"INDEX_LATCH {index:#x}, count {value:#x}"
            await ClockCycles(dut.clk, gap) if gap else None
        await bus.wr("PROBE_CTRL", 0)
        await bus.wr("INDEX_CTRL", 0)


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
            latch = await bus.get64("INDEX_LATCH")
            assert latch == model.idx_latch, \
                f"gate {gate}, Z in {QUAD[env.pos % 4]}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
    await bus.wr("INDEX_CTRL", 0)


@cocotb_test()
async def index_at_steps(dut):
    """An index preset in the clock right before steps in consecutive clocks (PRESET at, just above
    and just below CEILING, also in another 16-bit slice), and an index latch in the very clock of
    a wrap (down from 0 to CEILING, up from CEILING to 0) or of a step: COUNT, EVENTS and
    INDEX_LATCH equal the model's, in every bounded range (a lean build: in the free range, its
    wraps at 0 and the top)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    top = model.max
    for action in ("preset", "latch"):
        for mode in ("free",) if env.lean else ("modulo", "limit", "non_recycle"):
            for ceiling in [top] if env.lean else ceilings(env.count_w, zero=False):
                await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
                await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE="rising", ARM=1))
                model.idx_action, model.idx_oneshot, model.idx_edge = action, False, "rising"
                model.idx_gate, model.idx_arm = None, True
                lo16 = ceiling & ~0xFFFF  # the same upper slices, a lower low slice
                values = near([ceiling - 1, ceiling, ceiling + 1, 0] + ([lo16 | 0x10] if action ==
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


@cocotb_test(skip=lacks("PROBE"))
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
        await env.applied()
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


# ---- configuration changes are not index edges --------------------------------------------------
def _gate_state(option, ab, value):
    """The (A, B) state the index gate compares, for raw state ab with CTRL.<option> = value."""
    a, b = ab
    if option == "SWAP_AB" and value:
        a, b = b, a
    if option == "INV_A":
        a ^= value
    if option == "INV_B":
        b ^= value
    return a, b


@cocotb_test()
async def ctrl_change_is_not_an_index_edge(dut):
    """A CTRL write that changes INV_Z (Z steady, low or high), or SWAP_AB / INV_A / INV_B with the
    index gate on (Z high: the A/B state the gate compares enters or leaves the gate's), changes
    the qualified index level the way the armed EDGE acts on: no INDEX event and no action (an
    armed preset loads nothing, a latch keeps its value), for either EDGE. A real Z edge right
    after still acts (preset: COUNT = PRESET; latch: INDEX_LATCH = the count)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await env.play(walk([1], [3 * T_NS], start_pos=env.pos), None)  # state (1, 0): A != B
    ab = QUAD[env.pos % 4]
    preset = 0x0000_0007_5A5A_0123 & model.max
    await bus.set64("PRESET", preset)

    async def latch():
        return await bus.get64("INDEX_LATCH")

    def ctrl(option, value):
        return pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1, **{option: value})

    cases = [("INV_Z", z, edge, action) for z in (0, 1) for edge in ("rising", "falling")
             for action in ("preset", "latch")]
    cases += [(option, 1, edge, action) for option in ("SWAP_AB", "INV_A", "INV_B")
              for edge in ("rising", "falling") for action in ("preset", "latch")]
    for k, (option, z, edge, action) in enumerate(cases):
        before = int(edge == "falling")  # the qualified index level before the change
        if option == "INV_Z":  # Z ^ INV_Z goes from `before` to the other level
            v0, gate = z ^ before, None
        else:  # in the gate after the change (rising) or before it (falling)
            v0, gate = 0, _gate_state(option, ab, before ^ 1)
        what = f"{option} {v0} -> {1 - v0} (Z {z}, {action} on the {edge} edge" + \
            (f", gate {gate})" if gate else ")")
        await bus.wr("INDEX_CTRL", 0)
        dut.z_in.value = z
        await bus.wr("CTRL", ctrl(option, v0))
        count = (0x100 + 0x10 * k) & model.max
        await bus.set_count(count)
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE=edge, ARM=1,
                                        GATE_EN=int(gate is not None), GATE_A=gate[0] if gate else 0,
                                        GATE_B=gate[1] if gate else 0))
        await env.settle(4)
        held = await latch()
        await bus.events()
        await bus.wr("CTRL", ctrl(option, 1 - v0))
        await env.settle(4)
        ev = await bus.events()
        assert "INDEX" not in ev, f"{what}: the CTRL write raised INDEX ({sorted(ev)})"
        got = await bus.count()
        assert got == count, f"{what}: the CTRL write changed COUNT to {got:#x} (was {count:#x})"
        got = await latch()
        assert got == held, f"{what}: the CTRL write changed INDEX_LATCH to {got:#x} (was {held:#x})"
        # a real Z edge right after: a pulse of Z makes one edge of the armed type (with the gate
        # and the falling edge, back into the gate first: no edge either)
        count2 = (count + 5) & model.max
        await bus.set_count(count2)
        if gate is not None and edge == "falling":
            await bus.wr("CTRL", ctrl(option, v0))
        await env.applied()  # (the shared engine: the writes act before the Z edge)
        await FallingEdge(dut.clk)
        dut.z_in.value = 1 - z
        await ClockCycles(dut.clk, 3)
        await FallingEdge(dut.clk)
        dut.z_in.value = z
        await env.settle(6)
        ev = await bus.events()
        assert "INDEX" in ev, f"{what}: no INDEX event from the Z edge after the CTRL write"
        if action == "preset":
            got = await bus.count()
            assert got == preset, f"{what}: COUNT {got:#x} after the Z edge, PRESET {preset:#x}"
        else:
            got = await latch()
            assert got == count2, f"{what}: INDEX_LATCH {got:#x} after the Z edge, count {count2:#x}"
    await bus.wr("INDEX_CTRL", 0)


@cocotb_test()
async def gate_change_is_an_index_edge(dut):
    """An INDEX_CTRL write that changes the gate (GATE_EN, or GATE_A / GATE_B) with Z high and A, B
    still changes the qualified index, and that change is an index edge (the RDL): armed in the
    same write, it raises INDEX and performs ACTION (preset: COUNT = PRESET); written with ARM = 0
    it raises INDEX only, and arming after it does nothing more. Either direction, for the EDGE
    that the change makes; a change that makes the other edge raises nothing."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, filter_len=1)
    await env.play(walk([1], [3 * T_NS], start_pos=env.pos), None)
    ab = QUAD[env.pos % 4]
    other = QUAD[(env.pos + 2) % 4]  # a state the shaft is not in
    preset = 0x3A5 & model.max
    await bus.set64("PRESET", preset)
    dut.z_in.value = 1

    def gate(on, state):
        return dict(GATE_EN=on, GATE_A=state[0], GATE_B=state[1])

    # (before, after, the edge it makes): qualified index 0 -> 1 is rising, 1 -> 0 falling
    changes = [(gate(1, other), gate(0, other), "rising"),
               (gate(1, other), gate(1, ab), "rising"),
               (gate(0, other), gate(1, other), "falling"),
               (gate(1, ab), gate(1, other), "falling")]

    def index_ctrl(g, edge, arm):
        return pack("INDEX_CTRL", ACTION="preset", EDGE=edge, ARM=arm, **g)

    for k, (g0, g1, made) in enumerate(changes):
        for edge in ("rising", "falling"):
            for arm in (1, 0):
                what = f"gate {g0} -> {g1} ({made} edge), EDGE {edge}, ARM {arm} in the write"
                count = (0x100 + 0x20 * k) & model.max
                await bus.wr("INDEX_CTRL", index_ctrl(g0, edge, 0))
                await bus.set_count(count)
                await env.applied()
                await env.settle(4)
                await bus.events()
                await bus.wr("INDEX_CTRL", index_ctrl(g1, edge, arm))
                await env.applied()
                await env.settle(4)
                if not arm:
                    await bus.wr("INDEX_CTRL", index_ctrl(g1, edge, 1))
                    await env.applied()
                    await env.settle(4)
                ev = await bus.events()
                got = await bus.count()
                acts = edge == made
                assert ("INDEX" in ev) == acts, f"{what}: events {sorted(ev)}"
                want = preset if acts and arm else count
                assert got == want, f"{what}: COUNT {got:#x}, wanted {want:#x}"
    await bus.wr("INDEX_CTRL", 0)
    dut.z_in.value = 0


@cocotb_test()
async def index_preset_at_wraps(dut):
    """An index preset in the very clock of a step at a bound (up from CEILING, down from 0: a
    wrap in modulo, a blocked step in limit and non_recycle), then a step in the next clock, in
    every bounded range: the load wins, and the next step starts from the preset value (the
    at-zero and at-CEILING flags computed for that clock are the preset's, not the wrap's). A lean
    build: in the free range (CEILING the top)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    for mode in ("free",) if env.lean else ("modulo", "limit", "non_recycle"):
        for ceiling in (model.max,) if env.lean else ceilings(env.count_w, zero=False)[:2]:
            await env.setup(model, rng_mode=mode, filter_len=1, count=0, ceiling=ceiling)
            await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
            model.idx_action, model.idx_oneshot, model.idx_edge = "preset", False, "rising"
            model.idx_gate, model.idx_arm = None, True
            for preset in near([0, 1, ceiling // 2, ceiling - 1, ceiling], 0, model.max):
                await bus.set64("PRESET", preset)
                model.preset = preset
                for before, steps in ((ceiling, (+1, -1, 0)), (ceiling, (+1, +1, 0)),
                                      (0, (-1, +1, 0)), (0, (-1, -1, 0))):
                    await bus.set_count(before)
                    model.write_count(before)
                    await env.settle(4)
                    await play_clocks(env, model, step_clocks(env.pos, steps, (1, 0, 0)))
                    await env.settle(4)
                    await env.check(model, f"{mode} CEILING {ceiling:#x}: PRESET {preset:#x} in "
                                    f"the clock of a step from {before:#x}, steps {steps}")
            await bus.wr("INDEX_CTRL", 0)
            model.idx_action = "none"


@cocotb_test()
async def z_and_probe_filter_lengths(dut):
    """Z and probe_in go through a filter of CTRL.FILTER_LEN samples like A and B: at FILTER_LEN
    4 .. 7 and 12 .. 15 (bit 2 set) and 8, a pulse of FILTER_LEN - 1 clocks is rejected (no INDEX,
    no PROBE event) and one of FILTER_LEN + 1 clocks is taken (INDEX on its rising edge, PROBE
    with PROBE_CTRL on rising edges; a lean build: Z only). A level rejected on Z or probe_in is
    no GLITCH (EVENTS.GLITCH and GLITCH_COUNT are A's and B's)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    pins = ((dut.z_in, "INDEX"),) + (() if lacks("PROBE") else ((dut.probe_in, "PROBE"),))
    for f in (4, 5, 6, 7, 8, 12, 15):
        await env.setup(model, filter_len=f)
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none", EDGE="rising"))
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE="rising"))
        for sig, event in pins:
            for clocks, taken in ((f - 1, False), (f + 1, True)):
                await bus.events()
                await env.applied()
                await FallingEdge(dut.clk)
                sig.value = 1
                await ClockCycles(dut.clk, clocks)
                await FallingEdge(dut.clk)
                sig.value = 0
                await env.settle(2 * f + 8)
                ev = await bus.events()
                assert (event in ev) == taken, \
                    f"FILTER_LEN {f}: a {clocks}-clock pulse on {event}: events {sorted(ev)}"
                assert "GLITCH" not in ev and await bus.rd("GLITCH_COUNT") == 0, \
                    f"FILTER_LEN {f}: a {clocks}-clock pulse on {event} raised GLITCH"
    await bus.wr("PROBE_CTRL", 0)


@cocotb_test(skip=lacks("RANGE"))
async def index_preset_slice_compares(dut):
    """An index preset of a PRESET below, at or above CEILING, differing in one 16-bit slice above the
    lowest (the preset is compared with CEILING slice by slice for the range), in modulo, then
    steps up and down: below CEILING it counts on, at or above it wraps (every bit of every upper
    slice of CEILING and PRESET must reach that compare, the slice's bit 0 set or not)."""
    env, rng = await begin(dut)
    model = QeiModel(env.count_w)
    bus = env.bus
    await env.setup(model, rng_mode="modulo", filter_len=1, count=0)
    await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
    model.idx_action, model.idx_oneshot, model.idx_edge = "preset", False, "rising"
    model.idx_gate, model.idx_arm = None, True
    for ceiling, presets in slice_compare_cases(env.count_w):
        await bus.set64("CEILING", ceiling)
        model.ceiling = ceiling
        for preset in presets:
            await bus.set64("PRESET", preset)
            await env.applied()
            model.preset = preset
            await play_clocks(env, model, step_clocks(env.pos, (+1, +1, -1, 0), (1, 0, 0, 0)))
            await env.settle(4)
            await env.check(model, f"CEILING {ceiling:#x}: PRESET {preset:#x} by the index, then +1 -1")
    await bus.wr("INDEX_CTRL", 0)
    model.idx_action = "none"


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_index_probe(config):
    run_feature(__name__, *config)
