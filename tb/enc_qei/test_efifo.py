# SPDX-License-Identifier: Apache-2.0
"""The edge-capture FIFO (EFIFO_CTRL, EFIFO_STATUS, EFIFO_ENTRY, EFIFO_TIME, EFIFO_LOST and the
EFIFO_THRESH / EFIFO_OVF events), checked against the stimulus itself.

Every walk here has states lasting whole clocks and starts half a clock after a rising edge, so
every transition falls mid-clock and the clock that samples it is known exactly: an entry's time
must be the first entry's time plus the clocks between the two transitions (TB_PRESCALE 0), its
direction and A/B state those of the walk's step, and the last entry's time the SNAP_EDGE_TIME of
a snapshot taken after the walk. With the FIFO overrun, every step is either in the FIFO, in
order, or counted in EFIFO_LOST, with LOST = 1 on the first entry after each gap: nothing is lost
silently.

Runs on EFIFO_CONFIGS: enc_qei_wb with one full channel, TS_W 32 and a 16-entry FIFO, and
enc_qei_axil with two lean channels, TS_W 16 (TIME_LO is the whole timestamp; the timebase wraps
in a test) and 32 entries, random AXI back-pressure, the FIFO of channel 1 (channel 0 stays
still: its FIFO must stay empty); and the same two on the shared engine (ENGINE 1: the FIFOs
beside it, rtl/enc_qei_efifo_bank.v), the second with three channels (channel 2 walked) and on
Verilator whatever SIM says. Every cocotb test logs its seed (make test SEED=n).
"""

from __future__ import annotations

import cocotb
import pytest
from cocotb.triggers import ClockCycles, FallingEdge
import numpy as np
from hedsmodel import QUAD, EncoderUnit, Profile, walk
from hedsmodel.velocity import Timebase, edge_table, ideal_edge_entries

from enctools.qei.bus import T_NS
from enctools.qei.env import begin, build_name, channel, channel_envs
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import aimed_races, pulse_rst
from enctools.regmap import enum, event_bits, get_field, pack
from enctools.tb import cocotb_test

# (top, CHANNELS, PROFILE, COUNT_W, TS_W, EFIFO_LOG2, ENGINE)
EFIFO_CONFIGS = (("enc_qei_wb", 1, "full", 32, 32, 4, 0), ("enc_qei_axil", 2, "lean", 32, 16, 5, 0),
                 ("enc_qei_wb", 1, "full", 32, 32, 4, 1), ("enc_qei_axil", 3, "lean", 32, 16, 5, 1))


def entry_fields(word: int) -> dict:
    return {n: get_field("EFIFO_ENTRY", n, word)
            for n in ("VALID", "DIR", "A", "B", "LOST", "IDX", "LEFT", "TIME_LO")}


class Fifo:
    """One channel's FIFO as the host sees it, with the walk that feeds it."""

    def __init__(self, dut, env):
        self.dut, self.env, self.bus = dut, env, env.bus
        self.ts_w = int(dut.TS_W.value)
        self.depth = 1 << int(dut.EFIFO_LOG2.value)

    async def level(self) -> int:
        """EFIFO_STATUS.LEVEL (the register's other bits must read 0)."""
        word = await self.bus.rd("EFIFO_STATUS")
        assert word >> 9 == 0, f"EFIFO_STATUS {word:#x}: bits above LEVEL set"
        return word

    async def pop(self) -> dict | None:
        """One EFIFO_ENTRY read (and EFIFO_TIME when TS_W > 16): the entry, or None if empty."""
        word = await self.bus.rd("EFIFO_ENTRY")
        assert word & 0xC0 == 0, f"EFIFO_ENTRY {word:#x}: bits 7:6 set"
        e = entry_fields(word)
        if not e["VALID"]:
            assert all(v == 0 for v in e.values()), f"an empty read answered {e}"
            return None
        e["TIME"] = await self.bus.rd("EFIFO_TIME")  # (with TS_W 16: the same as TIME_LO)
        assert e["TIME"] & 0xFFFF == e["TIME_LO"], f"TIME_LO {e['TIME_LO']:#x}, EFIFO_TIME {e['TIME']:#x}"
        return e

    async def drain(self) -> list[dict]:
        out = []
        while (e := await self.pop()) is not None:
            out.append(e)
        if out:  # EFIFO_TIME holds the last pop's time (the empty read above popped nothing)
            held = await self.bus.rd("EFIFO_TIME")
            assert held == out[-1]["TIME"], f"EFIFO_TIME {held:#x} after the drain, last {out[-1]['TIME']:#x}"
        return out

    async def start(self, func="x4", thresh=1, clear=True):
        """Count with ``func``, the FIFO on (with CLEAR unless ``clear`` is False: then it must
        be empty from the reset alone), EFIFO_LOST and EVENTS cleared."""
        model = QeiModel(self.env.count_w)
        await self.env.setup(model, func=func)
        await self.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=int(clear), THRESH=thresh))
        if clear:
            await self.bus.wr("EFIFO_LOST", 0)
        await self.bus.events()
        return model

    async def check_empty(self, what: str):
        assert await self.level() == 0, what
        assert await self.bus.rd("EFIFO_ENTRY") == 0, what
        assert await self.bus.rd("EFIFO_TIME") == 0, what
        assert await self.bus.rd("EFIFO_LOST") == 0, what

    def walk(self, rng, n: int, lo: int, hi: int, p_rev: float = 0.3):
        """n steps, each state lasting lo .. hi whole clocks; returns the waveform and the list
        of (clock offset from the first step, +1/-1, (A, B) after it, position after it)."""
        steps, clocks, pos, out, t = [], [], self.env.pos, [], 0
        direction = 1
        for i in range(n):
            if rng.random() < p_rev:
                direction = -direction
            c = rng.randint(lo, hi)
            steps.append(direction)
            clocks.append(c)
        wf = walk(steps, [c * T_NS for c in clocks], start_pos=pos)
        for k, (s, c) in enumerate(zip(steps, clocks)):
            t += c if k else 0
            pos += s
            out.append((t, s, QUAD[pos % 4], pos))
        return wf, out

    async def play(self, wf):
        await FallingEdge(self.dut.clk)  # transitions mid-clock (states of whole clocks)
        await self.env.drv.play(wf)
        self.env.pos = wf.positions[-1]


