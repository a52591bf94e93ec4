# SPDX-License-Identifier: Apache-2.0
"""enc_qei through its bus: every register of the compiled RDL (offset, reset, access), register
patterns, byte enables, unmapped offsets, the coherent 64-bit count, concurrent reads and writes
(AXI4-Lite), abandoned Wishbone cycles and requests.

Runs on both builds of enctools.qei.env.CONFIGS (enc_qei_wb, cocotbext-wishbone; enc_qei_axil,
cocotbext-axi with random back-pressure), shared with the other feature files of tb/enc_qei/.
Every cocotb test logs its seed (make test SEED=n reproduces a run).
"""

from __future__ import annotations

import cocotb
import pytest
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, Timer
from hedsmodel import walk

from enctools.qei.bus import PERIOD_PS, T_NS, wb_abandon_read
from enctools.qei.env import (CONFIG_IDS, CONFIGS, begin, caps_of, channel, engine_build, engine_lag,
                              lacks, run_feature)
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import aimed_races, durations, illegal_jumps, rejected_pulses
from enctools.regmap import addr, built_mask, event_bits, regmap, size_mask, units
from enctools.tb import cocotb_test


@cocotb_test()
async def coherent_64bit(dut):
    """COUNT_LO then COUNT_HI is one value while the count carries across bit 32 between them.
    (Whether a carry fell between the two reads: from the core's count, or with the shared engine,
    whose count is in its memory, from the stimulus: the pins had not crossed it at the COUNT_LO
    read and had crossed it more than the engine's latency before the COUNT_HI read; one pair of
    reads per pass is timed to start just before the pins cross it.)"""
    env, rng = await begin(dut)
    if env.count_w <= 32:
        # COUNT_HI reads 0, LO is the whole count
        model = QeiModel(env.count_w)
        await env.setup(model, count=model.max - 4)
        wf = walk([1] * 10, durations(rng, 10, 1), start_pos=env.pos)
        await env.play(wf, model)
        assert await env.bus.rd("COUNT_HI") == 0
        await env.check(model, "wrap")
        return
    model = QeiModel(env.count_w)
    start_count = (1 << 32) - 60
    live = None if env.engine else channel(dut).u_core.count_q  # (when a carry fell between the reads)
    # the shared engine: its latency, and the pipeline from the pins to the count (FILTER_LEN 1)
    late = env.lag + 16
    n, straddled, reads, passes = 140, 0, 0, 0
    while straddled < 2 and passes < 10:
        passes += 1
        await env.setup(model, count=start_count, filter_len=1)
        wf = walk([1] * n, [rng.uniform(4.2 * T_NS, 6 * T_NS) for _ in range(n)], start_pos=env.pos)
        t0 = get_sim_time("ns")
        # the clock (from the start) at which the pins step onto the carry (start_count + 60 = 2^32)
        carry_clk = (t0 + wf.events[60][0]) / T_NS
        task = cocotb.start_soon(env.drv.play(wf))
        last = start_count
        aimed = live is not None  # (the engine: one pair per pass aimed at the carry)
        while not task.done():
            now = get_sim_time("ns") / T_NS
            if not aimed and now < carry_clk - 25:
                await ClockCycles(dut.clk, int(carry_clk - now) - rng.randint(5, 20))
                aimed = True
            lo = await env.bus.rd("COUNT_LO")
            if live is not None:
                hi_live_at_lo = int(live.value) >> 32
            else:
                below_at_lo = get_sim_time("ns") / T_NS < carry_clk
            await ClockCycles(dut.clk, rng.randint(0, 25) if live is not None else
                              rng.randint(late, 2 * late))
            hi = await env.bus.rd("COUNT_HI")
            value = hi << 32 | lo
            reads += 1
            assert start_count <= value <= start_count + n, f"incoherent read {value:#x}"
            assert value >= last, f"count went back: {value:#x} after {last:#x}"
            last = value
            if live is not None:
                straddled += (int(live.value) >> 32) != hi_live_at_lo
            else:
                straddled += below_at_lo and get_sim_time("ns") / T_NS - late > carry_clk
        await task
        env.pos = wf.positions[-1]
        await env.settle()
        assert await env.bus.count() == start_count + n
    assert straddled >= 1, "no LO/HI pair straddled the carry; the test did not test it"
    seen = range(reads)
    dut._log.info("%d coherent reads, %d across the carry", len(seen), straddled)


