# SPDX-License-Identifier: Apache-2.0
"""enc_qei's shared engine (ENGINE = 1) against its promises, the RDL text of CAPS.ENGINE's value
shared (P = 24 x max(CHANNELS, 2), the constants ENGINE_* of enctools.qei.env), on 1, 3 and 16
channels and on 2 channels at COUNT_W 64, and the same tests on a build with a datapath per channel (the reference: every value
the same, shown at once):

- latency: a step shows in COUNT at most P + 24 clocks later than on the per-channel build, an
  event in EVENTS, a level in STATUS, an index latch in INDEX_LATCH, a quadrature error in
  QERR_COUNT and a global snapshot in SNAP_TIME at most P + 44 later, irq and IRQ_SUMMARY rise at
  most P + 44 later (measured to the clock at every phase of the engine's reads of a channel);
- a bus write is answered in 4 clocks, a read in 5 (a COUNT_LO write keeping some bytes in 6; 2
  per channel), at every phase; a write acts once, at most P + 18 clocks after its request (a
  COUNT_LO write), or P + 26 (EVENTS, QERR_COUNT: on what a read could show at the request, an
  event after it stays), in order with the reads and writes after it; a read right after a write
  sees it and is answered at most P + 66 clocks after the write's request (P + 30 after a state
  write, P + 68 after a COUNT_LO write with some byte lanes off), and at some phase that late; a
  write right after a write of its channel one clock sooner (a COUNT_LO write with some byte
  lanes off: one clock later than the read), a write of another channel at once; an access
  P + 57 clocks after a write's answer (P + 21 after a state write) without a wait;
- COUNT_W > 32: a COUNT_LO read of another channel stores the COUNT_HI latch of the channel read
  before, and the next access of that channel waits for the store (P + 23 after that read's
  answer, P + 29 after its request); that read waits for the other channel's unstored write
  (P + 63 after its answer);
- every value exact: independent clock-exact random walks on every channel at the count-rate bound
  with index presets and latches, global snapshots every few hundred clocks, each channel against
  its own model; channels isolated from each other's bus traffic; reset in mid-motion;
- snapshots requested faster than the engine stores them: a global one waits for the captures of
  the one before (GSNAP_TIME tells when it was taken), a channel's own one waits for its visit
  (SNAP_TIME tells), and SNAP_READY rises only when SNAP_* hold the snapshot; a request that waits
  when its source is stopped (GSNAP_CTRL.PERIOD_EN written 0) is still taken, at most P clocks
  after the write's snapshot clock, and GSNAP_TIME holds still from P + 44 clocks after it; a
  channel's SNAP_CTRL.CMD then GSNAP_CTRL.CMD: in that order with a read of the channel between
  them, the global one possibly first without it.

Runs on ENGINE_CONFIGS (enc_qei_wb, lean, COUNT_W 32 or 64, TS_W 32; 16 channels on Verilator
whatever SIM says). Every cocotb test logs its seed.
"""

from __future__ import annotations

import json
import os

import cocotb
import pytest
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from enctools.qei.bus import WbRaw, signed
from enctools.qei.env import (ENGINE_ACT, ENGINE_ANSWER, ENGINE_IRQ, ENGINE_PART_ANSWER,
                              ENGINE_NO_WAIT, ENGINE_PART_WAIT, ENGINE_READ_ANSWER,
                              ENGINE_SAVE_READ, ENGINE_STATE_NO_WAIT,
                              ENGINE_SAVE_WAIT, ENGINE_SAVE_WAIT_REQ, ENGINE_SHOW,
                              ENGINE_SHOW_COUNT, ENGINE_STATE_WAIT, ENGINE_WAIT,
                              ENGINE_WRITE_PART_WAIT, ENGINE_WRITE_STATE_WAIT, ENGINE_WRITE_WAIT,
                              PER_CHANNEL_ANSWER, PROFILES, begin, build_name, channel_envs,
                              engine_period, read_snapshot)
from enctools.qei.model import QUAD, QeiModel
from enctools.qei.stimulus import ClockWalk, pulse_rst
from enctools.regmap import addr, built_mask, event_bits, field, pack, regmap, units
from enctools.tb import cocotb_test

# (top, CHANNELS, ENGINE, COUNT_W): the reference build with a datapath per channel, then the engine
ENGINE_CONFIGS = (("enc_qei_wb", 1, 0, 32), ("enc_qei_wb", 1, 1, 32), ("enc_qei_wb", 3, 1, 32),
                  ("enc_qei_wb", 16, 1, 32), ("enc_qei_wb", 2, 1, 64))

CHAN_REGS = tuple(r for r, x in regmap().items() if x.group == "chan")
TRAFFIC = ("CTRL", "COUNT_LO", "COUNT_HI", "PRESET_LO", "PRESET_HI", "INDEX_CTRL", "EVENTS",
           "IRQ_EN", "QERR_COUNT", "GLITCH_COUNT", "SNAP_CTRL")
QERR = event_bits("QERR")
STATUS_Z = field("STATUS", "Z").mask


class Pins:
    """The encoder pins of every channel, set at falling edges (FILTER_LEN 1: a level set there is
    sampled at the next rising edge)."""

    def __init__(self, dut, n):
        self.dut, self.n = dut, n
        self.pos = [0] * n
        self.z = [0] * n

    def apply(self) -> None:
        a = b = z = 0
        for k in range(self.n):
            qa, qb = QUAD[self.pos[k] % 4]
            a |= qa << k
            b |= qb << k
            z |= self.z[k] << k
        self.dut.a_in.value, self.dut.b_in.value, self.dut.z_in.value = a, b, z


async def at_phase(dut, p: int, r: int) -> int:
    """Wait for the falling edge at which the timebase is r modulo p (the engine's schedule and
    the timebase both start at rst: a residue is a phase of the visits); returns the timebase."""
    tb = dut.u_qei.timebase
    while True:
        await FallingEdge(dut.clk)
        t = int(tb.value)
        if t % p == r:
            return t


async def poll(raw: WbRaw, adr: int, shown, s: int, limit: int) -> tuple[int, int]:
    """Read adr back to back until shown(value); returns (lo, hi) relative to the stamp s: no read
    stamped before s + lo showed it, the read stamped s + hi did."""
    last = None
    while True:
        stamp, value, _ = await raw.access(adr)
        if shown(value):
            return (last - s + 1 if last is not None else 0), stamp - s
        last = stamp
        assert stamp - s < limit, f"not shown {limit} clocks after the stimulus"


# The latencies of the per-channel build (clocks from the stimulus's stamp to the first read that
# shows it, WbRaw's stamps; irq: to the clock it is high): fixed, checked on that build; the
# engine may add at most P + SHOWN[kind].
REF = {"COUNT": 5, "EVENTS": 4, "irq": 5, "IRQ_SUMMARY": 5, "STATUS": 2, "INDEX_LATCH": 5,
       "QERR_COUNT": 4, "SNAP_TIME": 3}
SHOWN = dict({k: ENGINE_SHOW for k in REF}, COUNT=ENGINE_SHOW_COUNT, irq=ENGINE_IRQ,
             IRQ_SUMMARY=ENGINE_IRQ)