def match(entries: list[dict], steps: list, ts_w: int, lost_count: int, what: str) -> None:
    """The entries against the walk's steps: each entry is the step whose clock offset its time
    gives (the first entry is the first step), in order, with its direction and state; a gap
    before an entry iff it has LOST; the steps missing = lost_count."""
    mask = (1 << ts_w) - 1
    assert entries, f"{what}: no entries"
    by_offset = {t: i for i, (t, _, _, _) in enumerate(steps)}
    t0, prev, missing = entries[0]["TIME"], -1, 0
    for n, e in enumerate(entries):
        off = (e["TIME"] - t0) & mask
        assert off in by_offset, f"{what}: entry {n} at +{off} clocks matches no step"
        i = by_offset[off]
        _, s, (a, b), _ = steps[i]
        assert i > prev, f"{what}: entry {n} (step {i}) out of order after step {prev}"
        assert (e["DIR"], e["A"], e["B"]) == (int(s > 0), a, b), \
            f"{what}: entry {n} = step {i}: DIR/A/B {e['DIR']}{e['A']}{e['B']}, step {s:+d} to {a}{b}"
        gap = i - prev - 1 if n else 0
        assert e["LOST"] == int(gap > 0), f"{what}: entry {n} (step {i}) LOST {e['LOST']}, gap {gap}"
        missing += gap
        prev = i
    missing += len(steps) - 1 - prev
    assert missing == lost_count, f"{what}: {missing} steps missing, EFIFO_LOST {lost_count}"


async def fifo_of(dut):
    envs, rng = await _start(dut)
    env = envs[-1]  # the last channel (channel 1 of the two-channel build)
    return Fifo(dut, env), envs, rng


async def _start(dut):
    _, rng = await begin(dut)
    return channel_envs(dut, rng, int(dut.CHANNELS.value)), rng


async def _white_box(dut):
    """Channel 0 counting x4 from 0 at FILTER_LEN 1, for the white-box tests: (its Env, rng, the
    FIFO's depth, its enc_qei_efifo instance: in the channel, or with the shared engine in the
    bank beside it)."""
    envs, rng = await _start(dut)
    env = envs[0]
    await env.setup(QeiModel(env.count_w), count=0, filter_len=1)
    qei = dut.u_qei
    efifo = (qei.g_engine.g_efifo.u_efifo_bank.g_ch[0].u_efifo if hasattr(qei, "g_engine")
             else channel(dut).g_efifo.u_efifo)
    return env, rng, 1 << int(dut.EFIFO_LOG2.value), efifo


async def _step_now(env):
    """One step forward, its pins changed at the next falling clock edge (no settling)."""
    await FallingEdge(env.dut.clk)
    env.pos += 1
    env.dut.a_in.value, env.dut.b_in.value = QUAD[env.pos % 4]


async def _one_step(env):
    """One step forward, its state held 3 clocks, then settled."""
    await env.play(walk([1], [3 * T_NS], start_pos=env.pos), None)


async def _fill(env, depth: int):
    """Steps until the FIFO holds ``depth`` entries (EFIFO_STATUS.LEVEL)."""
    while await env.bus.rd("EFIFO_STATUS") & 0x1FF < depth:
        await _one_step(env)


@cocotb_test()
async def entries_match_the_walk(dut):
    """A random walk (reversals at any state) read back in full: every step in order with its
    direction, A/B state and clock-exact time; the last entry's time is SNAP_EDGE_TIME; CAPS says
    the depth; the other channel's FIFO stays empty. The first round uses the FIFO as the reset
    left it (no CLEAR)."""
    fifo, envs, rng = await fifo_of(dut)
    assert get_field("CAPS", "EFIFO_LOG2", await fifo.bus.rd("CAPS")) == int(dut.EFIFO_LOG2.value)
    await fifo.check_empty("after reset")
    await fifo.start(clear=False)  # (the first round from the reset state alone)
    for rnd in range(3):
        if rnd == 1 and fifo.ts_w == 16:  # let the timebase wrap inside this round's walk
            tb = await fifo.bus.rd("TIMEBASE")
            await ClockCycles(dut.clk, ((1 << 16) - tb - 200) % (1 << 16) + 1)
        wf, steps = fifo.walk(rng, fifo.depth - 1, 3, 40)
        await fifo.play(wf)
        await ClockCycles(dut.clk, 12)
        assert await fifo.level() == len(steps)
        await fifo.bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE="any"))
        await fifo.env.applied()
        await fifo.env.settle(0)
        edge_time = await fifo.bus.rd("SNAP_EDGE_TIME")
        entries = await fifo.drain()
        assert [e["LEFT"] for e in entries] == list(range(len(steps) - 1, -1, -1))
        match(entries, steps, fifo.ts_w, 0, f"round {rnd}")
        assert entries[-1]["TIME"] == edge_time, \
            f"last entry at {entries[-1]['TIME']:#x}, SNAP_EDGE_TIME {edge_time:#x}"
        assert await fifo.bus.rd("EFIFO_LOST") == 0
    if len(envs) > 1:
        assert await Fifo(dut, envs[0]).level() == 0
        assert await envs[0].bus.rd("EFIFO_ENTRY") == 0


