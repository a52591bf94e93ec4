# SPDX-License-Identifier: Apache-2.0
"""Sweeps of the counting circuits driven by the HEDS-5000 model at the 12 MHz clock.

DUT: tb/hdl/enc_quad_probe.v (enc_conditioner -> enc_x4_decoder, enc_x2_xor, enc_x1_hysteresis
with net-count accumulators and flag counters), built with FILTER_LEN = 3 (the default) and 1
(no filter: the note's programmed-input sampling, one sample per clock). Shared logic, the
definition of "exact" and of "silent loss", and the two predictions are in enctools.benches.sweeps; the
dense version of these sweeps is scripts/sweep.py (`make sweep`).

Every point is one constant-speed run of one modelled unit; the truth is the model's waveform
(``Waveform.positions``), the timing its measurement (``hedsmodel.measure``). Held everywhere: no
silent loss (a wrong x4 / x2 / x1 count always comes with an error or glitch pulse on its path).

- frequency_sweep: a unit drawn at its table means (random directions, per-cycle play), from a
  120 rpm crawl through 3000 rpm (25 kHz) and the note's 200 kHz to 3 x the predicted count
  limit: exact at and below the limit, flagged from 1.5 x (the cliff of a real unit is soft).
- count_limit_boundary: units with static phase / pulse-width errors (a sharp cliff), walked on a
  0.5 % grid up to the first miscount: the highest exact frequency must lie within 5 % of the
  predicted limit, at or above it (the contract's 1.05 margin is the whole of the gap).
- phase_error_sweep: phase error 0, ±20, ±40, ±60 e°: exact at 0.95 x limit, flagged at 1.3 x.
- state_width_error_sweep: at 200 kHz (+0.1 %, see F_200K), state-width error 0 .. 83 e° (exact; the limit at 200 kHz
  is 83.7 e°) and 86, 88 e° (flagged).
- temperature_sweep: worst-case α = 2.5e-5: the pulse width moves by α ΔT f (checked with
  measure()) and counts stay exact: 200 kHz from 25 to 40 °C (ΔP up to 75 e°; at 42.5 °C the
  00 state is 2.5 e° wide and the flags must fire), 25 kHz from 25 to 70 °C (the note's design
  example, ΔP 28 e°), 200 kHz at 60 °C with typical α. Why not 200 kHz to 70 °C with worst α:
  ΔP = α ΔT f = 225 e° there, more than a whole level; the encoder's 00 state is gone at 43 °C.
- sampling_rule (FILTER_LEN = 1): the note's T_p <= T_s (1 - ΔS_max / 90) with T_p = 1 clock is
  sharp: exact at 0.98 x the frequency it allows, flagged at 1.03 x.
"""

from __future__ import annotations

import math


from enctools.tb import cocotb_test
import numpy as np
import pytest

from enctools.harness import run
from hedsmodel import EncoderUnit, measure, note
from enctools.benches.sweeps import (CLK_NS, MARGIN, assert_exact, assert_no_silent_loss, boundary_search,
                    filter_len, limits, run_point, start, unit_dict, waveform)

TOLERANCE = 0.05     # measured boundary within 5 % of the prediction
GRID_STEP = 0.005    # boundary grid, fraction of the limit
# 12 MHz / 200 kHz = 60 clocks exactly: a perfect 200 kHz encoder is sampled at the same clock
# phase in every cycle, so a state narrower than a clock is caught always or never, depending on
# where playback started. 0.1 % faster, the sampling phase walks 0.06 clock per cycle and a run
# of 250 cycles meets every phase many times (the stronger test on both sides of the limit).
F_200K = 2e5 * 1.001
DETUNE = 1.0013      # the same for round-number frequencies elsewhere (1.6 MHz = 7.5 clocks)


def clean_unit(phase: float = 0.0, pulse=(0.0, 0.0), **kw) -> dict:
    """A unit with static errors only (no eccentricity, play or line errors)."""
    return unit_dict(EncoderUnit(phase_error_deg=phase, pulse_error_deg=tuple(pulse), **kw))


def typical_unit(seed: int) -> dict:
    return unit_dict(EncoderUnit.typical(np.random.default_rng(seed)))


def must_flag(res: dict) -> None:
    assert not res["exact"] and res["flags"] > 0, (
        f"{res['tag']} at {res['f_hz']:.1f} Hz ({res['f_hz'] / res['f_limit_hz']:.3f} x the limit; "
        f"min state {res['min_state_clk']:.3f} clk, min level {res['min_level_clk']:.3f} clk): "
        "expected the error / glitch flags to fire, but the run was exact")


async def check_points(dut, rng, points, inside_max=1.0, outside_min=math.inf):
    """Run points; all: no silent loss; f <= inside_max x limit: exact; >= outside_min: flagged."""
    results = []
    for p in points:
        res = await run_point(dut, p, rng)
        assert_no_silent_loss(res)
        ratio = res["f_hz"] / res["f_limit_hz"]
        if ratio <= inside_max:
            assert_exact(res)
        if ratio >= outside_min:
            must_flag(res)
        results.append(res)
    return results


