# SPDX-License-Identifier: Apache-2.0
"""enc_characterizer (the Figure 3 encoding characteristics) against measurements of the waveform.

Two references, both computed from the waveform's event list and not from the RTL:
  - exact: the clock samples of the waveform (the first rising clock edge after each event),
    split into cycles from A rise to A rise, the Figure 3 quantities counted in clocks, then the
    documented conversion floor(x * 360 * 256 * n / total): the outputs must match to 1 LSB;
  - continuous: the same quantities on the real event times, in e-degrees against the mean period:
    the outputs must agree within one clock per measured interval (360 / period degrees).
Units: ideal, phase and pulse-width errors in both directions, timing jitter, the pass flag against
the note's room-temperature state-width limit, a reversal (window abandoned), and units drawn by
the HEDS-5000 model (the hedsmodel package, python/) from the note's tables.
"""

from __future__ import annotations

import random

import cocotb
import numpy as np
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from enctools import tb as tbutil
from enctools.harness import run
from enctools.tb.phase_models import (CLK_PS, DEG, Channels, characterizer_expect, cycles_of, figure3_degrees,
                          off_grid, sample_index, waveform)
from cocotbext.quadrature import play
from hedsmodel.waveform import Waveform
from enctools.tb import cocotb_test, log_seed

OUTPUTS = ("cycle_err", "pulse_err", "phase_err", "state_err", "state_min")
ROOM_LIMIT = 46 * DEG  # 90 - 44 e-degrees: the note's room-temperature test limit


async def start_clock(dut, clk_ps: int = CLK_PS):
    await tbutil.start(dut, clk_ps, {"a": 0, "b": 0, "min_state": ROOM_LIMIT}, do_reset=False)


def read_outputs(dut) -> dict:
    out = {k: getattr(dut, k).value.to_signed() for k in OUTPUTS[:4]}
    out["state_min"] = int(dut.state_min.value)
    out["pass"] = int(getattr(dut, "pass").value)  # `pass` is a Python keyword
    return out


async def characterize(dut, wf, clk_ps: int = CLK_PS, reset: bool = True):
    """Reset with the waveform's first levels on a/b (two clocks of rst; with ``reset=False`` none:
    the caller has reset, at a falling edge of the clock, with those levels), play it, return
    every result that lands during playback as (time_ps, outputs) and the playback start."""
    _, a0, b0 = wf.events[0]
    if reset:
        dut.a.value, dut.b.value = a0, b0
        dut.rst.value = 1
        await FallingEdge(dut.clk)
        await FallingEdge(dut.clk)
        dut.rst.value = 0
    else:
        assert (int(dut.a.value), int(dut.b.value)) == (a0, b0), "a/b not at the waveform's start"
    start_ps = get_sim_time("ps")
    results = []

    async def collect():
        while True:
            await RisingEdge(dut.valid)
            await ReadOnly()
            results.append((get_sim_time("ps"), read_outputs(dut)))

    task = cocotb.start_soon(collect())
    await play(dut, off_grid(wf, start_ps, clk_ps), "a", "b")
    await FallingEdge(dut.clk)
    task.cancel()
    return results, start_ps


def expected(wf, start_ps: int, n: int, clk_ps: int = CLK_PS):
    """Exact (sampled) and continuous references for the first window of ``n`` cycles."""
    ev = off_grid(wf, start_ps, clk_ps).events
    levels = [(a, b) for _, a, b in ev]
    samples = [sample_index(t, start_ps, clk_ps) for t, _, _ in ev]
    exact = characterizer_expect(cycles_of(samples, levels)[:n])
    cont = figure3_degrees(cycles_of([t for t, _, _ in ev], levels)[:n])
    return exact, cont