@cocotb_test()
async def unmapped_offsets(dut):
    """Unmapped offsets: read 0 with an error, write nothing with an error, never hang."""
    env, rng = await begin(dut)
    bus = env.bus
    mapped = {r.offset for r in regmap().values()}
    snapshot = {}
    for name, r in regmap().items():
        if name not in ("TIMEBASE", "STATUS"):
            snapshot[name] = await bus.rd(name)
    for off in range(0, 256, 4):
        if off in mapped:
            continue
        data, err = await bus.read(off)
        assert err and data == 0, f"read of unmapped {off:#04x}: data {data:#x}, err {err}"
        err = await bus.write(off, rng.getrandbits(32) | 1)
        assert err, f"write of unmapped {off:#04x} answered OK"
    for name, value in snapshot.items():
        assert await bus.rd(name) == value, f"{name} changed after unmapped writes"
    # a mapped read in between still works
    data, err = await bus.read(addr("ID"))
    assert not err and data == (await bus.rd("ID"))


@cocotb_test()
async def byte_address_low_bits(dut):
    """Bits [1:0] of the byte address are ignored, for reads and writes, on both buses: Wishbone
    reads of ID + 1, + 2, + 3 return ID, and a write of PRESET_LO + 2 (every byte enable) writes
    PRESET_LO; on AXI4-Lite (whose master puts an unaligned address on ARADDR / AWADDR with the
    byte lanes it covers) reads of 1 and 2 bytes at ID + 1, + 2, + 3 return those bytes of ID,
    and a write of 2 bytes at PRESET_LO + 1 writes its bytes 1 and 2."""
    env, rng = await begin(dut)
    bus = env.bus
    ident = await bus.rd("ID")
    preset = bus.offset("PRESET_LO")
    mask = (1 << min(32, env.count_w)) - 1
    old = await bus.rd("PRESET_LO")
    v = rng.getrandbits(32)
    if bus.kind == "wb":
        for k in (1, 2, 3):
            data, err = await bus.read(addr("ID") + k)
            assert not err and data == ident, f"read of ID + {k}: {data:#x} (err {err}), ID {ident:#x}"
        assert not await bus.write(preset + 2, v), "write of PRESET_LO + 2 answered an error"
        want = v & mask
    else:
        for k, n in ((1, 1), (2, 2), (3, 1), (1, 2)):
            resp = await bus.m.read(addr("ID") + k, n)
            got = int.from_bytes(resp.data, "little")
            assert int(resp.resp) == 0 and got == ident >> 8 * k & (1 << 8 * n) - 1, \
                f"read of {n} bytes at ID + {k}: {got:#x}, ID {ident:#x}"
        resp = await bus.m.write(preset + 1, (v >> 8 & 0xFFFF).to_bytes(2, "little"))
        assert int(resp.resp) == 0, "write of PRESET_LO + 1 answered an error"
        want = (old & ~0x00FFFF00 | v & 0x00FFFF00) & mask
    got = await bus.rd("PRESET_LO")
    assert got == want, f"PRESET_LO {got:#x} after the unaligned write, expected {want:#x} (before {old:#x})"


@cocotb_test()
async def byte_enables(dut):
    """Writes honour the byte enables: storage, the count, and W1C events."""
    env, rng = await begin(dut)
    bus = env.bus
    masks = [1, 2, 4, 8, 3, 6, 12, 7, 14, 15, 5, 9, 10, 13, 11]
    regs = ("PRESET_LO", "COUNT_LO") if env.lean else ("PRESET_LO", "COMPARE_LO", "COUNT_LO")
    for strb in masks:
        lanes = sum(0xFF << 8 * i for i in range(4) if strb >> i & 1)
        for reg in regs:
            old = rng.getrandbits(32)
            if reg == "COUNT_LO":
                await bus.set_count(old)
            else:
                await bus.wr(reg, old)
            new = rng.getrandbits(32)
            await bus.wr(reg, new, strb)
            got = await bus.rd(reg)
            exp = (old & ~lanes | new & lanes) & size_mask("COUNT_W:0", env.count_w, 32)
            assert got == exp, f"{reg} strb {strb:#x}: {got:#010x}, expected {exp:#010x}"
    # W1C with byte enables: only the enabled lanes clear
    await bus.wr("IRQ_EN", 0)
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, compare=0)
    await env.play(walk([2, -1], [30.0, 30.0], start_pos=env.pos), None)  # QERR (bit < 8) ...
    await env.play(walk([1, 1, -1], [30.0, 30.0, 30.0], start_pos=env.pos), None)  # DIR_CHANGE, CMP
    word = await bus.rd("EVENTS")
    assert word & event_bits("QERR", "DIR_CHANGE")
    await bus.write(addr("EVENTS"), 0xFFFFFFFF, 0x2)  # lane 1: bits 15:8 only
    assert await bus.rd("EVENTS") == word & ~0xFF00