@cocotb_test()
async def frequency_sweep(dut):
    """A typical unit from a 120 rpm crawl to 3 x the count limit: exact inside, flagged past.

    Past the limit the cliff of a typical unit is soft (its narrowest states are rare, so a miss
    is a matter of chance: in 24 units the first miscount came at up to 1.25 x the limit with
    FILTER_LEN = 1 and 1.10 x with 3); the flags are required from 1.5 x on."""
    rng = await start(dut)
    fl = filter_len(dut)
    unit = typical_unit(rng.randrange(2**32))
    lim = limits({"unit": unit, "f_hz": 1e5, "transitions": 2000}, fl)
    f_lim = lim["f_limit_hz"]
    dut._log.info("unit: measured ΔS %.2f e°, ΔP %.2f e°; count-limit (budget) %.0f Hz (%s), "
                  "direct %.0f Hz -> limit %.0f Hz = %.0f rpm (the note's 200 kHz = %.1f %% of it)",
                  lim["state_error_deg"], lim["pulse_error_deg"], lim["f_pred_hz"], lim["binding"],
                  lim["f_direct_hz"], f_lim, f_lim * 60 / note.CPR, 2e7 / f_lim)
    assert f_lim > 2e5, "the decoder's count limit should be far above the note's 200 kHz"
    spec = [("crawl 120 rpm", 1000.0, 12, 1), ("3000 rpm", 25e3, 400, 1),
            ("note 200 kHz", 2e5, 2000, 1), ("0.5 limit", 0.5 * f_lim, 2000, 1),
            ("0.9 limit rev", 0.9 * f_lim, 2000, -1), ("1.0 limit", f_lim, 3000, 1),
            ("1.5 limit", 1.5 * f_lim, 2000, 1), ("2 limit rev", 2.0 * f_lim, 2000, -1),
            ("3 limit", 3.0 * f_lim, 2000, 1)]
    points = [{"unit": unit, "tag": t, "f_hz": f, "transitions": n, "direction": d}
              for t, f, n, d in spec]
    await check_points(dut, rng, points, inside_max=1.0, outside_min=1.5)


@cocotb_test()
async def count_limit_boundary(dut):
    """Highest exact frequency vs the prediction, for a level-bound and a state-bound unit."""
    rng = await start(dut)
    fl = filter_len(dut)
    units = [("pulse +-12", clean_unit(0.0, (12.0, -12.0))),     # narrowest level 168 e°
             ("phase -45", clean_unit(-45.0))]                     # narrowest state 45 e°
    for tag, unit in units:
        b = await boundary_search(dut, {"unit": unit, "tag": tag}, rng, lo=0.98, hi=1.12,
                                  step=GRID_STEP, transitions=4000)
        dut._log.info("%s, F=%d: ΔS %.2f ΔP %.2f e°, predicted %.0f Hz (%s-bound, direct %.0f Hz), "
                      "highest exact %.0f Hz, first miscount %.0f Hz: ratio %.4f",
                      tag, fl, b["state_error_deg"], b["pulse_error_deg"], b["f_pred_hz"],
                      b["binding"], b["f_direct_hz"], b["measured_hz"], b["first_bad_hz"], b["ratio"])
        assert not math.isnan(b["first_bad_hz"]), f"{tag}: still exact at 1.12 x the prediction"
        assert 1.0 <= b["ratio"] <= 1.0 + TOLERANCE + GRID_STEP / 2, (
            f"{tag}: measured boundary {b['measured_hz']:.0f} Hz is {100 * (b['ratio'] - 1):+.2f} % "
            f"from the predicted {b['f_limit_hz']:.0f} Hz (allowed 0 .. +5 %)")


@cocotb_test()
async def phase_error_sweep(dut):
    """Phase error 0 .. ±60 e°: exact at 0.95 x each unit's limit, flagged at 1.3 x."""
    rng = await start(dut)
    points = []
    for i, phase in enumerate((0, 20, -20, 40, -40, 60, -60)):
        unit = clean_unit(phase, (6.0, -4.0))
        _, wf = waveform({"unit": unit, "f_hz": 1e5, "transitions": 400})
        m = measure(wf)
        assert abs(float(np.mean(m.phase_deg)) - 90 - phase) < 0.01, \
            f"model phase {np.mean(m.phase_deg):.3f} for a {phase} e° phase error"
        f_lim = limits({"unit": unit, "f_hz": 1e5, "transitions": 400}, filter_len(dut))["f_limit_hz"]
        d = 1 if i % 2 == 0 else -1
        points += [{"unit": unit, "tag": f"phase {phase:+d} in", "f_hz": 0.95 * f_lim,
                    "transitions": 1500, "direction": d},
                   {"unit": unit, "tag": f"phase {phase:+d} out", "f_hz": 1.3 * f_lim,
                    "transitions": 1500, "direction": -d}]
    await check_points(dut, rng, points, inside_max=1.0, outside_min=1.3)


