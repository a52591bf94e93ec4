# SPDX-License-Identifier: Apache-2.0
"""enc_qei with several channels behind one bus: every channel counting its own modelled walk at
the same time, isolation of the channel pages, the map of a multi-channel build (CAPS, pages,
unmapped offsets), the global snapshot (by GSNAP_CTRL.CMD, by snap_in, by the unit timer; every
channel latched in one clock, SNAP_TIME shared), IRQ_SUMMARY and writes right after rst.

Runs on CHANNEL_CONFIGS (a datapath per channel: enc_qei_wb with 3 full channels, enc_qei_axil
with 4 lean ones, random AXI back-pressure; the shared engine at 2, 3 and 16 channels, both
buses, both profiles, COUNT_W 64 with TS_W 16 at 2). Each channel has its own model
(enctools.qei.model); a lean channel's model has no compare unit. Every cocotb test logs its
seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import cocotb
import pytest
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer
from cocotbext.quadrature import QuadratureDriver, SharedVector
from hedsmodel import QUAD, random_walk, walk

from enctools.qei.bus import PERIOD_PS, T_NS, QeiBus, wb_abandon_read
from enctools.qei.env import (FILTER, begin, build_name, caps_of, channel_envs, engine_build,
                              engine_period)
from enctools.qei.model import QUAD_FUNCS, QeiModel
from enctools.qei.stimulus import pulse_rst
from enctools.regmap import PAGE, addr, built_mask, enum, get_field, pack, regmap, units
from enctools.tb import cocotb_test

# (top, CHANNELS, PROFILE, COUNT_W, TS_W, ENGINE); the engine at 2 channels (the channel whose
# results are written in a visit is the one its push reads), 3 and 16 (on Verilator whatever SIM
# says: Icarus takes about 30 times longer)
CHANNEL_CONFIGS = (("enc_qei_wb", 3, "full", 32, 32, 0), ("enc_qei_axil", 4, "lean", 32, 32, 0),
                   ("enc_qei_wb", 3, "lean", 32, 32, 1), ("enc_qei_axil", 3, "full", 32, 32, 1),
                   ("enc_qei_axil", 2, "lean", 64, 16, 1), ("enc_qei_wb", 16, "full", 32, 32, 1))
SNAP_REGS = ("SNAP_COUNT_LO", "SNAP_COUNT_HI", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA",
             "SNAP_EDGE_DELTA")
CHAN_REGS = tuple(n for n, r in regmap().items() if r.group == "chan")
SNAP_READY = regmap()["EVENTS"].fields["SNAP_READY"].mask


def channels_of(dut) -> int:
    return int(dut.CHANNELS.value)


async def start_channels(dut):
    """The clock, the reset, and one Env per channel."""
    _, rng = await begin(dut)
    return channel_envs(dut, rng, channels_of(dut)), rng


async def arm_index_preset(env, model, preset: int, oneshot: bool = False) -> None:
    """PRESET and INDEX_CTRL for an index preset on the rising edge (ARM), in the channel and in
    its model."""
    await env.bus.set64("PRESET", preset)
    await env.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1,
                                        ONESHOT=int(oneshot)))
    model.preset, model.idx_action, model.idx_edge, model.idx_arm = preset, "preset", "rising", True
    model.idx_gate, model.idx_oneshot = None, oneshot


async def set_index(env, model, rng) -> None:
    """A random INDEX_CTRL action on one channel (and its model)."""
    action = rng.choice(("none", "preset", "latch"))
    preset = rng.getrandbits(20)
    await env.bus.set64("PRESET", preset)
    await env.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE="rising", ARM=1))
    model.preset, model.idx_action, model.idx_edge, model.idx_arm = preset, action, "rising", True
    model.idx_gate, model.idx_oneshot = None, False


def bound_walk(rng, n: int, shortest: float, p_reverse: float, start_pos: int, dither: float):
    """random_walk's walk (states uniform in [shortest, 2 shortest] clocks, reversing with
    probability p_reverse at each transition), except that the state a reversal leaves lasts at
    least ``dither`` clocks: that state is a level of one channel that spans no change of the
    other (the dither of a reversal), which the filter rejects when it is shorter than FILTER_LEN
    samples. x4, x2 and x1 count the same with the dither or without it, but GLITCH and
    DIR_CHANGE differ (a rejected dither at the start of a reversal removes the change of
    direction); x1_hyst's count differs too (its hysteresis keeps the count it had before a
    dither it never saw)."""
    direction, steps, durs = 1, [], []
    for i in range(n):
        if rng.random() < p_reverse:
            direction = -direction
        dur = rng.uniform(shortest, 2 * shortest)
        if i > 0 and direction != steps[-1]:
            dur = max(dur, dither)
        steps.append(direction)
        durs.append(dur * T_NS + 0.01)
    return walk(steps, durs, start_pos=start_pos)


@cocotb_test()
async def independent_walks(dut):
    """Every channel plays its own random walk (runs at the count-rate bound, dither, index pulses)
    at the same time, with its own count function and index action; each channel's COUNT, EVENTS
    and INDEX_LATCH are checked against its own model. At the bound a channel plays a reversal's
    dither either long enough for the filter to pass, with every event checked, or (x4, x2 and x1
    only, half of the time) as short as the other states, with the count still exact but GLITCH
    and DIR_CHANGE not compared (bound_walk)."""
    envs, rng = await start_channels(dut)
    models = [QeiModel(env.count_w) for env in envs]
    funcs = [rng.choice(QUAD_FUNCS) for _ in envs]
    for env, model, func in zip(envs, models, funcs):
        await env.setup(model, func=func, count=rng.getrandbits(env.count_w))
        await set_index(env, model, rng)
    dut._log.info("count functions per channel: %s", funcs)
    short = [False] * len(envs)  # this round, channel k plays short dithers
    for rnd in range(4):
        tasks = []
        for k, (env, model) in enumerate(zip(envs, models)):
            p_rev = rng.choice((0.02, 0.2, 0.5))
            # rounds 0 and 1 at the count-rate bound (states of 1.05 max(1, F/2) clocks and up)
            shortest = 1.05 * max(1, FILTER / 2) if rnd < 2 else 1.05 * FILTER
            short[k] = rnd < 2 and funcs[k] != "x1_hyst" and rng.random() < 0.5
            dither = shortest if short[k] else 1.05 * FILTER
            wf = bound_walk(rng, rng.randint(80, 200), shortest, p_rev, env.pos, dither)
            period = rng.choice((24, 40, 64))
            # (no index pulses at the bound: a one-state level there may be shorter than the
            # filter)
            zf = (lambda p, n=period: int(5 <= p % n <= 7)) if rnd >= 2 else None
            tasks.append(cocotb.start_soon(env.play(wf, model, zfun=zf)))
        for t in tasks:
            await t
        for k, (env, model) in enumerate(zip(envs, models)):
            what = f"channel {k} ({funcs[k]}), round {rnd}"
            await env.check(model, what, events=False)
            ev, exp = await env.bus.events(), model.take_events()
            up = get_field("STATUS", "DIR", await env.bus.rd("STATUS"))
            if short[k]:
                ev -= {"GLITCH", "DIR_CHANGE"}
                exp -= {"GLITCH", "DIR_CHANGE"}
                # a dither the filter rejected leaves the model a step the decoder never saw: the
                # model's last direction (hence the next round's DIR_CHANGE) follows STATUS.DIR
                model.dir = 1 if up else -1
            assert ev == exp, f"{what}: EVENTS {sorted(ev)}, model {sorted(exp)}"
            assert up == (model.dir > 0), f"{what}: STATUS.DIR {up}, model direction {model.dir}"
            latch = await env.bus.get64("INDEX_LATCH")
            assert latch == model.idx_latch, \
                f"channel {k}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
    dut._log.info("final counts: %s", [hex(m.count) for m in models])


async def dump(bus: QeiBus, k: int) -> dict:
    """Every channel register of channel k (reads have no side effect on another channel)."""
    view = bus.at(k)
    return {reg: await view.rd(reg) for reg in CHAN_REGS}


STRB = tuple(range(1, 16))  # every byte-enable mask with a lane


@cocotb_test()
async def isolation(dut):
    """Random register traffic to channel k (writes of random values and byte lanes to every
    channel register, commands included, and reads) never changes any register of any other
    channel. After its traffic channel k is put back to quiet (no timers, no stall watchdog), so
    nothing in it runs on by itself."""
    envs, rng = await start_channels(dut)
    bus = envs[0].bus
    n = len(envs)
    for k in rng.sample(range(n), n):
        others = [j for j in range(n) if j != k]
        before = {j: await dump(bus, j) for j in others}
        view = bus.at(k)
        for _ in range(60):
            reg = rng.choice(CHAN_REGS)
            if rng.random() < 0.25:
                await view.rd(reg)
            else:
                await view.wr(reg, rng.getrandbits(32), strb=rng.choice(STRB))
        for reg in ("SNAP_CTRL", "PERIOD_CTRL", "STALL_TIMEOUT"):
            await view.wr(reg, 0)
        for j in others:
            after = await dump(bus, j)
            changed = {r: (hex(before[j][r]), hex(after[r])) for r in CHAN_REGS
                       if before[j][r] != after[r]}
            assert not changed, f"traffic to channel {k} changed channel {j}: {changed}"
    dut._log.info("%d channels: every register of every other channel unchanged", n)


# the channel registers a write keeps as written while the encoders stand still (COUNT_HI, whose
# reads go through COUNT_LO's latch, and the state registers excluded)
KEPT_REGS = tuple(r for r in CHAN_REGS
                  if r not in ("COUNT_HI", "EVENTS", "QERR_COUNT", "GLITCH_COUNT")
                  and any(f.sw == "rw" for f in regmap()[r].fields.values()))


@cocotb_test()
async def writes_after_reset(dut):
    """A write in the first clocks after rst is released (0 to 7 clocks after), of every register
    a channel keeps as written, on every channel with a random value, reads back what it wrote in
    its read-write fields; then a second write of the register, once the channel has been
    visited, does too. Both times the bits of read-write fields the build leaves out (a unit it
    lacks, bits above COUNT_W or TS_W) read 0. (The shared engine takes a channel's write before
    its first visit since rst, which writes the registers' reset values: the write must act on
    them; the second write merges into the stored word instead.)"""
    envs, rng = await start_channels(dut)
    bus = envs[0].bus
    have = units(await bus.rd("CAPS"))
    count_w, ts_w = envs[0].count_w, int(dut.TS_W.value)
    lost = []
    for k in range(len(envs)):
        for reg in KEPT_REGS:
            rw = [f for f in regmap()[reg].fields.values() if f.sw == "rw"]
            mask = sum(built_mask(f, count_w, ts_w, have) for f in rw)
            dark = sum(f.mask for f in rw) & ~mask  # read-write bits the build leaves out
            if not mask:
                continue
            await pulse_rst(dut, 2)
            await ClockCycles(dut.clk, rng.randrange(8))
            for when in ("after rst", "second write"):
                value = rng.getrandbits(32)
                await bus.at(k).wr(reg, value)
                got = await bus.at(k).rd(reg)
                if got & mask != value & mask or got & dark:
                    lost.append((k, reg, when, hex(value & mask), hex(got & (mask | dark))))
    assert not lost, f"writes not kept, or bits left out not 0 (channel, register, which write, " \
                     f"written, read): {lost}"


@cocotb_test()
async def channel_map(dut):
    """CAPS names the channels, the profile and the architecture (ENGINE); every page below
    CHANNELS answers its channel registers, a global offset in a page other than 0 and every page
    at or above CHANNELS answer a bus error; IRQ_SUMMARY bits at and above CHANNELS read 0."""
    envs, rng = await start_channels(dut)
    bus = envs[0].bus
    n = channels_of(dut)
    caps = await bus.rd("CAPS")
    assert get_field("CAPS", "CHANNELS", caps) == n, f"CAPS {caps:#x}: CHANNELS is not {n}"
    assert caps == caps_of(dut), f"CAPS {caps:#010x}, the build's {caps_of(dut):#010x}"
    profile = {v: k for k, v in enum("CAPS", "PROFILE").items()}[get_field("CAPS", "PROFILE", caps)]
    assert profile == PROFILE_OF[int(dut.PROFILE.value)], f"CAPS.PROFILE {profile}"
    arch = {v: k for k, v in enum("CAPS", "ENGINE").items()}[get_field("CAPS", "ENGINE", caps)]
    assert arch == ("shared" if envs[0].engine else "per_channel"), f"CAPS.ENGINE {arch}"
    version = get_field("ID", "VERSION", await bus.rd("ID"))
    assert version >= 0x0101, f"ID.VERSION {version:#06x}: a multi-channel map is 0x0101 or later"
    pages = 1 << (int(dut.ADDR_W.value) - 8)  # the pages the address reaches
    glb = [r for r, x in regmap().items() if x.group == "glb"]
    for k in range(1, n):
        for reg in rng.sample(glb, 3):
            _, err = await bus.read(k * PAGE + regmap()[reg].offset)
            assert err, f"{reg}'s offset in page {k} answered without an error"
        # a channel register of page k is channel k's: a PRESET written there reads back there only
        value = rng.getrandbits(32)
        await bus.at(k).wr("PRESET_LO", value)
        assert await bus.at(k).rd("PRESET_LO") == value
        assert await bus.at(k - 1).rd("PRESET_LO") != value or value == 0
    for k in range(n, min(pages, 16)):
        _, err = await bus.read(k * PAGE + regmap()["COUNT_LO"].offset)
        assert err, f"page {k} (CHANNELS {n}) answered a read without an error"
        err = await bus.write(k * PAGE + regmap()["CTRL"].offset, 0)
        assert err, f"page {k} (CHANNELS {n}) answered a write without an error"
    assert await bus.rd("IRQ_SUMMARY") == 0


PROFILE_OF = {v: k for k, v in enum("CAPS", "PROFILE").items()}


async def read_all(envs) -> list[dict]:
    return [dict(zip(SNAP_REGS, [await env.bus.rd(r) for r in SNAP_REGS])) for env in envs]


def check_same_instant(snaps, gtime, offsets, what, mask=(1 << 32) - 1):
    """Every channel's snapshot from one clock: SNAP_TIME = GSNAP_TIME everywhere, the counts
    apart by exactly their starting offsets (modulo 2^COUNT_W: ``mask``), the edge times and
    deltas equal."""
    base = snaps[0]
    for k, s in enumerate(snaps):
        assert s["SNAP_TIME"] == gtime, f"{what}: channel {k} SNAP_TIME {s['SNAP_TIME']:#x}, " \
                                        f"GSNAP_TIME {gtime:#x}"
        count = (s["SNAP_COUNT_HI"] << 32 | s["SNAP_COUNT_LO"]) - offsets[k] & mask
        count0 = (base["SNAP_COUNT_HI"] << 32 | base["SNAP_COUNT_LO"]) - offsets[0] & mask
        assert count == count0, f"{what}: channel {k} read position {count}, channel 0 {count0}"
        for r in ("SNAP_EDGE_TIME", "SNAP_DELTA", "SNAP_EDGE_DELTA"):
            assert s[r] == base[r], f"{what}: channel {k} {r} {s[r]:#x}, channel 0 {base[r]:#x}"


async def take_ready(envs, what) -> None:
    """Every channel raised SNAP_READY; clear it."""
    for k, env in enumerate(envs):
        ev = await env.bus.rd("EVENTS")
        assert ev & SNAP_READY, f"{what}: channel {k} has no SNAP_READY (EVENTS {ev:#x})"
        await env.bus.wr("EVENTS", SNAP_READY)


@cocotb_test()
async def global_snapshot(dut):
    """One shared motion on every channel (each count offset by 1000 k): snapshots by
    GSNAP_CTRL.CMD, by a rising snap_in (IN_EN; none without it) and by the unit timer
    (consecutive GSNAP_TIMEs exactly GSNAP_PERIOD apart) read the same position on every channel,
    with one SNAP_TIME equal to GSNAP_TIME, and raise SNAP_READY on every channel."""
    envs, rng = await start_channels(dut)
    n = len(envs)
    bus = envs[0].bus
    a, b = SharedVector(dut.a_in), SharedVector(dut.b_in)
    drv = QuadratureDriver(a.all_bits(), b.all_bits(), clock_period_ps=PERIOD_PS)
    offsets = [1000 * k for k in range(n)]
    for env, off in zip(envs, offsets):
        await env.setup(QeiModel(env.count_w), func="x4", count=off)
        await env.bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE=rng.choice(("any", "a_rising"))))
    edges = [await env.bus.rd("SNAP_CTRL") for env in envs]
    if len(set(edges)) > 1:  # one SNAP_CTRL.EDGE for all, so that the edge times compare
        for env in envs:
            await env.bus.wr("SNAP_CTRL", edges[0])
        await envs[0].applied()  # (the shared engine: every channel's before the motion starts)

    def motion(steps: int):
        return drv.start(random_walk(rng, steps, 1.05 * FILTER * T_NS + 0.1, 2 * FILTER * T_NS,
                                     p_reverse=0.1, start_pos=0))

    # by command, while moving
    task = motion(3000)
    for i in range(6):
        await ClockCycles(dut.clk, rng.randint(50, 400))
        await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1))
        await ClockCycles(dut.clk, envs[0].lag)  # (the shared engine: SNAP_* within its latency)
        snaps = await read_all(envs)
        check_same_instant(snaps, await bus.rd("GSNAP_TIME"), offsets, f"CMD snapshot {i}")
        await take_ready(envs, f"CMD snapshot {i}")
    # by snap_in: none while IN_EN = 0, one per rising edge with it
    last = await bus.rd("GSNAP_TIME")
    await pulse_snap_in(dut, rng)
    assert await bus.rd("GSNAP_TIME") == last, "snap_in with IN_EN = 0 took a global snapshot"
    await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", IN_EN=1))
    for i in range(4):
        await ClockCycles(dut.clk, rng.randint(20, 300))
        t_in = await pulse_snap_in(dut, rng)
        await ClockCycles(dut.clk, envs[0].lag)
        gtime = await bus.rd("GSNAP_TIME")
        assert gtime == t_in, f"snap_in snapshot {i}: GSNAP_TIME {gtime:#x}, timebase in the " \
                              f"clock snap_in was first high {t_in:#x}"
        check_same_instant(await read_all(envs), gtime, offsets, f"snap_in snapshot {i}")
        await take_ready(envs, f"snap_in snapshot {i}")
    await bus.wr("GSNAP_CTRL", 0)
    await task
    # by the unit timer
    period = 3000
    await bus.wr("GSNAP_PERIOD", period)
    await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
    task = motion(8000)
    times = []
    while len(times) < 5:
        await ClockCycles(dut.clk, 100)
        if not await envs[0].bus.rd("EVENTS") & SNAP_READY:
            continue
        await ClockCycles(dut.clk, envs[0].lag)
        gtime = await bus.rd("GSNAP_TIME")
        await take_ready(envs, f"timer snapshot {len(times)}")
        check_same_instant(await read_all(envs), gtime, offsets, f"timer snapshot {len(times)}")
        assert await bus.rd("GSNAP_TIME") == gtime, "the unit timer fired again during the reads"
        times.append(gtime)
    await bus.wr("GSNAP_CTRL", 0)
    gaps = [(t1 - t0) % (1 << 32) for t0, t1 in zip(times, times[1:])]
    assert all(g == period for g in gaps), f"unit-timer snapshots {gaps} ticks apart, not {period}"
    await task
    dut._log.info("global snapshots: 6 by command, 4 by snap_in, 5 by the timer (%s)", times)


async def pulse_snap_in(dut, rng) -> int:
    """snap_in high for a few clocks (set after a falling edge); returns the timebase in the clock
    it is first high (the clock that begins with the rising edge that first samples it high)."""
    await FallingEdge(dut.clk)
    dut.snap_in.value = 1
    await RisingEdge(dut.clk)
    await ReadOnly()
    t = int(dut.u_qei.g_timebase.u_timebase.timebase.value)
    await ClockCycles(dut.clk, rng.randint(1, 4))
    await FallingEdge(dut.clk)
    dut.snap_in.value = 0
    await ClockCycles(dut.clk, 4)
    return t


@cocotb_test()
async def irq_summary(dut):
    """IRQ_SUMMARY has the pending bit of exactly the channels with an event their IRQ_EN enables
    (events raised by each channel's own SNAP_CTRL.CMD), and irq is their OR; clearing a channel's
    event clears its bit."""
    envs, rng = await start_channels(dut)
    n = len(envs)
    bus = envs[0].bus
    for trial in range(8):
        en = [rng.choice((0, SNAP_READY, 0xFFF)) for _ in envs]
        for env, e in zip(envs, en):
            await env.bus.wr("IRQ_EN", e)
            await env.bus.wr("EVENTS", 0xFFF)
        hit = set(rng.sample(range(n), rng.randint(0, n)))
        for k in sorted(hit):
            await envs[k].bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
        await ClockCycles(dut.clk, 4 + envs[0].lag)
        exp = sum(1 << k for k in hit if en[k] & SNAP_READY)
        got = await bus.rd("IRQ_SUMMARY")
        assert got == exp, f"trial {trial}: IRQ_SUMMARY {got:#x}, expected {exp:#x} " \
                           f"(snapshots on {sorted(hit)}, IRQ_EN {[hex(e) for e in en]})"
        assert int(dut.irq.value) == int(exp != 0), f"trial {trial}: irq {int(dut.irq.value)}"
        for k in rng.sample(sorted(hit), len(hit) // 2):
            await envs[k].bus.wr("EVENTS", SNAP_READY)
            exp &= ~(1 << k)
        await ClockCycles(dut.clk, envs[0].lag)
        got = await bus.rd("IRQ_SUMMARY")
        assert got == exp, f"trial {trial}, after clearing: IRQ_SUMMARY {got:#x}, expected {exp:#x}"
    for env in envs:
        await env.bus.wr("IRQ_EN", 0)


@cocotb_test()
async def lanes_probe_compare_per_channel(dut):
    """Per channel, through its own page and pins: a PRESET_LO write with each byte-enable mask
    keeps the other lanes; a rising edge of that channel's bit of
    probe_in raises its PROBE event within a few clocks (while the pin is still high) and no other
    channel's; a compare match on a full channel pulses its bit of cmp_out only (cmp_out is 0
    while nothing matches); SNAP_DELTA between two SNAP_CTRL.CMD writes is the steps between them
    (each access is one request). On Wishbone, a read abandoned on a channel's page gets no ACK or
    ERR, and the read right after it is answered with its own register."""
    envs, rng = await start_channels(dut)
    n = len(envs)
    probe_ev = regmap()["EVENTS"].fields["PROBE"].mask
    seen = [0]

    async def watch_cmp():
        while True:
            await RisingEdge(dut.clk)
            seen[0] |= int(dut.cmp_out.value)

    watcher = cocotb.start_soon(watch_cmp())
    masks = (1, 2, 4, 8, 3, 6, 12, 7, 14, 5, 9, 10, 13, 11)
    for k, env in enumerate(envs):
        bus = env.bus
        for i, strb in enumerate(masks):
            lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
            old = (0xC3A55A3C * (i + 7 * k + 1)) & 0xFFFFFFFF
            new = ~old & 0xFFFFFFFF
            await bus.wr("PRESET_LO", old)
            await bus.wr("PRESET_LO", new, strb)
            got = await bus.rd("PRESET_LO")
            assert got == old & ~lanes | new & lanes, \
                f"channel {k} PRESET_LO strb {strb:#x}: {got:#010x}, old {old:#010x}, new {new:#010x}"
        await bus.wr("PRESET_LO", 0)
        if env.lean:  # (no probe unit)
            continue
        for e in envs:
            await e.bus.events()
        await bus.wr("PROBE_CTRL", pack("PROBE_CTRL", EN=1, EDGE="rising"))
        await bus.rd("PROBE_CTRL")  # (the shared engine: a read returns once the write took effect)
        await FallingEdge(dut.clk)
        dut.probe_in.value = 1 << k
        await ClockCycles(dut.clk, FILTER + 8 + env.lag)
        ev = await bus.rd("EVENTS")
        assert ev & probe_ev, f"channel {k}: no PROBE event while its probe_in is high (EVENTS {ev:#x})"
        await FallingEdge(dut.clk)
        dut.probe_in.value = 0
        await ClockCycles(dut.clk, FILTER + 8)
        await bus.wr("PROBE_CTRL", 0)
        for j, e in enumerate(envs):
            if j != k:
                ev = await e.bus.events()
                assert "PROBE" not in ev, f"probe_in of channel {k} raised PROBE on channel {j}"
    assert seen[0] == 0, f"cmp_out {seen[0]:#x} with no compare match"
    for k, env in enumerate(envs):
        if env.lean:  # (no compare unit)
            continue
        model = QeiModel(env.count_w)
        await env.setup(model, count=100, compare=101, filter_len=1)
        seen[0] = 0
        await env.play(walk([1, 1], [20 * T_NS, 20 * T_NS], start_pos=env.pos), model)
        assert seen[0] == 1 << k, f"channel {k}: cmp_out {seen[0]:#x} after its compare match"
        await env.bus.wr("COMPARE_LO", 0)
    watcher.cancel()
    # one request per bus access: SNAP_DELTA between two SNAP_CTRL.CMD writes is the steps played
    # between them (a repeated CMD write would take a second snapshot with no steps)
    for k, env in enumerate(envs):
        await env.bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
        await env.settle(4)
        await env.play(walk([1] * 5, [8 * T_NS] * 5, start_pos=env.pos), None)
        await env.bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1))
        await env.settle(4)
        delta = await env.bus.rd("SNAP_DELTA")
        assert delta == 5, f"channel {k}: SNAP_DELTA {delta:#x} over 5 steps between two commands"
        await env.bus.events()
    if envs[0].bus.kind != "wb":
        return
    for k in range(n):
        bus = envs[k].bus
        ctrl = await bus.rd("CTRL")
        marker = 0x5EED_0000 | k
        await bus.wr("PRESET_LO", marker)
        for hold in (1, 2):
            # a read of CTRL abandoned after `hold` clocks, then at once a read of PRESET_LO: its
            # answer is PRESET_LO's, never the abandoned read's
            await wb_abandon_read(dut, k * PAGE + regmap()["CTRL"].offset, hold)
            await Timer(PERIOD_PS // 10, unit="ps")  # the same clock, CYC already low
            assert dut.wb_ack_o.value == 0 and dut.wb_err_o.value == 0, \
                f"page {k}: ACK/ERR after the master dropped CYC"
            await FallingEdge(dut.clk)
            dut.wb_adr_i.value = k * PAGE + regmap()["PRESET_LO"].offset
            dut.wb_cyc_i.value = 1
            dut.wb_stb_i.value = 1
            for c in range(20 + 2 * envs[0].lag):  # ACK / ERR as the master samples them at the next rising edge
                await Timer(PERIOD_PS // 10, unit="ps")
                if dut.wb_ack_o.value or dut.wb_err_o.value:
                    break
                await FallingEdge(dut.clk)
            ack, err, data = int(dut.wb_ack_o.value), int(dut.wb_err_o.value), int(dut.wb_dat_o.value)
            await FallingEdge(dut.clk)
            dut.wb_cyc_i.value = 0
            dut.wb_stb_i.value = 0
            assert ack and not err and data == marker, \
                f"page {k}, CTRL read abandoned after {hold} clock(s): the next read (PRESET_LO " \
                f"{marker:#x}) answered ACK {ack} ERR {err} data {data:#x}"
            await ClockCycles(dut.clk, 4)
        assert await bus.rd("CTRL") == ctrl
        await bus.wr("PRESET_LO", 0)


@cocotb_test()
async def enable_overflow_glitches_per_channel(dut):
    """Per channel, on every channel at the same time, what its lane does with its own
    configuration and pins: CTRL.EN 0 on the odd channels while every channel walks up across the
    top of the free range from just below it (channel k from max - 3 - k: the enabled ones
    OVERFLOW once and no DIR_CHANGE, the others keep COUNT and raise nothing); an index preset of
    PRESET = max - 2 - k, then steps up across the top soon after the load (within about 30
    clocks: the count loaded by the index, then OVERFLOW from it); an index latch from COUNT =
    2^(COUNT_W - 1) - 2 - k (INDEX_LATCH on every channel; the steps cross the lane's low bits'
    wrap far from the top: no OVERFLOW); an index preset of PRESET = 2 + k, written over a PRESET
    with high low-word bits set, then steps down across 0 (UNDERFLOW from the preset's count);
    two more rounds of steps down (no DIR_CHANGE: the direction is down already);
    then 2k + 3 lone one-clock pulses of A on channel k at FILTER_LEN 2: GLITCH_COUNT 2k + 3 and
    EVENTS.GLITCH on channel k, COUNT unchanged. COUNT and EVENTS as each channel's model."""
    envs, rng = await start_channels(dut)
    models = [QeiModel(env.count_w) for env in envs]
    pairs = list(zip(envs, models))

    async def walk_all(marks=None, step=1):
        tasks = []
        for k, (env, model) in enumerate(pairs):
            n = 8 + k % 4
            zf = (lambda p, m=env.pos + 2 * step: int(p == m)) if marks else None
            tasks.append(cocotb.start_soon(
                env.play(walk([step] * n, [3 * T_NS] * n, start_pos=env.pos), model, zfun=zf)))
        for t in tasks:
            await t

    for k, (env, model) in enumerate(pairs):
        await env.setup(model, count=model.max - 3 - k, en=int(k % 2 == 0), filter_len=1)
    await walk_all()
    for k, (env, model) in enumerate(pairs):
        await env.check(model, f"channel {k}: EN {int(k % 2 == 0)}, steps up across the top")
    # (action, PRESET or COUNT, direction): each PRESET_LO write changes bits the one before set
    for action, near, step in (("preset", "top", 1), ("latch", "middle", 1), ("preset", "zero", -1)):
        for k, (env, model) in enumerate(pairs):
            value = {"top": model.max - 2 - k, "middle": (model.max >> 1) - 2 - k, "zero": 2 + k}[near]
            await env.setup(model, count=value if action == "latch" else 0x1000 + k, filter_len=1)
            await env.bus.set64("PRESET", value)
            await env.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE="rising", ARM=1))
            model.preset, model.idx_action, model.idx_edge, model.idx_arm = value, action, "rising", True
            model.idx_gate, model.idx_oneshot, model.idx_hits = None, False, 0
        await envs[-1].applied()
        await walk_all(marks=True, step=step)
        for k, (env, model) in enumerate(pairs):
            assert model.idx_hits == 1, f"channel {k}: {model.idx_hits} index pulses played, not 1"
            await env.check(model, f"channel {k}: index {action} near {near}, steps {step:+d}")
            latch = await env.bus.get64("INDEX_LATCH")
            assert latch == model.idx_latch, f"channel {k}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
            await env.bus.wr("INDEX_CTRL", 0)
            model.idx_action = "none"
    for rnd in range(2):
        await walk_all(step=-1)
        for k, (env, model) in enumerate(pairs):
            await env.check(model, f"channel {k}: steps down ({'after steps up' if rnd == 0 else 'again'})")
    for k, (env, model) in enumerate(pairs):
        await env.setup(model, count=0x100 + k, filter_len=2)
        await env.bus.wr("GLITCH_COUNT", 0)
    await envs[-1].applied()
    await envs[-1].settle()
    for env in envs:
        await env.bus.events()
    pulses = [2 * k + 3 for k in range(len(envs))]
    for i in range(max(pulses)):
        levels = [env.drv.a.value for env in envs]
        await FallingEdge(dut.clk)
        for env, n, a in zip(envs, pulses, levels):
            if i < n:
                env.drv.a.value = 1 - a
        await FallingEdge(dut.clk)
        for env, a in zip(envs, levels):
            env.drv.a.value = a
        await ClockCycles(dut.clk, 2)
    await envs[-1].settle()
    for k, (env, model) in enumerate(pairs):
        await env.check(model, f"channel {k}: {pulses[k]} lone pulses of A", events=False)
        got = await env.bus.rd("GLITCH_COUNT")
        assert got == pulses[k], f"channel {k}: GLITCH_COUNT {got} after {pulses[k]} lone pulses of A"
        ev = await env.bus.events()
        assert ev == {"GLITCH"}, f"channel {k}: EVENTS {sorted(ev)} after lone pulses, not GLITCH only"