@cocotb_test()
async def register_walk(dut):
    """Every register of the compiled RDL through the bus: CAPS equal to the build's parameters
    (every field, the feature bits included), offset, reset value, access. On the shared engine
    a write acts, and a snapshot it requests (GSNAP_CTRL, SNAP_CTRL, their timers) is taken, up
    to engine_lag clocks later: the walk waits that long after each register, so that a
    read-only register (GSNAP_TIME, SNAP_*) it reads next holds still."""
    env, rng = await begin(dut)
    bus = env.bus
    caps = await bus.rd("CAPS")
    count_w, ts_w = caps & 0xFF, caps >> 8 & 0xFF
    # every field of CAPS (the feature bits INDEX, PROBE, TIMING too) as the build's parameters give it
    assert caps == caps_of(dut), f"CAPS {caps:#010x}, the build's {caps_of(dut):#010x}"
    regs = sorted(regmap().values(), key=lambda r: r.offset)
    have = units(caps)
    settle = engine_lag(int(dut.CHANNELS.value)) if env.engine else 0

    def fmask(f):
        return built_mask(f, count_w, ts_w, have)

    # 1. reset values (the encoder is still): every field that has one
    for r in regs:
        got = await bus.rd(r.name)
        for f in r.fields.values():
            if f.reset is not None:
                exp = (f.reset << f.lsb) & fmask(f)
                assert got & f.mask == exp, \
                    f"{r.name}.{f.name} at {r.offset:#04x}: reset {got & f.mask:#x}, RDL {exp:#x}"
    # 2. access
    for r in regs:
        kinds = {f.kind for f in r.fields.values()}
        before = await bus.rd(r.name)
        if r.coherent:  # COUNT_LO / COUNT_HI: loads the count (checked as a pair below)
            continue
        if kinds <= {"const", "in"}:
            await bus.wr(r.name, ~before & 0xFFFFFFFF)
            after = await bus.rd(r.name)
            if r.name == "TIMEBASE":
                assert after != ~before & 0xFFFFFFFF and (after - before) % (1 << ts_w) < 1000
            else:
                assert after == before, f"read-only {r.name} changed on a write: {after:#x}"
            continue
        value = 0xFFFFFFFF if kinds == {"intr"} else rng.getrandbits(32)
        await bus.wr(r.name, value)
        after = await bus.rd(r.name)
        for f in r.fields.values():
            got = after & f.mask
            if f.kind == "cfg":
                exp = value & fmask(f)
            elif f.kind in ("intr", "counter", "pulse"):
                exp = 0  # W1C cleared whatever was set, a write clears, write-only reads 0
            else:  # live read-only bits of a mixed register: unchanged
                exp = before & f.mask
            assert got == exp, f"{r.name}.{f.name}: wrote {value:#x}, read {got:#x}, expected {exp:#x}"
        # back to the reset value
        reset = sum((f.reset or 0) << f.lsb for f in r.fields.values()) & 0xFFFFFFFF
        await bus.wr(r.name, reset)
        if settle:
            await ClockCycles(dut.clk, settle)
    value = rng.getrandbits(64) & ((1 << count_w) - 1)
    await bus.set_count(value)
    assert await bus.count() == value, "COUNT_HI/COUNT_LO write then read"
    await bus.events()


def _cfg_regs():
    """Registers with a storage (cfg) field and no write side effect the walk would disturb."""
    return [r for r in sorted(regmap().values(), key=lambda r: r.offset)
            if not r.coherent and r.name != "EVENTS" and any(f.kind == "cfg" for f in r.fields.values())]


def _cfg_mask(r, count_w, ts_w, have):
    """The storage bits at this COUNT_W / TS_W with these units (the bits a write sets)."""
    return sum(built_mask(f, count_w, ts_w, have) for f in r.fields.values() if f.kind == "cfg")


