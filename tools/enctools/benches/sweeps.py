# SPDX-License-Identifier: Apache-2.0
"""Shared logic of the counting-circuit sweeps: tb/sweeps/test_sweeps.py and scripts/sweep.py.

A sweep *point* is one constant-speed run of one modelled HEDS-5000 unit (the hedsmodel package, python/) played
into tb/hdl/enc_quad_probe.v (enc_conditioner -> enc_x4_decoder, enc_x2_xor, enc_x1_hysteresis,
each with a net-count accumulator and flag counters) at the default 12 MHz clock (T = 83.333 ns).
Points are plain dicts (JSON-able, so a script can hand a list to a simulation through the
environment)::

    {"f_hz": 2e5, "transitions": 4000, "direction": 1, "unit": {EncoderUnit fields}, "tag": "..."}

For every point :func:`run_point` resets the probe with the inputs held in state 00 (the state
enc_conditioner resets to) through rst and FILTER_LEN + 6 clocks after it, so the decoders'
reference state is the true one, plays
the unit's waveform from the middle of the 00 state before cycle 0, starting at a random phase of
the clock, waits FILTER_LEN + 6 clocks and reads the accumulators. The truth comes from the
waveform itself (``Waveform.positions``: the states the unit's outputs actually show), the timing
from :func:`hedsmodel.measure` and from the event list:

- ``exact``: pos4 == true 4X change, pos2 == true 2X change ((p + 1) // 2, enctools.tb.models),
  |4 pos1 - p| < 8 (the contract's 1X hysteresis bound), and no error / glitch flag at all;
- ``silent4`` / ``silent2`` / ``silent1``: a count is wrong (pos1: out of its bound) and its path
  raised no flag (n_err4 / n_err2 / n_err1 + n_glitch = 0): the one outcome the contract never
  allows;
- the prediction: ``scripts/error_budget.py count-limit`` (hedsmodel.budget.count_limit) with the
  point's *measured* state-width and pulse-width errors, plus the direct form of the contract's
  count-rate rule on the measured narrowest state and level (>= 1.05 T and >= 1.05 F T);
- the note's sampling rule T_p <= T_s (1 - ΔS_max / 90) with T_p = the clock period.
"""

from __future__ import annotations

import json
import math
import os
import random
from dataclasses import asdict

import cocotb
from cocotb.triggers import FallingEdge, Timer

from hedsmodel import EncoderUnit, Profile, budget, measure
from enctools import tb as tbutil
from enctools.tb.models import two_x_count
from cocotbext.quadrature import play
from enctools.tb import cocotb_test, reset_dut

CLK_PS = 83333                  # 12 MHz clock period, ps (odd: start_clock handles it)
CLK_NS = CLK_PS / 1000.0
CLK_HZ = 1e12 / CLK_PS
MARGIN = budget.COUNT_MARGIN    # the contract's 1.05
X1_BOUND = 8                    # contract: |4 n - p| < 8


# ------------------------------------------------------------------------------ stimulus side
def unit_dict(unit: EncoderUnit) -> dict:
    d = asdict(unit)
    d["pulse_error_deg"] = list(d["pulse_error_deg"])
    return d


def make_unit(spec: dict) -> EncoderUnit:
    return EncoderUnit(**spec)


def start_deg(unit: EncoderUnit) -> float:
    """The middle of the unit's state 00 just before cycle 0 (4X position 0), in e°: between edge
    m = -1 (B fall of cycle -1) and m = 0 (A rise of cycle 0), wherever the errors put them."""
    xe = unit.edges(-1, 1)
    return 180.0 * (xe[3] + xe[4])


def waveform(point: dict):
    """The point's unit and its waveform: ``transitions`` transitions at ``f_hz`` in ``direction``
    (from the middle of state 00), plus a short standstill so that late (delayed) edges land."""
    unit = make_unit(point["unit"])
    f = float(point["f_hz"])
    n = int(point["transitions"])
    rpm = f * 60.0 / unit.cpr * (1 if point.get("direction", 1) > 0 else -1)
    profile = Profile(start_deg=start_deg(unit), cpr=unit.cpr).constant(rpm, n / 4.0 / f)
    profile.stop(1.0 / f)
    return unit, unit.waveform(profile)


