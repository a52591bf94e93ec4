# SPDX-License-Identifier: Apache-2.0
"""enc_qei: when the global snapshot acts, to the clock, as doc/enc_qei.md and the RDL text of
GSNAP_CTRL / GSNAP_PERIOD say it:

- the clock of a CMD write's snapshot, counted one way for both buses: the *write clock* is the
  first clock of the Wishbone strobe, or the clock of the later of the AXI4-Lite AW and W
  handshakes; the snapshot is taken WB_SNAP_LAT (Wishbone) or AXIL_SNAP_LAT (AXI4-Lite) clocks
  after it, which is the clock after wb_ack_o, or the clock s_axil_bvalid rises; a channel's own
  SNAP_CTRL.CMD takes its snapshot in the same clock;
- PERIOD_EN written 1 while it is 1 does not restart the unit timer; a 0 -> 1 write starts it,
  its first snapshot GSNAP_PERIOD ticks after the write's snapshot clock (the clock a CMD in that
  write would take its snapshot);
- a new GSNAP_PERIOD applies after the period in progress: the timer snapshot that ends it comes
  at the old length, the next ones at the new; a write whose snapshot clock is less than
  PERIOD_LAG clocks before the end of the period in progress applies one period later;
  GSNAP_PERIOD 0 acts as 1 (a snapshot every tick);
- a TB_PRESCALE write that changes PRESCALE restarts the timebase's count of clocks from the
  write's snapshot clock (the RDL text of TB_PRESCALE); one that keeps it changes nothing.

With the shared engine (ENGINE = 1) the global snapshot is the same, but a channel's own
SNAP_CTRL.CMD is taken at the engine's next read of the channel, within P + 18 clocks of the
write clock (P = 24 x max(CHANNELS, 2), the clocks between two reads), and a global snapshot
requested while the capture of the one before still waits for its visit is taken when it no
longer waits (at most P clocks after the one before; requests meanwhile make one snapshot).

The times are taken from the design: the timebase (TB_PRESCALE 0: one tick per clock) and the
bus handshakes in every clock, and the global snapshots (the snapshot clocks). Runs on the builds
of enctools.qei.env.CONFIGS, with random AXI4-Lite back-pressure.
"""

from __future__ import annotations

import re

import pytest
from cocotb.triggers import ClockCycles, RisingEdge

from enctools.qei.bus import AXIL_SNAP_LAT, WB_SNAP_LAT, BusTrace, traced_write
from enctools.qei.env import ENGINE_ACT, CONFIG_IDS, CONFIGS, begin, engine_period, lacks, run_feature
from enctools.regmap import pack
from enctools.tb import cocotb_test

RESP = {True: -1, False: 0}   # the response's first clock - the snapshot clock (Wishbone: True)
TIMER_START = -1  # PERIOD_EN 0 -> 1: the timer counts from the clock before the write's snapshot
PERIOD_LAG = 1  # a new GSNAP_PERIOD: used for periods that start after the write's snapshot clock


async def traced_begin(dut):
    """begin(), TB_PRESCALE 0 (a tick a clock) and a BusTrace: (env, rng, trace, the bus's
    snapshot latency, WB_SNAP_LAT or AXIL_SNAP_LAT)."""
    env, rng = await begin(dut)
    await env.bus.wr("TB_PRESCALE", 0)
    trace = BusTrace(dut)
    return env, rng, trace, WB_SNAP_LAT if trace.wb else AXIL_SNAP_LAT