def check(dut, got: dict, exact: dict, cont: dict, what: str, clk_ns: float,
          limit: int = ROOM_LIMIT):
    per_clocks = cont["period"] / clk_ns
    # one clock per measured interval, plus the mean period's own error (one clock over n cycles,
    # scaled by the degrees measured: at most 5 % of a clock here) and the divider's floor
    tol_deg = 360.0 / per_clocks * 1.05 + 2.0 / DEG
    dut._log.info("%s: %.1f clocks/cycle", what, per_clocks)
    for k in OUTPUTS:
        g, e, c = got[k], exact[k], cont[k]
        dut._log.info("  %-9s %+9.3f e-deg  (sampled model %+9.3f, continuous extremes %s)", k,
                      g / DEG, e / DEG, ", ".join(f"{x:+.3f}" for x in c))
        assert abs(g - e) <= 1, f"{what}: {k} = {g} LSB, sampled model {e}"
        # the reported extreme is the one farther from nominal: within a clock of one of the two
        # continuous extremes, and as large as the larger one
        assert min(abs(g / DEG - x) for x in c) <= tol_deg, \
            f"{what}: {k} = {g / DEG:.3f}, continuous extremes {c} (tol {tol_deg:.3f})"
        assert abs(abs(g / DEG) - max(abs(x) for x in c)) <= tol_deg, f"{what}: {k} not the worst"
    assert got["pass"] == int(exact["state_min"] >= limit), f"{what}: pass flag"


def window_cycles(dut) -> int:
    return int(dut.WINDOW_CYCLES.value)


async def run_unit(dut, ch: Channels, cpc: float, forward: bool, what: str, jitter_clocks: float = 0.0,
                   rng: random.Random | None = None, limit: int = ROOM_LIMIT):
    n = window_cycles(dut)
    period_ns = cpc * CLK_PS / 1000.0
    theta0 = -30.0 if forward else 320.0
    wf = waveform(ch, [((n + 3) * period_ns, (1 if forward else -1) / period_ns)], theta0=theta0,
                  jitter_ns=jitter_clocks * CLK_PS / 1000.0, rng=rng)
    results, start_ps = await characterize(dut, wf)
    assert len(results) == 1, f"{what}: {len(results)} results, expected 1"
    exact, cont = expected(wf, start_ps, n)
    check(dut, results[0][1], exact, cont, what, CLK_PS / 1000.0, limit)
    return results[0][1]


# ----------------------------------------------------------------------------------------------
# Tests
# ----------------------------------------------------------------------------------------------
@cocotb_test()
async def ideal_and_adjusted_units(dut):
    """An ideal unit, phase error, pulse-width error, both directions."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    units = [Channels(90.0), Channels(70.0), Channels(90.0, 15.0, -10.0), Channels(110.0, -20.0, 8.0),
             Channels(60.0, 25.0, 25.0)]
    for forward in (True, False):
        for ch in units:
            cpc = rng.uniform(150.0, 400.0)
            got = await run_unit(dut, ch, cpc, forward,
                                 f"rise {ch.rise_phase} pa {ch.pulse_err_a:+} pb {ch.pulse_err_b:+} "
                                 f"{'fwd' if forward else 'rev'}")
            # a steady unit: the Figure 3 errors are the configured ones, within a clock or two
            one = 360.0 / cpc
            assert abs(got["phase_err"] / DEG - (ch.true_phase - 90.0)) <= 1.5 * one
            # (magnitudes: with equal deviations either way, e.g. states 70/110, the sign is a tie)
            pulse = max(abs(ch.pulse_err_a), abs(ch.pulse_err_b))
            assert abs(abs(got["pulse_err"] / DEG) - pulse) <= 1.5 * one
            assert abs(got["cycle_err"] / DEG) <= 1.5 * one
            state = max(abs(w - 90) for w in ch.state_widths())
            assert abs(abs(got["state_err"] / DEG) - state) <= 1.5 * one


@cocotb_test()
async def jittered_units(dut):
    """Timing jitter on every edge: the extremes grow, both references still agree."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    for k in range(4):
        ch = Channels(rng.uniform(70, 110), rng.uniform(-15, 15), rng.uniform(-15, 15))
        await run_unit(dut, ch, rng.uniform(150.0, 300.0), rng.random() < 0.5,
                       f"jittered unit {k}", jitter_clocks=rng.uniform(2.0, 8.0), rng=rng)


