# SPDX-License-Identifier: Apache-2.0
"""enc_phase_meter (Figure 11, the averaging phase meter) against the continuous waveform.

The stimulus comes from enctools.tb.phase_models: waveforms computed from the shaft angle, edges at
real-valued times (never on the clock grid), optional pulse-width error, phase, timing jitter,
stops and reversals. The expected reading is computed from the waveform, not from the RTL:
  - steady units: the true phase (between pulse centres = mean of rising- and falling-edge
    phases), so the contract bound |phase_err - (phase - 90)| <= 0.25 degree is checked directly;
  - jittered units: what an ideal averaging meter reads on A xor B over the whole cycles of the
    window (computed on the continuous waveform).
Also: a_leads / b_leads against the direction of rotation (and both 0 after reset), reset and
reversal in mid-window (the window is abandoned, no mixed reading), no reading from a standing
shaft, reading cadence, and an out-of-range WINDOW_LOG2 stopping the build.
"""

from __future__ import annotations

import os
import random
import subprocess

import cocotb
import pytest
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from enctools.harness import run
from enctools.paths import RTL, TOP
from enctools.tb.phase_models import (CLK_PS, Channels, Readings, off_grid, play_case, reset,
                                      rises_of_a, sampled_meter_reading, start_clock, steady,
                                      waveform, window_log2, xor_phase)
from cocotbext.quadrature import play
from enctools.tb import cocotb_test, log_seed

BOUND = 0.25  # contract accuracy, degrees
worst = {"err": 0.0, "what": ""}


# ----------------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------------
def note_error(err: float, what: str):
    if abs(err) > abs(worst["err"]):
        worst["err"], worst["what"] = err, what


def check_reading(dut, reading, true_phase: float, forward: bool | None, what: str,
                  bound: float = BOUND):
    t, perr, a_leads, b_leads = reading
    err = perr - (true_phase - 90.0)
    if bound == BOUND:  # the contract cases (jittered units have their own bound)
        note_error(err, what)
    dut._log.info("%s: phase_err %+8.3f (true %+8.3f) error %+.4f deg  a_leads=%d b_leads=%d", what,
                  perr, true_phase - 90.0, err, a_leads, b_leads)
    assert abs(err) <= bound, f"{what}: reads {perr:+.4f}, true {true_phase - 90:+.4f} (error {err:+.4f})"
    if forward is not None:
        assert (a_leads, b_leads) == ((1, 0) if forward else (0, 1)), \
            f"{what}: LEDs a_leads={a_leads} b_leads={b_leads}, rotation {'fwd' if forward else 'rev'}"


# "Asynchronous" speeds: the clock phase of the edges must move through the whole clock period
# within a window for the sampling errors to average out. A period that is close to a simple ratio
# (N or N + 1/2 clocks per cycle) samples every edge at the same few phases and reads up to about
# 2 clocks per cycle off (commensurate_speed test). Real motors wander far more than that; here the
# fractional part of the period is one of these badly approximable numbers (golden ratio and kin).
GENERIC_FRACS = (0.618034, 0.381966, 0.414214, 0.585786, 0.732051, 0.267949)


def async_cpc(rng: random.Random, lo: float, hi: float) -> float:
    return rng.randrange(int(lo), int(hi)) + rng.choice(GENERIC_FRACS) + rng.uniform(-5e-4, 5e-4)


def random_channels(rng: random.Random, lo: float = 5.0, hi: float = 175.0, pulse: float = 20.0):
    """A unit whose rising- and falling-edge phases both lie in [lo, hi] and whose four states are
    all at least ``lo`` wide: the ordinary quadrature sequence. (If a B pulse overlapped the next
    A rise, the XOR would no longer show the phase; no meter on A xor B can read such a unit.)"""
    while True:
        ch = Channels(rng.uniform(lo, hi), rng.uniform(-pulse, pulse), rng.uniform(-pulse, pulse))
        if min(ch.state_widths()) >= lo and lo <= ch.rise_phase + ch.pulse_err_b - ch.pulse_err_a <= hi:
            return ch


def cycles_for(dut, clocks_per_cycle: float, windows: int) -> float:
    """Enough cycles for ``windows`` windows and their readings."""
    w = 2 ** window_log2(dut)
    return windows * (w + clocks_per_cycle + 64) / clocks_per_cycle + 1.5


