# SPDX-License-Identifier: Apache-2.0
"""enc_conditioner against its Python model, clock by clock, with edges off the clock grid.

A monitor samples a_in/b_in at every rising edge (what the first synchronizer stage captures),
steps ConditionerModel with them, and compares a, b and glitch after the edge. FILTER_LEN 1, 2,
3 and 8; random walks with lone pulses of every width around FILTER_LEN; reset mid-motion;
simultaneous edges on both channels.
"""

import random

import cocotb
import pytest
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from enctools import tb as tbutil
from enctools.harness import run
from enctools.tb.models import ConditionerModel
from cocotbext.quadrature import play

from enctools.tb import cocotb_test
from hedsmodel.waveform import Waveform, random_walk, with_glitches

PERIOD_PS = 10_000
T_NS = PERIOD_PS / 1000


class Checker:
    """Per-clock comparison of the DUT with the model; counts what it saw."""

    def __init__(self, dut, filter_len):
        self.dut = dut
        self.model = ConditionerModel(filter_len)
        self.clocks = 0
        self.glitches = 0
        self.level_changes = 0

    async def run(self):
        dut = self.dut
        last = (0, 0)
        while True:
            await RisingEdge(dut.clk)
            a_in, b_in, rst = int(dut.a_in.value), int(dut.b_in.value), int(dut.rst.value)
            await ReadOnly()
            if rst:
                self.model.reset()
                exp = {"a": 0, "b": 0, "glitch": 0, "valid": 0}
            else:
                exp = self.model.clock(a_in, b_in)
            got = {k: int(getattr(dut, k).value) for k in ("a", "b", "glitch", "valid")}
            assert got == exp, f"clock {self.clocks}: got {got}, model {exp}"
            self.clocks += 1
            self.glitches += got["glitch"]
            self.level_changes += (got["a"], got["b"]) != last
            last = (got["a"], got["b"])


async def start(dut):
    await tbutil.start(dut, PERIOD_PS, {"a_in": 0, "b_in": 0})
    checker = Checker(dut, int(dut.FILTER_LEN.value))
    cocotb.start_soon(checker.run())
    return checker


@cocotb_test()
async def random_walk_with_glitches(dut):
    """5000 transitions with states from 0.5 T to 3F T, plus 500 lone pulses of 0.2 T .. (F+1) T."""
    f = int(dut.FILTER_LEN.value)
    checker = await start(dut)
    rng = random.Random(cocotb.RANDOM_SEED)
    wf = random_walk(rng, 5000, 0.5 * T_NS, 3 * f * T_NS + T_NS, p_reverse=0.3)
    for width_t in (0.2, 0.7, 1.3, f - 0.5, f, f + 0.6):
        if width_t > 0:
            wf = with_glitches(wf, rng, 80, width_t * T_NS, guard_ns=0.1 * T_NS)
    await play(dut, wf, clock_period_ps=PERIOD_PS)
    await Timer(30 * PERIOD_PS, unit="ps")
    assert checker.level_changes > 1000
    if f == 1:
        assert checker.glitches == 0, "FILTER_LEN = 1 must never report a glitch"
    else:
        assert checker.glitches > 0, "short pulses were driven but no glitch was reported"