@cocotb_test()
async def pass_flag_room_temperature_limit(dut):
    """pass = narrowest state >= min_state (46 e-degrees: 44 degrees of state-width error allowed)."""
    await start_clock(dut)
    good = await run_unit(dut, Channels(80.0, 10.0, -6.0), 237.3, True, "good unit")
    assert good["pass"] == 1
    bad = await run_unit(dut, Channels(40.0, 8.0, 0.0), 237.3, True, "unit with a 40 e-degree state")
    assert bad["pass"] == 0
    # the limit is an input: a looser one passes the same unit
    dut.min_state.value = 30 * DEG
    loose = await run_unit(dut, Channels(40.0, 8.0, 0.0), 237.3, True, "same unit, 30 e-degree limit",
                           limit=30 * DEG)
    assert loose["pass"] == 1
    dut.min_state.value = ROOM_LIMIT


@cocotb_test()
async def reversal_abandons_window(dut):
    """A reversal in mid-window gives no mixed result: the next window starts after it."""
    await start_clock(dut)
    n = window_cycles(dut)
    cpc = 211.7
    period_ns = cpc * CLK_PS / 1000.0
    ch = Channels(85.0, 5.0, -5.0)
    t_rev = n * period_ns / 2
    wf = waveform(ch, [(t_rev, 1 / period_ns), ((n + 3) * period_ns, -1 / period_ns)], theta0=-30.0)
    results, start_ps = await characterize(dut, wf)
    assert len(results) == 1, f"{len(results)} results"
    assert results[0][0] > start_ps + t_rev * 1000 + n * period_ns * 1000 * 0.98
    # the reference: the cycles after the reversal only
    ev = off_grid(wf, start_ps).events
    i_rev = next(i for i, e in enumerate(ev) if e[0] > t_rev)
    levels = [(a, b) for _, a, b in ev]
    samples = [sample_index(t, start_ps) for t, _, _ in ev]
    exact = characterizer_expect(cycles_of(samples, levels, i_rev)[:n])
    cont = figure3_degrees(cycles_of([t for t, _, _ in ev], levels, i_rev)[:n])
    check(dut, results[0][1], exact, cont, "after reversal", CLK_PS / 1000.0)