def min_level_ns(wf) -> float:
    """Narrowest level of A or B (time between two consecutive changes of the same channel)."""
    best = math.inf
    for ch in (1, 2):
        last_t, last_v = None, wf.events[0][ch]
        for ev in wf.events[1:]:
            if ev[ch] != last_v:
                if last_t is not None:
                    best = min(best, ev[0] - last_t)
                last_t, last_v = ev[0], ev[ch]
    return best


def true_counts(wf) -> tuple[int, int] | None:
    """(4X, 2X) change of the waveform; None if it ends on an ill-defined position."""
    p = [q for q in wf.positions if q is not None]
    if wf.positions[0] is None or wf.positions[-1] is None:
        return None
    d4 = p[-1] - p[0]
    return d4, two_x_count(p[-1]) - two_x_count(p[0])


def predict(f_hz: float, filter_len: int, state_error_deg: float, pulse_error_deg: float,
            min_state_ns: float, min_lvl_ns: float) -> dict:
    """The count limit two ways, and the one the tests hold the circuit to:

    - ``f_pred_hz``: ``scripts/error_budget.py count-limit`` (budget.count_limit) fed with the
      waveform's measured errors (measure(): ΔS = largest |state - 90|, ΔP = largest |high pulse
      - 180|, the note's definitions);
    - ``f_direct_hz``: the contract's rule on the narrowest state and level actually present
      (>= 1.05 T and >= 1.05 F T); at constant speed they scale as 1 / f. It sees low levels,
      which the note's pulse-width error (high pulses only) does not;
    - ``f_limit_hz``: the smaller of the two, below which counting must be exact.
    """
    cl = budget.count_limit(clk_hz=CLK_HZ, filter_len=filter_len,
                            state_error_deg=min(state_error_deg, 89.999),
                            pulse_error_deg=min(pulse_error_deg, 179.999))
    direct = f_hz * min(min_state_ns / (MARGIN * CLK_NS),
                        min_lvl_ns / (MARGIN * filter_len * CLK_NS))
    return {"f_pred_hz": cl["f_max_hz"], "binding": cl["binding"], "f_direct_hz": direct,
            "f_limit_hz": min(cl["f_max_hz"], direct)}


def sampling_rule_f_max(state_error_deg: float, tp_s: float = CLK_PS * 1e-12) -> float:
    """The note's programmed-input rule solved for frequency: f_max = (1 - ΔS/90) / (4 T_p)."""
    return budget.sampling_speed(tp_s, min(state_error_deg, 89.999))["f_max_hz"]


# ------------------------------------------------------------------------------ cocotb side
def filter_len(dut) -> int:
    return int(dut.FILTER_LEN.value)


async def start(dut) -> random.Random:
    """Start the 12 MHz clock, log the seed, return an RNG seeded from it."""
    return await tbutil.start(dut, CLK_PS, {"a_in": 0, "b_in": 0}, do_reset=False)


async def play_and_count(dut, wf, rng: random.Random) -> dict:
    """Reset the probe in state 00, play ``wf`` from a random clock phase, return the counts."""
    fl = filter_len(dut)
    dut.a_in.value, dut.b_in.value = wf.events[0][1], wf.events[0][2]
    await reset_dut(dut)
    for _ in range(fl + 6):
        await FallingEdge(dut.clk)
    await Timer(rng.randrange(1, CLK_PS), unit="ps")
    await play(dut, wf)
    for _ in range(fl + 6):
        await FallingEdge(dut.clk)
    out = {k: int(getattr(dut, k).value.to_signed()) for k in ("pos4", "pos2", "pos1")}
    out |= {k: int(getattr(dut, k).value) for k in ("n_err4", "n_err2", "n_err1", "n_glitch")}
    return out


def judge(counts: dict, true4: int, true2: int) -> dict:
    ok4 = counts["pos4"] == true4
    ok2 = counts["pos2"] == true2
    ok1 = abs(4 * counts["pos1"] - true4) < X1_BOUND
    flags = counts["n_err4"] + counts["n_err2"] + counts["n_err1"] + counts["n_glitch"]
    return {
        "ok4": ok4, "ok2": ok2, "ok1": ok1, "flags": flags,
        "exact": ok4 and ok2 and ok1 and flags == 0,
        "silent4": not ok4 and counts["n_err4"] + counts["n_glitch"] == 0,
        "silent2": not ok2 and counts["n_err2"] + counts["n_glitch"] == 0,
        "silent1": not ok1 and counts["n_err1"] + counts["n_glitch"] == 0,
    }