def check_deferred(requests, taken, p, what) -> None:
    """The shared engine's global snapshots: each request (a clock) is taken in its clock, or,
    while the capture of the snapshot before (at most p clocks before) waits for its visit, in
    the clock it is free (at most p clocks after that one); requests meanwhile make one snapshot;
    no snapshot without a request."""
    used = set()
    for r in sorted(requests):
        t = next((i for i in taken if i >= r), None)
        before = [i for i in taken if i < r]
        assert t is not None, f"{what}: no snapshot for the request in clock {r}"
        if t != r:
            assert before and r - before[-1] <= p and t <= before[-1] + p, \
                f"{what}: the request in clock {r} taken in clock {t} (the snapshot before: " \
                f"{before[-1] if before else None}, P {p})"
        used.add(t)
    assert used == set(taken), f"{what}: snapshots without a request: {sorted(set(taken) - used)}"


@cocotb_test(skip=lacks("TIMING"))
async def cmd_snapshot_clock(dut):
    """GSNAP_CTRL.CMD and a channel's SNAP_CTRL.CMD, twelve writes each at random distances:
    the snapshot clock (where GSNAP_TIME / SNAP_TIME take the timebase) is the write clock +
    WB_SNAP_LAT or AXIL_SNAP_LAT, the clock after the Wishbone acknowledge or the one BVALID
    rises in (with the shared engine, writes P clocks further apart, and SNAP_CTRL.CMD: from the
    write clock + that to the write clock + P + 18)."""
    env, rng, trace, lat = await traced_begin(dut)
    channels = int(dut.CHANNELS.value)
    bus = env.bus
    found = {}
    for reg, time_reg in (("GSNAP_CTRL", "GSNAP_TIME"), ("SNAP_CTRL", "SNAP_TIME")):
        for _ in range(12):
            # (the shared engine: after the capture of the snapshot before was visited)
            await ClockCycles(dut.clk, rng.randint(1, 30) + env.engine * engine_period(channels))
            n0 = trace.now()
            wclk, rclk = await traced_write(bus, trace, reg, pack(reg, CMD=1))
            snap = trace.clock_of(await bus.rd(time_reg), n0)
            found.setdefault(reg, set()).add((snap - wclk, rclk - snap))
    dut._log.info("snapshot clock - write clock, response clock - snapshot clock: %s", found)
    for reg, seen in found.items():
        if env.engine and reg == "SNAP_CTRL":
            d = sorted(d for d, _ in seen)
            assert lat <= d[0] and d[-1] <= engine_period(channels) + ENGINE_ACT, f"{reg}.CMD: {seen}"
            continue
        assert seen == {(lat, RESP[trace.wb])}, f"{reg}.CMD: {seen}"