@cocotb_test()
async def latency(dut):
    """Per kind, trials at phases spread over the engine's visits (relative to the visit of the
    channel tried, a random one), then around the worst phase found: the clocks until a read
    shows the change. Per-channel build: exactly REF. Engine: never more than REF + P + SHOWN,
    and the worst trial more than P (it reached the channel's far phase)."""
    env, rng = await begin(dut)
    n = int(dut.CHANNELS.value)
    envs = channel_envs(dut, rng, n)
    for e in envs:
        await e.bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1))
        await e.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION="latch", EDGE="rising", ARM=1))
    await env.settle()
    for e in envs:
        await e.bus.events()
    await env.applied()
    raw = WbRaw(dut)
    pins = Pins(dut, n)
    tb = dut.u_qei.timebase
    p = engine_period(n) if env.engine else 2
    visit = p // max(n, 2)  # (one channel's visit; the per-channel build: any 2 phases)
    lag = env.lag
    limit = 2 * lag + 60
    quiet = lag + 10  # clocks for the engine to show what came before
    irq_at = [None]

    async def watch_irq():
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if irq_at[0] is None and dut.irq.value:
                irq_at[0] = int(tb.value) - 1  # (stamped like a falling edge's)

    async def trial(kind: str, k: int, rel: int) -> tuple[int, int]:
        """One stimulus of channel k at phase rel of its visits; (lo, hi) as poll()'s."""
        old = None
        reg = {"COUNT": "COUNT_LO", "INDEX_LATCH": "INDEX_LATCH_LO"}.get(kind, kind)
        if kind == "INDEX_LATCH":
            pins.pos[k] += 1  # a new count to latch
            pins.apply()
            await ClockCycles(dut.clk, quiet)
        if kind in ("COUNT", "INDEX_LATCH", "QERR_COUNT", "SNAP_TIME"):
            old = (await raw.access(addr(reg, k)))[1]
        if kind in ("irq", "IRQ_SUMMARY"):
            await raw.access(addr("IRQ_EN", k), QERR)
            await ClockCycles(dut.clk, quiet)
        s = await at_phase(dut, p, (rel + visit * k) % p)
        if kind == "SNAP_TIME":
            s, _, _ = await raw.access(addr("GSNAP_CTRL"), pack("GSNAP_CTRL", CMD=1))
        elif kind in ("STATUS", "INDEX_LATCH"):
            pins.z[k] = 1
        elif kind == "COUNT":
            pins.pos[k] += 1
        else:
            pins.pos[k] += 2  # a jump: QERR
        pins.apply()
        irq_at[0] = None
        if kind == "irq":
            while irq_at[0] is None:
                await FallingEdge(dut.clk)
                assert int(tb.value) - s < limit, f"irq: not high {limit} clocks after a QERR"
            lo = hi = irq_at[0] - s
        else:
            await ClockCycles(dut.clk, rng.randrange(4))  # (reads at every phase too)
            shown = {"EVENTS": lambda v: v & QERR, "IRQ_SUMMARY": lambda v: v >> k & 1,
                     "STATUS": lambda v: v & STATUS_Z}.get(kind, lambda v: v != old)
            lo, hi = await poll(raw, addr(reg) if reg == "IRQ_SUMMARY" else addr(reg, k), shown, s,
                                limit)
        # back to quiet: Z low, events cleared, irq off
        pins.z[k] = 0
        pins.apply()
        if kind not in ("COUNT", "SNAP_TIME"):
            await ClockCycles(dut.clk, quiet)
            await raw.access(addr("IRQ_EN", k), 0)
            await raw.access(addr("EVENTS", k), 0x3FFF)
            await ClockCycles(dut.clk, quiet)
        return lo, hi

    watcher = cocotb.start_soon(watch_irq())
    coarse = 16 if not env.engine else min(24, p // 2)
    found = {}
    for kind in REF:
        results = []  # (lo, hi, rel)
        phases = [(i * p // coarse + rng.randrange(max(1, p // coarse))) % p for i in range(coarse)]
        while phases:
            rel = phases.pop(0)
            k = rng.randrange(n)
            lo, hi = await trial(kind, k, rel)
            bound = p + SHOWN[kind] if env.engine else 0
            assert lo <= REF[kind] + bound, \
                f"{kind}, channel {k}: a read {lo - 1} clocks after the stimulus did not show it " \
                f"(per-channel build: {REF[kind]} clocks; the engine may add P + {SHOWN[kind]})"
            results.append((lo, hi, rel))
            if len(results) == coarse and env.engine:  # then around the worst phase found
                worst = max(results)[2]
                phases = [(worst + d) % p for d in range(-p // coarse, p // coarse + 1, 2)]
        lo_max, hi_max = max(r[0] for r in results), max(r[1] for r in results)
        hi_min = min(r[1] for r in results)
        found[kind] = (lo_max - REF[kind], hi_max - REF[kind])
        if not env.engine:
            assert lo_max <= REF[kind] <= hi_min, \
                f"{kind}: the per-channel build shows it after {lo_max} .. {hi_min} clocks, not {REF[kind]}"
        else:
            dut._log.info("%s: at worst %d .. %d clocks later than the per-channel build (bound "
                          "P + %d, P %d)", kind, *found[kind], SHOWN[kind], p)
            assert lo_max - REF[kind] > p, \
                f"{kind}: the worst trial was only {lo_max - REF[kind]} clocks late (P {p}): the " \
                "trials missed the channel's far phase"
    watcher.cancel()
    out = os.environ.get("ENC_RESULTS")
    if out and env.engine:
        with open(out, "w") as fh:
            json.dump({"channels": n, "P": p, "bounds": SHOWN, "worst": found}, fh)


# ---- every channel moving at once ---------------------------------------------------------------------
async def start_all(dut, index: bool = True):
    """Clock, reset, one Env and one model per channel: x4, FILTER_LEN 1, a random count (some near
    the ends of the range) and, with ``index``, a random INDEX_CTRL action (preset, latch, none) on
    rising Z with a random PRESET; events cleared."""
    env, rng = await begin(dut)
    n = int(dut.CHANNELS.value)
    envs = channel_envs(dut, rng, n)
    models = [QeiModel(e.count_w) for e in envs]
    for e, m in zip(envs, models):
        count = rng.choice((rng.getrandbits(32), rng.randint(0, 60), m.max - rng.randint(0, 60)))
        await e.setup(m, func="x4", filter_len=1, count=count)
        if index:
            action = rng.choice(("preset", "latch", "none"))
            preset = rng.choice((rng.getrandbits(32), m.max - rng.randint(0, 30)))
            await e.bus.set64("PRESET", preset)
            await e.bus.wr("INDEX_CTRL", pack("INDEX_CTRL", ACTION=action, EDGE="rising", ARM=1))
            m.preset, m.idx_action, m.idx_edge, m.idx_arm = preset, action, "rising", True
    await env.applied()
    for e, m in zip(envs, models):
        await e.bus.events()
        m.take_events()
    await env.applied()
    return env, rng, envs, models


def index_pulses(rng, n):
    """Per channel, Z high over three positions of every 17 .. 40 (an index pulse per turn)."""
    out = []
    for _ in range(n):
        rev = rng.randint(17, 40)
        out.append(lambda p, rev=rev: int(p % rev < 3))
    return out


async def global_snapshot(env, envs, walker, rng, t_prev, what) -> int:
    """A global snapshot by command while walker walks; up to four channels' SNAP_* checked against
    their Timelines; returns its (unwrapped) timebase."""
    await env.bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", CMD=1))
    await env.settle()
    t = walker.unwrap(await env.bus.rd("GSNAP_TIME"))
    for k in rng.sample(range(len(envs)), min(len(envs), 4)):
        await check_snapshot(envs[k], walker.lines[k], t, t_prev, f"{what}, channel {k}")
    return t


async def check_snapshot(env, line, t, t_prev, what) -> None:
    """Channel env's SNAP_* against its Timeline at (unwrapped) timebase t; t_prev: the timebase of
    the channel's capture before (None: unknown)."""
    snap = await read_snapshot(env.bus)
    ts_mask = (1 << int(env.dut.TS_W.value)) - 1
    assert snap["time"] == t & ts_mask, f"{what}: SNAP_TIME {snap['time']:#x}, expected {t & ts_mask:#x}"
    mark = line.at(t)
    count = (snap["count_hi"] << 32 | snap["count"]) & ((1 << env.count_w) - 1)
    assert count == mark.count, f"{what}: SNAP_COUNT {count:#x}, the count then {mark.count:#x}"
    e = line.edge(t, False)
    if e is not None:
        assert snap["edge_time"] == (e.t + line.EDGE_PIPE) & ts_mask, \
            f"{what}: SNAP_EDGE_TIME {snap['edge_time']:#x}, last edge's pins set at {e.t & ts_mask:#x}"
    if t_prev is not None:
        motion = mark.motion - line.at(t_prev).motion
        assert signed(snap["delta"]) == motion, f"{what}: SNAP_DELTA {signed(snap['delta'])}, motion {motion}"
        pe = line.edge(t_prev, False)
        if e is not None and pe is not None:
            assert signed(snap["edge_delta"]) == e.motion - pe.motion, \
                f"{what}: SNAP_EDGE_DELTA {signed(snap['edge_delta'])}, motion {e.motion - pe.motion}"


async def check_final(env, model, k, pins_pos):
    """After the motion (and the engine's latency): COUNT, EVENTS (but SNAP_READY), INDEX_LATCH
    and STATUS.A/B equal the model's / the pins'."""
    what = f"channel {k}"
    got = await env.bus.count()
    assert got == model.count, f"{what}: COUNT {got:#x}, model {model.count:#x}"
    ev = await env.bus.events()
    ev.discard("SNAP_READY")
    exp = model.take_events()
    assert ev == exp, f"{what}: EVENTS {sorted(ev)}, model {sorted(exp)}"
    latch = await env.bus.get64("INDEX_LATCH")
    assert latch == model.idx_latch, f"{what}: INDEX_LATCH {latch:#x}, model {model.idx_latch:#x}"
    st = await env.bus.rd("STATUS")
    ab = (st >> field("STATUS", "A").lsb & 1, st >> field("STATUS", "B").lsb & 1)
    assert ab == QUAD[pins_pos % 4], f"{what}: STATUS A/B {ab}, pins {QUAD[pins_pos % 4]}"


@cocotb_test()
async def random_motion(dut):
    """Every channel its own random walk at the count-rate bound (FILTER_LEN 1, a state every
    clock, reversals), index presets and latches, counts crossing the ends of the range; global
    snapshots (GSNAP_CTRL.CMD) every few hundred clocks, each checked on four random channels:
    SNAP_TIME = GSNAP_TIME, SNAP_COUNT, SNAP_EDGE_TIME and the deltas those of that clock (the
    channel's model, enctools.qei.stimulus.Timeline); at the end COUNT, EVENTS, INDEX_LATCH and
    STATUS of every channel."""
    env, rng, envs, models = await start_all(dut)
    n = len(envs)
    walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=1,
                       p_reverse=0.3, zfuns=index_pulses(rng, n))
    snaps = 12
    task = cocotb.start_soon(walker.run(10 ** 9))
    t_prev = None  # the last global snapshot's timebase
    for i in range(snaps):
        await ClockCycles(dut.clk, rng.randint(100, 400))
        t_prev = await global_snapshot(env, envs, walker, rng, t_prev, f"global snapshot {i}")
    task.cancel()
    await env.settle()
    for k, (e, m) in enumerate(zip(envs, models)):
        await check_final(e, m, k, walker.pos[k])
    dut._log.info("%d channels, %d global snapshots; counts %s", n, snaps,
                  [hex(m.count) for m in models])


# ---- bus writes -----------------------------------------------------------------------------------------
# A COUNT_LO write's load clock on the per-channel build: the write request's stamp + REF_LOAD (the
# clock E such that the steps whose pins were set after E - Timeline.SNAP_PIPE count from the
# written value); the engine loads at most P + ENGINE_ACT after that.
REF_LOAD = 4
GLOBAL_REGS = ("ID", "CAPS", "TIMEBASE", "TB_PRESCALE", "GSNAP_CTRL", "GSNAP_PERIOD", "GSNAP_TIME",
               "IRQ_SUMMARY")


async def answered(raw: WbRaw, adr: int, data: int | None = None, sel: int = 0xF) -> int:
    """Clocks from an access's request to its answer (WbRaw's stamp: the clock before the request
    is sampled; its return: the falling edge after the acknowledge)."""
    stamp, _, err = await raw.access(adr, data, sel=sel)
    assert not err, f"access of {adr:#x} answered an error"
    return int(raw.tb.value) - stamp


@cocotb_test()
async def answer_times(dut):
    """Every channel register of a random channel, read, then written with what it read (a COUNT_LO
    write: count_lo_write_answer), at random phases of the engine's reads, each when no write of
    the channel waits: a read answered ENGINE_READ_ANSWER clocks after its request on the engine,
    a write ENGINE_ANSWER, both PER_CHANNEL_ANSWER on the per-channel build (the RDL); the global
    registers in PER_CHANNEL_ANSWER on both. Random phases include the clocks in which the engine
    writes the register's word (a read taken then must still be answered in time)."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    wait = engine_period(n) + ENGINE_WAIT if env.engine else 2
    want = (ENGINE_READ_ANSWER, ENGINE_ANSWER) if env.engine else (PER_CHANNEL_ANSWER,) * 2
    late = []
    for reg in CHAN_REGS + GLOBAL_REGS:
        k = rng.randrange(n) if reg in CHAN_REGS else 0
        adr = addr(reg, k)
        await ClockCycles(dut.clk, wait + rng.randrange(engine_period(n)))
        got = await answered(raw, adr)
        value = (await raw.access(adr))[1]
        await ClockCycles(dut.clk, wait + rng.randrange(engine_period(n)))
        put = None if reg == "COUNT_LO" else await answered(raw, adr, value)
        exp = want if reg in CHAN_REGS else (PER_CHANNEL_ANSWER,) * 2
        if got != exp[0] or put not in (None, exp[1]):
            late.append((reg, got, put))
    assert not late, f"answered not {want} (channel registers: read, write) / {PER_CHANNEL_ANSWER} " \
                     f"(global ones) clocks after the request (register, read, write): {late}"


@cocotb_test()
async def count_lo_write_answer(dut):
    """A COUNT_LO write, when no write of its channel waits, is answered ENGINE_ANSWER clocks after
    its request on the engine with all byte enables set, ENGINE_PART_ANSWER with some (it reads
    the count for the bytes it keeps: the RDL), PER_CHANNEL_ANSWER on the per-channel build; at
    random phases of the engine's reads, so also in the clock the engine writes the count."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    for sel, want in ((0xF, ENGINE_ANSWER), (0x3, ENGINE_PART_ANSWER), (0x8, ENGINE_PART_ANSWER)):
        want = want if env.engine else PER_CHANNEL_ANSWER
        seen = set()
        for _ in range(8):
            await ClockCycles(dut.clk, engine_period(n) + ENGINE_WAIT + rng.randrange(engine_period(n)))
            seen.add(await answered(raw, addr("COUNT_LO", rng.randrange(n)), rng.getrandbits(32), sel))
        assert seen == {want}, f"COUNT_LO writes (byte enables {sel:#x}) answered {sorted(seen)} " \
                               f"clocks after the request, not {want}"


@cocotb_test()
async def write_effect(dut):
    """Every channel moving forward a step a clock; at phases spread over the engine's reads, a
    COUNT_LO write to a random channel: a read right after it gives the written count (plus the
    steps since); it loads the count once, in one clock E (from a global snapshot later: SNAP_COUNT =
    value + the steps after E), no earlier than on the per-channel build (REF_LOAD after the
    request) and at most P + ENGINE_ACT clocks after the request (the RDL: the write acts, loading
    the count in the clock before the channel's read, at most P + 18 clocks after its request).
    Then, a channel standing still, COUNT_LO writes with some byte lanes: the
    other lanes from COUNT."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    p = engine_period(n) if env.engine else 2
    visit = p // max(n, 2)
    wlag = p + ENGINE_ACT - REF_LOAD if env.engine else 0  # (E - REF_LOAD after the request)
    walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=1,
                       p_reverse=0)
    task = cocotb.start_soon(walker.run(10 ** 9))
    trials = 12 if not env.engine else min(24, p // 2)
    worst = 0
    for i in range(trials):
        k = rng.randrange(n)
        value = rng.getrandbits(32) & ~0xFFFF | 0x8000
        await at_phase(dut, p, (i * p // trials + rng.randrange(max(1, p // trials)) + visit * k) % p)
        w, _, _ = await raw.access(addr("COUNT_LO", k), value)
        _, got, _ = await raw.access(addr("COUNT_LO", k))
        since = (got - value) & 0xFFFFFFFF
        assert since <= wlag + env.lag + 20, \
            f"channel {k}: COUNT_LO read right after writing {value:#x} gave {got:#x}"
        await ClockCycles(dut.clk, wlag + 10)
        g, _, _ = await raw.access(addr("GSNAP_CTRL"), pack("GSNAP_CTRL", CMD=1))
        await ClockCycles(dut.clk, env.lag + 10)
        t = walker.unwrap((await raw.access(addr("SNAP_TIME", k)))[1])
        count = (await raw.access(addr("SNAP_COUNT_LO", k)))[1]
        load = t - ((count - value) & 0xFFFFFFFF)  # E
        d = load - w - REF_LOAD
        assert 0 <= d <= wlag, \
            f"channel {k}: the COUNT_LO write (stamp {w:#x}) loaded the count in clock {load:#x}, " \
            f"{d} clocks later than the per-channel build (at most {wlag}: P + {ENGINE_ACT} after " \
            f"the request)"
        worst = max(worst, d)
    task.cancel()
    if env.engine:
        dut._log.info("a COUNT_LO write loads at most %d clocks later than on the per-channel "
                      "build (bound %d, P %d)", worst, wlag, p)
        assert worst > p - 2 * p // trials, f"the worst trial loaded only {worst} clocks late (P {p})"
    # byte lanes, the channel still: the lanes not written are COUNT's
    await env.settle()
    for i, strb in enumerate((1, 2, 4, 8, 3, 6, 12, 7, 14, 5, 9, 10, 13, 11)):
        k = rng.randrange(n)
        old = (await raw.access(addr("COUNT_LO", k)))[1]
        new = rng.getrandbits(32)
        lanes = sum(0xFF << 8 * j for j in range(4) if strb >> j & 1)
        await raw.access(addr("COUNT_LO", k), new, strb)
        got = (await raw.access(addr("COUNT_LO", k)))[1]
        assert got == old & ~lanes | new & lanes, \
            f"channel {k}: COUNT_LO {old:#x}, written {new:#x} with byte enables {strb:#x}: {got:#x}"


# the bits of a register the wait tests write (COUNT_LO: byte lanes 0 and 1, IRQ_EN: its events)
WRITE_MASK = {"PRESET_LO": 0xFFFFFFFF, "COUNT_LO": 0xFFFF, "IRQ_EN": 0x3FF}


async def random_value(raw: WbRaw, rng, reg: str, k: int, sel: int) -> int:
    """A random value of reg for channel k in its WRITE_MASK bits; the other bits as the register
    reads now when the write keeps some byte lanes (sel not 0xF), else 0."""
    old = (await raw.access(addr(reg, k)))[1] if sel != 0xF else 0
    return (old & ~WRITE_MASK[reg]) | (rng.getrandbits(32) & WRITE_MASK[reg])


async def after_write(dut, raw: WbRaw, env, p: int, phase: int, k: int, first: tuple,
                      second: tuple, bound: int) -> tuple[int, int]:
    """At the phase of channel k's visits: a write of first = (register, value, byte enables),
    then at once an access of second (the same, a read when its value is None). Its answer is
    held to P + bound clocks after the first's request on the engine, to PER_CHANNEL_ANSWER after
    its own on the per-channel build; returns (that answer's clocks after the first's request,
    less P; the data the access read)."""
    (reg1, v1, sel1), (reg2, v2, sel2) = first, second
    await at_phase(dut, p, phase)
    w, _, _ = await raw.access(addr(reg1, k), v1, sel=sel1)
    s, got, _ = await raw.access(addr(reg2, k), v2, sel=sel2)
    done = int(raw.tb.value)
    what = "read" if v2 is None else "write"
    if env.engine:
        assert done - w <= p + bound, \
            f"channel {k}: a {reg2} {what} right after a {reg1} write answered {done - w} clocks " \
            f"after the write's request (bound P + {bound}, P {p})"
    else:
        assert done - s == PER_CHANNEL_ANSWER, f"{reg2} {what}: answered {done - s} clocks"
    return done - w - p, got


@cocotb_test()
async def read_after_write_wait(dut):
    """A write of a channel, then at once a read of the same register (it must see the write),
    at every phase of the engine's visits: the read is answered at most P + ENGINE_WAIT clocks
    after the write's request (a COUNT_LO write with byte lanes 0 and 1 only: P + ENGINE_PART_WAIT;
    a state write, IRQ_EN: P + ENGINE_STATE_WAIT; the RDL), and at some phase within 2 clocks of
    that (the bound is the real one). The channels stand still (COUNT reads back as written).
    Per-channel build: the read answered PER_CHANNEL_ANSWER after its own request."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    p = engine_period(n) if env.engine else 2
    worst = {}
    for reg, sel, bound in (("PRESET_LO", 0xF, ENGINE_WAIT), ("COUNT_LO", 0x3, ENGINE_PART_WAIT),
                            ("IRQ_EN", 0xF, ENGINE_STATE_WAIT)):
        worst[reg] = 0
        for rel in range(p):
            k = rng.randrange(n)
            value = await random_value(raw, rng, reg, k, sel)
            late, got = await after_write(dut, raw, env, p, (rel + (p // max(n, 2)) * k) % p, k,
                                          (reg, value, sel), (reg, None, 0xF), bound)
            assert got == value, f"channel {k}: {reg} written {value:#x}, read right after: {got:#x}"
            worst[reg] = max(worst[reg], late)
            await ClockCycles(dut.clk, p + ENGINE_WAIT)
        dut._log.info("a read of %s right after a write answered at worst P + %d clocks after the "
                      "write's request (bound P + %d, P %d)", reg, worst[reg], bound, p)
        if env.engine:
            assert worst[reg] >= bound - 2, \
                f"the worst read of {reg} after a write was answered at P + {worst[reg]}: the " \
                f"RDL's P + {bound} is loose"


@cocotb_test()
async def write_after_write_wait(dut):
    """A write of a channel, then at once a second write of the same channel, at every phase of the
    engine's visits: the second is answered at most
    P + ENGINE_WRITE_WAIT clocks after the first's request (after IRQ_EN, a state write:
    P + ENGINE_WRITE_STATE_WAIT; after a COUNT_LO write with byte lanes 0 and 1:
    P + ENGINE_WRITE_PART_WAIT; the second itself a COUNT_LO write with byte lanes 0 and 1: one
    clock more; the RDL), and within 2 clocks of that at some phase (the bound is the real one);
    reads after them see both writes, the second last. A write of another channel right after a
    write does not wait: answered in ENGINE_ANSWER clocks. The channels stand still. Per-channel
    build: the second write answered PER_CHANNEL_ANSWER after its own request."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    p = engine_period(n) if env.engine else 2
    # (first register, its byte enables, second register, its byte enables, bound)
    cases = (("PRESET_LO", 0xF, "PRESET_LO", 0xF, ENGINE_WRITE_WAIT),
             ("COUNT_LO", 0x3, "PRESET_LO", 0xF, ENGINE_WRITE_PART_WAIT),
             ("IRQ_EN", 0xF, "IRQ_EN", 0xF, ENGINE_WRITE_STATE_WAIT),
             ("PRESET_LO", 0xF, "COUNT_LO", 0x3, ENGINE_WRITE_WAIT + 2))

    for first, sel1, second, sel2, bound in cases:
        worst = 0
        for rel in range(p):
            k = rng.randrange(n)
            v1 = await random_value(raw, rng, first, k, sel1)
            v2 = await random_value(raw, rng, second, k, sel2)
            if first == second:
                v2 ^= 1  # (the read must tell the second from the first)
            late, _ = await after_write(dut, raw, env, p, (rel + (p // max(n, 2)) * k) % p, k,
                                        (first, v1, sel1), (second, v2, sel2), bound)
            worst = max(worst, late)
            got1 = (await raw.access(addr(first, k)))[1]
            got2 = (await raw.access(addr(second, k)))[1]
            assert got2 == v2, f"channel {k}: {second} written {v2:#x} second, reads {got2:#x}"
            if first != second:
                assert got1 == v1, f"channel {k}: {first} written {v1:#x} first, reads {got1:#x}"
            await ClockCycles(dut.clk, p + ENGINE_WAIT)
        if env.engine:
            dut._log.info("a %s write right after a %s write of its channel answered at worst "
                          "P + %d clocks after the first's request (bound P + %d, P %d)", second,
                          first, worst, bound, p)
            assert worst >= bound - 2, \
                f"the worst {second} write after a {first} write was answered at P + {worst}: " \
                f"the RDL's P + {bound} is loose"
    if n > 1:
        for _ in range(8):
            k, j = rng.sample(range(n), 2)
            await at_phase(dut, p, rng.randrange(p))
            await raw.access(addr("PRESET_LO", k), rng.getrandbits(32))
            got = await answered(raw, addr("PRESET_LO", j), rng.getrandbits(32))
            want = ENGINE_ANSWER if env.engine else PER_CHANNEL_ANSWER
            assert got == want, f"a write of channel {j} right after one of channel {k} answered " \
                                f"in {got} clocks, not {want}: it waited"
            await ClockCycles(dut.clk, p + ENGINE_WAIT)


@cocotb_test()
async def no_wait_after_store(dut):
    """A write of a channel, then a read of it (STATUS) requested P + ENGINE_NO_WAIT clocks after
    the write's answer (PRESET_LO; a COUNT_LO write with byte lanes 0 and 1; IRQ_EN, a state write:
    P + ENGINE_STATE_NO_WAIT), at every phase of the engine's visits: the read is answered in its
    own ENGINE_READ_ANSWER clocks, it does not wait (the RDL). On 1 and 3 channels also one clock
    earlier, where the read waits at some phase (the bound is the real one); on 16 channels
    PRESET_LO and IRQ_EN. Per-channel build: a read 3 clocks after a write's answer takes its
    PER_CHANNEL_ANSWER."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    p = engine_period(n) if env.engine else 2
    want = ENGINE_READ_ANSWER if env.engine else PER_CHANNEL_ANSWER
    tight = env.engine and p <= 72
    cases = (("PRESET_LO", 0xF, ENGINE_NO_WAIT), ("COUNT_LO", 0x3, ENGINE_NO_WAIT),
             ("IRQ_EN", 0xF, ENGINE_STATE_NO_WAIT))
    for reg, sel, bound in (cases if p <= 72 else cases[::2]):
        waited = 0
        for rel in range(p):
            for early in ((0, 1) if tight else (0,)):
                k = rng.randrange(n)
                value = await random_value(raw, rng, reg, k, sel)
                await at_phase(dut, p, (rel + (p // max(n, 2)) * k) % p)
                await raw.access(addr(reg, k), value, sel=sel)
                answer = int(raw.tb.value)
                at = answer + (p + bound - early if env.engine else 3)
                while int(raw.tb.value) < at - 1:
                    await FallingEdge(dut.clk)
                r, _, _ = await raw.access(addr("STATUS", k))
                assert r == at, f"the read requested in clock {r:#x}, not {at:#x}"
                got = int(raw.tb.value) - r
                if early:
                    waited += got != want
                else:
                    assert got == want, \
                        f"channel {k}: a read requested P + {bound} clocks after the answer to a " \
                        f"{reg} write was answered {got} clocks after its request, not {want}: it " \
                        f"waited for the write"
                await ClockCycles(dut.clk, p + ENGINE_WAIT)
        if tight:
            dut._log.info("a read P + %d clocks after a %s write's answer waited at %d of %d "
                          "phases (P %d)", bound - 1, reg, waited, p, p)
            assert waited > 0, f"no read P + {bound - 1} clocks after a {reg} write's answer " \
                               f"waited: the RDL's P + {bound} is loose"


@cocotb_test()
async def snapshot_order(dut):
    """A channel's SNAP_CTRL.CMD, then at once GSNAP_CTRL.CMD, at phases spread over the engine's
    visits, the channels standing still. With a read of the channel between the two writes (the
    RDL's way to keep the order) every channel's SNAP_TIME is GSNAP_TIME afterwards, on both
    builds. Without it the per-channel build takes them in the order written (the same); the
    engine may take the global one first (the RDL, CAPS.ENGINE shared (3)): then that channel's
    SNAP_TIME is later than GSNAP_TIME, by at most 2 P + ENGINE_ACT clocks after its write's
    request, at some phase (the warning is real), and every other channel's is GSNAP_TIME."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    p = engine_period(n) if env.engine else 2
    wait = engine_period(n) + ENGINE_SHOW + 20
    late = 0
    trials = 8
    for i in range(2 * trials):
        keep = i % 2 == 1
        k = rng.randrange(n)
        await at_phase(dut, p, (i // 2 * p // trials + rng.randrange(max(1, p // trials))) % p)
        w, _, _ = await raw.access(addr("SNAP_CTRL", k), pack("SNAP_CTRL", CMD=1))
        if keep:
            await raw.access(addr("STATUS", k))
        await raw.access(addr("GSNAP_CTRL"), pack("GSNAP_CTRL", CMD=1))
        await ClockCycles(dut.clk, 2 * wait)
        g = (await raw.access(addr("GSNAP_TIME")))[1]
        times = [(await raw.access(addr("SNAP_TIME", j)))[1] for j in range(n)]
        what = f"trial {i}: SNAP_CTRL.CMD of channel {k} (request {w:#x}), " + \
               ("a read of it, " if keep else "") + f"then GSNAP_CTRL.CMD: GSNAP_TIME {g:#x}"
        for j in range(n):
            if j != k or keep or not env.engine:
                assert times[j] == g, f"{what}, channel {j}'s SNAP_TIME {times[j]:#x}"
            else:
                assert g <= times[j] <= w + 2 * p + ENGINE_ACT, \
                    f"{what}, channel {j}'s own snapshot at {times[j]:#x}"
                late += times[j] > g
    dut._log.info("the global snapshot taken before the channel's own one in %d of %d trials "
                  "without a read between", late, trials)
    if env.engine:
        assert late > 0, "the global snapshot was never taken first: the RDL's warning is not real"


@cocotb_test()
async def count_hi_save_wait(dut):
    """COUNT_W > 32 with two channels or more: a COUNT_LO read of channel k after one of channel j
    stores j's COUNT_HI latch (the high word of j's count at that read) in the engine's memory;
    COUNT_HI of j reads that word afterwards. A read or write of j requested after the read of k
    (the next request) waits for the store: it is answered at most P + ENGINE_SAVE_WAIT clocks
    after that read's answer (P + ENGINE_SAVE_WAIT_REQ after its request when it did not wait), or
    in its own clocks when it comes later; when j had a write not yet stored, the read of k waits
    for it: answered at most P + ENGINE_SAVE_READ after that write's answer (the RDL). Each case at
    every phase of the visits, right after the read of k; a COUNT_LO read of j (which stores k's
    latch in turn) also after 0 .. P + 24 idle clocks at three phases, so that it comes as j's
    store ends. Each bound is met within 2 clocks at some phase."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    if not env.engine or env.count_w <= 32 or n < 2:
        dut._log.info("skipped: COUNT_W %d, %d channel(s)", env.count_w, n)
        return
    raw = WbRaw(dut)
    p = engine_period(n)
    worst = {"answer": 0, "request": 0, "k read": 0}
    runs = [(rel, c, 0) for rel in range(p)
            for c in ("read", "write", "count_lo", "j written", "j written, k state written")]
    runs += [(rel, "count_lo", d) for rel in rng.sample(range(p), 3) for d in range(1, p + 25)]
    for rel, case, idle in runs:
        j = rng.randrange(n)
        k = rng.choice([c for c in range(n) if c != j])
        hi = rng.getrandbits(32) & ((1 << (env.count_w - 32)) - 1)
        await raw.access(addr("COUNT_HI", j), hi)
        await raw.access(addr("COUNT_LO", j), rng.getrandbits(32))
        await ClockCycles(dut.clk, p + ENGINE_WAIT)
        await raw.access(addr("COUNT_LO", j))  # COUNT_HI's latch: j's
        await at_phase(dut, p, rel)
        if case.startswith("j written"):  # j has a write not stored yet: the read of k waits for it
            await raw.access(addr("PRESET_LO", j), rng.getrandbits(32))
            w_done = int(raw.tb.value)
        if case.endswith("k state written"):  # ... and k a state write, stored sooner than j's
            await raw.access(addr("IRQ_EN", k), 0)
        r, _, _ = await raw.access(addr("COUNT_LO", k))  # ... stored, the latch k's
        r_done = int(raw.tb.value)
        if case.startswith("j written"):
            assert r_done - w_done <= p + ENGINE_SAVE_READ, \
                f"channel {k}: a COUNT_LO read after a write of channel {j} (whose latch it stores) " \
                f"answered {r_done - w_done} clocks after that write's answer (bound P + {ENGINE_SAVE_READ})"
            worst["k read"] = max(worst["k read"], r_done - w_done - p)
        if idle:
            await ClockCycles(dut.clk, idle)
        if case == "write":
            a = (await raw.access(addr("IRQ_EN", j), 0))[0]
            own = ENGINE_ANSWER
        elif case == "count_lo":  # (itself a COUNT_LO read of another channel than k: it stores k's)
            a = (await raw.access(addr("COUNT_LO", j)))[0]
            own = ENGINE_READ_ANSWER + 1
        else:
            a = (await raw.access(addr("PRESET_LO", j)))[0]
            own = ENGINE_READ_ANSWER
        done = int(raw.tb.value)
        what = f"channel {j}: an access ({case}, {idle} idle clocks) after a COUNT_LO read of channel {k} answered"
        assert done - a <= own or done - r_done <= p + ENGINE_SAVE_WAIT, \
            f"{what} {done - r_done} clocks after that read's answer, {done - a} after its own " \
            f"request (bound P + {ENGINE_SAVE_WAIT}, or {own} after its own request; P {p})"
        if done - a > own:  # (it waited for the store)
            worst["answer"] = max(worst["answer"], done - r_done - p)
        if not case.startswith("j written") and not idle:
            assert done - r <= p + ENGINE_SAVE_WAIT_REQ, \
                f"{what} {done - r} clocks after that read's request (bound P + {ENGINE_SAVE_WAIT_REQ}, P {p})"
            worst["request"] = max(worst["request"], done - r - p)
        got = (await raw.access(addr("COUNT_HI", j)))[1]
        assert got == hi, f"channel {j}: COUNT_HI {got:#x} after its latch was stored, {hi:#x} written"
    dut._log.info("an access of channel j after a COUNT_LO read that stored j's latch: answered at "
                  "worst P + %d after that read's answer (bound P + %d), P + %d after its request "
                  "(bound P + %d); that read, after a write of j: P + %d after the write's answer "
                  "(bound P + %d); P %d", worst["answer"], ENGINE_SAVE_WAIT, worst["request"],
                  ENGINE_SAVE_WAIT_REQ, worst["k read"], ENGINE_SAVE_READ, p)
    for key, bound in (("answer", ENGINE_SAVE_WAIT), ("request", ENGINE_SAVE_WAIT_REQ),
                       ("k read", ENGINE_SAVE_READ)):
        assert worst[key] >= bound - 2, \
            f"the worst case ({key}) was P + {worst[key]}: the RDL's P + {bound} is loose"


@cocotb_test()
async def writes_once_in_order(dut):
    """Writes to one channel back to back, and reads right after them: each read gives what the
    writes before it wrote (PRESET_LO, IRQ_EN, INDEX_CTRL, a W1C of EVENTS); a SNAP_CTRL.CMD takes
    one snapshot: SNAP_TIME stays put afterwards, SNAP_READY once cleared does not come back."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    ready = event_bits("SNAP_READY")
    for i in range(6 * n if n < 16 else 24):
        k = rng.randrange(n)
        values = [rng.getrandbits(32) for _ in range(3)]
        for v in values:
            await raw.access(addr("PRESET_LO", k), v)
        await raw.access(addr("IRQ_EN", k), values[0] & 0x3FF)
        got = [(await raw.access(addr(r, k)))[1] for r in ("PRESET_LO", "IRQ_EN")]
        assert got == [values[-1], values[0] & 0x3FF], \
            f"channel {k}: PRESET_LO {values[-1]:#x}, then IRQ_EN {values[0] & 0x3FF:#x} written, read {got}"
        await raw.access(addr("IRQ_EN", k), 0)
        await raw.access(addr("SNAP_CTRL", k), pack("SNAP_CTRL", CMD=1))
        t1 = (await raw.access(addr("SNAP_TIME", k)))[1]
        ev = (await raw.access(addr("EVENTS", k)))[1]
        assert ev & ready, f"channel {k}: no SNAP_READY right after SNAP_CTRL.CMD and a read"
        await raw.access(addr("EVENTS", k), ready)
        assert not (await raw.access(addr("EVENTS", k)))[1] & ready, f"channel {k}: W1C read back"
        await ClockCycles(dut.clk, 3 * env.lag + 10)
        t2 = (await raw.access(addr("SNAP_TIME", k)))[1]
        ev = (await raw.access(addr("EVENTS", k)))[1]
        assert t2 == t1 and not ev & ready, \
            f"channel {k}: one SNAP_CTRL.CMD, SNAP_TIME {t1:#x} then {t2:#x}, EVENTS {ev:#x} after " \
            "SNAP_READY was cleared"


@cocotb_test()
async def clears_keep_later_events(dut):
    """EVENTS written 1 to clear QERR, then a quadrature error d clocks after the write's answer (d
    spread over one and a half engine periods): EVENTS has QERR afterwards. The same with
    QERR_COUNT cleared by a write: it counts the error after the write. (The per-channel build
    clears at once; an event after the clear is a new one.)"""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    pins = Pins(dut, n)
    p = engine_period(n) if env.engine else 12
    lost = []
    for reg in ("EVENTS", "QERR_COUNT"):
        for i in range(12):
            k = rng.randrange(n)
            pins.pos[k] += 2
            pins.apply()  # a quadrature error before the clear
            await ClockCycles(dut.clk, env.lag + 10)
            await raw.access(addr(reg, k), QERR if reg == "EVENTS" else 0)
            d = i * 3 * p // 24 + rng.randrange(3)
            await ClockCycles(dut.clk, d)
            pins.pos[k] += 2
            pins.apply()  # the one after it
            await ClockCycles(dut.clk, env.lag + 10)
            got = (await raw.access(addr(reg, k)))[1]
            if (reg == "EVENTS" and not got & QERR) or (reg == "QERR_COUNT" and got != 1):
                lost.append((reg, k, d, hex(got)))
    assert not lost, f"a quadrature error after a clear was lost (register, channel, clocks from " \
                     f"the write's answer, its value afterwards): {lost}"


# ---- isolation and reset ------------------------------------------------------------------------------


@cocotb_test()
async def isolation_in_motion(dut):
    """Half of the channels (at random) walk at the count-rate bound with index actions, the other
    half stand still and take random writes of every channel register (random values and byte
    lanes, commands included) and reads: every walking channel ends exact against its model
    (COUNT, EVENTS, INDEX_LATCH) with its configuration registers unchanged. (One channel: it
    walks alone.)"""
    env, rng, envs, models = await start_all(dut)
    n = len(envs)
    moving = sorted(rng.sample(range(n), max(1, n // 2)))
    still = [k for k in range(n) if k not in moving]
    cfg = ("CTRL", "PRESET_LO", "PRESET_HI", "INDEX_CTRL", "IRQ_EN", "SNAP_CTRL")
    before = {k: [await envs[k].bus.rd(r) for r in cfg] for k in moving}
    zf = index_pulses(rng, n)
    walker = ClockWalk(dut, [models[k] for k in moving], rng, positions=[envs[k].pos for k in moving],
                       shortest=1, longest=3, p_reverse=0.3, zfuns=[zf[k] for k in moving], bits=moving)
    task = cocotb.start_soon(walker.run(10 ** 9))
    ops = 0
    for _ in range(40 if still else 0):
        k = rng.choice(still)
        reg = rng.choice(TRAFFIC + ("read",))
        if reg == "read":
            await envs[k].bus.rd(rng.choice(CHAN_REGS))
        else:
            await envs[k].bus.wr(reg, rng.getrandbits(32), strb=rng.choice((1, 2, 4, 8, 3, 12, 15)))
        ops += 1
    if not still:
        await ClockCycles(dut.clk, 2000)
    task.cancel()
    await env.settle()
    for j, k in enumerate(moving):
        await check_final(envs[k], models[k], k, walker.pos[j])
        after = [await envs[k].bus.rd(r) for r in cfg]
        assert after == before[k], f"channel {k}: {cfg} {before[k]} became {after}"
    dut._log.info("channels %s walked exact through %d accesses to channels %s", moving, ops, still)


@cocotb_test()
async def reset_mid_motion(dut):
    """rst (1 to 3 clocks, at a random phase of the engine's visits) while every channel walks and
    a write waits for its channel: afterwards every channel register reads its reset value (but
    the count and the error counts, which the steps since the reset may have moved), and, with
    FILTER_LEN 1 again, every channel counts on exactly from the state it stands in, global
    snapshots included."""
    env, rng, envs, models = await start_all(dut)
    n = len(envs)
    for rep in range(2):
        walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=2,
                           p_reverse=0.3)
        task = cocotb.start_soon(walker.run(10 ** 9))
        await ClockCycles(dut.clk, rng.randint(50, 50 + 2 * env.lag))
        k = rng.randrange(n)
        await envs[k].bus.wr("PRESET_LO", 0x5A5A_5A5A)  # (waits for the channel's visit)
        await ClockCycles(dut.clk, rng.randrange(4))
        await pulse_rst(dut, rng.randint(1, 3))
        await ClockCycles(dut.clk, rng.randint(5, 60))
        task.cancel()
        for e, pos in zip(envs, walker.pos):
            e.pos = pos
        await env.settle(30)
        have = units(await env.bus.rd("CAPS"))
        for k, e in enumerate(envs):
            for reg in CHAN_REGS:
                r = regmap()[reg]
                if reg in ("STATUS", "EVENTS", "QERR_COUNT", "GLITCH_COUNT") or r.coherent:
                    continue
                mask = sum(built_mask(f, 32, 32, have) for f in r.fields.values() if f.reset is not None)
                exp = sum((f.reset or 0) << f.lsb for f in r.fields.values()) & mask
                got = await e.bus.rd(reg) & mask
                assert got == exp, f"reset {rep}, channel {k}: {reg} {got:#x}, reset value {exp:#x}"
        # counting on from where each channel stands (its count: the steps after rst)
        for e in envs:
            await e.bus.wr("CTRL", pack("CTRL", EN=1, FUNC="x4", FILTER_LEN=1))
        await env.settle()
        models = []
        for e in envs:
            m = QeiModel(e.count_w)
            m.reference(QUAD[e.pos % 4])
            m.count = await e.bus.count()
            models.append(m)
            await e.bus.events()
        await env.applied()
        walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=1,
                           p_reverse=0.3)
        task = cocotb.start_soon(walker.run(10 ** 9))
        await ClockCycles(dut.clk, rng.randint(100, 300))
        await global_snapshot(env, envs, walker, rng, None, f"after reset {rep}")
        task.cancel()
        await env.settle()
        for k, (e, m) in enumerate(zip(envs, models)):
            e.pos = walker.pos[k]
            await check_final(e, m, k, e.pos)


# ---- snapshots faster than the engine stores them -----------------------------------------------------
# The snapshot clock (the timebase SNAP_TIME / GSNAP_TIME take) on the per-channel build: a
# GSNAP_CTRL.CMD write's stamp + C_GSNAP, a snap_in pulse's stamp (the falling edge that raises it)
# + C_IN. The engine takes them there too, unless the capture before still waits for its visit.
C_GSNAP = 3
C_IN = 1


class Snapper:
    """Requests on the raw bus and snap_in, each channel's captures kept (its timebase) to check
    SNAP_DELTA with, and the checks of what the registers hold."""

    def __init__(self, env, envs, walker, raw):
        self.env, self.envs, self.walker, self.raw = env, envs, walker, raw
        self.dut = env.dut
        self.n = len(envs)
        self.p = engine_period(self.n) if env.engine else 0
        self.last = [None] * self.n  # each channel's last capture
        self.ts_mask = (1 << int(self.dut.TS_W.value)) - 1

    async def gsnap(self) -> int:
        w, _, _ = await self.raw.access(addr("GSNAP_CTRL"), pack("GSNAP_CTRL", CMD=1))
        return self.walker.unwrap(w) + C_GSNAP

    async def snap_in(self) -> int:
        await FallingEdge(self.dut.clk)
        self.dut.snap_in.value = 1
        r = self.walker.now()
        await FallingEdge(self.dut.clk)
        self.dut.snap_in.value = 0
        return r + C_IN

    def when(self, t: int, wanted: int, free: int | None, what: str) -> None:
        """A snapshot wanted at `wanted` was taken at t: there, or with the engine, later while a
        capture before waited (no later than `free`, when it no longer waits)."""
        if t == wanted:
            return
        assert self.env.engine and free is not None and wanted < t <= free, \
            f"{what}: taken at {t & self.ts_mask:#x}, wanted at {wanted & self.ts_mask:#x}" + \
            (f" (the capture before waits until {free & self.ts_mask:#x} at most)" if free else "")

    async def check(self, k: int, t: int, what: str) -> None:
        """Channel k holds its capture at t (SNAP_READY set, then cleared); it is its last."""
        ev = await self.envs[k].bus.rd("EVENTS")
        assert ev & event_bits("SNAP_READY"), f"{what}, channel {k}: no SNAP_READY"
        await check_snapshot(self.envs[k], self.walker.lines[k], t, self.last[k], f"{what}, channel {k}")
        await self.envs[k].bus.wr("EVENTS", event_bits("SNAP_READY"))
        self.last[k] = t

    async def quiet(self) -> None:
        await ClockCycles(self.dut.clk, self.env.lag + self.p + 10)


@cocotb_test()
async def snapshot_merge_defer(dut):
    """Every channel walking; pairs of snapshot requests d = 2 .. P clocks apart, faster than the
    engine stores them: two global ones; two of a channel's own (snap_in with SNAP_CTRL.IN_EN on
    some channels); a channel's own then a global one; a global then a channel's own. The first
    is taken at once; the second in its clock, or, with the engine, when the capture before no
    longer waits for its visit (a global: at most P after the first; a channel's own: at the
    channel's next visit, at most P after it is asked). GSNAP_TIME and SNAP_TIME tell the clock;
    every SNAP_* of every channel is that of its clock, SNAP_DELTA counting from the channel's
    capture before, and a channel without IN_EN takes no snap_in snapshot."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=2,
                       p_reverse=0.1)
    task = cocotb.start_soon(walker.run(10 ** 9))
    sn = Snapper(env, envs, walker, WbRaw(dut))
    p = max(sn.p, 8)
    counts = {}
    for trial in range(12):
        case = ("global, global", "own, own", "own, global", "global, own")[trial % 4]
        what = f"{case} (trial {trial})"
        own = sorted(rng.sample(range(n), rng.randint(1, n)))
        for k in range(n):
            await envs[k].bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=int(k in own)))
        await sn.quiet()
        d = rng.randint(2, p)
        first = await (sn.gsnap() if case.startswith("global") else sn.snap_in())
        await ClockCycles(dut.clk, d)
        second = await (sn.gsnap() if case.endswith("global") else sn.snap_in())
        await sn.quiet()
        g = walker.unwrap(await env.bus.rd("GSNAP_TIME"))
        if case == "global, global":
            sn.when(g, second, first + sn.p, what)
            for k in range(n):
                sn.last[k] = first
                await sn.check(k, g, what)
        elif case == "own, own":
            for k in own:
                t = walker.unwrap(await envs[k].bus.rd("SNAP_TIME"))
                sn.when(t, second, second + sn.p, f"{what}, channel {k}")
                sn.last[k] = first
                await sn.check(k, t, what)
            for k in set(range(n)) - set(own):
                t = walker.unwrap(await envs[k].bus.rd("SNAP_TIME"))
                assert t == sn.last[k] or sn.last[k] is None, \
                    f"{what}, channel {k} (IN_EN 0): a snap_in snapshot at {t & sn.ts_mask:#x}"
        elif case == "own, global":
            sn.when(g, second, first + sn.p, what)
            for k in range(n):
                if k in own:
                    sn.last[k] = first
                await sn.check(k, g, what)
        else:  # global, own
            assert g == first, f"{what}: GSNAP_TIME {g & sn.ts_mask:#x}, wanted {first & sn.ts_mask:#x}"
            for k in range(n):
                t = walker.unwrap(await envs[k].bus.rd("SNAP_TIME"))
                if k in own:
                    sn.when(t, second, second + sn.p, f"{what}, channel {k}")
                    sn.last[k] = first
                await sn.check(k, t if k in own else g, what)
        counts[case] = counts.get(case, 0) + 1
    task.cancel()
    dut._log.info("request pairs: %s", counts)


@cocotb_test()
async def stop_keeps_a_waiting_snapshot(dut):
    """The global unit timer at GSNAP_PERIOD 0 (a request every tick, faster than the engine
    stores the captures), stopped by a GSNAP_CTRL write at a random clock: on the per-channel
    build no snapshot comes after the write's snapshot clock; with the engine the request that
    waits then is still taken (the RDL text of CAPS.ENGINE shared, (3)), at most P clocks after
    that clock, and GSNAP_TIME holds still from P + 44 clocks after the write on."""
    env, rng, envs, _ = await start_all(dut, index=False)
    raw = WbRaw(dut)
    p = engine_period(len(envs)) if env.engine else 0
    late = 0
    for trial in range(8):
        await env.bus.wr("GSNAP_PERIOD", 0)
        await env.bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", PERIOD_EN=1))
        await ClockCycles(dut.clk, rng.randint(1, 3 * max(p, 8)))
        w, _, _ = await raw.access(addr("GSNAP_CTRL"), 0)
        stop = w + C_GSNAP  # the write's snapshot clock
        await ClockCycles(dut.clk, p + ENGINE_SHOW)
        g = await env.bus.rd("GSNAP_TIME")
        await ClockCycles(dut.clk, 2 * p + ENGINE_SHOW)
        assert await env.bus.rd("GSNAP_TIME") == g, \
            f"trial {trial}: GSNAP_TIME changed more than P + {ENGINE_SHOW} clocks after the stop"
        assert stop - max(p, 8) <= g <= stop + p, \
            f"trial {trial}: the last timer snapshot at {g:#x}, the stop's snapshot clock {stop:#x} (P {p})"
        late += g > stop
    if env.engine:
        assert late, "no snapshot after the stop: a waiting request was dropped"
    dut._log.info("snapshots after the stop (a request that waited): %d of 8", late)


@cocotb_test()
async def snap_in_clock(dut):
    """A rising snap_in takes its snapshot in the clock snap_in is first high (the RDL text of
    SNAP_CTRL.IN_EN and GSNAP_CTRL.IN_EN): with a channel's SNAP_CTRL.IN_EN its SNAP_TIME, with
    GSNAP_CTRL.IN_EN GSNAP_TIME and every channel's SNAP_TIME, with both one snapshot of that
    channel: all the timebase of that clock."""
    env, rng, envs, models = await start_all(dut, index=False)
    tb = dut.u_qei.timebase
    for trial in range(12):
        mode = ("own", "global", "both")[trial % 3]
        k = rng.randrange(len(envs))
        await envs[k].bus.wr("SNAP_CTRL", pack("SNAP_CTRL", IN_EN=int(mode != "global")))
        await env.bus.wr("GSNAP_CTRL", pack("GSNAP_CTRL", IN_EN=int(mode != "own")))
        await env.settle()
        await ClockCycles(dut.clk, rng.randrange(env.lag + 12))
        await FallingEdge(dut.clk)
        dut.snap_in.value = 1
        await RisingEdge(dut.clk)
        await ReadOnly()
        t = int(tb.value)  # the clock snap_in is first high
        await ClockCycles(dut.clk, rng.randint(1, 4))
        await FallingEdge(dut.clk)
        dut.snap_in.value = 0
        await env.settle()
        got = {"SNAP_TIME": await envs[k].bus.rd("SNAP_TIME")}
        if mode != "own":
            got["GSNAP_TIME"] = await env.bus.rd("GSNAP_TIME")
        assert set(got.values()) == {t}, \
            f"snap_in ({mode}, channel {k}) first high in the clock of timebase {t:#x}: {got}"
        await envs[k].bus.wr("SNAP_CTRL", 0)
    await env.bus.wr("GSNAP_CTRL", 0)


@cocotb_test()
async def snap_ready_means_values(dut):
    """A snapshot (GSNAP_CTRL.CMD, or a channel's SNAP_CTRL.CMD) at phases spread over the engine's
    visits, every channel walking; EVENTS of the channel read back to back until SNAP_READY, then
    at once SNAP_DELTA, SNAP_EDGE_DELTA, SNAP_TIME, SNAP_EDGE_TIME, SNAP_COUNT: the new snapshot's,
    every one (SNAP_READY rises only when SNAP_* hold it)."""
    env, rng, envs, models = await start_all(dut, index=False)
    n = len(envs)
    raw = WbRaw(dut)
    walker = ClockWalk(dut, models, rng, positions=[e.pos for e in envs], shortest=1, longest=2,
                       p_reverse=0.1)
    task = cocotb.start_soon(walker.run(10 ** 9))
    sn = Snapper(env, envs, walker, raw)
    p = max(sn.p, 12)
    visit = p // max(n, 2)
    ready = event_bits("SNAP_READY")
    ts_mask = sn.ts_mask
    trials = 24
    for i in range(trials):
        k = rng.randrange(n)
        await sn.quiet()
        await raw.access(addr("EVENTS", k), ready)
        await ClockCycles(dut.clk, env.lag + 10)
        await at_phase(dut, p, (i * p // trials + visit * k) % p)
        if i % 2:
            t0 = await sn.gsnap()
        else:
            w, _, _ = await raw.access(addr("SNAP_CTRL", k), pack("SNAP_CTRL", CMD=1))
            t0 = walker.unwrap(w)
        while not (await raw.access(addr("EVENTS", k)))[1] & ready:
            assert walker.now() - t0 < 3 * env.lag + 50, f"channel {k}: no SNAP_READY"
        regs = ("SNAP_DELTA", "SNAP_EDGE_DELTA", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_COUNT_LO")
        got = {r: (await raw.access(addr(r, k)))[1] for r in regs}
        t = walker.unwrap(got["SNAP_TIME"])
        what = f"trial {i}, channel {k}, {'GSNAP_CTRL' if i % 2 else 'SNAP_CTRL'}.CMD"
        assert t0 <= t <= t0 + sn.p + ENGINE_ACT, \
            f"{what}: SNAP_READY with SNAP_TIME {got['SNAP_TIME']:#x}, asked at {t0 & ts_mask:#x}"
        line = walker.lines[k]
        mark = line.at(t)
        assert got["SNAP_COUNT_LO"] == mark.count & 0xFFFFFFFF, f"{what}: SNAP_COUNT_LO {got['SNAP_COUNT_LO']:#x}"
        if sn.last[k] is not None:
            motion = mark.motion - line.at(sn.last[k]).motion
            assert signed(got["SNAP_DELTA"]) == motion, f"{what}: SNAP_DELTA {signed(got['SNAP_DELTA'])}, motion {motion}"
        e = line.edge(t, False)
        assert e is None or got["SNAP_EDGE_TIME"] == (e.t + line.EDGE_PIPE) & ts_mask, \
            f"{what}: SNAP_EDGE_TIME {got['SNAP_EDGE_TIME']:#x}"
        for j in range(n) if i % 2 else (k,):  # (a global snapshot: every channel's capture)
            sn.last[j] = t
    task.cancel()


# ---- pytest ---------------------------------------------------------------------------------------
def test_rdl_says_the_bounds():
    """The RDL text of CAPS.ENGINE's value shared gives the bounds these tests hold the RTL to
    (enctools.qei.env.ENGINE_*), in these words."""
    import re

    from enctools.qei import env
    from enctools.regmap import nodes

    caps = {r.inst_name: r for _, _, r in nodes()}["CAPS"]
    enc = next(f for f in caps.fields() if f.inst_name == "ENGINE").get_property("encode")
    text = " ".join(next(m for m in enc if m.name == "shared").rdl_desc.split())
    said = {
        "ENGINE_VISIT": r"P = (\d+) \* max\(CHANNELS, 2\)",
        "ENGINE_SHOW": r"request comes P \+ (\d+) clocks or more after",
        "ENGINE_SHOW_COUNT": r"\(COUNT_LO and COUNT_HI: P \+ (\d+) clocks\)",
        "ENGINE_IRQ": r"irq and IRQ_SUMMARY rise and fall at most P \+ (\d+) clocks",
        "ENGINE_ACT": r"acts at the channel's first read after it, at most P \+ (\d+) clocks",
        "ENGINE_STATE_ACT": r"COUNT_HI acts \(irq included\) at most P \+ (\d+) clocks",
        "ENGINE_WAIT": r"a read requested right after a write of its channel is answered at most P \+ (\d+) clocks",
        "ENGINE_STATE_WAIT": r"\(a state write: P \+ (\d+)\)",
        "ENGINE_PART_WAIT": r"and P \+ (\d+) after a COUNT_LO write with some but not all byte enables set",
        "ENGINE_NO_WAIT": r"one requested P \+ (\d+) clocks or more after the write's answer",
        "ENGINE_STATE_NO_WAIT": r"after the write's answer \(after a state write: P \+ (\d+)\) does not wait",
        "ENGINE_WRITE_WAIT": r"answered one clock sooner than such a read would be \(P \+ (\d+), P \+ \d+, P \+ \d+ after",
        "ENGINE_WRITE_STATE_WAIT": r"one clock sooner than such a read would be \(P \+ \d+, P \+ (\d+), P \+ \d+ after",
        "ENGINE_WRITE_PART_WAIT": r"one clock sooner than such a read would be \(P \+ \d+, P \+ \d+, P \+ (\d+) after",
        "ENGINE_SAVE_WAIT": r"answered at most P \+ (\d+) clocks after the COUNT_LO read's answer",
        "ENGINE_SAVE_WAIT_REQ": r"\(P \+ (\d+) after its request when it did not wait\)",
        "ENGINE_SAVE_READ": r"then it is answered at most P \+ (\d+) clocks after that write's answer",
        "ENGINE_ANSWER": r"a write of a channel register is answered (\d+) clocks after its request",
        "ENGINE_READ_ANSWER": r"a read (\d+) clocks after its request",
        "ENGINE_PART_ANSWER": r"a COUNT_LO write with some but not all byte enables set (\d+)",
        "PER_CHANNEL_ANSWER": r"a read \d+ clocks after its request \((\d+) in a per_channel build\)",
    }
    for name, pattern in said.items():
        m = re.search(pattern, text)
        assert m, f"CAPS.ENGINE shared: no {pattern!r} in its text"
        assert int(m.group(1)) == getattr(env, name), \
            f"CAPS.ENGINE shared says {m.group(0)!r}, enctools.qei.env.{name} = {getattr(env, name)}"


# what each register's own RDL text must state for the shared engine (the contract: "the RDL text
# of that register gives the bound in clocks as a formula in CHANNELS"): P + the env constant
SHOWN_REGS = ("STATUS", "INDEX_LATCH_LO", "INDEX_LATCH_HI", "PROBE_LATCH_LO", "PROBE_LATCH_HI",
         "PROBE_TIME", "EVENTS", "QERR_COUNT", "GLITCH_COUNT", "SNAP_COUNT_LO", "SNAP_COUNT_HI",
         "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA", "SNAP_EDGE_DELTA", "PERIOD", "IRQ_SUMMARY")
ACTING_REGS = ("CTRL", "COUNT_LO", "PRESET_LO", "PRESET_HI", "CEILING_LO", "CEILING_HI", "COMPARE_LO",
          "COMPARE_HI", "INDEX_CTRL", "PROBE_CTRL", "SNAP_CTRL", "SNAP_PERIOD", "PERIOD_CTRL",
          "STALL_TIMEOUT")
STATE_ACTING_REGS = ("EVENTS", "IRQ_EN", "QERR_COUNT", "GLITCH_COUNT", "COUNT_HI")


def test_registers_state_their_bounds():
    """Every register whose value the engine shows later, or whose write acts later, states that
    bound in its own RDL text as 24 * max(CHANNELS, 2) + N with the N of CAPS.ENGINE's text (shown
    P + 44, COUNT P + 24, acting P + 18, state writes P + 26); no text gives another number."""
    import re

    from enctools.qei import env
    from enctools.regmap import nodes

    said: dict[str, set[int]] = {}
    for _, _, r in nodes():
        text = " ".join([r.get_property("desc") or ""] +
                        [f.get_property("desc") or "" for f in r.fields()])
        for m in re.finditer(rf"{env.ENGINE_VISIT} \* max\(CHANNELS, 2\) \+ (\d+)", " ".join(text.split())):
            said.setdefault(r.inst_name, set()).add(int(m.group(1)))
    want = {r: {env.ENGINE_SHOW} for r in SHOWN_REGS}
    want["COUNT_LO"] = {env.ENGINE_SHOW_COUNT}
    for r in ACTING_REGS:
        want.setdefault(r, set()).add(env.ENGINE_ACT)
    for r in STATE_ACTING_REGS:
        want.setdefault(r, set()).add(env.ENGINE_STATE_ACT)
    for r, bounds in want.items():
        missing = bounds - said.get(r, set())
        assert not missing, f"{r}: its RDL text does not state P + {sorted(missing)}"
    known = {env.ENGINE_SHOW, env.ENGINE_SHOW_COUNT, env.ENGINE_ACT, env.ENGINE_STATE_ACT,
             env.ENGINE_WAIT, env.ENGINE_STATE_WAIT, env.ENGINE_IRQ, env.ENGINE_SAVE_WAIT}
    for r, bounds in said.items():
        assert bounds <= known, f"{r}: its RDL text states P + {sorted(bounds - known)}, a bound " \
                                f"CAPS.ENGINE's text does not give"


@pytest.mark.parametrize("top,channels,engine,count_w", ENGINE_CONFIGS,
                         ids=[f"{t}-ch{c}" + ("" if w == 32 else f"-c{w}") + ("-engine" if e else "")
                              for t, c, e, w in ENGINE_CONFIGS])
def test_engine(top, channels, engine, count_w):
    from enctools.harness import run

    # (16 channels on Verilator whatever SIM says: Icarus takes about 30 times longer)
    run(top, __name__, name=f"{build_name(top, count_w, 32, 'lean', engine)}_ch{channels}",
        parameters={"COUNT_W": count_w, "TS_W": 32, "CHANNELS": channels, "PROFILE": PROFILES["lean"],
                    "ENGINE": engine}, sim="verilator" if channels > 3 else None)