@cocotb_test()
async def state_width_error_sweep(dut):
    """At 200 kHz, state-width error up to the limit the count rule allows there, and past it."""
    rng = await start(dut)
    f = F_200K
    ds_limit = 90.0 - MARGIN * CLK_NS * 1e-9 * f * 360.0
    dut._log.info("at %.0f Hz the narrowest state must be >= 1.05 clocks: ΔS <= %.2f e°", f, ds_limit)
    points = []
    for i, ds in enumerate((0, 30, 60, 75, 80, 83, 86, 88)):
        unit = clean_unit(ds / 2, (ds / 2, ds / 2))   # narrowest state 00 = 90 - ΔS
        points.append({"unit": unit, "tag": f"dS {ds}", "f_hz": f, "transitions": 1000,
                       "direction": 1 if i % 2 == 0 else -1})
    results = await check_points(dut, rng, points, inside_max=1.0, outside_min=1.2)
    for p, res in zip(points, results):
        ds = float(p["tag"].split()[1])
        assert abs(res["state_error_deg"] - ds) < 0.01, f"model gave ΔS {res['state_error_deg']:.3f}"
        if ds < ds_limit:
            assert res["exact"]
        else:
            must_flag(res)


@cocotb_test()
async def temperature_sweep(dut):
    """Worst-case α: the pulse width moves by α ΔT f, the counts stay exact inside the limit."""
    rng = await start(dut)
    alpha = note.ALPHA_WORST
    cases = [(F_200K, 25.0, alpha), (F_200K, 32.5, alpha), (F_200K, 40.0, alpha),
             (F_200K, 42.5, alpha), (F_200K, 60.0, note.ALPHA_TYPICAL),
             (25e3, 25.0, alpha), (25e3, 47.5, alpha), (25e3, 70.0, alpha)]
    for i, (f, t, a) in enumerate(cases):
        unit = clean_unit(0.0, (0.0, 0.0), temp_c=t, alpha=a)
        n = 1000 if f > 1e5 else 200
        res = await run_point(dut, {"unit": unit, "tag": f"{f / 1e3:.4g} kHz {t:g} C a={a:g}",
                                    "f_hz": f, "transitions": n,
                                    "direction": 1 if i % 2 == 0 else -1}, rng)
        assert_no_silent_loss(res)
        moved = res["pulse_a_mean_deg"] - 180.0
        want = a * (t - note.T_REF_C) * f
        dut._log.info("  %s: pulse A %.3f e°, moved %.3f e°, α ΔT f = %.3f e°",
                      res["tag"], res["pulse_a_mean_deg"], moved, want)
        assert abs(moved - want) < 0.01 and abs(res["pulse_b_mean_deg"] - 180.0 - want) < 0.01, (
            f"{res['tag']}: pulse width moved {moved:.3f} e°, expected α ΔT f = {want:.3f}")
        if res["f_hz"] <= res["f_limit_hz"]:
            assert_exact(res)
        else:
            must_flag(res)


@cocotb_test()
async def sampling_rule(dut):
    """FILTER_LEN = 1, one sample per clock: T_p <= T_s (1 - ΔS_max/90) is exactly the boundary."""
    rng = await start(dut)
    assert filter_len(dut) == 1
    tp_ns = CLK_NS
    for tag, unit, clean in [("dS 0", clean_unit(0.0), True), ("dS 30", clean_unit(30.0), True),
                             ("dS 60", clean_unit(30.0, (30.0, 30.0)), True),
                             ("typical", typical_unit(rng.randrange(2**32)), False)]:
        lim = limits({"unit": unit, "f_hz": 1e5, "transitions": 2000}, 1)
        f_rule = lim["f_sampling_rule_hz"]
        ts_ns = 1e9 / (4 * f_rule)
        dut._log.info("%s: ΔS_max %.2f e°: T_p = %.3f ns <= T_s (1 - ΔS/90) allows f <= %.0f Hz "
                      "(T_s = %.2f ns)", tag, lim["state_error_deg"], tp_ns, f_rule, ts_ns)
        for k, ratio in enumerate((0.98, 1.03, 1.6)):   # x DETUNE: 0.9813, 1.0313, 1.602
            res = await run_point(dut, {"unit": unit, "tag": f"{tag} rule x{ratio}",
                                        "f_hz": ratio * f_rule * DETUNE, "transitions": 2000,
                                        "direction": 1 if k % 2 == 0 else -1}, rng)
            assert_no_silent_loss(res)
            if ratio < 1:
                assert_exact(res)
            elif clean or ratio > 1.5:
                must_flag(res)


SETS = {
    3: "frequency_sweep,count_limit_boundary,phase_error_sweep,state_width_error_sweep,temperature_sweep",
    1: "frequency_sweep,count_limit_boundary,sampling_rule",
}


@pytest.mark.parametrize("filter_len", sorted(SETS, reverse=True))
def test_sweeps(filter_len):
    run("enc_quad_probe", __name__, name=f"sweeps_F{filter_len}",
        parameters={"FILTER_LEN": filter_len}, tb_sources=("enc_quad_probe.v",),
        testcase=SETS[filter_len])
