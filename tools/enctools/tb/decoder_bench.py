# SPDX-License-Identifier: Apache-2.0
"""cocotb tests shared by the synchronous decoders, against their Python models, clock by clock:
enc_x4_decoder (look-up-table 4X), enc_x2_xor (Figure 15), enc_x1_hysteresis (Figure 14).

Stimulus is a sequence of (a, b) samples, one per clock, as enc_conditioner delivers them. Every
test compares every output on every clock with the model in tb/common/models.py; the 1X tests also check
the contract's hysteresis bound |4n - p| <= 4 directly, which is what the naive counter fails.
"""

import random

import cocotb
from cocotb.triggers import FallingEdge

from enctools.tb import cocotb_test

from enctools import tb as tbutil
from enctools.tb.models import X1Model, X2Model, X4Model
from hedsmodel.waveform import state_of

MODELS = {"enc_x4_decoder": X4Model, "enc_x2_xor": X2Model, "enc_x1_hysteresis": X1Model}


class Samples:
    """A clock-by-clock stimulus: (a, b) per clock, the true 4X position, and reset clocks."""

    def __init__(self, start_pos: int = 0):
        self.ab: list[tuple[int, int]] = []
        self.pos: list[int] = []
        self.rst: set[int] = set()
        self.p = start_pos

    def hold(self, clocks: int) -> None:
        for _ in range(clocks):
            self.ab.append(state_of(self.p))
            self.pos.append(self.p)

    def move(self, step: int, clocks: int) -> None:
        """Change position by `step` (+-1 valid, +-2 illegal: both channels flip) and hold."""
        self.p += step
        self.hold(clocks)

    def reset(self) -> None:
        """Assert rst during the next clock (inputs held)."""
        self.rst.add(len(self.ab))
        self.hold(1)


def random_walk(rng, n, start_pos=0, max_clocks=3, p_reverse=0.3, p_illegal=0.0, p_reset=0.0):
    s = Samples(start_pos)
    s.hold(2)
    direction = 1
    for _ in range(n):
        if rng.random() < p_reverse:
            direction = -direction
        if rng.random() < p_reset:
            s.reset()
        step = 2 * direction if rng.random() < p_illegal else direction
        s.move(step, rng.randint(1, max_clocks))
    return s


async def start(dut):
    await tbutil.start(dut, 10_000, {"a": 0, "b": 0})


async def play_samples(dut, s: Samples, model=None, bound=None, count_from: int = 0):
    """Drive `s` and compare with `model` every clock. With `bound`, also check the 1X hysteresis
    invariant |4n - p| <= bound, n counted from the DUT's pulses and p from the stimulus since the
    last reset. Returns (#up pulses, #down pulses) seen (for 1X) or counts (x4/x2), from clock
    `count_from` of `s` on."""
    names = model.outputs if model else ("up_pulse", "dn_pulse")
    handles = [getattr(dut, nm) for nm in names]
    ups = dns = 0
    p0 = s.pos[0]
    n = 0
    for i, (a, b) in enumerate(s.ab):
        in_reset = i in s.rst
        dut.a.value = a
        dut.b.value = b
        dut.rst.value = int(in_reset)
        await FallingEdge(dut.clk)
        got = {nm: int(h.value) for nm, h in zip(names, handles)}
        if model is not None:
            if in_reset:
                model.reset()
                exp = {nm: 0 for nm in names}
            else:
                exp = model.step(a, b)
            if exp.get("cnt_pulse") == 0:  # `up` is the direction of a count: only then defined
                got.pop("up")
                exp = {k: v for k, v in exp.items() if k != "up"}
            assert got == exp, f"clock {i}: pos {s.pos[i]} ab={a}{b}: got {got}, expected {exp}"
        if in_reset:
            p0, n = s.pos[i], 0
            continue
        counted = i >= count_from
        if "up_pulse" in got:
            n += got["up_pulse"] - got["dn_pulse"]
            ups += counted and got["up_pulse"]
            dns += counted and got["dn_pulse"]
        else:
            c = got["cnt_pulse"]
            ups += counted and c and got["up"]
            dns += counted and c and not got["up"]
        if bound is not None:
            p = s.pos[i] - p0
            assert abs(4 * n - p) <= bound, f"clock {i}: net count {n} vs 4X position {p}: |4n-p| > {bound}"
    dut.rst.value = 0
    return ups, dns


def model_for(dut):
    return MODELS[dut._name]()


@cocotb_test()
async def random_walk_20k(dut):
    """20,000 transitions, 1-3 clocks per state, reversals, ~1% illegal jumps: exact per clock."""
    await start(dut)
    rng = random.Random(cocotb.RANDOM_SEED)
    await play_samples(dut, random_walk(rng, 20000, p_illegal=0.01), model_for(dut))


@cocotb_test()
async def reset_mid_motion(dut):
    """Random walk with rst asserted at random clocks while the shaft moves."""
    await start(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 1)
    await play_samples(dut, random_walk(rng, 4000, start_pos=rng.randrange(4), p_reset=0.01),
                       model_for(dut))


@cocotb_test()
async def reversal_at_every_state(dut):
    """From each reset state, run k = 0..7 steps in each direction, then reverse for 9."""
    await start(dut)
    model = model_for(dut)
    for start_pos in range(4):
        for direction in (1, -1):
            for k in range(8):
                s = Samples(start_pos)
                s.reset()
                s.hold(1)
                for _ in range(k):
                    s.move(direction, 2)
                for _ in range(9):
                    s.move(-direction, 1)
                await play_samples(dut, s, model, bound=4 if "x1" in dut._name else None)