def _cfg_fields(r):
    """The bits of the storage fields, sized or not (bits above the size must read 0)."""
    return sum(f.mask for f in r.fields.values() if f.kind == "cfg")


@cocotb_test()
async def register_patterns(dut):
    """Every storage register written with its own pattern, then all read back (no write lands in
    another register, no read shows another one), twice with the patterns complemented, each read
    repeated one and two clocks later (the value holds)."""
    env, rng = await begin(dut)
    bus = env.bus
    count_w, ts_w = env.count_w, int(dut.TS_W.value)
    have = units(await bus.rd("CAPS"))
    regs = _cfg_regs()
    for flip in (0, 0xFFFFFFFF):
        want = {}
        for i, r in enumerate(regs):
            value = ((0x9E3779B9 * (i + 1)) & 0xFFFFFFFF) ^ flip
            await bus.wr(r.name, value)
            want[r.name] = value & _cfg_mask(r, count_w, ts_w, have)
        for r in regs:
            m = _cfg_fields(r)
            for gap in (1, 2, 0):
                got = await bus.rd(r.name) & m
                assert got == want[r.name], \
                    f"{r.name}: read {got:#010x}, wrote {want[r.name]:#010x} (flip {flip:#x})"
                if gap:
                    await ClockCycles(dut.clk, gap)
    for r in regs:  # back to the reset values
        await bus.wr(r.name, sum((f.reset or 0) << f.lsb for f in r.fields.values()) & 0xFFFFFFFF)
    await bus.events()


async def make_errors(env, reg: str, n: int) -> None:
    """n quadrature errors (illegal jumps) or n rejected pulses on A (FILTER_LEN 3)."""
    if reg == "QERR_COUNT":
        await illegal_jumps(env, n)
    else:
        await rejected_pulses(env, n)


@cocotb_test()
async def clear_and_command_strobes(dut):
    """Byte enables of the writes that clear or command (the RDL): a write of QERR_COUNT or
    GLITCH_COUNT with any one byte enable set, byte 3 alone included, clears it, one with none
    (SEL or WSTRB 0) leaves it; SNAP_CTRL.CMD and GSNAP_CTRL.CMD take a snapshot only when byte
    0's enable is set (SNAP_READY, and SNAP_TIME moves, or neither)."""
    env, rng = await begin(dut)
    bus = env.bus
    await env.setup(QeiModel(env.count_w), count=0, filter_len=3)
    masks = [1, 2, 4, 8, 3, 6, 12, 15, 0, 5, 9, 10]
    for reg in ("QERR_COUNT", "GLITCH_COUNT"):
        for strb in masks:
            await make_errors(env, reg, 3)
            before = await bus.rd(reg)
            assert before >= 3, f"{reg}: {before} after 3 errors"
            await bus.wr(reg, rng.getrandbits(32), strb)
            await env.applied()
            await env.settle()
            after = await bus.rd(reg)
            assert after == (before if strb == 0 else 0), \
                f"{reg} written with byte enables {strb:#x}: {before} -> {after}"
    for reg in () if lacks("TIMING") else ("SNAP_CTRL", "GSNAP_CTRL"):
        for strb in masks:
            await bus.events()
            t0 = await bus.rd("SNAP_TIME")
            await ClockCycles(dut.clk, 3)
            await bus.wr(reg, regmap()[reg].fields["CMD"].mask | rng.getrandbits(32) & 0xFFFFFF00, strb)
            await bus.wr(reg, 0)
            await env.applied()
            await env.settle()
            snapped = "SNAP_READY" in await bus.events()
            moved = await bus.rd("SNAP_TIME") != t0
            assert snapped == moved == bool(strb & 1), \
                f"{reg}.CMD written with byte enables {strb:#x}: SNAP_READY {snapped}, SNAP_TIME moved {moved}"