@cocotb_test()
async def overrun_is_never_silent(dut):
    """Twice the depth of steps with no reads: LEVEL is the depth, EFIFO_LOST counts the rest,
    EFIFO_OVF is raised, the entries are the first steps; after draining, the next entry has
    LOST = 1 and the one after it LOST = 0."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    n = 2 * fifo.depth + 3
    wf, steps = fifo.walk(rng, n, 3, 8)
    await fifo.play(wf)
    await fifo.env.settle()  # (12 clocks, and the shared engine's latency for EVENTS)
    assert await fifo.level() == fifo.depth
    lost = await fifo.bus.rd("EFIFO_LOST")
    assert lost == n - fifo.depth, f"EFIFO_LOST {lost}, expected {n - fifo.depth}"
    assert "EFIFO_OVF" in await fifo.bus.events()
    entries = await fifo.drain()
    assert len(entries) == fifo.depth and not any(e["LOST"] for e in entries)
    match(entries, steps[:fifo.depth], fifo.ts_w, 0, "the stored steps")
    wf, more = fifo.walk(rng, 2, 5, 9)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    after = await fifo.drain()
    assert [e["LOST"] for e in after] == [1, 0], f"LOST after the gap: {[e['LOST'] for e in after]}"
    await fifo.bus.wr("EFIFO_LOST", 0)
    assert await fifo.bus.rd("EFIFO_LOST") == 0


@cocotb_test()
async def drained_while_counting_at_the_bound(dut):
    """Steps every 2 .. 4 clocks (the count-rate bound at FILTER_LEN 2) while the host drains
    the FIFO as fast as the bus allows (pops and pushes in the same clocks, the FIFO full at
    times): every step is an entry in order or is counted in EFIFO_LOST, and LOST marks every
    gap."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    wf, steps = fifo.walk(rng, 6 * fifo.depth, 2, 4, p_rev=0.1)
    entries: list[dict] = []
    player = cocotb.start_soon(fifo.play(wf))
    while not player.done():
        if (e := await fifo.pop()) is not None:
            entries.append(e)
    await ClockCycles(dut.clk, 12)
    entries += await fifo.drain()
    lost = await fifo.bus.rd("EFIFO_LOST")
    dut._log.info("%d steps: %d entries, %d lost", len(steps), len(entries), lost)
    match(entries, steps, fifo.ts_w, lost, "drained at the bound")
    assert len(entries) + lost == len(steps)


@cocotb_test()
async def threshold_event_and_irq(dut):
    """EFIFO_THRESH is set while LEVEL >= THRESH (a clear does not stick until the FIFO is drained
    below it; THRESH 0 acts as 1) and drives irq when enabled; EN = 0 stores nothing; CLEAR empties the FIFO; an
    empty read pops nothing and leaves EFIFO_TIME alone. With the shared engine EVENTS and irq
    follow P + 44 clocks late at most (env.settle waits for that), and a clear acts on what a read
    could show: a level >= THRESH the register could not show yet at the clear sets the event again
    once (so each clear here comes a settle after the FIFO changed)."""
    fifo, _, rng = await fifo_of(dut)
    env = fifo.env
    thresh = 2 * rng.randint(1, fifo.depth // 2 - 1)  # even: a THRESH off by one in bit 0 shows
    # THRESH 0 acts as 1: one entry sets the event
    await fifo.start(thresh=0)
    wf, _ = fifo.walk(rng, 1, 3, 9)
    await fifo.play(wf)
    await env.settle()
    assert "EFIFO_THRESH" in await fifo.bus.events(), "THRESH 0 with one entry"
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=0))
    await env.settle()
    await fifo.bus.events()
    await env.settle()
    assert "EFIFO_THRESH" not in await fifo.bus.events(clear=False), "THRESH 0, FIFO empty"
    await fifo.start(thresh=thresh)
    await fifo.bus.wr("IRQ_EN", event_bits("EFIFO_THRESH"))
    await env.applied()
    wf, _ = fifo.walk(rng, thresh - 1, 3, 9)
    await fifo.play(wf)
    await env.settle()
    assert "EFIFO_THRESH" not in await fifo.bus.events(clear=False)
    assert dut.irq.value == 0
    wf, _ = fifo.walk(rng, 1, 3, 9)
    await fifo.play(wf)
    await env.settle()
    assert "EFIFO_THRESH" in await fifo.bus.events()  # (cleared, set again)
    await env.settle()
    assert "EFIFO_THRESH" in await fifo.bus.events(clear=False), "cleared above THRESH"
    assert dut.irq.value == 1
    e = await fifo.pop()
    time = e["TIME"]
    await env.settle()
    await fifo.bus.events()
    await env.settle()
    assert "EFIFO_THRESH" not in await fifo.bus.events(clear=False)
    await ClockCycles(dut.clk, 3)
    assert dut.irq.value == 0
    # EN = 0: no pushes; CLEAR: empty; an empty read pops nothing
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=0, THRESH=thresh))
    wf, _ = fifo.walk(rng, 3, 3, 9)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    assert await fifo.level() == thresh - 1
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=0, CLEAR=1, THRESH=thresh))
    assert await fifo.level() == 0
    assert await fifo.bus.rd("EFIFO_ENTRY") == 0
    assert await fifo.bus.rd("EFIFO_TIME") == time


