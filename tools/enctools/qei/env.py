# SPDX-License-Identifier: Apache-2.0
"""The enc_qei test environment shared by the feature files of tb/enc_qei/.

- ``CONFIGS`` / ``CONFIG_IDS``: the builds every feature file runs on (enc_qei_wb at COUNT_W 32 /
  TS_W 32, enc_qei_axil at COUNT_W 64 / TS_W 16, each with a datapath per channel and with the
  shared engine), and ``run_feature()``, the pytest side of a feature file: one build name per
  configuration, so that every feature file shares its build. ``lacks()`` tells a test file
  which units (enctools.regmap.units) the build it runs on leaves out, to skip their tests.
- ``Env`` (``begin(dut)`` makes one): the bus, the quadrature driver and the stimulus position;
  ``setup`` programs the peripheral and the model alike, ``play`` drives a waveform into both,
  ``check`` compares COUNT and EVENTS with the model.
- ``ClockTrace`` and ``read_snapshot``: what the design did in each clock, and the snapshot
  registers, for the snapshot tests.

Stimulus helpers (waveforms, clock-exact steps, resets) are in enctools.qei.stimulus.
"""

from __future__ import annotations

import cocotb
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge
from cocotbext.quadrature import QuadratureDriver, SharedVector
from hedsmodel import QUAD

from enctools.qei.bus import PERIOD_PS, QeiBus
from enctools.qei.model import QeiModel
from enctools.qei.stimulus import FILTER
from enctools.regmap import enum, pack, units
from enctools.tb import start

PROFILES = enum("CAPS", "PROFILE")  # name -> CAPS.PROFILE / the PROFILE parameter
PROFILE_LEAN = PROFILES["lean"]


# The shared engine's bounds (ENGINE = 1), as the RDL text of CAPS.ENGINE's value shared gives them
# (tb/enc_qei/test_engine.py holds the RTL to them and checks that the text says these numbers):
# clocks after the per-channel build shows a value, or after a write's request, with P below.
ENGINE_VISIT = 24       # clocks the engine spends on one channel
ENGINE_SHOW = 44        # a read requested P + 44 clocks after the per-channel build shows a value shows it
ENGINE_SHOW_COUNT = 24  # ... COUNT_LO / COUNT_HI: P + 24
ENGINE_IRQ = 44         # irq and IRQ_SUMMARY rise and fall at most P + 44 later
ENGINE_ACT = 18         # a write of a register the counting uses acts at most P + 18 after its request
ENGINE_STATE_ACT = 26   # a write of EVENTS, QERR_COUNT, GLITCH_COUNT, IRQ_EN or COUNT_HI: P + 26
ENGINE_WAIT = 66        # a read right after a write of its channel is answered at most P + 66 after the write's request
ENGINE_PART_WAIT = 68   # ... after a COUNT_LO write with some but not all byte enables: P + 68
ENGINE_SAVE_WAIT = 23   # COUNT_W > 32: an access of channel j right after a COUNT_LO read of another channel that stored j's COUNT_HI latch: P + 23 after that read's answer
ENGINE_SAVE_WAIT_REQ = 29  # ... P + 29 after its request, when it did not wait
ENGINE_SAVE_READ = 63   # ... that read, when j had a write not stored yet: P + 63 after that write's answer
ENGINE_STATE_WAIT = 30  # ... after a state write (EVENTS, QERR_COUNT, GLITCH_COUNT, IRQ_EN, COUNT_HI): P + 30
ENGINE_WRITE_WAIT = 65  # a write right after a write of its channel: one clock sooner than a read, P + 65 after the first's request
ENGINE_WRITE_STATE_WAIT = 29  # ... after a state write: P + 29
ENGINE_WRITE_PART_WAIT = 67   # ... after a COUNT_LO write with some but not all byte enables: P + 67 (the second such a write itself: one clock more)
ENGINE_NO_WAIT = 57     # an access requested P + 57 or more after a write's answer does not wait for it
ENGINE_STATE_NO_WAIT = 21  # ... after a state write's answer: P + 21
ENGINE_ANSWER = 4       # otherwise a channel register write is answered 4 clocks after its request
ENGINE_READ_ANSWER = 5  # ... a read 5
ENGINE_PART_ANSWER = 6  # ... a COUNT_LO write with some but not all byte enables 6
PER_CHANNEL_ANSWER = 2  # ... 2 on a per-channel build (reads and writes)


def engine_period(channels: int) -> int:
    """P: the clocks between two reads of a channel by the shared engine (one visit per channel,
    at least two channels: one idle with one channel)."""
    return ENGINE_VISIT * max(channels, 2)