@cocotb_test(skip=engine_build())
async def count_clear_loses_no_error(dut):
    """A per_channel build loses no error to a clear of QERR_COUNT or GLITCH_COUNT (the RDL):
    the clearing write and an error timed so that the error reaches the counter from 3 clocks
    before the clock the write takes effect to 3 after it (white box: the register block's write
    strobe and the channel's error pulse, sampled every clock); the count after is 1 exactly
    when the error came in that clock or later, 0 when before."""
    env, rng = await begin(dut)
    bus = env.bus
    regs, chan = dut.u_qei.u_regs, channel(dut)
    seen = {}
    for reg, pulse, flen in (("QERR_COUNT", chan.ev_qerr, 1), ("GLITCH_COUNT", chan.glitch_ab, 3)):
        await env.setup(QeiModel(env.count_w), count=0, filter_len=flen)
        # (the register block numbers a page's registers in the order of their offsets: its write
        # strobe wr_c_q[k] is the k-th's)
        bit = [r.name for r in sorted(regmap().values(), key=lambda r: r.offset)
               if r.group == "chan"].index(reg)

        async def prepare():
            await bus.wr(reg, 0)
            await env.settle()

        async def judge(d, _):
            await env.settle()
            value = await bus.rd(reg)
            assert value == int(d >= 0), \
                f"{reg}: the error {d:+d} clocks from the clearing write's clock, the count {value}"

        # (the error's stimulus starts `lead` clocks after the write's)
        seen[reg] = await aimed_races(dut, lambda: int(regs.wr_c_q.value) >> bit & 1,
                                      lambda: int(pulse.value), prepare,
                                      lambda: make_errors(env, reg, 1), lambda: bus.wr(reg, 0), judge,
                                      lead=-10)
    dut._log.info("errors at these clocks from the clearing write's: %s", seen)


@cocotb_test()
async def byte_enables_all(dut):
    """Every storage register and COUNT_HI honour each byte-enable mask (on AXI4-Lite too, the
    non-contiguous ones straight onto the master's channels): the lanes written take the new
    bytes, the others keep theirs."""
    env, rng = await begin(dut)
    bus = env.bus
    count_w, ts_w = env.count_w, int(dut.TS_W.value)
    masks = [1, 2, 4, 8, 3, 6, 12, 7, 14, 5, 9, 10, 13, 11]
    have = units(await bus.rd("CAPS"))
    for i, r in enumerate(_cfg_regs()):
        m, fm = _cfg_mask(r, count_w, ts_w, have), _cfg_fields(r)
        for k, (strb, flip) in enumerate((m, f) for m in masks for f in (0, 0xFFFFFFFF)):
            lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
            old = ((0xC3A55A3C * (i + 3 * k + 1)) ^ flip) & 0xFFFFFFFF  # each bit kept as 0 and as 1
            new = ~old & 0xFFFFFFFF
            await bus.wr(r.name, old)
            await bus.wr(r.name, new, strb)
            got = await bus.rd(r.name) & fm
            exp = (old & ~lanes | new & lanes) & m
            assert got == exp, f"{r.name} strb {strb:#x}: {got:#010x}, expected {exp:#010x}"
        await bus.wr(r.name, sum((f.reset or 0) << f.lsb for f in r.fields.values()) & 0xFFFFFFFF)
    await bus.events()
    # COUNT_HI: a write stages the enabled lanes over the word staged before (set_count staged the
    # high word of old, which the COUNT_LO read latches too)
    model = QeiModel(count_w)
    await env.setup(model, count=0, en=0)
    for k, strb in enumerate(masks):
        lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
        old = (0x5AC3A53C * (k + 1) << 32 | 0x1234_5678) & model.max
        await bus.set_count(old)
        await bus.rd("COUNT_LO")  # latches COUNT_HI
        new_hi = ~(old >> 32) & 0xFFFFFFFF
        await bus.wr("COUNT_HI", new_hi, strb)
        await bus.wr("COUNT_LO", 0x0BAD_F00D)
        hi = ((old >> 32) & ~lanes | new_hi & lanes) & 0xFFFFFFFF
        exp = (hi << 32 | 0x0BAD_F00D) & model.max
        got = await bus.count()
        assert got == exp, f"COUNT_HI strb {strb:#x}: count {got:#x}, expected {exp:#x}"


