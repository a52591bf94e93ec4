# SPDX-License-Identifier: Apache-2.0
"""enc_qei snapshots: SNAP_COUNT, SNAP_TIME, SNAP_EDGE_TIME, SNAP_DELTA and SNAP_EDGE_DELTA by
bus command, snap_in and the unit timer (SNAP_PERIOD): coherence within one clock, deltas across
wraps and reversals, held values, wide values. A lean build has no unit timer of its own (the
global one is there); with the shared engine, whose values are not in per-clock registers,
snapshot_values_exact checks every snapshot against the motion played clock by clock instead of
against the core's registers.

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

from enctools.qei.bus import AXIL_SNAP_LAT, PERIOD_PS, T_NS, WB_SNAP_LAT, BusTrace, signed, traced_write
from enctools.qei.env import (CONFIG_IDS, CONFIGS, ClockTrace, Timebase, begin, build_param,
                              engine_build, engine_period, lacks, read_snapshot, run_feature)
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import ClockWalk, Timeline, durations
from enctools.regmap import event_bits, pack
from enctools.tb import cocotb_test


@cocotb_test(skip=lacks("PERIOD") or engine_build())
async def snapshot_coherence(dut):
    """Snapshots by bus command, snap_in and the unit timer while the shaft turns: SNAP_COUNT,
    SNAP_TIME, SNAP_EDGE_TIME and SNAP_DELTA all belong to one clock (the core's and the timing
    unit's registers in that clock)."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=1000, filter_len=1)
    trace = ClockTrace(dut)
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    snaps = []
    switched = {}  # edge type -> trace clock of the switch to it
    for edge in ("any", "a_rising"):
        switched[edge] = len(trace.tb)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=1, PERIOD_EN=1, EDGE=edge))
        await bus.wr("SNAP_PERIOD", rng.randint(60, 90))
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, IN_EN=1, PERIOD_EN=1, EDGE=edge))
        wf = random_walk(rng, 300, 2.2 * T_NS, 6 * T_NS, p_reverse=0.15, start_pos=env.pos)
        task = cocotb.start_soon(env.drv.play(wf))
        while not task.done():
            how = rng.choice(["cmd", "in", "wait"])
            if how == "cmd":
                await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, IN_EN=1, PERIOD_EN=1, EDGE=edge))
            elif how == "in":
                await FallingEdge(dut.clk)
                dut.snap_in.value = 1
                await FallingEdge(dut.clk)
                dut.snap_in.value = 0
            else:
                await ClockCycles(dut.clk, rng.randint(5, 40))
            # the unit timer keeps snapping; read whatever is latched now, coherently or not
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=0, PERIOD_EN=0, EDGE=edge))
            snaps.append((edge, await read_snapshot(bus)))
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=1, PERIOD_EN=1, EDGE=edge))
        await task
        env.pos = wf.positions[-1]
    await env.settle()
    assert len(snaps) >= 20
    prev_i = None
    for edge, s in snaps:
        i = trace.clock_of(s["time"], after=0 if prev_i is None else max(prev_i - 5, 0))
        count = (s["count_hi"] << 32 | s["count"]) & model.max
        assert count == trace.count[i], f"SNAP_COUNT {count} is not the count of clock {i}"
        exp_edge = trace.last_edge_time(i, edge == "a_rising")
        edges = trace.arise if edge == "a_rising" else trace.any
        if not any(edges[switched[edge] + 2:i]):
            exp_edge = None  # no edge of the new type yet: edge_change_chooses_later_edges
        if exp_edge is not None:
            assert s["edge_time"] == exp_edge & ts_mask, \
                f"SNAP_EDGE_TIME {s['edge_time']}, last {edge} edge at {exp_edge} (clock {i})"
        prev_i = i
    # deltas: consecutive snapshots (no other snapshot in between) differ by SNAP_DELTA
    checked = 0
    for (_, a), (_, b) in zip(snaps, snaps[1:]):
        ia, ib = trace.clock_of(a["time"]), trace.clock_of(b["time"])
        if ib > ia and not any(trace.tb[k] == 0 for k in range(ia, ib)):
            steps = trace.count[ib] - trace.count[ia]
            if signed(b["delta"]) == steps:
                checked += 1
    assert checked >= 1, "no snapshot pair showed SNAP_DELTA = the count change between them"
    trace.task.cancel()
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_values_exact(dut):
    """Snapshots by SNAP_CTRL.CMD, by snap_in (SNAP_CTRL.IN_EN) and by GSNAP_CTRL.CMD while the
    shaft moves clock by clock (FILTER_LEN 1, states of 1 to 6 clocks, reversals): each one's
    SNAP_COUNT, SNAP_EDGE_TIME, SNAP_DELTA and SNAP_EDGE_DELTA are those of the clock its
    SNAP_TIME names (enctools.qei.stimulus.Timeline: the same pipeline on every build), SNAP_TIME
    lies between the request and the read, and SNAP_READY is set. EDGE any, then A rising."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=1000, filter_len=1)
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    walker = ClockWalk(dut, [model], rng, positions=[env.pos], shortest=1, longest=6)
    line = walker.lines[0]
    task = cocotb.start_soon(walker.run(12000))
    seen = {}
    for edge in ("any", "a_rising"):
        ctrl = pack("SNAP_CTRL", IN_EN=1, EDGE=edge)
        await bus.wr("SNAP_CTRL", ctrl)
        await env.applied()
        switched, prev = walker.now(), None
        for i in range(14):
            await ClockCycles(dut.clk, rng.randint(1, 60))
            how = rng.choice(("cmd", "in", "gsnap"))
            t0 = walker.now()
            if how == "cmd":
                await bus.wr("SNAP_CTRL", ctrl | pack("SNAP_CTRL", CMD=1))
            elif how == "gsnap":
                await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1))
            else:
                await FallingEdge(dut.clk)
                dut.snap_in.value = 1
                await FallingEdge(dut.clk)
                dut.snap_in.value = 0
            await env.settle(8)
            snap = await read_snapshot(bus)
            t = walker.unwrap(snap["time"])
            what = f"EDGE {edge}, snapshot {i} by {how} at timebase {snap['time']:#x}"
            assert t0 <= t <= walker.now(), f"{what}: requested at {t0 & ts_mask:#x}"
            mark = line.at(t)
            count = (snap["count_hi"] << 32 | snap["count"]) & model.max
            assert count == mark.count, f"{what}: SNAP_COUNT {count:#x}, count then {mark.count:#x}"
            e = line.edge(t, edge == "a_rising")
            if e is not None and e.t > switched:
                assert snap["edge_time"] == (e.t + line.EDGE_PIPE) & ts_mask, \
                    f"{what}: SNAP_EDGE_TIME {snap['edge_time']:#x}, last edge's pins set at " \
                    f"{e.t & ts_mask:#x}"
            if prev is not None:
                delta = signed(snap["delta"])
                assert delta == mark.motion - prev[0].motion, \
                    f"{what}: SNAP_DELTA {delta}, motion {mark.motion - prev[0].motion}"
                if e is not None and prev[1] is not None and prev[1].t > switched:
                    edge_delta = signed(snap["edge_delta"])
                    assert edge_delta == e.motion - prev[1].motion, \
                        f"{what}: SNAP_EDGE_DELTA {edge_delta}, motion {e.motion - prev[1].motion}"
            ev = await bus.events()
            assert "SNAP_READY" in ev, f"{what}: no SNAP_READY ({sorted(ev)})"
            await env.applied()
            prev = (mark, e)
            seen[how] = seen.get(how, 0) + 1
    task.cancel()
    await bus.wr("SNAP_CTRL", 0)
    dut._log.info("snapshots checked: %s", seen)


@cocotb_test(skip=lacks("TIMING"))
async def edge_change_chooses_later_edges(dut):
    """SNAP_CTRL.EDGE changed (any <-> A rising, no CMD) while the shaft moves clock by clock
    (FILTER_LEN 1, states of 1 to 6 clocks), then a CMD snapshot: each edge was chosen by the EDGE
    in force when the count took it, so SNAP_EDGE_TIME is the last edge chosen that way (one of the
    old type while no edge of the new one came) and SNAP_EDGE_DELTA the motion from the previous
    snapshot's edge to it. On the per-channel build the new EDGE chooses exactly the edges whose
    timestamp is the write's snapshot clock's timebase or later; with the shared engine, the edges
    the count takes from the clock of the channel's read that applies the write on (channel 0's
    reads watched, white box; half the snapshots then by snap_in just after that read). With the
    shaft at rest, a change moves nothing: a snapshot after it holds the same SNAP_EDGE_TIME with
    SNAP_EDGE_DELTA and SNAP_DELTA 0."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=1000, filter_len=1)
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE="any"))
    await env.applied()
    trace = BusTrace(dut)
    lat = WB_SNAP_LAT if trace.wb else AXIL_SNAP_LAT
    walker = ClockWalk(dut, [model], rng, positions=[env.pos], shortest=1, longest=6)
    line = walker.lines[0]
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    late = env.lag + 6 if env.engine else 0  # the engine applies the write at the next read
    reads = []  # the engine: the timebase of every read of channel 0 (white box)
    if env.engine:
        lane = dut.u_qei.g_engine.u_engine.g_lane[0].u_lane

        async def watch_reads():
            while True:
                await RisingEdge(dut.clk)
                await ReadOnly()
                if int(lane.rd.value):
                    reads.append(walker.now())
        watcher = cocotb.start_soon(watch_reads())
    a_now, floor, prev, checked = False, walker.now(), None, 0
    for trial in range(24):
        new_a = not a_now
        task = cocotb.start_soon(walker.run(rng.randint(80, 300)))
        await ClockCycles(dut.clk, rng.randint(2, 60))
        ctrl = pack("SNAP_CTRL", EDGE="a_rising" if new_a else "any", IN_EN=1)
        wclk, _ = await traced_write(bus, trace, "SNAP_CTRL", ctrl)
        switch = walker.unwrap(trace.rows[wclk + lat]["tb"])  # (the write's snapshot clock)
        if env.engine and trial % 2:
            # a snap_in snapshot 1 .. 4 clocks after the read that applies the write: the edges
            # around that read tell where the new EDGE starts
            while not [r for r in reads if r + 1 >= switch]:
                await RisingEdge(dut.clk)
            await ClockCycles(dut.clk, rng.randint(0, 3))
            await FallingEdge(dut.clk)
            dut.snap_in.value = 1
            await FallingEdge(dut.clk)
            dut.snap_in.value = 0
        else:
            # (mostly soon after the change: the edges near it tell where the new EDGE starts)
            await ClockCycles(dut.clk, rng.choice((1, 1, 2, 3, 4, 6, rng.randint(8, 80))))
            await bus.wr("SNAP_CTRL", ctrl | pack("SNAP_CTRL", CMD=1))
        await env.settle(8)
        snap = await read_snapshot(bus)
        t = walker.unwrap(snap["time"])
        what = f"trial {trial}, EDGE to {'a_rising' if new_a else 'any'} at timebase {switch & ts_mask:#x}, " \
            f"snapshot at {snap['time']:#x}"
        cands = {}
        # the new EDGE chooses the edges stamped from S on; with the engine those the count takes
        # from the clock of the read that applies the write on, stamped from that read + 1
        switches = [r + 1 for r in reads if switch <= r + 1 <= switch + late] if env.engine else [switch]
        assert switches, f"{what}: no read of the channel within {late} clocks of the write"
        for sw in switches:
            m = line.edge(t, new_a, switch=sw, old_a=a_now, floor=floor)
            if m is not None:
                cands[(m.t + line.EDGE_PIPE) & ts_mask] = m
        if cands:  # (else the last chosen edge is older than the walk so far: not judged)
            assert snap["edge_time"] in cands, \
                f"{what}: SNAP_EDGE_TIME {snap['edge_time']:#x}, the last chosen edge at " \
                f"{[hex(c) for c in cands]}"
            e = cands[snap["edge_time"]]
            if prev is not None:
                assert signed(snap["edge_delta"]) == e.motion - prev.motion, \
                    f"{what}: SNAP_EDGE_DELTA {signed(snap['edge_delta'])}, the motion from the " \
                    f"previous snapshot's edge {e.motion - prev.motion}"
            checked += 1
        prev = cands.get(snap["edge_time"])
        await task
        env.pos = walker.pos[0]
        a_now, floor = new_a, switch + late + 1
        if trial % 3 == 2:  # at rest: a change moves nothing
            await env.settle(8)
            await bus.wr("SNAP_CTRL", ctrl | pack("SNAP_CTRL", CMD=1))
            await env.settle(8)
            before = await read_snapshot(bus)
            a_now = not a_now
            ctrl = pack("SNAP_CTRL", EDGE="a_rising" if a_now else "any", IN_EN=1)
            await bus.wr("SNAP_CTRL", ctrl)
            await env.applied()
            await bus.wr("SNAP_CTRL", ctrl | pack("SNAP_CTRL", CMD=1))
            await env.settle(8)
            after = await read_snapshot(bus)
            assert (after["edge_time"], after["edge_delta"], after["delta"]) == (before["edge_time"], 0, 0), \
                f"trial {trial}: EDGE changed at rest: SNAP_EDGE_TIME {before['edge_time']:#x} -> " \
                f"{after['edge_time']:#x}, SNAP_EDGE_DELTA {after['edge_delta']:#x}, SNAP_DELTA {after['delta']:#x}"
            # the edges before this change were chosen by the type before it, which is the next
            # trial's new type, and its search would take them for its old type's: it stops here
            prev, floor = None, walker.now()
    assert checked >= 16, f"only {checked} of 24 snapshots judged"
    trace.task.cancel()
    if env.engine:
        watcher.cancel()
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_deltas_across_wraps(dut):
    """SNAP_DELTA counts the motion (every step of the function) across modulo wraps and limit
    stops; SNAP_EDGE_DELTA is the position change between the last selected edges (any edge, and
    A rising with x4 counting), whatever the range did to the count."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for mode, edge in (("modulo", "any"), ("modulo", "a_rising"), ("limit", "any"), ("free", "a_rising")):
        ceiling = 9 if mode != "free" else None
        await env.setup(model, rng_mode=mode, count=3, ceiling=ceiling)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE=edge))
        await env.settle()
        model.delta = 0
        pos_hist = [env.pos]  # 4X positions, for the A-rising edge deltas
        prev_edge_pos = None
        for seg in range(6):
            steps = [rng.choice([1, 1, 1, -1])] * rng.randint(5, 40)
            wf = walk(steps, durations(rng, len(steps)), start_pos=env.pos)
            await env.play(wf, model)
            pos_hist += wf.positions[1:]
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE=edge))
            await env.settle(4)
            snap = await read_snapshot(bus)
            assert signed(snap["delta"]) == model.delta, \
                f"{mode}: SNAP_DELTA {signed(snap['delta'])}, model {model.delta} steps of motion"
            # edge delta: position change between the last selected edges (the motion, in every
            # range: a step a limit blocks counts too)
            if True:
                if edge == "any":
                    last = len(pos_hist) - 1
                else:
                    rises = [k for k in range(1, len(pos_hist))
                             if QUAD[pos_hist[k - 1] % 4][0] == 0 and QUAD[pos_hist[k] % 4][0] == 1]
                    last = rises[-1] if rises else None
                if last is not None and prev_edge_pos is not None:
                    exp = pos_hist[last] - prev_edge_pos
                    assert signed(snap["edge_delta"]) == exp, \
                        f"{mode}/{edge}: SNAP_EDGE_DELTA {signed(snap['edge_delta'])}, expected {exp}"
                if last is not None:
                    prev_edge_pos = pos_hist[last]
            model.delta = 0
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("PERIOD"))
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
        await env.applied()
        times = []
        for wait in (step + 5, 2 * step + step // 2 + 7):
            await Timer((wait * (pre + 1) + env.lag) * PERIOD_PS, unit="ps")
            t = await bus.rd("SNAP_TIME")
            tb = await bus.rd("TIMEBASE")
            assert (tb - t) & ts_mask <= step + 40 + env.lag, \
                f"SNAP_PERIOD {p} PRESCALE {pre}: SNAP_TIME {t} a period behind TIMEBASE {tb}"
            times.append(t)
        d = (times[1] - times[0]) & ts_mask
        assert d % step == 0 and d >= 2 * step, \
            f"SNAP_PERIOD {p} PRESCALE {pre}: snapshots {d} ticks apart, not a multiple of {step}"
        await bus.wr("SNAP_CTRL", 0)
    await bus.wr("TB_PRESCALE", 0)


@cocotb_test(skip=lacks("PERIOD"))
async def unit_timer_rewrites(dut):
    """The channel's unit timer keeps its grid through rewrites (SNAP_CTRL.PERIOD_EN, SNAP_PERIOD):
    SNAP_PERIOD 400 ticks (PRESCALE 0), PERIOD_EN 0 -> 1, then SNAP_CTRL rewritten with PERIOD_EN
    1, EDGE changed and IN_EN set, a snap_in pulse, SNAP_CTRL rewritten with PERIOD_EN 1 and CMD,
    then SNAP_PERIOD 150 in the middle of a period: the periodic SNAP_TIMEs (SNAP_TIME polled
    every 20 clocks) stay 400 apart on one grid through the rewrites, snap_in's and CMD's
    snapshots are their own, off the grid, the period in progress at the SNAP_PERIOD write keeps
    its 400, and the next ones come 150 apart."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0)
    clock = Timebase(dut)
    await bus.wr("SNAP_PERIOD", 400)
    await env.applied()
    t0 = clock.now()
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1))
    # (one coroutine on the bus: the writes at their times between the polls)
    acts = [(1000, "SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1, EDGE="a_rising", IN_EN=1)),
            (1400, "snap_in", 1), (1410, "snap_in", 0),
            (2200, "SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1, CMD=1)),
            (3100, "SNAP_PERIOD", 150)]
    at, seen, last = {}, [], None
    while clock.now() - t0 < 4300:
        if acts and clock.now() - t0 >= acts[0][0]:
            _, reg, value = acts.pop(0)
            at[reg, value] = clock.now() - t0
            if reg == "snap_in":
                dut.snap_in.value = value
            else:
                await bus.wr(reg, value)
        t = await bus.rd("SNAP_TIME")
        if t != last:
            seen.append((t - t0) & ((1 << int(dut.TS_W.value)) - 1))
            last = t
        await ClockCycles(dut.clk, 20)
    await bus.wr("SNAP_CTRL", 0)
    dut._log.info("SNAP_TIMEs from the PERIOD_EN write: %s", seen)
    seen = [t for t in seen if 0 < t <= 4300]  # (the one before the timer: SNAP_TIME as it was)
    g = seen[0]
    in_at, cmd_at = at["snap_in", 1], at["SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1, CMD=1)]
    new_at = at["SNAP_PERIOD", 150]
    off = [t for t in seen if t < new_at and (t - g) % 400]
    assert len(off) == 2 and in_at <= off[0] <= in_at + 40 + env.lag and \
        cmd_at <= off[1] <= cmd_at + 40 + env.lag, \
        f"SNAP_TIMEs off the 400-tick grid from {g}: {off} (snap_in at {in_at}, CMD at {cmd_at})"
    grid = [t for t in seen if t not in off]
    first_new = min(t for t in grid if t > new_at)
    want = list(range(g, first_new, 400)) + list(range(first_new, grid[-1] + 1, 150))
    assert grid == want, f"periodic SNAP_TIMEs {grid}, expected {want}"
    assert (first_new - g) % 400 == 0 and grid[-1] > first_new, \
        f"the period in progress at SNAP_PERIOD 150 (written at {new_at}) ended at {first_new}"


@cocotb_test(skip=lacks("PERIOD") or not engine_build())
async def unit_timer_faster_than_the_engine(dut):
    """The shared engine: SNAP_PERIOD below P (0, 1, 5, P / 2, P - 1) with PERIOD_EN, a request at
    least every P - 1 ticks: once one request has waited for a read, every later one waits too,
    and the channel takes one snapshot per read, SNAP_TIME values exactly P ticks apart (the RDL,
    CAPS.ENGINE shared (3)). Before that (SNAP_PERIOD near P: the timer's grid drifts against the
    reads by P - SNAP_PERIOD a period) the snapshots are SNAP_PERIOD apart. SNAP_TIME is polled
    every few clocks, so no value is missed; the regime must start within P + 2 periods."""
    env, rng = await begin(dut)
    bus = env.bus
    p = engine_period(int(dut.CHANNELS.value))
    tb = Timebase(dut)  # (a tick a clock: TB_PRESCALE 0)
    for sp in (0, 1, 5, p // 2, p - 1):
        step = max(sp, 1)
        await bus.wr("SNAP_PERIOD", sp)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1))
        await env.applied()
        seen = [await bus.rd("SNAP_TIME")]
        gaps = []
        waited = False
        limit = (p + 2) * step + 4 * p
        start = tb.now()
        while len(gaps) < 6:
            t = await bus.rd("SNAP_TIME")
            if t == seen[-1]:
                assert tb.now() - start < limit + 10 * p, \
                    f"SNAP_PERIOD {sp}: SNAP_TIME stopped at {t:#x}"
                continue
            gap = (t - seen[-1]) & tb.mask
            seen.append(t)
            if len(seen) == 2:
                continue  # (from the value before the timer)
            if waited:
                gaps.append(gap)
            elif gap != step:
                # the first snapshot that waited for a read: at most P after the one before
                assert 0 < gap <= p, f"SNAP_PERIOD {sp}: snapshots {[hex(x) for x in seen]}"
                waited = True
            else:
                assert tb.now() - start < limit, \
                    f"SNAP_PERIOD {sp}: no snapshot waited for a read in {limit} clocks"
        assert set(gaps) == {p}, f"SNAP_PERIOD {sp}: once one waited, snapshots {gaps} apart, not " \
                                 f"one at each read, every P = {p}"
        await bus.wr("SNAP_CTRL", 0)
        await env.applied()


@cocotb_test(skip=lacks("TIMING"))
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


@cocotb_test(skip=lacks("PERIOD"))
async def unit_timer_prescaled(dut):
    """The unit timer at PRESCALE 2 .. 5 (ticks 3 .. 6 clocks apart: clocks without a tick between
    the ticks): SNAP_PERIOD = P gives a SNAP_READY exactly P x (PRESCALE + 1) clocks after the
    previous one, and SNAP_TIME values exactly P ticks apart. (The shared engine shows a snapshot
    up to its latency late: SNAP_TIME read until it changes, each new value exactly P ticks after
    the one before.)"""
    env, rng = await begin(dut)
    bus = env.bus
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    await bus.wr("IRQ_EN", event_bits("SNAP_READY"))
    for pre, p in ((2, 0x2D), (3, 0x24), (3, 0x28), (4, 0x1E), (5, 0x1C), (3, 0x2C), (5, 0x25)):
        await bus.wr("TB_PRESCALE", pre)
        await bus.wr("SNAP_PERIOD", p)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", PERIOD_EN=1))
        seen = []
        if env.engine:
            last = await bus.rd("SNAP_TIME")
            for _ in range(4 * p * (pre + 1)):
                if len(seen) == 4:
                    break
                t = await bus.rd("SNAP_TIME")
                if t != last:
                    seen.append((None, t))
                last = t
            assert len(seen) == 4, f"PRESCALE {pre} SNAP_PERIOD {p}: {len(seen)} snapshots"
        for k in range(4 if not env.engine else 0):
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
            assert env.engine or c1 - c0 == p * (pre + 1), \
                f"PRESCALE {pre} SNAP_PERIOD {p}: snapshots {c1 - c0} clocks apart, not {p * (pre + 1)}"
            assert (t1 - t0) & ts_mask == p, \
                f"PRESCALE {pre} SNAP_PERIOD {p}: SNAP_TIME {t0:#x} then {t1:#x}, not {p} ticks apart"
        await bus.wr("SNAP_CTRL", 0)
    await bus.wr("TB_PRESCALE", 0)
    await bus.wr("IRQ_EN", 0)
    await bus.events()


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_delta_across_presets(dut):
    """A preset on every index (a rotary axis referenced every turn) at the count-rate bound:
    SNAP_DELTA and SNAP_EDGE_DELTA count the motion, the steps the shaft moved, including the
    step of the transition an index preset overrides; SNAP_COUNT is the model's count. Forward,
    backward and turning walks over many index pulses, snapshots by bus command between them."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    rev = 40  # 4X counts per revolution: an index pulse at positions 0 .. 2 of each
    zf = lambda p: int(p % rev < 3)  # noqa: E731  (Z rises with the transition onto p % rev == 0)
    for func in ("x4", "x2a"):
        await env.setup(model, func=func, count=0, filter_len=1)
        preset = rng.randint(1000, 5000)
        await bus.set64("PRESET", preset)
        await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="preset", EDGE="rising", ARM=1))
        model.preset, model.idx_action, model.idx_edge, model.idx_arm = preset, "preset", "rising", True
        model.idx_gate, model.idx_oneshot = None, False
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        model.delta = 0
        model.idx_hits = 0
        for steps in ([1] * 170, [-1] * 130, [1, 1, 1, -1] * 30, [-1] * 90):
            wf = walk(steps, durations(rng, len(steps), f=1), start_pos=env.pos)
            await env.play(wf, model, zfun=zf)
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
            await env.settle(4)
            snap = await read_snapshot(bus)
            assert signed(snap["delta"]) == model.delta, \
                f"{func}: SNAP_DELTA {signed(snap['delta'])} after {model.idx_hits} presets, " \
                f"model {model.delta} steps of motion"
            # (EDGE any: every step is at an edge, so the steps between the two last edges are all
            # the steps between the snapshots)
            assert signed(snap["edge_delta"]) == model.delta, \
                f"{func}: SNAP_EDGE_DELTA {signed(snap['edge_delta'])}, model {model.delta}"
            count = snap["count"] | snap["count_hi"] << 32
            assert count == model.count, f"{func}: SNAP_COUNT {count:#x}, model {model.count:#x}"
            model.delta = 0
        assert model.idx_hits >= 10, f"{func}: only {model.idx_hits} index pulses"
        dut._log.info("%s: %d index presets, SNAP_DELTA = the motion", func, model.idx_hits)
    await bus.wr("INDEX_CTRL", 0)
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
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


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_edge_time_long_after_the_edge(dut):
    """Five steps, a snapshot, then snapshots 1,061, 2,122 and 5,305 clocks later with the shaft
    at rest (EDGE any, PRESCALE 0): SNAP_EDGE_TIME stays the last step's time, SNAP_DELTA and
    SNAP_EDGE_DELTA are 0, SNAP_TIME moves on. The shared engine's lane keeps only the low bits of
    an edge's time (256 ticks at one channel); the engine takes them in the window of the edge
    only: rebuilt from them later, an old edge's time would move forward by a multiple of 256."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=1000, filter_len=1)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE="any"))
    await env.applied()
    await env.play(walk([1] * 5, [3 * T_NS] * 5, start_pos=env.pos), model)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
    await env.settle(4)
    first = await read_snapshot(bus)
    last_time = first["time"]
    for rest in (1061, 2122, 5305):
        await ClockCycles(dut.clk, rest)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        snap = await read_snapshot(bus)
        what = f"a snapshot {rest} clocks after the one after the last step"
        assert snap["time"] != last_time, f"{what}: SNAP_TIME {snap['time']:#x} did not move"
        assert snap["edge_time"] == first["edge_time"], \
            f"{what}: SNAP_EDGE_TIME {snap['edge_time']:#x}, the last step's {first['edge_time']:#x}"
        assert snap["delta"] == 0 and snap["edge_delta"] == 0, \
            f"{what}: SNAP_DELTA {snap['delta']:#x}, SNAP_EDGE_DELTA {snap['edge_delta']:#x}, not 0"
        last_time = snap["time"]
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
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


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_deltas_backward(dut):
    """SNAP_DELTA and SNAP_EDGE_DELTA when the motion since reset is negative: the shaft first
    turns backward from reset, so the motion a snapshot keeps (the base of the next delta) has
    every high bit set; then segments backward and forward, a snapshot after each. Each delta is
    the steps between the two snapshots, whatever the motion's absolute value."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=rng.getrandbits(16), filter_len=1)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
    await env.settle(4)
    model.delta = 0
    for n, way in ((rng.randint(20, 60), -1), (rng.randint(5, 30), -1), (rng.randint(70, 120), 1),
                   (rng.randint(100, 160), -1), (rng.randint(5, 30), 1)):
        steps = [way] * n
        wf = walk(steps, durations(rng, n, f=1), start_pos=env.pos)
        await env.play(wf, model)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        snap = await read_snapshot(bus)
        assert signed(snap["delta"]) == model.delta, \
            f"after {n} x {way:+d}: SNAP_DELTA {signed(snap['delta'])}, model {model.delta}"
        # (EDGE any: every step is at an edge)
        assert signed(snap["edge_delta"]) == model.delta, \
            f"after {n} x {way:+d}: SNAP_EDGE_DELTA {signed(snap['edge_delta'])}, model {model.delta}"
        model.delta = 0
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING") or build_param("COUNT_W", 64) <= 32)
async def snapshot_count_across_bit_32(dut):
    """COUNT_W > 32: the count crosses bit 32 between two snapshots, up (a carry into the high
    word) and down (a borrow from it), and the top of the range (2^64 - 1 to 0 and back): each
    SNAP_COUNT_LO / SNAP_COUNT_HI pair is the model's count, SNAP_DELTA and SNAP_EDGE_DELTA
    (EDGE any) the steps between the snapshots, COUNT_LO / COUNT_HI the count."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    for base in (0x0000_0000_FFFF_FFE0, 0x1234_5678_0000_0010, model.max - 0x18):
        await env.setup(model, count=base, filter_len=1)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        model.delta = 0
        for n, way in ((rng.randint(40, 70), 1), (rng.randint(80, 140), -1), (rng.randint(60, 90), 1)):
            wf = walk([way] * n, durations(rng, n, f=1), start_pos=env.pos)
            await env.play(wf, model)
            await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
            await env.settle(4)
            snap = await read_snapshot(bus)
            got = snap["count_hi"] << 32 | snap["count"]
            what = f"from {base:#x}, {n} x {way:+d}"
            assert got == model.count, f"{what}: SNAP_COUNT {got:#x}, model {model.count:#x}"
            assert signed(snap["delta"]) == model.delta == signed(snap["edge_delta"]), \
                f"{what}: SNAP_DELTA {signed(snap['delta'])}, SNAP_EDGE_DELTA " \
                f"{signed(snap['edge_delta'])}, model {model.delta}"
            assert await bus.count() == model.count, f"{what}: COUNT, model {model.count:#x}"
            model.delta = 0
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def snapshot_deltas_skip_en_off(dut):
    """Steps while CTRL.EN = 0 are not counted in SNAP_DELTA or SNAP_EDGE_DELTA (their text):
    a snapshot, steps with EN 0, steps with EN 1, a snapshot: both deltas are the EN 1 steps;
    COUNT moved by them only."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0x1000, filter_len=1, en=0)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
    await env.settle(4)
    for off, on in ((rng.randint(5, 15), rng.randint(3, 9)), (rng.randint(5, 15), -rng.randint(3, 9))):
        await bus.wr("CTRL", pack("CTRL", EN=0, FUNC="x4", FILTER_LEN=1))
        await env.applied()
        await env.play(walk([1] * off, durations(rng, off, f=1), start_pos=env.pos), None)
        await bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1))
        model.set_func("x4", QUAD[env.pos % 4])
        model.en = True
        await env.applied()
        model.delta = 0
        steps = [1 if on > 0 else -1] * abs(on)
        await env.play(walk(steps, durations(rng, abs(on), f=1), start_pos=env.pos), model)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await env.settle(4)
        snap = await read_snapshot(bus)
        assert signed(snap["delta"]) == on == signed(snap["edge_delta"]), \
            f"{off} steps with EN 0, then {on:+d} with EN 1: SNAP_DELTA {signed(snap['delta'])}, " \
            f"SNAP_EDGE_DELTA {signed(snap['edge_delta'])}"
        assert await bus.count() == model.count, f"{off} steps with EN 0: COUNT moved"
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def edge_time_across_count_writes(dut):
    """A COUNT_LO write leaves the filters' FILTER_LEN alone in every clock: FILTER_LEN 3, then
    COUNT_LO writes, each with one step whose pins change i clocks after the write starts. With
    the shared engine every write starts at one phase of its visits and i runs over 2 P + 24
    clocks, so that in one trial the filter takes the step's third sample in the clock before the
    load (when the engine pushes the channel's configuration for the load), in another in the
    load's clock, and so on; a per-channel build loads at once (i over 8 clocks). Each trial's
    SNAP_EDGE_TIME (a snapshot after the load) is the step's clock + Timeline.EDGE_PIPE + 2 (two
    samples more than FILTER_LEN 1), whatever i."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=rng.getrandbits(16), filter_len=3)
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE="any"))
    clock = Timebase(dut)
    ts_mask = clock.mask
    p = engine_period(int(dut.CHANNELS.value)) if env.engine else 1
    span = 2 * p + 24 if env.engine else 8
    r0 = rng.randrange(p)
    pipe = Timeline.EDGE_PIPE + 2
    for i in range(span):
        await clock.phase(p, r0)
        at = []

        async def step() -> None:
            for _ in range(i):
                await FallingEdge(dut.clk)
            env.pos += 1
            dut.a_in.value, dut.b_in.value = QUAD[env.pos % 4]
            at.append(clock.now())

        task = cocotb.start_soon(step())
        await bus.wr("COUNT_LO", rng.getrandbits(32))
        await task
        await ClockCycles(dut.clk, pipe + 4)
        await env.applied()
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE="any", CMD=1))
        await env.settle(4)
        edge = await bus.rd("SNAP_EDGE_TIME")
        assert edge == (at[0] + pipe) & ts_mask, \
            f"step {i} clocks after a COUNT_LO write (pins at timebase {at[0] & ts_mask:#x}): " \
            f"SNAP_EDGE_TIME {edge:#x}, not {(at[0] + pipe) & ts_mask:#x}"
        clock.now()
    await bus.wr("SNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def global_snapshot_one_channel(dut):
    """The global snapshot of a one-channel build: by GSNAP_CTRL.CMD (ten of them, at timebase
    values 173 clocks and a bus transfer apart), by a rising snap_in with GSNAP_CTRL.IN_EN (none
    without it; GSNAP_TIME between the TIMEBASE values read before and after) and by the global
    unit timer (GSNAP_PERIOD 0x155, then 0x2AA: consecutive GSNAP_TIMEs exactly that far apart). Each one
    latches the channel's snapshot in its own clock (SNAP_TIME = GSNAP_TIME) and raises
    SNAP_READY."""
    env, rng = await begin(dut)
    bus = env.bus
    ready = event_bits("SNAP_READY")
    ts_mask = (1 << int(dut.TS_W.value)) - 1
    await env.setup(QeiModel(env.count_w), count=0)

    async def taken(what: str) -> int:
        gtime = await bus.rd("GSNAP_TIME")
        own = await bus.rd("SNAP_TIME")
        assert own == gtime, f"{what}: SNAP_TIME {own:#x}, GSNAP_TIME {gtime:#x}"
        ev = await bus.rd("EVENTS")
        assert ev & ready, f"{what}: no SNAP_READY (EVENTS {ev:#x})"
        await bus.wr("EVENTS", ready)
        return gtime

    for i in range(10):
        await ClockCycles(dut.clk, 173)
        await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1))
        await env.settle(4)
        await taken(f"CMD snapshot {i}")

    async def pulse_snap_in() -> tuple[int, int]:
        before = await bus.rd("TIMEBASE")
        await FallingEdge(dut.clk)
        dut.snap_in.value = 1
        await ClockCycles(dut.clk, 3)
        await FallingEdge(dut.clk)
        dut.snap_in.value = 0
        await env.settle(4)
        return before, await bus.rd("TIMEBASE")

    last = await bus.rd("GSNAP_TIME")
    await pulse_snap_in()
    assert await bus.rd("GSNAP_TIME") == last, "snap_in with IN_EN = 0 took a global snapshot"
    assert not await bus.rd("EVENTS") & ready, "snap_in with IN_EN = 0 raised SNAP_READY"
    await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", IN_EN=1))
    for i in range(4):
        await ClockCycles(dut.clk, 150 + 61 * i)
        before, after = await pulse_snap_in()
        gtime = await taken(f"snap_in snapshot {i}")
        assert (gtime - before) & ts_mask <= (after - before) & ts_mask, \
            f"snap_in snapshot {i}: GSNAP_TIME {gtime:#x} outside {before:#x}..{after:#x}"
    await bus.wr("GSNAP_CTRL", 0)

    for period in (0x155, 0x2AA):  # every bit of 0 .. 9 set in one of the two, clear in the other
        await bus.wr("GSNAP_PERIOD", period)
        await bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
        times = []
        while len(times) < 4:
            await ClockCycles(dut.clk, 40)
            if not await bus.rd("EVENTS") & ready:
                continue
            gtime = await taken(f"timer snapshot {len(times)}")
            assert await bus.rd("GSNAP_TIME") == gtime, "the unit timer fired again during the reads"
            times.append(gtime)
        await bus.wr("GSNAP_CTRL", 0)
        await env.settle(4)
        await bus.wr("EVENTS", ready)
        gaps = [(b - a) & ts_mask for a, b in zip(times, times[1:])]
        assert gaps == [period] * 3, \
            f"GSNAP_TIMEs {[hex(t) for t in times]}: gaps {gaps}, GSNAP_PERIOD {period:#x}"