@cocotb_test()
async def index_right_after_preset_writes(dut):
    """An index preset at every phase of the shared engine's visits after a PRESET_HI write
    (every 8 clocks from the write's answer to P + 24 after it; the write gives PRESET_HI the value
    it has, so PRESET stays max - 5), then steps up across the top of the range: COUNT and
    OVERFLOW as the model's. The engine hands the lane a written PRESET at its next read, with
    the validity set that tells the lane whether the top of the range is within reach; one
    computed from a PRESET the write's merge got wrong acts only in the window up to the read
    after, so only an index in that window shows it."""
    envs, rng = await start_channels(dut)
    env = envs[0]
    model = QeiModel(env.count_w)
    span = engine_period(len(envs)) + 24 if engine_build() else 24
    preset = model.max - 5
    await env.setup(model, count=0x1000, filter_len=1)
    await arm_index_preset(env, model, preset)
    for j in range(0, span, 8):
        await env.bus.set_count(0x1000)
        model.write_count(0x1000)
        await env.settle()
        await env.bus.wr("PRESET_HI", preset >> 32)
        await ClockCycles(dut.clk, j)
        start = env.pos
        await env.play(walk([1] * 10, [3 * T_NS] * 10, start_pos=start), model,
                       zfun=lambda p: int(p == start))
        await env.check(model, f"an index {j} clocks after a PRESET_HI write, then 10 steps up")