@cocotb_test(timeout_time=200, timeout_unit="us")  # a lost response must not hang the run
async def concurrent_reads_and_writes(dut):
    """AXI4-Lite: reads and writes outstanding at the same time (the master's read and write
    channels run independently): every read answers its own register, every write lands.
    (Wishbone has one transaction at a time: the same traffic, in turn.)"""
    env, rng = await begin(dut)
    bus = env.bus
    ident = await bus.rd("ID")
    caps = await bus.rd("CAPS")
    for rnd in range(12):
        values = {r: (0x3C5A_96E1 * (rnd + 1) + 0x1111 * k) & 0xFFFFFFFF
                  for k, r in enumerate(("PRESET_LO", "COMPARE_LO", "IRQ_EN", "SNAP_PERIOD"))}
        reads = []
        if bus.kind == "axil":
            writes = [cocotb.start_soon(bus.wr(r, v)) for r, v in values.items()]
            reads = [cocotb.start_soon(bus.rd(n)) for n in ("ID", "CAPS", "ID", "CAPS")]
            for t in writes:
                await t
            got = [await t for t in reads]
        else:
            for r, v in values.items():
                await bus.wr(r, v)
            got = [await bus.rd(n) for n in ("ID", "CAPS", "ID", "CAPS")]
        assert got == [ident, caps, ident, caps], f"round {rnd}: reads {got}"
        for r, v in values.items():
            m = _cfg_mask(regmap()[r], env.count_w, int(dut.TS_W.value), units(caps))
            assert await bus.rd(r) == v & m, f"round {rnd}: {r}"
    for r in ("PRESET_LO", "COMPARE_LO", "IRQ_EN", "SNAP_PERIOD"):
        await bus.wr(r, 0)