@cocotb_test()
async def registers_byte_enables(dut):
    """The EFIFO_* registers under byte enables (every mask, on both buses):
    EFIFO_CTRL.EN takes lane 0, THRESH lanes 1 (bits 7:0) and 2 (bit 8), the other lanes keep
    theirs; CLEAR reads 0 and empties the FIFO only when lane 0 is written; a write of EFIFO_LOST
    with any lane clears it, one with none keeps it; writes of EFIFO_STATUS,
    EFIFO_ENTRY and EFIFO_TIME change nothing and pop nothing."""
    fifo, _, rng = await fifo_of(dut)
    bus = fifo.bus
    masks = [1, 2, 4, 8, 3, 6, 12, 7, 14, 15, 5, 9, 10, 13, 11]
    await fifo.start()
    for strb in masks:
        en, th = rng.getrandbits(1), rng.getrandbits(9)
        await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=en, THRESH=th))
        await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1 - en, THRESH=~th & 0x1FF), strb)
        want_en = 1 - en if strb & 1 else en
        want_th = ((~th if strb & 2 else th) & 0xFF) | ((~th if strb & 4 else th) & 0x100)
        got = await bus.rd("EFIFO_CTRL")
        assert got == pack("EFIFO_CTRL", EN=want_en, THRESH=want_th), \
            f"EFIFO_CTRL byte enables {strb:#x}: {got:#x}, EN {want_en} THRESH {want_th:#x} expected"
    # CLEAR acts only with lane 0
    await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=1))
    wf, _ = fifo.walk(rng, 3, 3, 9)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    for strb in (2, 4, 8, 6, 14):
        await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=1), strb)
        assert await fifo.level() == 3, f"CLEAR with byte enables {strb:#x} emptied the FIFO"
    # writes of the read-only registers: nothing changes, nothing is popped
    for reg in ("EFIFO_STATUS", "EFIFO_ENTRY", "EFIFO_TIME"):
        await bus.wr(reg, rng.getrandbits(32))
        assert await fifo.level() == 3, f"a write of {reg} changed LEVEL"
    await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=1), 1)
    assert await fifo.level() == 0, "CLEAR with lane 0 left entries"
    assert get_field("EFIFO_CTRL", "CLEAR", await bus.rd("EFIFO_CTRL")) == 0
    # EFIFO_LOST: any lane clears, none keeps
    wf, _ = fifo.walk(rng, fifo.depth + 5, 3, 8)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    assert await bus.rd("EFIFO_LOST") == 5
    await bus.wr("EFIFO_LOST", 0, 0)
    assert await bus.rd("EFIFO_LOST") == 5, "a write of EFIFO_LOST with no byte enable cleared it"
    await bus.wr("EFIFO_LOST", 0xFFFFFFFF, rng.choice((1, 2, 4, 8)))
    assert await bus.rd("EFIFO_LOST") == 0, "a write of EFIFO_LOST with one byte enable kept it"


@cocotb_test()
async def every_channel_its_own(dut):
    """Every channel's EFIFO_* registers and FIFO are its own: EFIFO_CTRL written on every page
    with different values, then with each bit the other way, reads back each page's own (read
    twice, an odd number of clocks apart; EFIFO_LOST 0 without a loss; a read of EFIFO_CTRL
    right after a write of 0x2 elsewhere empties nothing); then
    channel k walked k + 1 steps (one channel after the other): every FIFO holds exactly its own
    channel's steps, in order, at their clocks."""
    envs, rng = await _start(dut)
    fifos = [Fifo(dut, e) for e in envs]
    values = [(rng.getrandbits(1), rng.getrandbits(9)) for _ in fifos]
    for rnd in range(2):
        if rnd:
            values = [(1 - en, ~th & 0x1FF) for en, th in values]
        for f, (en, th) in zip(fifos, values):
            await f.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=en, THRESH=th))
        for gap in (0, 1):  # (read at both clock parities: a held value must not toggle)
            await ClockCycles(dut.clk, gap)
            for k, (f, (en, th)) in enumerate(zip(fifos, values)):
                got = await f.bus.rd("EFIFO_CTRL")
                assert got == pack("EFIFO_CTRL", EN=en, THRESH=th), \
                    f"channel {k}: EFIFO_CTRL {got:#x} after the writes of every page, wrote EN {en} " \
                    f"THRESH {th:#x}"
    for f in fifos:
        await f.start()
    walks = []
    for k, f in enumerate(fifos):
        wf, steps = f.walk(rng, k + 1, 3, 9)
        await f.play(wf)
        walks.append(steps)
    await ClockCycles(dut.clk, 12)
    for k, f in enumerate(fifos):
        # (an AXI4-Lite port keeps the last write's data and byte enables: a read of EFIFO_CTRL
        # after a write of 0x2, CLEAR's bit, with every lane must not clear)
        assert await f.bus.rd("EFIFO_LOST") == 0, f"channel {k}: EFIFO_LOST without a loss"
        await f.bus.wr("EFIFO_LOST", pack("EFIFO_CTRL", CLEAR=1))
        await f.bus.rd("EFIFO_CTRL")
    for k, f in enumerate(fifos):
        assert await f.level() == k + 1, f"channel {k}: LEVEL {await f.level()}, walked {k + 1} steps"
    for k, f in enumerate(fifos):
        entries = await f.drain()
        match(entries, walks[k], f.ts_w, 0, f"channel {k}")