# ----------------------------------------------------------------------------------------------
# Tests
# ----------------------------------------------------------------------------------------------
@cocotb_test()
async def phase_sweep_both_directions(dut):
    """Phases from near 0 to near 180 e-degrees, forward and reverse, ~100..130 clocks/cycle."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    for forward in (True, False):
        for phase in (3.0, 10.0, 30.0, 60.0, 85.0, 90.0, 95.0, 120.0, 150.0, 170.0, 177.0):
            cpc = async_cpc(rng, 100, 130)
            ch = Channels(rise_phase=phase)
            wf = steady(ch, cpc, cycles_for(dut, cpc, 1), forward=forward,
                        theta0=rng.uniform(-100.0, -20.0) if forward else rng.uniform(200.0, 280.0))
            items, _ = await play_case(dut, wf)
            what = f"phase {phase} {'fwd' if forward else 'rev'} {cpc:.2f} clk/cycle"
            assert len(items) == 1, f"{what}: {len(items)} readings, expected 1"
            # near 0 / 180 degrees a state can be shorter than a clock; the LEDs are still right
            check_reading(dut, items[0], ch.true_phase, forward, what)


@cocotb_test()
async def zero_reading_at_90(dut):
    """An encoder adjusted to 90 degrees reads zero (within the contract bound)."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    for cpc in (async_cpc(rng, 100, 101), async_cpc(rng, 150, 200), async_cpc(rng, 250, 260)):
        ch = Channels(rise_phase=90.0)
        items, _ = await play_case(dut, steady(ch, cpc, cycles_for(dut, cpc, 2)))
        assert len(items) == 2
        for i, r in enumerate(items):
            check_reading(dut, r, 90.0, True, f"90 deg at {cpc:.2f} clk/cycle, reading {i}")


@cocotb_test()
async def pulse_width_error_reads_mean_of_edges(dut):
    """With pulse-width error the reading is the mean of the rising- and falling-edge phases."""
    await start_clock(dut)
    cases = [  # rise phase, A pulse error, B pulse error
        (80.0, +20.0, -16.0),  # rising 80, falling 44: mean 62
        (60.0, -30.0, +30.0),  # rising 60, falling 120: mean 90 -> zero reading
        (100.0, +12.0, +12.0),  # both pulses long: edge phases equal
        (45.0, -25.0, 0.0),
    ]
    for forward in (True, False):
        for rise, pa, pb in cases:
            ch = Channels(rise_phase=rise, pulse_err_a=pa, pulse_err_b=pb)
            cpc = 117.381966
            wf = steady(ch, cpc, cycles_for(dut, cpc, 1), forward=forward,
                        theta0=-60.0 if forward else 300.0)
            items, _ = await play_case(dut, wf)
            what = f"rise {rise} pa {pa:+} pb {pb:+} {'fwd' if forward else 'rev'}"
            assert len(items) == 1
            check_reading(dut, items[0], ch.true_phase, forward, what)
            # and not the rising-edge phase alone (these cases are far enough apart to tell)
            if abs(ch.true_phase - rise) > 2:
                assert abs(items[0][1] - (rise - 90.0)) > 1.0, f"{what}: reads the rising edges only"


@cocotb_test()
async def jittered_edges(dut):
    """Edge jitter: the reading matches an ideal averaging meter on the same whole cycles."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    for k in range(4):
        cpc = rng.uniform(100.0, 200.0)  # jitter spreads the edge phases: any speed will do
        period_ns = cpc * CLK_PS / 1000.0
        ch = random_channels(rng, 40.0, 140.0, 10.0)
        jitter = 0.04 * period_ns
        wf = waveform(ch, [(cycles_for(dut, cpc, 2) * period_ns, 1.0 / period_ns)],
                      jitter_ns=jitter, rng=rng)
        items, start_ps = await play_case(dut, wf)
        assert len(items) == 2
        rises = rises_of_a(wf)
        for i, (t_ps, perr, a_l, b_l) in enumerate(items):
            # the window's whole-cycle span ends at the last rise before the window closes, some
            # W + 18 clocks before the reading; take every span of length < 2^W clocks that ends
            # near there and use the one the reading is closest to (they differ by < 0.1 degree)
            t_ns = (t_ps - start_ps) / 1000.0
            ends = [r for r in rises if t_ns - 60 * 10.0 - period_ns <= r <= t_ns - 10 * 10.0]
            expect = []
            for r1 in ends:
                for r0 in rises:
                    n = round((r1 - r0) / period_ns)
                    if r0 < r1 and (r1 - r0) <= w * 10.0 and (r1 - r0) > w * 10.0 - 1.5 * period_ns:
                        expect.append(xor_phase(wf, r0, r1))
            best = min(expect, key=lambda e: abs(perr - (e - 90.0)))
            # random edge phases make the sampling error a random walk over the 4 N edges of the
            # window: sigma = 180 sqrt(N / 3) / T degrees (about 0.1 here), so allow 0.5
            check_reading(dut, items[i], best, True, f"jitter {jitter:.1f} ns unit {k} reading {i}",
                          bound=0.5)


@cocotb_test()
async def random_units(dut):
    """Random steady units (>= 100 clocks/cycle, >= 64 cycles/window): the contract bound."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    max_cpc = w / 64.0
    for k in range(int(os.environ.get("ENC_PHASE_UNITS", "8"))):
        cpc = async_cpc(rng, 100.0, min(max_cpc, 400.0))
        forward = rng.random() < 0.5
        ch = random_channels(rng)
        wf = steady(ch, cpc, cycles_for(dut, cpc, 1), forward=forward,
                    theta0=rng.uniform(-180.0, 180.0))
        items, start_ps = await play_case(dut, wf)
        assert len(items) >= 1
        sampled = sampled_meter_reading(off_grid(wf, start_ps), window_log2(dut))
        dut._log.info("unit %d: %.6f clk/cycle %s; clocked-sampling model of the first window: %s",
                      k, cpc, ch, sampled)
        assert round(items[0][1] * 256) == sampled[0], \
            f"first reading {round(items[0][1] * 256)} differs from the sampled model {sampled}"
        for r in items:
            check_reading(dut, r, ch.true_phase, forward,
                          f"unit {k}: {cpc:.2f} clk/cycle rise {ch.rise_phase:.2f} "
                          f"pa {ch.pulse_err_a:+.2f} pb {ch.pulse_err_b:+.2f}")
    dut._log.info("worst |error| in this build: %.4f deg (%s)", abs(worst["err"]), worst["what"])