@cocotb_test()
async def wb_abandoned_cycle(dut):
    """Wishbone: a cycle the master drops (CYC low) before the answer gets no ACK or ERR
    outside it (a mapped and an unmapped offset); the next cycle works. (AXI4-Lite has no such case: nothing to do.)"""
    env, rng = await begin(dut)
    bus = env.bus
    if bus.kind != "wb":
        return
    ident = await bus.rd("ID")
    unmapped = max(r.offset for r in regmap().values()) + 4
    for hold, adr in ((1, regmap()["ID"].offset), (2, regmap()["ID"].offset), (1, unmapped),
                      (2, unmapped)):
        await wb_abandon_read(dut, adr, hold)
        for k in range(8):
            await Timer(PERIOD_PS // 10, unit="ps")  # the same clock, CYC already low
            assert dut.wb_ack_o.value == 0 and dut.wb_err_o.value == 0, \
                f"ACK/ERR {k} clocks after the master dropped CYC"
            await FallingEdge(dut.clk)
        assert await bus.rd("ID") == ident


@cocotb_test()
async def count_hi_lanes_keep_staged_word(dut):
    """COUNT_HI written in full, then with some byte lanes: the lanes not enabled keep the bytes
    of the word staged by the first write, not those of the high word a COUNT_LO read latched
    before; COUNT_LO then loads {the staged word, its word} (COUNT_W 64). With COUNT_W <= 32 the
    high word is absent: COUNT_HI reads 0 and the count is the COUNT_LO word."""
    env, rng = await begin(dut)
    bus = env.bus
    model = QeiModel(env.count_w)
    await env.setup(model, count=0, en=0)
    masks = [5, 9, 10, 13, 11, 1, 2, 4, 8, 3, 6, 12, 7, 14]
    latched, w1, w2 = 0x1122_3344, 0xA5B6_C7D8, 0x5A69_7887  # every byte differs between them
    for k, strb in enumerate(masks):
        lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
        lo = 0x0BAD_F000 + k
        await bus.set_count(latched << 32 | 0x600D_0000)
        assert await bus.rd("COUNT_LO") == 0x600D_0000 & model.max  # latches COUNT_HI
        assert await bus.rd("COUNT_HI") == latched & size_mask("COUNT_W:1", env.count_w, 32)
        await bus.wr("COUNT_HI", w1)
        await bus.wr("COUNT_HI", w2, strb)
        await bus.wr("COUNT_LO", lo)
        exp = ((w1 & ~lanes | w2 & lanes) << 32 | lo) & model.max
        got = await bus.count()
        assert got == exp, \
            f"COUNT_HI {w1:#010x}, then {w2:#010x} strb {strb:#x}, COUNT_LO {lo:#010x}: count " \
            f"{got:#x}, expected {exp:#x} (COUNT_HI latched {latched:#010x} by a read before)"


@cocotb_test()
async def wb_abandoned_request(dut):
    """Wishbone: a master that abandons a request (drops CYC after the request was taken, before
    a clock edge took its answer: 1 or 2 clocks after) and starts a new one 1 or 2 clocks later
    gets the new request's own answer (ACK or ERR) and data, and no other answer; an abandoned
    write has been carried out (the new request reads it back). (A lean build has no COMPARE:
    GSNAP_PERIOD, a global register, takes its place; with the shared engine, an answer may wait
    for the engine's latency.)
    Driven on the raw signals (cocotbext's master cannot abort). (AXI4-Lite: nothing to do.)"""
    env, rng = await begin(dut)
    bus = env.bus
    if bus.kind != "wb":
        return
    ident, caps = await bus.rd("ID"), await bus.rd("CAPS")
    unmapped = max(r.offset for r in regmap().values()) + 4
    other = "GSNAP_PERIOD" if env.lean else "COMPARE_LO"

    async def request(we, adr, data):
        """Drive a request at the next falling edge (CYC, STB and the request's signals)."""
        await FallingEdge(dut.clk)
        dut.wb_adr_i.value, dut.wb_we_i.value, dut.wb_dat_i.value = adr, we, data
        dut.wb_sel_i.value = 0xF
        dut.wb_cyc_i.value = dut.wb_stb_i.value = 1

    def answered():
        return int(dut.wb_ack_o.value) or int(dut.wb_err_o.value)

    wide = env.count_w >= 32  # (PRESET_LO and COMPARE_LO hold COUNT_W bits)
    flip = 0xFF0000 if wide else 0xF0
    for gap in (1, 2):
        for hold in (1, 2):
            v = (0x3C5A_0000 | gap << 8 if wide else 0x5000 | gap << 8 if env.count_w >= 16
                 else 0x50 | gap << 2) | hold
            # (what, abandoned request, new request: (we, adr, data), the new one's answer: (err,
            # data read), the registers written by either, to read back afterwards)
            cases = (
                ("read ID, then read CAPS", (0, addr("ID"), 0), (0, addr("CAPS"), 0), (0, caps), {}),
                ("read unmapped, then read ID", (0, unmapped, 0), (0, addr("ID"), 0), (0, ident), {}),
                ("read ID, then read unmapped", (0, addr("ID"), 0), (0, unmapped, 0), (1, 0), {}),
                ("write PRESET_LO, then read it", (1, addr("PRESET_LO"), v), (0, addr("PRESET_LO"), 0),
                 (0, v), {"PRESET_LO": v}),
                (f"write {other}, then write PRESET_LO", (1, addr(other), v ^ flip),
                 (1, addr("PRESET_LO"), v ^ 0xFF), (0, None),
                 {other: v ^ flip, "PRESET_LO": v ^ 0xFF}),
                (f"write unmapped, then write {other}", (1, unmapped, 0), (1, addr(other), v),
                 (0, None), {other: v}),
            )
            for what, first, second, exp, written in cases:
                what = f"{what} (held {hold}, CYC low {gap} clocks)"
                await request(*first)
                for k in range(hold):  # (held 2: the answer shows in the clock CYC drops)
                    await FallingEdge(dut.clk)
                    assert k == hold - 1 or not answered(), f"{what}: answered before CYC dropped"
                dut.wb_cyc_i.value = dut.wb_stb_i.value = 0
                for k in range(gap - 1):
                    await FallingEdge(dut.clk)
                await request(*second)
                await ReadOnly()  # an answer may show at once (taken at the next rising edge)
                for n in range(20 + 2 * env.lag):
                    if answered():
                        break
                    await FallingEdge(dut.clk)
                else:
                    raise AssertionError(f"{what}: the new request got no answer in {n + 1} clocks")
                err, data = int(dut.wb_err_o.value), int(dut.wb_dat_o.value)
                await FallingEdge(dut.clk)
                dut.wb_stb_i.value = dut.wb_we_i.value = 0  # CYC stays: no other answer may come
                for k in range(4):
                    await FallingEdge(dut.clk)
                    assert not answered(), f"{what}: another answer {k + 1} clocks after the first"
                dut.wb_cyc_i.value = 0
                assert err == exp[0], f"{what}: the new request answered {'ERR' if err else 'ACK'}"
                if second[0] == 0:
                    assert data == exp[1], f"{what}: the new request read {data:#x}, expected {exp[1]:#x}"
                for reg, value in written.items():
                    got = await bus.rd(reg)
                    assert got == value, f"{what}: {reg} reads {got:#x}, written {value:#x}"


# ---- pytest ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("config", CONFIGS, ids=CONFIG_IDS)
def test_bus(config):
    run_feature(__name__, *config)