class Timebase:
    """The design's timebase (``u_qei.timebase``, TS_W bits) counted on without wrapping, and the
    wait for one phase of the shared engine's visits (they and the timebase both start at rst,
    the timebase advancing every clock). A build without the timing unit (CAPS.TIMING 0) has no
    timebase: a test that uses this skips there (lacks("TIMING"))."""

    def __init__(self, dut):
        self.dut = dut
        self.sig = dut.u_qei.timebase
        self.mask = (1 << int(dut.TS_W.value)) - 1
        self.raw = int(self.sig.value)
        self.total = self.raw

    def now(self) -> int:
        """The timebase now, unwrapped (call it at least once per 2^TS_W clocks)."""
        raw = int(self.sig.value)
        self.total += (raw - self.raw) & self.mask
        self.raw = raw
        return self.total

    async def phase(self, p: int, r: int) -> None:
        """Wait for the falling clock edge at which now() mod p is r."""
        while True:
            await FallingEdge(self.dut.clk)
            if self.now() % p == r:
                return


def caps_of(dut) -> int:
    """The CAPS word the RDL gives the build being simulated, from its parameters alone: INDEX 1;
    PROBE with the counting and full profiles, TIMING with full and lean (the profile enum's
    descriptions); the widths, CHANNELS, EFIFO_LOG2 and ENGINE as built. Written out here, not
    taken from enctools.regmap.units, which reads the units from a CAPS word."""
    profile = {v: k for k, v in PROFILES.items()}[int(dut.PROFILE.value)]
    return pack("CAPS", COUNT_W=int(dut.COUNT_W.value), TS_W=int(dut.TS_W.value), INDEX=1,
                PROBE=int(profile in ("counting", "full")), TIMING=int(profile in ("full", "lean")),
                PROFILE=profile, CHANNELS=int(dut.CHANNELS.value),
                EFIFO_LOG2=int(dut.EFIFO_LOG2.value) if hasattr(dut, "EFIFO_LOG2") else 0,
                ENGINE="shared" if int(dut.ENGINE.value) else "per_channel")


def engine_lag(channels: int) -> int:
    """The clocks a test waits for the shared engine to show what happened before (a step in
    COUNT, an event in EVENTS, a snapshot in SNAP_*, a write acting): more than every bound
    above."""
    return engine_period(channels) + 52


# ---- configurations and the pytest side -----------------------------------------------------------
# (top, COUNT_W, TS_W, PROFILE, ENGINE): one channel each; the shared engine's on Verilator whatever
# SIM says (Icarus takes about 5 times longer; tb/enc_qei/test_engine.py and test_channels.py run
# the engine on Icarus too)
CONFIGS = (("enc_qei_wb", 32, 32, "full", 0), ("enc_qei_axil", 64, 16, "full", 0),
           ("enc_qei_wb", 32, 32, "full", 1), ("enc_qei_axil", 64, 16, "full", 1),
           ("enc_qei_wb", 32, 32, "lean", 1),
           # a count narrower than a register (COUNT_W 16): both architectures
           ("enc_qei_wb", 16, 32, "full", 0), ("enc_qei_wb", 16, 32, "full", 1),
           # the narrowest count (COUNT_W 8: the engine's lane holds all of it)
           ("enc_qei_wb", 8, 32, "full", 0), ("enc_qei_wb", 8, 32, "full", 1),
           # the counting profile (no timing unit: CAPS.TIMING 0): both architectures
           ("enc_qei_wb", 32, 32, "counting", 0), ("enc_qei_wb", 32, 32, "counting", 1))


def config_id(top: str, count_w: int, ts_w: int, profile: str = "full", engine: int = 0) -> str:
    return f"{top}-c{count_w}-t{ts_w}" + ("" if profile == "full" else f"-{profile}") + \
        ("-engine" if engine else "")


CONFIG_IDS = tuple(config_id(*c) for c in CONFIGS)


def build_name(top: str, count_w: int, ts_w: int, profile: str = "full", engine: int = 0) -> str:
    """The one build name of a configuration: every feature file runs on the same build."""
    return f"{top}_c{count_w}_t{ts_w}" + ("" if profile == "full" else f"_{profile}") + \
        (f"_e{engine}" if engine else "")