@cocotb_test()
async def reset_mid_window(dut):
    """rst in mid-window: LEDs back to 0, the window is abandoned, the next reading is clean."""
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    cpc = 123.618034
    period_ns = cpc * CLK_PS / 1000.0
    ch = Channels(rise_phase=70.0)
    wf = off_grid(steady(ch, cpc, cycles_for(dut, cpc, 3.2)), 0)
    await reset(dut)
    start_ps = get_sim_time("ps")
    wf = off_grid(wf, start_ps)
    rd = Readings(dut)
    player = cocotb.start_soon(play(dut, wf, "a", "b"))
    # reset 1.5 windows in, in the middle of a state (so no transition right after the release)
    t_target = 1.5 * w * 10.0
    ev = wf.events
    i = next(i for i in range(len(ev) - 1) if ev[i][0] > t_target and ev[i + 1][0] - ev[i][0] > 8 * 10.0)
    t_rst_ns = ev[i][0] + 2 * 10.0
    await Timer(int((start_ps + t_rst_ns * 1000)) - get_sim_time("ps"), unit="ps")
    await FallingEdge(dut.clk)
    n_before = len(rd.items)
    dut.rst.value = 1
    await FallingEdge(dut.clk)
    dut.rst.value = 0
    rst_ps = get_sim_time("ps")
    await ReadOnly()
    assert (int(dut.a_leads.value), int(dut.b_leads.value)) == (0, 0), "LEDs not cleared by rst"
    assert int(dut.phase_err.value.to_signed()) == 0 and int(dut.valid.value) == 0
    await FallingEdge(dut.clk)
    await player
    await FallingEdge(dut.clk)
    rd.stop()
    assert n_before == 1, f"{n_before} readings before the reset, expected 1"
    after = [r for r in rd.items if r[0] > rst_ps]
    assert len(after) >= 1, "no reading after the reset"
    # the abandoned window must not report: the first reading comes a full window after the reset
    assert after[0][0] - rst_ps >= w * CLK_PS, "a reading landed less than a window after rst"
    assert after[0][0] - rst_ps <= (w + 2 * cpc + 64) * CLK_PS
    for r in rd.items:
        check_reading(dut, r, ch.true_phase, True, "reset mid-window")