@cocotb_test()
async def short_pulses_rejected(dut):
    """Lone pulses shorter than FILTER_LEN samples never reach the outputs; each one that was
    sampled at all gives exactly one glitch pulse. (FILTER_LEN = 1 has no filter: every pulse that
    was sampled passes, and glitch stays 0.)"""
    f = int(dut.FILTER_LEN.value)
    checker = await start(dut)
    # rising edges, in playback time: k * T - start
    offset_ns = (-get_sim_time("ps") % PERIOD_PS) / 1000
    rng = random.Random(cocotb.RANDOM_SEED + 1)
    wf = Waveform()
    wf.append(0.0, 0)
    t = 5 * T_NS
    sampled = 0

    def near_sample(t_ns):  # within 1% of a clock period of a sampling edge: ambiguous, redraw
        phase = ((t_ns - offset_ns) / T_NS) % 1.0
        return phase < 0.01 or phase > 0.99

    for i in range(200):
        while True:
            width = rng.uniform(0.05, f - 1.05 if f > 1 else 0.95) * T_NS  # <= max(1, f-1) samples
            start_t = t + rng.uniform(0, T_NS)
            if not (near_sample(start_t) or near_sample(start_t + width)):
                break
        ab = (1, 0) if i % 2 else (0, 1)
        wf.append(start_t, 0, ab)
        wf.append(start_t + width, 0, (0, 0))
        # a pulse is seen by k = number of sample instants inside it
        first = int((start_t - offset_ns) // T_NS) + 1
        last = int((start_t + width - offset_ns) // T_NS)
        sampled += last >= first
        t = start_t + width + (f + 3) * T_NS
    await play(dut, wf, clock_period_ps=PERIOD_PS)
    await Timer((f + 5) * PERIOD_PS, unit="ps")
    if f == 1:
        assert checker.level_changes == 2 * sampled, "FILTER_LEN = 1 must pass every sampled pulse"
        assert checker.glitches == 0
    else:
        assert checker.level_changes == 0, "a pulse shorter than FILTER_LEN reached the output"
        assert checker.glitches == sampled, f"{checker.glitches} glitch pulses, expected {sampled}"
    assert sampled > 20


@cocotb_test()
async def reset_mid_motion(dut):
    """rst for one clock at random times while both channels move."""
    f = int(dut.FILTER_LEN.value)
    checker = await start(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 2)
    wf = random_walk(rng, 3000, 0.6 * T_NS, 2 * f * T_NS + T_NS)

    async def resets():
        while True:
            await Timer(rng.randint(20, 300) * PERIOD_PS, unit="ps")
            await FallingEdge(dut.clk)
            dut.rst.value = 1
            await FallingEdge(dut.clk)
            dut.rst.value = 0

    task = cocotb.start_soon(resets())
    await play(dut, wf, clock_period_ps=PERIOD_PS)
    task.cancel()
    dut.rst.value = 0
    await Timer(30 * PERIOD_PS, unit="ps")
    assert checker.clocks > 1000


@cocotb_test()
async def channels_keep_relative_timing(dut):
    """Edges on A and B at the same instant come out on the same clock; edges k clocks apart come
    out k clocks apart; the latency is 2 + FILTER_LEN clocks after the sampling edge."""
    f = int(dut.FILTER_LEN.value)
    await start(dut)
    for gap in (0, 1, 2, 5):
        t_in, t_out = {}, {}
        for i in range(gap + f + 8):
            await FallingEdge(dut.clk)
            await Timer(PERIOD_PS // 4, unit="ps")  # a quarter period before the rising edge
            if i == 0:
                t_in["a"] = get_sim_time("ps")
                dut.a_in.value = 1 - int(dut.a_in.value)
            if i == gap:
                t_in["b"] = get_sim_time("ps")
                dut.b_in.value = 1 - int(dut.b_in.value)
            await RisingEdge(dut.clk)
            await ReadOnly()
            for ch in t_in:
                if ch not in t_out and int(getattr(dut, ch).value) == int(getattr(dut, ch + "_in").value):
                    t_out[ch] = get_sim_time("ps")
        assert t_out["b"] - t_out["a"] == gap * PERIOD_PS, f"gap {gap} clocks in, {t_out} out"
        for ch in ("a", "b"):
            latency = (t_out[ch] - t_in[ch]) / PERIOD_PS
            assert latency == f + 1 + 0.25, f"{ch}: {latency} clocks from the edge to the output"


@cocotb_test()
async def reset_on_rejection_clock(dut):
    """A one-clock rst that falls exactly on the clock a short pulse is rejected: glitch must stay
    0 there (rst clears it), and the outputs follow the model after it. For each channel (and
    both), each rejected width 1 .. FILTER_LEN-1 samples, the reset is swept over every clock from
    the pulse's first sample to past its rejection, so exactly one of the sweeps lands on the
    rejection clock; the test counts those. Deterministic: random resets hit that clock only on
    some seeds. FILTER_LEN = 1 rejects nothing: only the sweep runs."""
    f = int(dut.FILTER_LEN.value)
    checker = await start(dut)
    model = checker.model
    hits = 0
    model_reset = model.reset

    def reset_and_count():  # the model's view: would this clock have rejected a level?
        nonlocal hits
        hits += any(model.pipe[1][ch] == model.level[ch] and model.run[ch] for ch in range(2))
        model_reset()

    model.reset = reset_and_count
    channels = (("a_in",), ("b_in",), ("a_in", "b_in"))
    for names in channels:
        for width in range(1, max(2, f)):
            for at in range(width + 5):  # rst during the rising edge after falling edge `at`
                for i in range(width + f + 8):
                    await FallingEdge(dut.clk)
                    for name in names:
                        getattr(dut, name).value = int(i < width)
                    dut.rst.value = int(i == at)
                dut.rst.value = 0
    await FallingEdge(dut.clk)
    model.reset = model_reset
    if f > 1:
        want = len(channels) * (f - 1)
        assert hits == want, f"{hits} resets on a rejection clock, expected {want}"


@pytest.mark.parametrize("filter_len", [1, 2, 3, 8])
def test_enc_conditioner(filter_len):
    run("enc_conditioner", __name__, name=f"enc_conditioner_f{filter_len}",
        parameters={"FILTER_LEN": filter_len})