def run_feature(module: str, top: str, count_w: int, ts_w: int, profile: str = "full",
                engine: int = 0):
    """Run the cocotb tests of feature file ``module`` (its ``__name__``) on one configuration."""
    from enctools.harness import run  # (here: the simulator's Python, importing env, needs no harness)

    return run(top, module, name=build_name(top, count_w, ts_w, profile, engine),
               parameters={"COUNT_W": count_w, "TS_W": ts_w, "PROFILE": PROFILES[profile],
                           "ENGINE": engine}, sim="verilator" if engine else None)


def engine_build() -> bool:
    """True when the build being simulated has the shared engine (ENGINE = 1), whose channel
    values are in its memory, not in per-channel registers a test could watch. False outside a
    simulation."""
    top = getattr(cocotb, "top", None)
    return top is not None and int(top.ENGINE.value) != 0


def build_param(name: str, default: int) -> int:
    """The parameter ``name`` of the build being simulated (COUNT_W, TS_W, ...), for a test's skip
    option; ``default`` outside a simulation (pytest collecting)."""
    top = getattr(cocotb, "top", None)
    return default if top is None else int(getattr(top, name).value)


def lacks(*names: str) -> bool:
    """True when the build being simulated leaves out one of the units ``names`` (the RDL's
    feature names, enctools.regmap.units: RANGE = range modes, CEILING and compare; PROBE;
    PERIOD = period capture, stall and the channel's own unit timer), for a test's skip option:
    ``@cocotb_test(skip=lacks("RANGE"))``. False outside a simulation (pytest collecting)."""
    top = getattr(cocotb, "top", None)
    if top is None:
        return False
    profile = int(top.PROFILE.value)
    have = units(pack("CAPS", PROFILE=profile, TIMING=int(profile != PROFILES["counting"])))
    return not set(names) <= have


# ---- the environment -------------------------------------------------------------------------------
class Env:
    """One channel's environment: ``bus`` and ``drv`` default to channel 0's (see
    channel_envs() for every channel of a multi-channel build)."""

    def __init__(self, dut, rng, bus: QeiBus | None = None, drv: QuadratureDriver | None = None):
        self.dut, self.rng = dut, rng
        self.bus = bus or QeiBus(dut, rng)
        self.count_w = int(dut.COUNT_W.value)
        self.drv = drv or QuadratureDriver(dut.a_in, dut.b_in, dut.z_in, clock_period_ps=PERIOD_PS)
        self.pos = 0  # 4X position of the stimulus now
        # the lean profile has no compare unit (and no range modes: its count is free-running)
        self.lean = int(dut.PROFILE.value) == PROFILE_LEAN
        # the shared engine shows a step in COUNT (and EVENTS, STATUS) up to `lag` clocks later
        self.engine = int(dut.ENGINE.value) if hasattr(dut, "ENGINE") else 0
        self.lag = engine_lag(int(dut.CHANNELS.value)) if self.engine else 0

    async def settle(self, clocks: int = 12):
        """Wait `clocks`, and with the shared engine also its latency (so that COUNT, EVENTS and
        STATUS show what happened before)."""
        await ClockCycles(self.dut.clk, clocks + self.lag)

    async def applied(self):
        """Wait until the bus writes before have taken effect: the shared engine applies a write
        at the channel's next visit, within `lag` clocks (a W1C of EVENTS or a write clearing
        QERR_COUNT / GLITCH_COUNT clears what the channel raised up to then); the per-channel
        build at once."""
        if self.lag:
            await ClockCycles(self.dut.clk, self.lag)

    async def setup(self, model: QeiModel, func="x4", rng_mode="free", filter_len=FILTER,
                    count=0, ceiling=None, compare=None, en=1):
        bus = self.bus
        model.range = rng_mode
        model.ceiling = model.max if ceiling is None else ceiling
        # compare=None: CTRL.CMP_EN = 0 (compare off); a value: CMP_EN = 1
        model.compare = compare
        if self.lean:  # (CEILING, COMPARE and CMP_EN are still written: they must have no effect)
            model.compare = None
        model.en = bool(en)
        await bus.set64("CEILING", model.ceiling)
        await bus.set64("COMPARE", compare or 0)
        ctrl = pack("CTRL", EN=en, FUNC=func, RANGE=rng_mode, FILTER_LEN=filter_len,
                    CMP_EN=int(compare is not None))
        await bus.wr("CTRL", ctrl)
        model.set_func(func, QUAD[self.pos % 4])
        await bus.set_count(count)
        model.write_count(count)
        # (the shared engine: the load acts within P + 14 of the write's answer, and an event it
        # raises, CMP, shows within P + 44 after that; then the events are cleared)
        await self.applied()
        await self.settle()
        await bus.events()
        await bus.wr("QERR_COUNT", 0)
        await bus.wr("GLITCH_COUNT", 0)
        await self.applied()
        model.take_events()
        model.qerrs = 0

    async def play(self, wf, model: QeiModel | None, zfun=None):
        """Play wf from the present position; feed every event to the model."""
        index = None
        if zfun is not None:
            index = [(t, zfun(p)) for (t, _, _), p in zip(wf.events, wf.positions)]
        await self.drv.play(wf, index=index)
        if model is not None:
            # every event, the first included: it holds the present A/B (no step) but sets Z to
            # zfun of the start position, which the driver plays too (an index edge there)
            for (_, a, b), p in zip(wf.events, wf.positions):
                model.sample((a, b), zfun(p) if zfun else 0)
        self.pos = wf.positions[-1]
        await self.settle()

    async def check(self, model: QeiModel, what: str, events=True):
        got = await self.bus.count()
        assert got == model.count, f"{what}: COUNT {got:#x}, model {model.count:#x}"
        if events:
            ev = await self.bus.events()
            exp = model.take_events()
            assert ev == exp, f"{what}: EVENTS {sorted(ev)}, model {sorted(exp)}"