@cocotb_test()
async def times_on_every_channel(dut):
    """Every channel's entry times through both registers, over the timebase's low 16 bits: 17
    rounds 4,096 + 0 .. 63 clocks apart (so bits 12 to 15 of the timebase take each value), each
    channel one step a round; each entry's EFIFO_ENTRY.TIME_LO equals its EFIFO_TIME's low 16 bits
    and EFIFO_TIME is the clock of the step, 0 .. 200 ticks before TIMEBASE read after it."""
    envs, rng = await _start(dut)
    fifos = [Fifo(dut, e) for e in envs]
    mask = (1 << fifos[0].ts_w) - 1
    for f in fifos:
        await f.start()
    for rnd in range(17):
        plays = []
        for f in fifos:
            wf, _ = f.walk(rng, 1, 3, 9, p_rev=0.5)
            plays.append(cocotb.start_soon(f.play(wf)))
        for p in plays:
            await p
        await ClockCycles(dut.clk, 12)
        for k, f in enumerate(fifos):
            e = await f.pop()  # (TIME_LO = EFIFO_TIME's low bits: checked there)
            now = await f.bus.rd("TIMEBASE")
            assert e is not None, f"round {rnd}: channel {k} has no entry"
            age = (now - e["TIME"]) & mask
            assert age <= 200, f"round {rnd}: channel {k}'s entry at {e['TIME']:#x}, TIMEBASE {now:#x}"
        await ClockCycles(dut.clk, 4096 + rng.randrange(64))


@cocotb_test()
async def lost_counts_past_255(dut):
    """EFIFO_LOST counts every loss, past 8 bits: the depth plus 300 steps with no reads give
    EFIFO_LOST = 300 and the FIFO's first depth steps."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    wf, steps = fifo.walk(rng, fifo.depth + 300, 3, 4)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    assert await fifo.bus.rd("EFIFO_LOST") == 300
    entries = await fifo.drain()
    match(entries, steps[:fifo.depth], fifo.ts_w, 0, "the stored steps")


@cocotb_test()
async def x2a_steps_only(dut):
    """With CTRL.FUNC = x2a only the transitions of A are steps: the entries are exactly those
    steps (direction, state, time), the transitions of B leave no entry."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start(func="x2a")
    wf, steps = fifo.walk(rng, fifo.depth - 1, 3, 20)
    before = [wf.positions[0]] + [p for _, _, _, p in steps[:-1]]
    a_steps = [st for st, p0 in zip(steps, before) if QUAD[p0 % 4][0] != st[2][0]]
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    entries = await fifo.drain()
    assert len(entries) == len(a_steps), f"{len(entries)} entries, {len(a_steps)} steps of A"
    t0 = a_steps[0][0]
    match(entries, [(t - t0, s_, ab, p) for t, s_, ab, p in a_steps], fifo.ts_w, 0, "x2a")