@cocotb_test()
async def dither_every_transition(dut):
    """Approach each of the four transitions from both sides, then dither across it 40 times."""
    await start(dut)
    model = model_for(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 2)
    for start_pos in range(4):
        for t in range(4):
            for approach in (1, -1):
                s = Samples(start_pos)
                s.reset()
                s.hold(1)
                # walk to one side of transition t <-> t+1 (relative to the reset state)
                target = t if approach > 0 else t + 1 - 4
                while s.p - start_pos != target:
                    s.move(approach, 1)
                side = 1 if approach > 0 else -1
                for _ in range(40):
                    s.move(side, rng.randint(1, 3))
                    side = -side
                await play_samples(dut, s, model, bound=4 if "x1" in dut._name else None)


@cocotb_test()
async def monotone_runs(dut):
    """From reset at every state, 4m transitions in one direction give exactly 4m (x4), 2m (x2) or
    m (x1) counts in that direction and none in the other."""
    await start(dut)
    per_cycle = {"enc_x4_decoder": 4, "enc_x2_xor": 2, "enc_x1_hysteresis": 1}[dut._name]
    model = model_for(dut)
    for start_pos in range(4):
        for direction in (1, -1):
            for m in (1, 2, 5):
                s = Samples(start_pos)
                s.reset()
                s.hold(1)
                for _ in range(4 * m):
                    s.move(direction, 1)
                s.hold(2)
                ups, dns = await play_samples(dut, s, model)
                want = per_cycle * m
                got = (ups, dns) if direction > 0 else (dns, ups)
                assert got == (want, 0), (f"start {start_pos} dir {direction} m={m}: "
                                          f"{got[0]} counts forward-in-direction, {got[1]} against; want {want}, 0")


@cocotb_test()
async def x1_hysteresis_bound(dut):
    """The contract's latched-hysteresis property, checked on the outputs alone (no model): dither
    about every transition and random walks never let |4n - p| exceed 4 (the contract's bound)."""
    await start(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 3)
    for start_pos in range(4):
        for t in range(4):
            s = Samples(start_pos)
            s.reset()
            s.hold(1)
            while s.p - start_pos != t:
                s.move(1, 1)
            dither = len(s.ab)
            side = 1
            for _ in range(30):  # 30 crossings of the same edge
                s.move(side, rng.randint(1, 3))
                side = -side
            # the bound on every clock, and at most one pulse in total in the dither (X1.2),
            # counted on the outputs from its first crossing
            ups, dns = await play_samples(dut, s, bound=4, count_from=dither)
            assert ups + dns <= 1, f"start {start_pos}, transition {t}: {ups} up and {dns} down " \
                "pulses in 30 crossings of one transition"
    await play_samples(dut, random_walk(rng, 3000), bound=4)


@cocotb_test()
async def x1_runs_after_any_history(dut):
    """A monotone run of 4m valid transitions gives m or m - 1 pulses in its direction and none in
    the other, after any history (X1.5, counted on the run's own outputs, against the model too);
    continuing a monotone run from reset in the same direction, exactly m. From every state, both
    directions, m = 1, 2, 3, after random walks of 0 .. 12 transitions with reversals and after
    monotone runs of 1 .. 9 transitions."""
    await start(dut)
    model = model_for(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 5)
    for start_pos in range(4):
        for direction in (1, -1):
            for trial in range(12):
                continuing = trial % 3 == 0
                s = Samples(start_pos)
                s.reset()
                s.hold(1)
                if continuing:
                    for _ in range(rng.randint(1, 9)):
                        s.move(direction, rng.randint(1, 2))
                else:
                    step = rng.choice((1, -1))
                    for _ in range(rng.randint(0, 12)):
                        step = -step if rng.random() < 0.4 else step
                        s.move(step, rng.randint(1, 2))
                await play_samples(dut, s, model)
                m = rng.randint(1, 3)
                run = Samples(s.p)
                for _ in range(4 * m):
                    run.move(direction, rng.randint(1, 2))
                run.hold(2)
                ups, dns = await play_samples(dut, run, model)
                along, against = (ups, dns) if direction > 0 else (dns, ups)
                want = {m} if continuing else {m - 1, m}
                what = "continuing" if continuing else "after a walk"
                assert along in want and against == 0, \
                    f"start {start_pos} dir {direction} trial {trial} ({what}): a run of {4 * m} " \
                    f"gave {along} pulses along and {against} against; want {sorted(want)}, 0"


@cocotb_test()
async def reset_then_illegal_jump(dut):
    """A one-clock reset followed at once, on the first clock after it, by a jump of either channel
    or of both (the illegal two-channel change): that first sample is only the new reference, so
    no count and no error pulse; then a short run is counted from it. From every state, for
    every step, and with the decoder's internal state before the reset varied (a run of k steps
    in either direction: a latched hysteresis state, a pending count). Deterministic: it catches
    an `error` (or count) that ignores the reference flag on every seed."""
    await start(dut)
    model = model_for(dut)
    for start_pos in range(4):
        for before in (0, 3, -3, 6):
            for jump in (2, -2, 1, -1):
                s = Samples(start_pos)
                s.reset()
                s.hold(1)
                for _ in range(abs(before)):
                    s.move(1 if before > 0 else -1, 1)
                s.reset()  # rst during one clock, inputs held
                s.move(jump, 1)  # the first sample after the reset differs in one or both channels
                s.hold(1)
                for _ in range(5):
                    s.move(1 if jump > 0 else -1, 1)
                s.hold(2)
                # no |4n - p| bound here: the jump's two steps are before the reference
                await play_samples(dut, s, model)


# cocotb tests every decoder runs (enc_x1_hysteresis adds x1_hysteresis_bound and
# x1_runs_after_any_history)
COMMON_TESTS = ("random_walk_20k,reset_mid_motion,reversal_at_every_state,dither_every_transition,"
                "monotone_runs")