@cocotb_test()
async def index_presets_next_to_low_bit_wraps(dut):
    """Index presets of a PRESET in the middle of the range whose low 16 bits are 0x0001 (then
    four steps down) or 0xFFFE (four steps up), so the count's low bits wrap two steps after the
    preset; the index at every phase of the shared engine's visits (every 8 clocks over P + 24),
    on channel 0: COUNT and EVENTS as the model's (no UNDERFLOW, no OVERFLOW). The lane counts
    the count's low bits and takes where the full count is from the validity set of its last
    anchor, here the PRESET's (the ends of the range out of reach); the set of another anchor
    (CEILING's: all ones, an end in reach) would call that wrap of the low bits the end of the
    range, in the window up to the engine's next read."""
    envs, rng = await start_channels(dut)
    env = envs[0]
    model = QeiModel(env.count_w)
    span = engine_period(len(envs)) + 24 if engine_build() else 24
    mid = (model.max + 1) >> 1
    await env.setup(model, count=0x1000, filter_len=1)
    for preset, step in ((mid + 1, -1), (mid - 2, 1)):
        await arm_index_preset(env, model, preset)
        for j in range(0, span, 8):
            await env.bus.set_count(0x1000)
            model.write_count(0x1000)
            await env.settle()
            await ClockCycles(dut.clk, j)
            start = env.pos
            await env.play(walk([step] * 4, [3 * T_NS] * 4, start_pos=start), model,
                           zfun=lambda p: int(p == start))
            await env.check(model, f"an index preset of {preset:#x} {j} clocks after a COUNT write's "
                                   f"answer, then 4 steps {'up' if step > 0 else 'down'}")