@cocotb_test()
async def en_off_keeps_lost_forgets_idx(dut):
    """A loss pending when EN goes to 0 marks the first entry after EN returns to 1; an index edge
    while EN = 0 (Z rising with the shaft standing) marks nothing; steps while EN = 0 are neither
    entries nor losses."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    wf, _ = fifo.walk(rng, fifo.depth + 2, 3, 8)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=0, THRESH=1))
    assert len(await fifo.drain()) == fifo.depth
    wf, _ = fifo.walk(rng, 3, 3, 8)
    await fifo.play(wf)
    a, b = QUAD[fifo.env.pos % 4]
    fifo.env.drv.set_state(a, b, 1)  # an index edge while EN = 0
    await fifo.env.settle()
    assert "INDEX" in await fifo.bus.events(), "the Z edge is an index"
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, THRESH=1))
    wf, steps = fifo.walk(rng, 2, 3, 8, p_rev=0.0)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    after = await fifo.drain()
    assert [(e["LOST"], e["IDX"]) for e in after] == [(1, 0), (0, 0)], \
        f"(LOST, IDX) after EN 0 -> 1: {[(e['LOST'], e['IDX']) for e in after]}"
    assert await fifo.bus.rd("EFIFO_LOST") == 2, "steps while EN = 0 counted as lost"
    fifo.env.drv.set_state(*QUAD[fifo.env.pos % 4], 0)


@cocotb_test()
async def clear_forgets_marks(dut):
    """EFIFO_CTRL.CLEAR written with EN = 1 empties the FIFO and forgets a pending LOST mark and a
    pending IDX mark, and leaves EFIFO_LOST and EFIFO_TIME as they were: after an overrun (a loss
    pending, one entry popped) and a CLEAR, the next walk's entries have LOST = 0 and EFIFO_LOST
    still counts the lost steps; an index edge with the shaft standing (Z rising, INDEX_CTRL EDGE
    rising, ACTION none) marks the next entry stored (IDX = 1) without a CLEAR in between and
    marks nothing when a CLEAR comes between."""
    fifo, _, rng = await fifo_of(dut)
    bus = fifo.bus
    await fifo.start()
    await bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none", EDGE="rising"))
    await fifo.env.applied()
    clear = pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=1)

    async def index_edge(z):  # Z to z with the shaft standing
        fifo.env.drv.set_state(*QUAD[fifo.env.pos % 4], z)
        await fifo.env.settle()

    async def after(what):  # two steps on: the entries' (LOST, IDX)
        wf, steps = fifo.walk(rng, 2, 3, 8, p_rev=0.0)
        await fifo.play(wf)
        await ClockCycles(dut.clk, 12)
        entries = await fifo.drain()
        match(entries, steps, fifo.ts_w, 0, what)
        return [(e["LOST"], e["IDX"]) for e in entries]

    # a pending LOST mark
    wf, _ = fifo.walk(rng, fifo.depth + 2, 3, 8)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    time = (await fifo.pop())["TIME"]
    await bus.wr("EFIFO_CTRL", clear)
    assert await fifo.level() == 0, "CLEAR left entries"
    assert await bus.rd("EFIFO_TIME") == time, "CLEAR changed EFIFO_TIME"
    assert await bus.rd("EFIFO_LOST") == 2, "CLEAR changed EFIFO_LOST"
    got = await after("after CLEAR with a loss pending")
    assert got == [(0, 0), (0, 0)], f"(LOST, IDX) after CLEAR with a loss pending: {got}"
    assert await bus.rd("EFIFO_LOST") == 2
    # a pending IDX mark: kept without a CLEAR (the control), forgotten with one
    await index_edge(1)
    got = await after("an index edge with the shaft standing")
    assert got == [(0, 1), (0, 0)], f"(LOST, IDX) after an index edge, no CLEAR: {got}"
    await index_edge(0)
    await index_edge(1)
    await bus.wr("EFIFO_CTRL", clear)
    got = await after("after CLEAR with an index mark pending")
    assert got == [(0, 0), (0, 0)], f"(LOST, IDX) after CLEAR with an index mark pending: {got}"
    assert await bus.rd("EFIFO_LOST") == 2
    await index_edge(0)


@cocotb_test()
async def reset_with_entries(dut):
    """rst while the FIFO holds entries, a loss is pending and the shaft moves: after it the FIFO
    is empty, EFIFO_TIME and EFIFO_LOST read 0, EN is off; enabled again (no CLEAR) it stores the
    next walk exactly, with no LOST mark."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    wf, _ = fifo.walk(rng, fifo.depth + 3, 3, 8)
    await fifo.play(wf)
    await fifo.pop()
    wf, _ = fifo.walk(rng, 40, 3, 8)
    player = cocotb.start_soon(fifo.play(wf))
    await ClockCycles(dut.clk, rng.randint(20, 120))
    await pulse_rst(dut, 3)
    await player
    await ClockCycles(dut.clk, 30)
    await fifo.check_empty("after rst with entries")
    assert get_field("EFIFO_CTRL", "EN", await fifo.bus.rd("EFIFO_CTRL")) == 0
    await fifo.start(clear=False)
    wf, steps = fifo.walk(rng, fifo.depth - 1, 3, 20)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    match(await fifo.drain(), steps, fifo.ts_w, 0, "after rst")