@cocotb_test()
async def leds_dark_until_first_transition(dut):
    """After rst both LEDs stay 0 while the shaft stands (any of the four states, held for a
    random time) and across a double change (both channels in one clock: no direction); the first
    valid transition lights the LED of its direction within 8 clocks and only that one. Both
    directions, from each state."""
    await start_clock(dut)
    rng = random.Random(log_seed(dut))
    quad = [(0, 0), (1, 0), (1, 1), (0, 1)]  # forward: A leads
    for trial in range(8):
        k = rng.randrange(4)
        forward = trial % 2 == 0
        await FallingEdge(dut.clk)
        dut.a.value, dut.b.value = quad[k]
        await reset(dut, 2)
        lit = []
        for _ in range(rng.randint(10, 60)):  # standing
            await RisingEdge(dut.clk)
            await ReadOnly()
            lit.append((int(dut.a_leads.value), int(dut.b_leads.value)))
        await FallingEdge(dut.clk)
        far = quad[(k + 2) % 4]  # both channels at once
        dut.a.value, dut.b.value = far
        for _ in range(12):
            await RisingEdge(dut.clk)
            await ReadOnly()
            lit.append((int(dut.a_leads.value), int(dut.b_leads.value)))
        assert set(lit) == {(0, 0)}, f"trial {trial}: an LED lit before a valid transition: {sorted(set(lit))}"
        await FallingEdge(dut.clk)
        dut.a.value, dut.b.value = quad[(k + 2 + (1 if forward else -1)) % 4]
        after = []
        for _ in range(8):
            await RisingEdge(dut.clk)
            await ReadOnly()
            after.append((int(dut.a_leads.value), int(dut.b_leads.value)))
        want = (1, 0) if forward else (0, 1)
        assert set(after) <= {(0, 0), want} and after[-1] == want, \
            f"trial {trial}: {'forward' if forward else 'reverse'} transition from {far}: LEDs {after}"


@cocotb_test()
async def direction_change_mid_window(dut):
    """Reverse in mid-window: the LEDs swap, the mixed window gives no reading, later ones are right."""
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    for first_fwd in (True, False):
        cpc = 111.414214
        period_ns = cpc * CLK_PS / 1000.0
        ch = Channels(rise_phase=75.0, pulse_err_a=6.0, pulse_err_b=-4.0)
        s = 1.0 if first_fwd else -1.0
        t_rev = 1.6 * w * 10.0
        seg2 = cycles_for(dut, cpc, 2) * period_ns
        wf = waveform(ch, [(t_rev, s / period_ns), (seg2, -s / period_ns)],
                      theta0=-30.0 if first_fwd else 300.0)
        items, start_ps = await play_case(dut, wf)
        t_rev_ps = start_ps + t_rev * 1000
        before = [r for r in items if r[0] < t_rev_ps]
        after = [r for r in items if r[0] > t_rev_ps]
        assert len(before) == 1 and len(after) == 2, f"readings {len(before)} before, {len(after)} after"
        assert after[0][0] - t_rev_ps >= w * CLK_PS, "the window with the reversal reported"
        for r in before:
            check_reading(dut, r, ch.true_phase, first_fwd, "before reversal")
        for r in after:
            check_reading(dut, r, ch.true_phase, not first_fwd, "after reversal")


@cocotb_test()
async def standing_shaft_no_reading(dut):
    """No whole cycle in a window (standing, or slower than one cycle per window): no reading."""
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    ch = Channels(rise_phase=90.0)
    # most of a cycle forward (one rise of A only), then stand for three windows: the LEDs keep
    # the last direction
    period_ns = 150.0 * CLK_PS / 1000.0
    wf = waveform(ch, [(period_ns * 0.9, 1.0 / period_ns), (3 * w * 10.0, 0.0)], theta0=-30.0)
    items, _ = await play_case(dut, wf)
    assert items == [], f"readings from a standing shaft: {items}"
    assert (int(dut.a_leads.value), int(dut.b_leads.value)) == (1, 0)
    # a cycle longer than the window
    slow = 1.3 * w
    items, _ = await play_case(dut, steady(ch, slow, 3.0, theta0=-30.0))
    assert items == [], f"readings with {slow} clocks per cycle: {items}"


@cocotb_test()
async def reading_cadence(dut):
    """Readings come once per window: 2^W clocks + at most one cycle + the divider."""
    await start_clock(dut)
    w = 2 ** window_log2(dut)
    cpc = 141.732051
    ch = Channels(rise_phase=100.0)
    items, _ = await play_case(dut, steady(ch, cpc, cycles_for(dut, cpc, 4)))
    assert len(items) == 4
    for r0, r1 in zip(items, items[1:]):
        gap = (r1[0] - r0[0]) / CLK_PS
        assert w < gap <= w + cpc + window_log2(dut) + 20, f"reading gap {gap} clocks"
    for r in items:
        check_reading(dut, r, 100.0, True, "cadence")