@cocotb_test()
async def first_snapshot_after_reset(dut):
    """After rst (and again after a second rst, the pins where the walks left them), channel k
    walks 5 + 7 k steps, up on even channels and down on odd ones, with no snapshot before: the
    first global snapshot's SNAP_DELTA and SNAP_EDGE_DELTA (EDGE any, from rst) on channel k are
    exactly those steps (the motion since rst; signed) and its SNAP_COUNT the count. Every
    channel walks its own number of steps, so a motion that starts from the same wrong value on
    every channel does not hide behind equal deltas."""
    envs, rng = await start_channels(dut)
    bus = envs[0].bus
    moves = [(5 + 7 * k) * (1 if k % 2 == 0 else -1) for k in range(len(envs))]  # signed steps
    for rnd in range(2):
        if rnd:  # rst, every channel's pins where its walk left them
            await pulse_rst(dut, clocks=4)
        models = [QeiModel(env.count_w) for env in envs]
        for env, model in zip(envs, models):
            await env.setup(model, count=0, filter_len=1)
        for env, model, m in zip(envs, models, moves):
            n = abs(m)
            await env.play(walk([1 if m > 0 else -1] * n, [3 * T_NS] * n, start_pos=env.pos), model)
        await env.settle()
        await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1))
        await ClockCycles(dut.clk, envs[0].lag)
        for k, (model, m, snap) in enumerate(zip(models, moves, await read_all(envs))):
            want = m & 0xFFFF_FFFF
            what = f"round {rnd}, channel {k}: the first snapshot after rst, {m:+d} steps"
            assert snap["SNAP_DELTA"] == want, \
                f"{what}: SNAP_DELTA {snap['SNAP_DELTA']:#x}, steps {want:#x}"
            # (SNAP_CTRL.EDGE = any from rst: the last selected edge is the last step)
            assert snap["SNAP_EDGE_DELTA"] == want, \
                f"{what}: SNAP_EDGE_DELTA {snap['SNAP_EDGE_DELTA']:#x}, steps {want:#x}"
            count = (snap["SNAP_COUNT_HI"] << 32 | snap["SNAP_COUNT_LO"]) & model.max
            assert count == model.count, f"{what}: SNAP_COUNT {count:#x}, model {model.count:#x}"