def channel_envs(dut, rng, channels: int) -> list[Env]:
    """One Env per channel: its register page (QeiBus.at) and its own bits of the vector inputs
    a_in / b_in / z_in (cocotbext.quadrature.SharedVector), so that every channel can play its
    own waveform at the same time."""
    bus = QeiBus(dut, rng)
    a, b, z = SharedVector(dut.a_in), SharedVector(dut.b_in), SharedVector(dut.z_in)
    return [Env(dut, rng, bus=bus.at(k),
                drv=QuadratureDriver(a.bit(k), b.bit(k), z.bit(k), clock_period_ps=PERIOD_PS))
            for k in range(channels)]


async def begin(dut):
    rng = await start(dut, PERIOD_PS, inputs={"a_in": 0, "b_in": 0, "z_in": 0, "probe_in": 0,
                                               "snap_in": 0})
    env = Env(dut, rng)
    await env.settle(30)
    return env, rng


def channel(dut, k: int = 0):
    """Channel k's enc_qei_channel instance inside the bus adapter (its core is ``.u_core``, its
    timing unit ``.g_timing.u_timing``) of a build with a datapath per channel (ENGINE = 0; in
    enc_qei's generate block g_per_channel, or without it where a tool rewrote the design)."""
    qei = dut.u_qei
    return (qei.g_per_channel if hasattr(qei, "g_per_channel") else qei).g_ch[k].u_chan


# ---- clock trace and snapshots ---------------------------------------------------------------------
class ClockTrace:
    """Per clock (sampled after each rising edge): the count, the timebase and the decoder's edge
    pulses of the core, read from the design's registers. It says what happened in each clock, so
    a snapshot's values can be checked to come from one and the same clock."""

    def __init__(self, dut):
        chan = channel(dut)
        core, timing = chan.u_core, chan.g_timing.u_timing
        self.sig = (core.count_q, timing.timebase, core.edge_any, core.edge_a_rise)
        self.count, self.tb, self.any, self.arise = [], [], [], []
        self.task = cocotb.start_soon(self._run(dut))

    async def _run(self, dut):
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            c, t, e, r = (int(x.value) for x in self.sig)
            self.count.append(c)
            self.tb.append(t)
            self.any.append(e)
            self.arise.append(r)

    def clock_of(self, tb_value: int, after: int = 0) -> int:
        """The clock index whose timebase is tb_value (prescaler 0: one clock per value)."""
        for i in range(after, len(self.tb)):
            if self.tb[i] == tb_value:
                return i
        raise AssertionError(f"no clock with timebase {tb_value}")

    def last_edge_time(self, i: int, a_rising: bool) -> int | None:
        """Timestamp of the last edge a snapshot in clock i includes: an edge of clock j <= i - 1,
        stamped with the timebase of clock j + 1 (the timing unit sees the core a clock late)."""
        edges = self.arise if a_rising else self.any
        for j in range(i - 1, -1, -1):
            if edges[j]:
                return self.tb[j + 1]
        return None


async def read_snapshot(bus):
    return {n: await bus.rd(r) for n, r in (
        ("count", "SNAP_COUNT_LO"), ("count_hi", "SNAP_COUNT_HI"), ("time", "SNAP_TIME"),
        ("edge_time", "SNAP_EDGE_TIME"), ("delta", "SNAP_DELTA"), ("edge_delta", "SNAP_EDGE_DELTA"))}