@cocotb_test()
async def double_transition_and_stall_abandon_window(dut):
    """In mid-window, a double transition (A falling and B changing between two samples) or a
    stalled state (2^CNT_W - 1 clocks: the shortest that abandons) gives no result for that
    window: the one result lands a whole window after the disturbance and describes the cycles
    from the first rising edge of A after it, checked against the references. A state of
    2^CNT_W - 2 clocks (the longest the state counter holds) abandons nothing: the window's
    result lands at its end and includes that state."""
    await start_clock(dut)
    n = window_cycles(dut)
    cpc = 211.7
    period_ns = cpc * CLK_PS / 1000.0
    ch = Channels(85.0, 5.0, -5.0)
    longest = 2 ** int(dut.CNT_W.value) - 2
    for kind in ("double transition", "stall", "longest state"):
        wf0 = off_grid(waveform(ch, [((2 * n + 6) * period_ns, 1 / period_ns)], theta0=-30.0), 0)
        ev, pos = wf0.events, wf0.positions
        # mid-window: an event whose next one is a falling edge of A
        i = next(k for k in range(len(ev) - 1) if ev[k][0] > n * period_ns / 2
                 and ev[k][1] == ev[k - 1][1] and (ev[k + 1][1], ev[k][1]) == (0, 1))
        # the state entered at event i - 1 sampled for exactly `width` clocks: the events from i
        # on moved by whole clocks (the samples see every later state as wide as before)
        width = {"stall": longest + 1, "longest state": longest}.get(kind)
        shift_ns = 0.0
        if width is not None:
            now = sample_index(ev[i][0]) - sample_index(ev[i - 1][0])
            shift_ns = (width - now) * CLK_PS / 1000.0
        wf = Waveform()
        for k, ((t, a, b), p) in enumerate(zip(ev, pos)):
            if kind == "double transition" and k == i:
                continue  # (event i's change lands together with event i + 1's)
            if kind == "double transition" and k == i + 1:
                t = ev[i][0]
            if k >= i:
                t += shift_ns
            wf.append(t, p, (a, b))
        at = i  # the index, in wf, of the disturbance's own event
        results, start_ps = await characterize(dut, wf)
        # (with the longest state the disturbed window is not abandoned, so the playback, 2n + 6
        # cycles, also holds the next window whole: two results)
        assert len(results) == (2 if kind == "longest state" else 1), \
            f"{kind}: {len(results)} results"
        oev = off_grid(wf, start_ps).events
        samples = [sample_index(t, start_ps) for t, _, _ in oev]
        if width is not None:
            assert samples[at] - samples[at - 1] == width, f"{kind}: the state's samples"
        t_at = wf.events[at][0]
        after = (results[0][0] - start_ps) / 1000 - t_at
        levels = [(a, b) for _, a, b in oev]
        if kind == "longest state":
            # the window's own result, at its end: its errors saturate (a state of 2^CNT_W - 2
            # clocks among states of about 50), so it is checked against the sampled model only
            assert after < n * period_ns * 0.75, f"{kind}: the result {after:.0f} ns after it"
            exact = characterizer_expect(cycles_of(samples, levels)[:n])
            got = results[0][1]
            assert all(abs(got[k] - exact[k]) <= 1 for k in OUTPUTS), \
                f"{kind}: {got}, model {exact}"
            assert got["pass"] == int(exact["state_min"] >= ROOM_LIMIT), f"{kind}: pass flag"
            continue
        assert after > n * period_ns * 0.98, f"{kind}: a result {after:.0f} ns after it"
        exact = characterizer_expect(cycles_of(samples, levels, at)[:n])
        cont = figure3_degrees(cycles_of([t for t, _, _ in oev], levels, at)[:n])
        check(dut, results[0][1], exact, cont, f"after a {kind}", CLK_PS / 1000.0)


@cocotb_test()
async def slow_units_wide_states(dut):
    """A slow shaft: 2300 clocks per cycle, states of 450 to 750 clocks, so the upper bits of
    the state, pulse, phase and period registers carry data (the other tests run 150 to 400
    clocks per cycle: no state reaches 512 clocks, and a stuck bit 9 of the widest-state register
    went unseen by mutation testing). Within the state counter's range (2^CNT_W - 2
    clocks; CNT_W >= 11 for this speed)."""
    await start_clock(dut)
    if int(dut.CNT_W.value) < 11:
        dut._log.info("CNT_W < 11: states of 1000 clocks would stall the counter; skipped")
        return
    # the widest state is the farther extreme here (105 + 10 e-degrees against 90 - 15), so it
    # is the one reported in state_err
    for ch, cpc, forward in ((Channels(105.0, -10.0, 6.0), 2300.9, False),):
        got = await run_unit(dut, ch, cpc, forward, f"slow unit {cpc} clocks/cycle "
                             f"{'fwd' if forward else 'rev'}")
        one = 360.0 / cpc
        state = max(abs(w - 90) for w in ch.state_widths())
        assert abs(abs(got["state_err"] / DEG) - state) <= 1.5 * one


@cocotb_test()
async def hedsmodel_units(dut):
    """Units drawn from the note's tables by the hedsmodel package, 600 rpm, clk 1 MHz (~200 clocks/cycle)."""
    from hedsmodel import EncoderUnit, Profile, measure

    seed = log_seed(dut)
    rng = np.random.default_rng(seed)
    clk_ps = 1_000_000
    await start_clock(dut, clk_ps)
    n = window_cycles(dut)
    for k in range(3):
        unit = EncoderUnit.draw(rng)
        wf = unit.waveform(Profile().constant(600, (n + 4) / 5000.0))
        results, start_ps = await characterize(dut, wf, clk_ps)
        assert len(results) == 1, f"unit {k}: {len(results)} results"
        exact, cont = expected(wf, start_ps, n, clk_ps)
        check(dut, results[0][1], exact, cont, f"hedsmodel unit {k}", clk_ps / 1000.0)
        m = measure(wf)
        dut._log.info("  hedsmodel.measure over the whole waveform: %s", m.summary())
        # the model's own measurement of the same waveform (all of its cycles, local period):
        # same state-width extreme within a few clocks' worth of degrees
        assert abs(results[0][1]["state_min"] / DEG - m.min_state_deg) <= 3 * 360.0 / 200 + 1.0