async def run_point(dut, point: dict, rng: random.Random) -> dict:
    """Simulate one point; returns the point, its measurement, prediction, counts and verdict."""
    fl = filter_len(dut)
    unit, wf = waveform(point)
    m = measure(wf)
    truth = true_counts(wf)
    assert truth is not None, f"{point.get('tag')}: the model's waveform ends on an ill-defined state"
    true4, true2 = truth
    lvl = min_level_ns(wf)
    f = float(point["f_hz"])
    pred = predict(f, fl, m.state_error_deg, m.pulse_error_deg, m.min_state_ns, lvl)
    counts = await play_and_count(dut, wf, rng)
    verdict = judge(counts, true4, true2)
    res = {
        "tag": point.get("tag", ""), "f_hz": f, "filter_len": fl,
        "direction": point.get("direction", 1), "transitions": len(wf.events) - 1,
        "phase_error_deg": unit.phase_error_deg, "temp_c": unit.temp_c, "alpha": unit.alpha,
        "state_error_deg": m.state_error_deg, "pulse_error_deg": m.pulse_error_deg,
        "pulse_a_mean_deg": float(m.pulse_a_deg.mean()) if m.cycles else math.nan,
        "pulse_b_mean_deg": float(m.pulse_b_deg.mean()) if m.cycles else math.nan,
        "min_state_ns": m.min_state_ns, "min_level_ns": lvl,
        "min_state_clk": m.min_state_ns / CLK_NS, "min_level_clk": lvl / CLK_NS,
        "f_sampling_rule_hz": sampling_rule_f_max(m.state_error_deg),
        "true4": true4, "true2": true2, **pred, **counts, **verdict,
    }
    dut._log.info(
        "%-22s f %9.1f Hz (%7.3f x limit %9.1f Hz, %s) dS %5.1f dP %5.1f e°, min state %5.2f clk, "
        "min level %5.2f clk | pos4 %d/%d pos2 %d/%d pos1 %d err4 %d err2 %d err1 %d glitch %d -> %s",
        res["tag"], f, f / res["f_limit_hz"], res["f_limit_hz"], res["binding"], m.state_error_deg,
        m.pulse_error_deg, res["min_state_clk"], res["min_level_clk"], counts["pos4"], true4,
        counts["pos2"], true2, counts["pos1"], counts["n_err4"], counts["n_err2"], counts["n_err1"],
        counts["n_glitch"],
        "exact" if verdict["exact"] else ("SILENT LOSS" if verdict["silent4"] or verdict["silent2"] or verdict["silent1"]
                                          else "flagged"))
    return res


def assert_no_silent_loss(res: dict) -> None:
    assert not res["silent4"], (f"{res['tag']} at {res['f_hz']:.1f} Hz: x4 count wrong "
                                f"(pos4 {res['pos4']} vs {res['true4']}) with no error or glitch flag")
    assert not res["silent1"], (f"{res['tag']} at {res['f_hz']:.1f} Hz: x1 count out of its bound "
                                f"(pos1 {res['pos1']} vs 4X {res['true4']}) with no error or glitch flag")
    assert not res["silent2"], (f"{res['tag']} at {res['f_hz']:.1f} Hz: x2 count wrong "
                                f"(pos2 {res['pos2']} vs {res['true2']}) with no error or glitch flag")


def assert_exact(res: dict) -> None:
    assert res["exact"], (
        f"{res['tag']} at {res['f_hz']:.1f} Hz (inside the limit {res['f_limit_hz']:.1f} Hz; "
        f"min state {res['min_state_clk']:.3f} clk, min level {res['min_level_clk']:.3f} clk): "
        f"pos4 {res['pos4']} (true {res['true4']}), pos2 {res['pos2']} (true {res['true2']}), "
        f"pos1 {res['pos1']}, err4 {res['n_err4']}, err2 {res['n_err2']}, err1 {res['n_err1']}, "
        f"glitch {res['n_glitch']}")


def limits(point: dict, filter_len: int) -> dict:
    """Measure the point's waveform (no simulation) and return :func:`predict` for it, plus the
    measured errors. For a unit at 25 °C the errors in e° do not depend on the frequency, so this
    is the unit's count limit whatever ``point["f_hz"]`` is."""
    _, wf = waveform(point)
    m = measure(wf)
    out = predict(float(point["f_hz"]), filter_len, m.state_error_deg, m.pulse_error_deg,
                  m.min_state_ns, min_level_ns(wf))
    return out | {"state_error_deg": m.state_error_deg, "pulse_error_deg": m.pulse_error_deg,
                  "f_sampling_rule_hz": sampling_rule_f_max(m.state_error_deg)}