@cocotb_test(skip=lacks("TIMING"))
async def period_en_rewrite_and_restart(dut):
    """The unit timer at GSNAP_PERIOD P: PERIOD_EN written 1 again (and CMD with it) at random
    phases keeps every timer snapshot on the grid of the first one, P clocks apart, and a CMD in
    such a rewrite is a snapshot of its own in its snapshot clock; PERIOD_EN
    written 0 and then 1 restarts it, the first snapshot P clocks after the write's snapshot
    clock. (The shared engine: a snapshot may be deferred, check_deferred.)"""
    env, rng, trace, lat = await traced_begin(dut)
    channels = int(dut.CHANNELS.value)
    bus = env.bus
    for period in (rng.randint(60, 90), rng.randint(150, 200)):
        await bus.wr("GSNAP_PERIOD", period)
        wclk, _ = await traced_write(bus, trace, "GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
        start = wclk + lat + TIMER_START
        rewrites = []
        for k in range(4):   # PERIOD_EN = 1 again, at random phases, the first with a CMD
            await ClockCycles(dut.clk, rng.randint(period // 3, 2 * period))
            cmd = int(k == 0 or rng.random() < 0.3)
            w, _ = await traced_write(bus, trace, "GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1, CMD=cmd))
            rewrites.append((w + lat, cmd))   # (its snapshot clock, with a CMD)
        await ClockCycles(dut.clk, 2 * period)
        # (at least five timer periods, that the shared engine has shown too)
        shown = engine_period(channels) if env.engine else 0
        await ClockCycles(dut.clk, max(1, start + 6 * period + shown - trace.now()))
        end = trace.now()
        cmds = {c for c, with_cmd in rewrites if with_cmd}
        if env.engine:  # the timer's grid and the commands, some of them deferred
            grid = range(start + period, end - engine_period(channels), period)
            assert len(grid) >= 5
            # (the next timer request, grid[-1] + period, is left out; period > P, so a snapshot
            # deferred from grid[-1], at most P clocks after the one before it, comes before it)
            assert period > engine_period(channels)
            taken = [i for i in trace.snapshots(start + 1, end) if i < grid[-1] + period]
            check_deferred(set(grid) | cmds, taken, engine_period(channels),
                           f"period {period}, PERIOD_EN rewritten at {[c - start for c, _ in rewrites]} "
                           f"clocks after the start (snapshots at {[i - start for i in taken]})")
        else:
            # a CMD in a rewrite is a snapshot of its own, in its snapshot clock (one in a clock
            # of the timer's grid is that snapshot too: kept below)
            assert cmds <= set(trace.snapshots(start + 1, end)), \
                f"period {period}: CMDs in PERIOD_EN rewrites at {sorted(c - start for c in cmds)} " \
                f"clocks after the start, snapshots at {[i - start for i in trace.snapshots(start + 1, end)]}"
            timer = [i for i in trace.snapshots(start + 1, end)
                     if i not in cmds or (i - start) % period == 0]
            assert len(timer) >= 5, f"period {period}: timer snapshots at {[i - start for i in timer]}, " \
                f"commands at {[c - start for c in cmds]}, end {end - start}"
            assert [i - start for i in timer] == [period * (k + 1) for k in range(len(timer))], \
                f"period {period}: timer snapshots at {[i - start for i in timer]} clocks after " \
                f"the start; PERIOD_EN rewritten at {[c - start for c, _ in rewrites]}"
        # 0, then 1: a restart
        await ClockCycles(dut.clk, rng.randint(1, period))
        await bus.wr("GSNAP_CTRL", 0)
        await ClockCycles(dut.clk, rng.randint(0, 20))
        n0 = trace.now()
        wclk, _ = await traced_write(bus, trace, "GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
        await ClockCycles(dut.clk, period + 10)
        first = trace.snapshots(n0)[0]
        assert first - (wclk + lat + TIMER_START) == period, \
            f"restart: first timer snapshot {first - (wclk + lat)} clocks after the write's " \
            f"snapshot clock, GSNAP_PERIOD {period}"
        await bus.wr("GSNAP_CTRL", 0)


@cocotb_test(skip=lacks("TIMING"))
async def new_period_after_the_one_in_progress(dut):
    """GSNAP_PERIOD changed (P1 <-> P2) while the timer runs, the write's snapshot clock d clocks
    before the end of the period in progress (aimed at d = -2 .. 11 and four random d): the timer
    snapshot that ends it comes at the old length; the following period is the new one when
    d >= PERIOD_LAG, else the old one once more; the one after that is the new one."""
    env, rng, trace, lat = await traced_begin(dut)
    bus = env.bus
    p1, p2 = rng.randint(70, 90), rng.randint(100, 120)
    await bus.wr("GSNAP_PERIOD", p1)
    await traced_write(bus, trace, "GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
    await ClockCycles(dut.clk, 2 * p1 + 5)
    p_cur, seen = p1, {}
    aims = [*range(-2, 12), *(rng.randint(12, p1 - 20) for _ in range(4))]
    # AXI4-Lite back-pressure moves a write by a few clocks, by amounts that can repeat with the
    # phase of the timer: aim at the boundary until both of its sides were hit (at most 60 more
    # writes), moving the aim after each write: later when it landed past the end of the period
    # (d is then most of a period) or at d < PERIOD_LAG, earlier when at d >= PERIOD_LAG
    n_fixed, extra, b_aim, k = len(aims), 60, PERIOD_LAG, 0
    while aims:
        aim, k = aims.pop(0), k + 1
        if not aims and not (PERIOD_LAG - 1 in seen.get(False, ()) and
                             PERIOD_LAG in seen.get(True, ())) and extra:
            extra -= 1
            aims.append(b_aim)
        p_new = p2 if p_cur == p1 else p1
        nxt = trace.snapshots(0)[-1] + p_cur
        while nxt - aim - lat - 2 <= trace.now():
            nxt += p_cur
        while trace.now() < nxt - aim - lat - 1:   # the master starts a clock after it is asked
            await RisingEdge(dut.clk)
        n0 = trace.now()
        wclk, _ = await traced_write(bus, trace, "GSNAP_PERIOD", p_new)
        await ClockCycles(dut.clk, 3 * max(p_cur, p_new) + 10)
        wsnap = wclk + lat
        snaps = trace.snapshots(n0 - p_cur - 5)
        ends = [i for i in snaps if i >= wsnap]
        prev = max(i for i in snaps if i < ends[0])
        d = ends[0] - wsnap
        gaps = [b - a for a, b in zip(ends, ends[1:])][:2]
        seen.setdefault(d >= PERIOD_LAG, set()).add(d)
        if k > n_fixed:  # (a boundary write)
            late = d > p_cur // 2  # (landed after the end: d counts to the next one)
            b_aim += 1 if late or d < PERIOD_LAG else -1
        assert ends[0] - prev == p_cur, f"d {d}: the period in progress lasted {ends[0] - prev}, not {p_cur}"
        expect = [p_new, p_new] if d >= PERIOD_LAG else [p_cur, p_new]
        assert gaps == expect, f"d {d}: periods {gaps} after the write, expected {expect}"
        p_cur = p_new
    dut._log.info("d (write's snapshot clock to the end of the period) by 'new period next': %s", seen)
    assert PERIOD_LAG - 1 in seen.get(False, ()) and PERIOD_LAG in seen.get(True, ()), \
        f"the sweep missed the boundary: {seen}"


@cocotb_test(skip=lacks("TIMING"))
async def period_zero_acts_as_one(dut):
    """GSNAP_PERIOD 0 and 1 (TB_PRESCALE 0), the timer started by a 0 -> 1 write of PERIOD_EN: a
    snapshot in every clock from the write's snapshot clock on (the snapshot clock + GSNAP_PERIOD
    - 1), the same for both values, until PERIOD_EN is written 0 (the shared engine: requests in
    every clock, taken as check_deferred allows)."""
    env, rng, trace, lat = await traced_begin(dut)
    channels = int(dut.CHANNELS.value)
    bus = env.bus
    p = engine_period(channels) if env.engine else 0
    for period in (0, 1, 0):
        await bus.wr("GSNAP_PERIOD", period)
        await ClockCycles(dut.clk, rng.randint(1, 20) + p)
        wclk, _ = await traced_write(bus, trace, "GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
        start = wclk + lat + TIMER_START
        await ClockCycles(dut.clk, rng.randint(30, 60) + 2 * p)
        stop, _ = await traced_write(bus, trace, "GSNAP_CTRL", 0)
        stop += lat  # (the stop's snapshot clock: no timer request from there on)
        await ClockCycles(dut.clk, 2 * p + 4)
        taken = [i for i in trace.snapshots(start - 5) if i < stop + p + 1]
        what = f"GSNAP_PERIOD {period}: snapshots at {[i - start for i in taken]} clocks from the " \
            f"timer's start (the stop at {stop - start})"
        if env.engine:
            check_deferred(set(range(start + 1, stop)), taken, p, what)
        else:
            assert taken == list(range(start + 1, stop)), what
        assert not trace.snapshots(stop + p + 1), f"{what}: snapshots after the stop"
        await ClockCycles(dut.clk, p)


@cocotb_test(skip=lacks("TIMING"))
async def prescale_write_restarts_the_count(dut):
    """TB_PRESCALE written at random phases (the timebase in every clock): a write that changes
    PRESCALE to Q restarts the prescaler's count, so the timebase holds the value it has in the
    write's snapshot clock S for Q + 2 clocks (no tick in S .. S + Q) and then advances every Q + 1
    clocks (the first tick in S + Q + 1); before S it keeps the old pace (a tick of the old grid
    may still come in S - 1). A write of the value it holds changes nothing: the ticks keep their
    grid across it."""
    env, rng, trace, lat = await traced_begin(dut)
    bus = env.bus
    cur, seen = 0, set()
    for trial in range(16):
        new = rng.choice((0, 1, 2, 3, 6, 9, cur))
        await ClockCycles(dut.clk, rng.randint(1, 3 * (cur + 1)))
        wclk, _ = await traced_write(bus, trace, "TB_PRESCALE", new)
        await ClockCycles(dut.clk, 4 * (new + 1) + 8)
        s = wclk + lat
        tb = [r["tb"] for r in trace.rows]
        # the clocks with a tick (the timebase advances at the end of them), from S
        ticks = [k - s for k in range(s - 3 * (cur + 1), len(tb) - 1) if tb[k + 1] != tb[k]]
        what = f"trial {trial}, PRESCALE {cur} -> {new}: ticks at {ticks} clocks from the write's snapshot clock"
        before, after = [k for k in ticks if k < 0], [k for k in ticks if k >= 0]
        assert len(before) >= 2 and all(b - a == cur + 1 for a, b in zip(before, before[1:])), what
        if new == cur:
            assert all(b - a == cur + 1 for a, b in zip(ticks, ticks[1:])), what
            assert before[-1] + cur + 1 == after[0], what
        else:
            assert before[-1] >= -1 - cur, f"{what}: the old pace stopped before S - 1"
            assert after[:4] == [new + 1 + k * (new + 1) for k in range(4)], what
            seen.add(after[0] - before[-1] > cur + 1)  # (the restart moved the grid)
        cur = new
    await bus.wr("TB_PRESCALE", 0)
    dut._log.info("PRESCALE changes that moved the tick grid: %s", seen)


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_gsnap_timing(config):
    run_feature(__name__, *config)


def test_doc_and_rdl_say_the_measured_clocks():
    """doc/enc_qei.md and the RDL text of GSNAP_CTRL give the clocks these tests measure: the
    snapshot clock as the strobe's first clock + WB_SNAP_LAT and the later handshake + AXIL_SNAP_LAT, the
    timer's first snapshot at the snapshot clock + GSNAP_PERIOD - 1."""
    from enctools.paths import DOC
    from enctools.regmap import nodes

    glb = {r.inst_name: r for _, _, r in nodes()}["GSNAP_CTRL"]
    texts = {"doc/enc_qei.md": (DOC / "enc_qei.md").read_text(),
             "GSNAP_CTRL (RDL)": " ".join([glb.get_property("desc")] +
                                          [f.get_property("desc") for f in glb.fields()])}
    for where, text in texts.items():
        text = " ".join(text.split())
        wb = set(re.findall(r"strobe(?:'s)? first clock \+ (\d+)|first clock of the strobe \+ (\d+)", text))
        axil = set(re.findall(r"handshakes?(?: clocks)? \+ (\d+)", text))
        assert {int(a or b) for a, b in wb} == {WB_SNAP_LAT}, f"{where}: Wishbone snapshot clock {wb}"
        assert {int(x) for x in axil} == {AXIL_SNAP_LAT}, f"{where}: AXI4-Lite snapshot clock {axil}"
        assert re.search(r"snapshot clock \+ GSNAP_PERIOD [-−] 1|snapshot clock \+ `GSNAP_PERIOD` [-−] 1",
                         text), f"{where}: the timer's first snapshot"
        assert "three clocks after its bus request" not in text