@cocotb_test(skip=lacks("TIMING"))
async def unit_timer_high_bits(dut):
    """SNAP_PERIOD and GSNAP_PERIOD (a lean build: GSNAP_PERIOD) with a high bit set (each of bits 10 .. TS_W - 1, with 3 ticks
    more): no snapshot within 600 clocks of setting PERIOD_EN (a period bit lost on its way to a
    timer would make it fire after a few ticks). And with PERIOD_EN = 0 and the period 0x7FF
    (bits 0 .. 10 set), no snapshot in 2,100 clocks (PERIOD_EN must not depend on the period)."""
    env, rng = await begin(dut)
    bus = env.bus
    ready = event_bits("SNAP_READY")
    ts_w = int(dut.TS_W.value)
    timers = (("GSNAP_PERIOD", "GSNAP_CTRL"),) if lacks("PERIOD") else \
        (("SNAP_PERIOD", "SNAP_CTRL"), ("GSNAP_PERIOD", "GSNAP_CTRL"))
    for reg, ctrl_reg in timers:
        await bus.wr(reg, 0x7FF)
        await bus.events()
        await bus.wr(ctrl_reg, 0)
        await ClockCycles(dut.clk, 2100)
        assert not await bus.rd("EVENTS") & ready, f"{reg} 0x7ff with PERIOD_EN = 0: a snapshot"
        await bus.wr(reg, 0)
    for bit in range(ts_w - 1, 9, -1):
        period = 1 << bit | 3
        for reg, ctrl_reg in timers:
            await bus.wr(reg, period)
            await bus.events()
            await bus.wr(ctrl_reg, pack(ctrl_reg, PERIOD_EN=1))
            await ClockCycles(dut.clk, 600)
            ev = await bus.rd("EVENTS")
            await bus.wr(ctrl_reg, 0)
            assert not ev & ready, f"{reg} {period:#x}: a snapshot within 600 clocks"
            await bus.wr(reg, 0)
    await bus.events()


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_snapshots(config):
    run_feature(__name__, *config)