@cocotb_test()
async def reset_clears_outputs(dut):
    """One clock of rst: in the next clock every output is 0 (the results, state_min, pass and
    valid), whether a result was held alone, or held while a window was being measured or its
    conversion was running; a conversion cut by rst lands no result; and a window that starts
    right after the one clock of rst (no other reset) measures only cycles after it: its result
    is a fresh window's, checked against the references."""
    rng = random.Random(log_seed(dut))
    await start_clock(dut)
    n = window_cycles(dut)
    ch, cpc = Channels(70.0, 12.0, -9.0), 203.9
    period_ns = cpc * CLK_PS / 1000.0
    valids = []

    def unit_waveform():
        return waveform(ch, [((n + 3) * period_ns, 1 / period_ns)], theta0=-30.0)

    async def count_valid():
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if int(dut.valid.value):
                valids.append((get_sim_time("ps"), read_outputs(dut)))

    async def one_reset_clock(what):
        await FallingEdge(dut.clk)
        dut.rst.value = 1
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        dut.rst.value = 0
        await ReadOnly()  # (the clock after the one rst clock)
        got = {k: int(getattr(dut, k).value) for k in OUTPUTS + ("pass", "valid")}
        assert not any(got.values()), f"{what}: outputs after one clock of rst: {got}"
        await FallingEdge(dut.clk)

    async def hold_a_result(what):
        held = await run_unit(dut, ch, cpc, True, what)
        assert held["phase_err"] and held["state_min"] and held["pass"] == 1, held

    watch = cocotb.start_soon(count_valid())
    await hold_a_result("a result to clear")
    await one_reset_clock("a result held")
    for where in ("measuring", "converting"):
        # a result held, and a new window cut by rst part way through its measurement or in its
        # conversion
        await hold_a_result(f"a result held while {where}")
        play_task = cocotb.start_soon(play(dut, off_grid(unit_waveform(), get_sim_time("ps"), CLK_PS),
                                           "a", "b"))
        if where == "measuring":
            await Timer(int(rng.uniform(0.3, 0.8) * n * period_ns), unit="ns")
        else:
            while not int(dut.conv_q.value):  # (white box: the conversion's run flag)
                await RisingEdge(dut.clk)
            await ClockCycles(dut.clk, rng.randint(0, 20))
        before = len(valids)
        await one_reset_clock(f"rst while {where}")
        await play_task
        await ClockCycles(dut.clk, 1000)  # (a conversion takes about 300)
        assert len(valids) == before, f"rst while {where}: a result landed after it"
    # a full window started right after one clock of rst, the levels of the waveform's start on
    # a and b in that clock: one result, a fresh window's
    watch.cancel()
    wf = unit_waveform()
    _, dut.a.value, dut.b.value = wf.events[0]
    await one_reset_clock("before a full window")
    got, start_ps = await characterize(dut, wf, reset=False)
    assert len(got) == 1, f"{len(got)} results from the window after one clock of rst"
    exact, cont = expected(wf, start_ps, n)
    check(dut, got[0][1], exact, cont, "the first window after one clock of rst", CLK_PS / 1000.0)


# ----------------------------------------------------------------------------------------------
# pytest entry points
# ----------------------------------------------------------------------------------------------
def test_enc_characterizer():
    run("enc_characterizer", __name__, name="enc_characterizer_n32",
        parameters={"CNT_W": 12, "WINDOW_CYCLES": 32})