def boundary(results: list[dict]) -> tuple[float, float]:
    """(highest frequency below the first non-exact one, first non-exact frequency) of a grid."""
    rs = sorted(results, key=lambda r: r["f_hz"])
    last_ok, first_bad = math.nan, math.nan
    for r in rs:
        if r["exact"]:
            last_ok = r["f_hz"]
        else:
            first_bad = r["f_hz"]
            break
    return last_ok, first_bad


async def boundary_search(dut, base: dict, rng: random.Random, lo: float = 0.98,
                          hi: float = 1.20, step: float = 0.005,
                          transitions: int = 4000, strict: bool = True, on_result=None) -> dict:
    """Walk a fine grid f_limit x [lo, hi] upwards until the count stops being exact.

    The grid is walked, not bisected, so every point up to the cliff is checked: the cliff is
    statistical (a state a little under one clock is missed only when no clock edge falls in
    it), so a bisection could step over a failure. Every point must be free of silent loss and
    every point at or under the limit exact (asserted here unless ``strict`` is false). Returns the limit, the highest
    exact frequency (the measured boundary), the first failing one and all results."""
    fl = filter_len(dut)
    lim = limits(dict(base, transitions=transitions, f_hz=base.get("f_hz", 1e5)), fl)
    f_lim = lim["f_limit_hz"]
    results = []
    k = 0
    while lo + k * step <= hi + 1e-9:
        ratio = lo + k * step
        res = await run_point(dut, dict(base, f_hz=f_lim * ratio, transitions=transitions,
                                        tag=f"{base.get('tag', 'boundary')} x{ratio:.3f}"), rng)
        results.append(res)
        if on_result is not None:
            on_result(res)
        if strict:
            assert_no_silent_loss(res)
            if ratio <= 1.0 + 1e-9:
                assert_exact(res)
        k += 1
        if not res["exact"]:
            break
    ok, bad = boundary(results)
    return {"tag": base.get("tag", ""), "filter_len": fl, **lim, "measured_hz": ok,
            "first_bad_hz": bad, "ratio": ok / f_lim, "results": results}


@cocotb_test()
async def sweep_points(dut):
    """scripts/sweep.py: run the job in $ENC_SWEEP_POINTS (a JSON file: {"points": [point, ...],
    "boundary": [point, ...]}; a boundary entry is a unit to walk up to its count limit) and
    write the results to $ENC_SWEEP_OUT. Prints a progress line per point to stdout."""
    rng = await start(dut)
    with open(os.environ["ENC_SWEEP_POINTS"]) as f:
        spec = json.load(f)
    fl = filter_len(dut)
    out = {"filter_len": fl, "points": [], "boundaries": []}
    n_points, n_walks = len(spec.get("points", [])), len(spec.get("boundary", []))
    where = [""]

    def progress(res):
        state = ("exact" if res["exact"] else "flagged" if not (res["silent4"] or res["silent2"]
                 or res["silent1"]) else "WRONG COUNT WITHOUT A FLAG")
        print(f"sweep F={fl} {where[0]} {res['tag']}: {res['f_hz'] / 1e3:9.2f} kHz "
              f"({res['f_hz'] / res['f_limit_hz']:6.3f} x limit {res['f_limit_hz'] / 1e3:8.2f} kHz)"
              f": {state}", flush=True)

    for i, point in enumerate(spec.get("points", [])):
        where[0] = f"point {i + 1}/{n_points}"
        res = await run_point(dut, point, rng)
        out["points"].append(res)
        progress(res)
    for i, base in enumerate(spec.get("boundary", [])):
        where[0] = f"walk {i + 1}/{n_walks}"
        b = await boundary_search(dut, base, rng, on_result=progress,
                                  **spec.get("boundary_args", {}))
        out["boundaries"].append(b)
        print(f"sweep F={fl} {where[0]} {b['tag']}: limit {b['f_limit_hz']:.0f} Hz, "
              f"highest exact {b['measured_hz']:.0f} Hz (ratio {b['ratio']:.4f}), "
              f"{len(b['results'])} points", flush=True)
    with open(os.environ["ENC_SWEEP_OUT"], "w") as f:
        json.dump(out, f, indent=1, default=float)