@cocotb_test()
async def commensurate_speed(dut):
    """Not asynchronous: a whole or half-integer number of clocks per cycle samples every edge at
    the same one or two clock phases. The reading is then off by the sampling error of one cycle,
    at most 2 clocks per cycle (the contract's 0.25 degree needs asynchronous edges)."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    for cpc in (100.0, 120.5):
        ch = random_channels(rng, 30.0, 150.0, 10.0)
        items, _ = await play_case(dut, steady(ch, cpc, cycles_for(dut, cpc, 1),
                                               theta0=rng.uniform(-180, 0)))
        assert len(items) == 1
        err = items[0][1] - (ch.true_phase - 90.0)
        dut._log.info("%.1f clocks/cycle (commensurate): error %+.4f deg (limit %.2f)", cpc, err,
                      2 * 180.0 / cpc)
        assert abs(err) <= 2 * 180.0 / cpc


@cocotb_test()
async def frequency_case(dut):
    """One encoder speed chosen by the pytest entry (ENC_PHASE_CPC clocks/cycle): phases both ways."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    cpc0 = float(os.environ["ENC_PHASE_CPC"])
    cases = ((True, 45.0), (False, 135.0), (True, 92.0))[:int(os.environ.get("ENC_PHASE_CASES", "3"))]
    for forward, phase in cases:
        cpc = async_cpc(rng, cpc0, cpc0 * 1.01)
        ch = Channels(rise_phase=phase, pulse_err_a=rng.uniform(-10, 10), pulse_err_b=rng.uniform(-10, 10))
        wf = steady(ch, cpc, cycles_for(dut, cpc, 1), forward=forward,
                    theta0=rng.uniform(-100.0, -10.0) if forward else rng.uniform(200, 300))
        items, _ = await play_case(dut, wf)
        assert len(items) == 1
        check_reading(dut, items[0], ch.true_phase, forward,
                      f"{cpc:.2f} clk/cycle, phase {ch.true_phase:.2f} {'fwd' if forward else 'rev'}")
    dut._log.info("worst |error| in this build: %.4f deg (%s)", abs(worst["err"]), worst["what"])


# ----------------------------------------------------------------------------------------------
# pytest entry points
# ----------------------------------------------------------------------------------------------
MAIN_TESTS = ("phase_sweep_both_directions,zero_reading_at_90,pulse_width_error_reads_mean_of_edges,"
              "jittered_edges,random_units,reset_mid_window,direction_change_mid_window,"
              "standing_shaft_no_reading,reading_cadence,commensurate_speed")


def test_enc_phase_meter():
    """The behaviour tests at WINDOW_LOG2 = 13 (8192 clocks: 64+ cycles of 100..128 clocks)."""
    run("enc_phase_meter", __name__, name="enc_phase_meter_w13",
        parameters={"WINDOW_LOG2": 13}, testcase=MAIN_TESTS)


@pytest.mark.parametrize("log2,cpc,cases", [(16, 1000.0, 3), (17, 10000.0, 1)])
def test_enc_phase_meter_speed(log2, cpc, cases):
    """Slower encoders: 1000 clocks/cycle at WINDOW_LOG2 = 16 (65 cycles per window, both
    directions) and 10000 at WINDOW_LOG2 = 17 (13 cycles: fewer than the contract's 64, but each
    cycle's sampling error is 100 times smaller; a 64-cycle window would be a million clocks, too
    slow for Icarus), each held to the 0.25 degree bound."""
    run("enc_phase_meter", __name__, name=f"enc_phase_meter_w{log2}",
        parameters={"WINDOW_LOG2": log2}, testcase="frequency_case",
        extra_env={"ENC_PHASE_CPC": str(cpc), "ENC_PHASE_CASES": str(cases)})


@pytest.mark.parametrize("value", [7, 25])
def test_enc_phase_meter_bad_window(value, tmp_path):
    """WINDOW_LOG2 outside 8..24 stops elaboration, naming the parameter, in both simulators."""
    src = str(RTL / "enc_phase_meter.v")
    iv = subprocess.run(["iverilog", "-g2005", f"-I{RTL}", "-o", str(tmp_path / "x.vvp"), "-s", "enc_phase_meter",
                         f"-Penc_phase_meter.WINDOW_LOG2={value}", src], capture_output=True, text=True)
    assert iv.returncode != 0, "iverilog built an out-of-range WINDOW_LOG2"
    assert "WINDOW_LOG2" in iv.stdout + iv.stderr
    env = dict(os.environ, PATH=f"{TOP / 'scripts' / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
    vl = subprocess.run(["verilator", "--lint-only", f"-I{RTL}", "--top-module", "enc_phase_meter",
                         f"-GWINDOW_LOG2={value}", src], capture_output=True, text=True, env=env)
    assert vl.returncode != 0, "verilator accepted an out-of-range WINDOW_LOG2"
    assert "WINDOW_LOG2" in vl.stdout + vl.stderr