@cocotb_test()
async def index_marks_its_entry(dut):
    """An index pulse over a few positions (INDEX_CTRL EDGE rising, no gate): the entry of the
    step into the pulse, either way, has IDX = 1, every other entry IDX = 0; an index while
    EN = 0 marks nothing."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    await fifo.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none", EDGE="rising"))
    await fifo.env.applied()
    period = rng.choice((12, 16, 20))

    def zf(p, n=period):
        return int(5 <= p % n <= 7)
    wf, steps = fifo.walk(rng, fifo.depth - 1, 4, 12, p_rev=0.3)
    index = [(t, zf(p)) for (t, _, _), p in zip(wf.events, wf.positions)]
    await FallingEdge(dut.clk)
    await fifo.env.drv.play(wf, index=index)
    fifo.env.pos = wf.positions[-1]
    await ClockCycles(dut.clk, 12)
    entries = await fifo.drain()
    match(entries, steps, fifo.ts_w, 0, "index walk")
    # Z was 0: a walk starting inside the pulse raises it with no step, which marks the first entry
    prev_z = zf(wf.positions[0])
    pending = prev_z
    expect = []
    for _, _, _, pos in steps:
        z = zf(pos)
        expect.append(int(bool(z and not prev_z) or bool(pending)))
        prev_z, pending = z, 0
    assert [e["IDX"] for e in entries] == expect, \
        f"IDX {[e['IDX'] for e in entries]}, index rising at {expect}"
    dut._log.info("%d entries, %d with IDX", len(entries), sum(expect))


@cocotb_test()
async def lost_step_passes_its_idx_mark(dut):
    """An index edge made by a step lost to a full FIFO (Z rising with the transition, INDEX_CTRL
    EDGE rising, ACTION none) marks the next entry stored: depth + 3 steps with no reads, Z rising
    with the second lost step; the stored steps have IDX = 0, and after the drain the next entry
    has LOST = 1 and IDX = 1, the one after it neither."""
    fifo, _, rng = await fifo_of(dut)
    await fifo.start()
    await fifo.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="none", EDGE="rising"))
    await fifo.env.applied()
    wf, steps = fifo.walk(rng, fifo.depth + 3, 3, 8)
    rise = fifo.depth + 1  # the step Z rises with (steps depth .. depth + 2 are lost)
    index = [(t, int(k > rise)) for k, (t, _, _) in enumerate(wf.events)]  # (event k + 1: step k)
    await FallingEdge(dut.clk)
    await fifo.env.drv.play(wf, index=index)
    fifo.env.pos = wf.positions[-1]
    await fifo.env.settle()
    assert "INDEX" in await fifo.bus.events(), "the Z edge is an index"
    assert await fifo.bus.rd("EFIFO_LOST") == 3
    entries = await fifo.drain()
    match(entries, steps[:fifo.depth], fifo.ts_w, 0, "the stored steps")
    assert not any(e["IDX"] for e in entries), f"IDX on a stored step: {[e['IDX'] for e in entries]}"
    wf, more = fifo.walk(rng, 2, 3, 8)
    await fifo.play(wf)
    await ClockCycles(dut.clk, 12)
    after = await fifo.drain()
    match([dict(e, LOST=0) for e in after], more, fifo.ts_w, 0, "after the gap")  # (LOST below)
    assert [(e["LOST"], e["IDX"]) for e in after] == [(1, 1), (0, 0)], \
        f"(LOST, IDX) after the gap: {[(e['LOST'], e['IDX']) for e in after]}"
    fifo.env.drv.set_state(*QUAD[fifo.env.pos % 4], 0)


@cocotb_test()
async def full_fifo_pop_in_the_push_clock(dut):
    """A full FIFO and a step against an EFIFO_ENTRY read (white box, on both architectures: the
    FIFO's push and pop clocks sampled every clock): the step's entry is written in the clock
    after the step (its timestamp clock); it is stored when the read pops in that clock or before
    and dropped (EFIFO_LOST 1) only when the pop comes later (EFIFO_CTRL's text). The read's LEFT
    never counts an entry written in its own clock (depth - 1 every time)."""
    env, rng, depth, efifo = await _white_box(dut)
    bus = env.bus
    await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1))
    await env.applied()

    async def prepare():
        await _fill(env, depth)  # full again
        await bus.wr("EFIFO_LOST", 0)
        await env.settle()

    async def judge(d, word):
        await env.settle()
        lost = await bus.rd("EFIFO_LOST")
        e = entry_fields(word)
        assert e["VALID"] and e["LEFT"] == depth - 1, \
            f"the step's entry {d:+d} clocks from the pop: the read answered {e} (LEFT {depth - 1})"
        assert lost == int(d < 0), \
            f"a full FIFO, the step's entry written {d:+d} clocks from the pop: EFIFO_LOST {lost}"

    got = await aimed_races(dut, lambda: int(efifo.pop.value), lambda: int(efifo.push_q.value),
                            prepare, lambda: _step_now(env), lambda: bus.rd("EFIFO_ENTRY"), judge,
                            lead=-4)
    dut._log.info("pushes at these clocks from the pop: %s", got)
    await bus.wr("EFIFO_CTRL", 0)


@cocotb_test()
async def ctrl_and_lost_write_clocks(dut):
    """The clocks a write of EFIFO_CTRL and of EFIFO_LOST acts in (white box, on both architectures:
    the clock r of the write's request, on Wishbone the strobe's first clock, on AXI4-Lite the
    request into enc_qei, and the clock s of a step, the FIFO's step input, sampled every clock;
    the step's entry is written in s + 1; the write's snapshot clock is r + 3 on both buses).
    EN = 1 (from 0) stores the steps with s >= r + 2 (entry clock >= r + 3) and none before;
    EN = 0 (from 1) stores the steps with s <= r + 1 (entry clock <= r + 2) and none after; CLEAR
    (with EN = 1, the FIFO full) removes or drops every step with s <= r + 1 and stores those with
    s >= r + 2: a step with s <= r is lost before it (EFIFO_LOST 1), the one with s = r + 1 (entry
    clock r + 2, the clear's) is neither stored nor lost; a write of EFIFO_LOST clears the losses
    of the steps with s <= r - 1 (entry clock <= r) and counts those with s >= r (entry clock
    >= r + 1: the value becomes 1). Each boundary is met from both sides, steps aimed at -3 .. 3
    clocks around it."""
    env, rng, depth, efifo = await _white_box(dut)
    bus = env.bus
    if bus.kind == "wb":
        def request():
            return int(dut.wb_cyc_i.value) & int(dut.wb_stb_i.value)
    else:  # (the later AW / W handshake + 2: the adapter is idle)
        def request():
            return int(dut.u_qei.req_valid.value)

    def stepped():
        return int(efifo.step_up.value) | int(efifo.step_dn.value)

    async def race(what, prepare, access, outcome, first):
        """Steps aimed at s = r + first - 3 .. r + first + 3: ``outcome(s - r)`` after each must
        be 1 iff s >= r + first (aimed_races's d is s - (r + first): its reference is the clock
        ``first`` clocks after the request's first clock)."""
        seen = []  # the clocks sampled since the request's first one

        def boundary():  # (aimed_races asks once a clock until it answers 1)
            if seen or request():
                seen.append(1)
            return int(len(seen) == first + 1)

        async def arm():
            seen.clear()
            await prepare()

        async def judge(d, _):
            await env.settle()
            got = await outcome(first + d)
            assert got == int(d >= 0), \
                f"{what}: a step at s = r{first + d:+d}: {got}, expected {int(d >= 0)}"

        got = await aimed_races(dut, boundary, stepped, arm, lambda: _step_now(env), access, judge,
                                lead=-4 - first)
        dut._log.info("%s: steps at s = r + %s", what, [first + d for d in got])

    def ctrl(en, clear=0):
        return lambda: bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=en, CLEAR=clear))

    async def level(_=None):
        return await bus.rd("EFIFO_STATUS")

    async def empty(_):
        return int(await level() == 0)

    async def emptied(en):
        await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=en, CLEAR=1))
        await bus.wr("EFIFO_LOST", 0)
        await env.settle()

    # EN on: the step is an entry (LEVEL 1) iff s >= r + 2
    await race("EN = 1", lambda: emptied(0), ctrl(1), level, 2)
    # EN off: the step is not an entry iff s >= r + 2
    await race("EN = 0", lambda: emptied(1), ctrl(0), empty, 2)

    # CLEAR, the FIFO full: the step is the one entry after it iff s >= r + 2; before, it is lost
    # iff s <= r (the one with s = r + 1 is dropped by the clear, no loss)
    async def full():
        await emptied(1)
        await _fill(env, depth)

    async def cleared(s):
        n, lost = await level(), await bus.rd("EFIFO_LOST")
        if n:
            e = entry_fields(await bus.rd("EFIFO_ENTRY"))
            assert n == 1 and e["LOST"] == 0 and lost == 0, \
                f"after CLEAR: LEVEL {n}, the entry {e}, EFIFO_LOST {lost} (a step at s = r{s:+d})"
        else:
            assert lost == int(s <= 0), f"CLEAR: a step at s = r{s:+d} not stored: EFIFO_LOST {lost}"
        return n
    await race("CLEAR", full, ctrl(1, 1), cleared, 2)

    # EFIFO_LOST: a full FIFO, two steps lost before; the step's loss stays counted iff s >= r
    async def full_and_lost():
        await bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1))
        await _fill(env, depth)
        await _one_step(env)
        await _one_step(env)
        await env.settle()
        assert await bus.rd("EFIFO_LOST") >= 2

    async def lost(_):
        return await bus.rd("EFIFO_LOST")
    await race("EFIFO_LOST", full_and_lost, lambda: bus.wr("EFIFO_LOST", 0), lost, 0)
    await bus.wr("EFIFO_CTRL", 0)