@cocotb_test()
async def count_writes_out_of_reach_then_across_the_ends(dut):
    """Per channel: a COUNT write to R + 40 + k (R: the steps the shared engine's validity sets
    describe, 2 P + 4; 300 without the engine), then R + 60 + k steps down across 0 (UNDERFLOW),
    and a COUNT write to max - (R + 40 + k), then as many steps up across the top (OVERFLOW):
    COUNT and EVENTS as the model's. The lane counts the count's low bits; the write's set says the
    ends are out of reach, and the sets of the reads that follow, as the count comes near, say
    where the end is: a lane that kept the write's set would miss the end."""
    envs, rng = await start_channels(dut)
    reach = 2 * engine_period(len(envs)) + 4 if engine_build() else 300
    for k, env in enumerate(envs):
        model = QeiModel(env.count_w)
        for start, step in ((reach + 40 + k, -1), (model.max - (reach + 40 + k), 1)):
            await env.setup(model, count=start, filter_len=1)
            n = reach + 60 + k
            await env.play(walk([step] * n, [3 * T_NS] * n, start_pos=env.pos), model)
            await env.check(model, f"channel {k}: COUNT written {start:#x}, then {n} steps "
                                   f"{'up' if step > 0 else 'down'}")


@cocotb_test()
async def presets_ranges_periods_per_channel(dut):
    """Per channel, through its own page and pins, what the shared engine keeps per channel and
    hands to each lane: index presets of PRESET with every low bit both ways (two PRESETs, one
    the complement of the other, the channel number in them), and a one-shot preset (ARM clears
    after the first index: a second pulse presets nothing), each followed by steps. On a full
    build also a modulo range with CEILING near the count (20 + k), up across CEILING and down
    across 0, and one step up from CEILING a window after a COUNT write (in clocks of both
    parities), and the period capture (N = 1, any edge, states of 5 + 2k and 90 + 4k clocks:
    PERIOD and PERIOD_READY on that channel only). COUNT and EVENTS as the model's."""
    envs, rng = await start_channels(dut)
    for k, env in enumerate(envs):
        model = QeiModel(env.count_w)
        await env.setup(model, count=rng.getrandbits(16), filter_len=1)
        for value, oneshot in ((0xA5C3_5A3C ^ k, False), (0x5A3C_A5C3 ^ k, False), (0x1234_5678 + k, True)):
            value &= model.max
            await arm_index_preset(env, model, value, oneshot)
            await env.applied()
            # an index pulse two steps in, another five steps later (the one-shot takes the first)
            marks = (env.pos + 2, env.pos + 7)
            wf = walk([1] * 9 + [-1] * 3, [12 * T_NS] * 12, start_pos=env.pos)
            await env.play(wf, model, zfun=lambda p, m=marks: int(p in m))
            await env.check(model, f"channel {k}: index preset of {value:#x} (one-shot {oneshot}) and steps")
            await env.bus.wr("INDEX_CTRL", 0)
            model.idx_action = "none"
    if envs[0].lean:  # (no range modes, no period unit)
        return
    for k, env in enumerate(envs):
        model = QeiModel(env.count_w)
        ceiling = 20 + k
        await env.setup(model, rng_mode="modulo", count=ceiling - 3, ceiling=ceiling, filter_len=1)
        wf = walk([1] * 6 + [-1] * 26 + [1] * 4, [3 * T_NS] * 36, start_pos=env.pos)
        await env.play(wf, model)
        await env.check(model, f"channel {k}: modulo CEILING {ceiling}, across both ends")
        # one step up from CEILING, a window after the last load (the range ends then come from
        # the count at the read before), in clocks of both parities
        for delay in (0, 1):
            await env.setup(model, rng_mode="modulo", count=ceiling, ceiling=ceiling, filter_len=1)
            await ClockCycles(dut.clk, delay)
            await env.play(walk([1], [3 * T_NS], start_pos=env.pos), model)
            await env.check(model, f"channel {k}: modulo CEILING {ceiling}, a step up from it ({delay})")
        await env.setup(model, filter_len=1)
    for e in envs:
        await e.bus.events()
    for k, env in enumerate(envs):
        # (states shorter and longer than the engine's P = 72 clocks at three channels: several
        # period boundaries in one engine window, or one)
        for d in (5 + 2 * k, 90 + 4 * k):
            await env.bus.wr("PERIOD_CTRL", pack("PERIOD_CTRL", EN=1, EDGE="any", N=1))
            await env.applied()
            await env.play(walk([1] * 8, [d * T_NS] * 8, start_pos=env.pos), None)
            period = await env.bus.rd("PERIOD")
            assert period == d, f"channel {k}: PERIOD {period} over states of {d} clocks"
            assert "PERIOD_READY" in await env.bus.events(), f"channel {k}: no PERIOD_READY"
            await env.bus.wr("PERIOD_CTRL", 0)
            for j, e in enumerate(envs):
                if j != k:
                    assert "PERIOD_READY" not in await e.bus.events(), \
                        f"a period on channel {k} raised PERIOD_READY on channel {j}"


# ---- pytest --------------------------------------------------------------------------------------
@pytest.mark.parametrize("top,channels,profile,count_w,ts_w,engine", CHANNEL_CONFIGS,
                         ids=[f"{t}-ch{c}-{p}" + ("-engine" if e else "")
                              for t, c, p, _, _, e in CHANNEL_CONFIGS])
def test_channels(top, channels, profile, count_w, ts_w, engine):
    from enctools.harness import run

    code = enum("CAPS", "PROFILE")[profile]
    run(top, __name__, name=f"{build_name(top, count_w, ts_w)}_ch{channels}_{profile}_e{engine}",
        parameters={"COUNT_W": count_w, "TS_W": ts_w, "CHANNELS": channels, "PROFILE": code,
                    "ENGINE": engine}, sim="verilator" if channels > 4 else None)