@cocotb_test()
async def model_unit_matches_ideal_entries(dut):
    """A modelled HEDS-5000 unit (hedsmodel.EncoderUnit.typical, its edges at every phase of the
    clock) turning at a constant speed: the FIFO's entries are hedsmodel.velocity.
    ideal_edge_entries of its waveform, the input of the calibrated velocity bench (`make
    velocity`): the same directions, states and times relative to the first entry (exact, but
    +-1 tick for an edge within 2 ps of a clock edge, where the driver keeps it 1 ps clear)."""
    fifo, _, rng = await fifo_of(dut)
    unit = EncoderUnit.typical(np.random.default_rng(rng.getrandbits(32)))
    rpm = rng.choice((1500.0, 3000.0, -2200.0))
    n = fifo.depth - 1
    wf = unit.waveform(Profile().constant(abs(rpm), 1.0 / (abs(rpm) / 60 * 500 * 4) * (n + 0.5)))
    if rpm < 0:  # the same edges played backwards: the reversed walk
        wf = walk([-1] * (len(wf.events) - 1), np.diff([t for t, _, _ in wf.events])[::-1],
                  start_pos=wf.positions[-1])
    et = edge_table(wf)
    assert len(et.t_s) >= 2
    await fifo.start()
    a0, b0 = QUAD[wf.positions[0] % 4]  # the waveform's first state, then a clean FIFO
    fifo.env.drv.set_state(a0, b0)
    await ClockCycles(dut.clk, 30)
    await fifo.bus.wr("EFIFO_CTRL", pack("EFIFO_CTRL", EN=1, CLEAR=1, THRESH=1))
    await fifo.play(wf)  # from a falling edge: clock edges at (k + 0.5) periods after its start
    await ClockCycles(dut.clk, 12)
    got = await fifo.drain()
    tb = Timebase(clk_hz=1e9 / T_NS, ts_w=fifo.ts_w, phase=0.5)
    ideal = ideal_edge_entries(wf, tb)
    assert len(got) == len(ideal), f"{len(got)} entries, ideal {len(ideal)}"
    mask = (1 << fifo.ts_w) - 1
    for k, (g, i) in enumerate(zip(got, ideal)):
        assert (g["DIR"], g["A"], g["B"]) == (int(i.up), i.a, i.b), f"entry {k}: {g}, ideal {i}"
        d_got = (g["TIME"] - got[0]["TIME"]) & mask
        d_ideal = (i.time - ideal[0].time) & mask
        frac = et.t_s[k] * 1e9 / T_NS - 0.5
        near = min(abs(frac - round(frac)), abs(et.t_s[0] * 1e9 / T_NS - 0.5
                                                 - round(et.t_s[0] * 1e9 / T_NS - 0.5))) < 2e-4
        assert d_got == d_ideal or (near and abs(d_got - d_ideal) <= 1), \
            f"entry {k}: +{d_got} ticks after the first, ideal +{d_ideal}"
    dut._log.info("%d entries of a typical unit at %g rpm match ideal_edge_entries", len(got), rpm)


# ---- pytest --------------------------------------------------------------------------------------
@pytest.mark.parametrize("top,channels,profile,count_w,ts_w,efifo_log2,engine", EFIFO_CONFIGS,
                         ids=[f"{t}-ch{c}-{p}-e{e}" + ("-engine" if g else "")
                              for t, c, p, _, _, e, g in EFIFO_CONFIGS])
def test_efifo(top, channels, profile, count_w, ts_w, efifo_log2, engine):
    from enctools.harness import run

    code = enum("CAPS", "PROFILE")[profile]
    run(top, __name__, name=f"{build_name(top, count_w, ts_w)}_ch{channels}_{profile}_e{efifo_log2}" +
        (f"_g{engine}" if engine else ""),
        parameters={"COUNT_W": count_w, "TS_W": ts_w, "CHANNELS": channels, "PROFILE": code,
                    "EFIFO_LOG2": efifo_log2, "ENGINE": engine},
        sim="verilator" if engine and channels > 1 else None)
