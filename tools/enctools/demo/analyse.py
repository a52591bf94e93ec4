# SPDX-License-Identifier: Apache-2.0
"""The bench's records against the model: one verdict per circuit (the counters, the BCD buffer,
the phase meter, the characterizer; enc_qei_wb's in analyse_qei), and the rows the tables show."""

from __future__ import annotations

from .analyse_qei import analyze_velocity, qei_verdict
from .config import (CHAR_CNT_W, CHAR_CYCLES, FILTER_LEN, LEVEL_LIMIT, PM_BOUND, PM_MIN_CPC,
                     TEST_LIMIT_DEG)
from .plan import Plan, a_rises, events_between


def a_edges(p: int) -> int:
    """Net transitions of A from position 0 to 4X position p (edges m = 0, 2 mod 4 are A's)."""
    return -(-p // 2)


def _match_rises(dut_rises_ps, model_rises, clk_ps):
    """Map each conditioned-A rise seen in the DUT to the model event that caused it (latency
    2 + FILTER_LEN clocks, plus up to one of sampling)."""
    import bisect
    times = [t for t, _ in model_rises]
    out = {}
    for r in dut_rises_ps:
        j = bisect.bisect_right(times, r - (1 + FILTER_LEN) * clk_ps) - 1
        if j >= 0 and r - times[j] <= (4 + FILTER_LEN) * clk_ps:
            out[r] = model_rises[j][1]
    return out


def _measure_rises(plan: Plan, res: dict, rises: list):
    """hedsmodel.measure over the model cycles between the first and last of the DUT's A rises
    ``rises`` (None if either matches no model edge)."""
    from hedsmodel import measure
    mapping = _match_rises(rises, a_rises(plan.wf, res["t0_ps"]), plan.clk_ps)
    if rises[0] not in mapping or rises[-1] not in mapping:
        return None
    return measure(events_between(plan.wf, mapping[rises[0]] - 1, mapping[rises[-1]]),
                   window=10**6)


def true_phase(plan: Plan, res: dict, reading_ps: float):
    """The model's phase over the cycles of the phase-meter window that produced the reading at
    ``reading_ps``: measure() over those whole cycles (mean of the per-cycle phase, each cycle
    converted with the window's mean period = 180 x XOR-high time / span, what the meter reads)."""
    clk = plan.clk_ps
    w = 2 ** plan.window_log2
    # valid rises WINDOW_LOG2 + 18 clocks after the window's last sample; the window's first
    # sample is its opening rising edge of A, which the bench saw on `a` 2 clocks earlier (the
    # meter's input register and its edge detector)
    last = reading_ps - (plan.window_log2 + 18) * clk - 2 * clk
    first = last - (w - 1) * clk
    rises = [r for r in res["a_rises_ps"] if first - 0.5 * clk <= r <= last + 0.5 * clk]
    if len(rises) < 2:
        return None
    m = _measure_rises(plan, res, rises)
    if m is None:
        return None
    aligned = abs(rises[0] - first) < 0.5 * clk
    return {"phase": float(m.phase_deg.mean()), "cycles": m.cycles, "aligned": aligned,
            "first_ns": (rises[0] - res["t0_ps"]) / 1000, "last_ns": (rises[-1] - res["t0_ps"]) / 1000,
            "m": m}


def char_wide_w() -> int:
    k = 92160 * CHAR_CYCLES
    return CHAR_CNT_W + 2 + (k).bit_length()


def char_truth(plan: Plan, res: dict, valid_ps: float):
    """The model's Figure 3 numbers over the CHAR_CYCLES cycles of the characterizer window whose
    results landed at ``valid_ps`` (the window closes on the A rise ~8 x WIDE_W clocks before)."""
    before = [r for r in res["a_rises_ps"] if r <= valid_ps - 8 * char_wide_w() * plan.clk_ps]
    if len(before) < CHAR_CYCLES + 1:
        return None
    rises = before[-(CHAR_CYCLES + 1):]
    m = _measure_rises(plan, res, rises)
    if m is None:
        return None
    return {"m": m, "first_ns": (rises[0] - res["t0_ps"]) / 1000,
            "last_ns": (rises[-1] - res["t0_ps"]) / 1000}


def counter_verdicts(res: dict, p: int, p2: int, min_clk: float) -> list:
    """(name, ok, why) for the conditioner and the 4X, 2X and 1X counters."""
    fin, dith = res["final"], res["dither"]
    out = []
    ok = fin["n_glitch"] == 0 and min_clk >= LEVEL_LIMIT
    out.append(("enc_conditioner", ok,
                "no glitch flagged; every state wider than the filter" if ok else
                f"{fin['n_glitch']} glitches flagged" if fin["n_glitch"] else
                f"narrowest state {min_clk:.2f} clocks < {LEVEL_LIMIT:.2f}"))
    ok = fin["x4_count"] == p and fin["n_x4_err"] == 0
    out.append(("enc_x4_decoder", ok, "count = true 4X position, no error pulse" if ok else
                f"count {fin['x4_count']} vs {p}, {fin['n_x4_err']} error pulses"))
    ok = fin["x2_count"] == p2 and fin["n_x2_err"] == 0
    out.append(("enc_x2_xor", ok, "count = true 2X position, no error pulse" if ok else
                f"count {fin['x2_count']} vs {p2}, {fin['n_x2_err']} error pulses"))
    d = p - 4 * fin["x1_count"]
    ok = -1 <= d <= 3 and fin["n_x1_err"] == 0 and dith["x1_pulses"] <= 1
    out.append(("enc_x1_hysteresis", ok,
                f"p - 4n = {d} in -1..3; {dith['x1_pulses']} pulse(s) in the dither" if ok else
                f"p - 4n = {d} (band -1..3), {fin['n_x1_err']} errors, "
                f"{dith['x1_pulses']} pulses while dithering"))
    return out


def buffer_verdict(res: dict, p2: int) -> tuple:
    """The Figure 17 BCD buffer: the 2X count mod 10^4, and rd_data held by the inhibit."""
    fin, ht = res["final"], res["hold_test"]
    bcd = fin["bcd_count"]
    bcd_val = int(f"{bcd:04x}") if all(c in "0123456789" for c in f"{bcd:04x}") else None
    want = p2 % 10000
    ok = (bcd_val == want and fin["bcd_rd"] == bcd and fin["n_bcd_flag"] == 0 and ht["frozen"]
          and ht["moved"] > 0 and ht["caught_up"])
    return ("enc_updown_buffer", ok,
            f"BCD = 2X mod 10^4; rd_data frozen during hold while the count moved {ht['moved']}"
            if ok else
            f"BCD {bcd:04x} vs {want:04d}, rd {fin['bcd_rd']:04x}, flags {fin['n_bcd_flag']}, "
            f"hold frozen={ht['frozen']} moved={ht['moved']} caught_up={ht['caught_up']}")


def phase_meter(plan: Plan, res: dict) -> dict:
    """Readings of constant-speed windows against the model's phase over the same cycles, the
    bound (the contract's 0.25 degree at >= 100 clocks per cycle, else one clock) and the verdict."""
    hold0, hold1 = plan.seg["hold"]
    rows, worst, misaligned = [], None, 0
    in_contract = plan.cpc >= PM_MIN_CPC
    bound = PM_BOUND if in_contract else max(PM_BOUND, 360.0 / plan.cpc)
    for rd in res["pm_readings"]:
        tp = true_phase(plan, res, rd["t_ps"])
        if tp is None or not (hold0 <= tp["first_ns"] and tp["last_ns"] <= hold1):
            continue
        if not tp["aligned"]:
            misaligned += 1  # the window's opening edge is not where the contract timing says
            continue
        err = rd["phase_err"] / 256.0 - (tp["phase"] - 90.0)
        rows.append((rd, tp, err))
        if worst is None or abs(err) > abs(worst[2]):
            worst = (rd, tp, err)
    leds = res["leds"]
    if worst is None:
        verdict = ("enc_phase_meter", False, "no reading from a constant-speed window" +
                   (f" ({misaligned} window(s) not where the contract's timing puts them)"
                    if misaligned else ""))
    else:
        ok = abs(worst[2]) <= bound and leds["hold"] == [1, 0] and leds["back"] == [0, 1]
        verdict = ("enc_phase_meter", ok,
                   f"|error| {abs(worst[2]):.3f} <= {bound:.2f} deg over {len(rows)} reading(s); "
                   f"LEDs follow the direction" if ok else
                   f"error {worst[2]:+.3f} deg (bound {bound:.2f}); LEDs hold {leds['hold']} "
                   f"reverse {leds['back']}")
    return dict(rows=rows, bound=bound, in_contract=in_contract, verdict=verdict)


def characterizer(plan: Plan, res: dict) -> dict:
    """Each constant-speed window's Figure 3 numbers against the model's over the same cycles
    (one clock of sampling per measured width), and the verdict."""
    hold0, hold1 = plan.seg["hold"]
    rows = []
    tol = 360.0 / plan.cpc + 2.0 / 256.0     # one clock of sampling per measured width
    for rd in res["ch_readings"]:
        tr = char_truth(plan, res, rd["t_ps"])
        if tr is None or not (hold0 <= tr["first_ns"] and tr["last_ns"] <= hold1):
            continue
        m = tr["m"]
        pairs = {
            "cycle": (abs(rd["cycle_err"]) / 256, m.cycle_error_deg),
            "pulse": (abs(rd["pulse_err"]) / 256, m.pulse_error_deg),
            "phase": (abs(rd["phase_err"]) / 256, m.phase_error_deg),
            "state": (abs(rd["state_err"]) / 256, m.state_error_deg),
            "min state": (rd["state_min"] / 256, m.min_state_deg),
        }
        dev = max(abs(a - b) for a, b in pairs.values())
        pass_ok = rd["pass"] == int(m.min_state_deg >= TEST_LIMIT_DEG) or \
            abs(m.min_state_deg - TEST_LIMIT_DEG) <= tol
        rows.append((rd, pairs, dev, pass_ok))
    if not rows:
        verdict = ("enc_characterizer", False, "no result from a constant-speed window")
    else:
        dev = max(r[2] for r in rows)
        ok = dev <= tol and all(r[3] for r in rows)
        verdict = ("enc_characterizer", ok,
                   f"all within {dev:.2f} <= {tol:.2f} deg (1 clock) of the model, "
                   f"{len(rows)} window(s)" if ok else
                   f"off by {dev:.2f} deg (tolerance {tol:.2f}) or pass flag wrong")
    return dict(rows=rows, tol=tol, verdict=verdict)


def analyze(plan: Plan, res: dict) -> dict:
    """Rows of the tables and the verdicts, in the order they are printed."""
    from hedsmodel import measure

    wf = plan.wf
    p = wf.final_position - plan.start_pos
    p2 = a_edges(wf.final_position) - a_edges(plan.start_pos)
    m_all = measure(wf, window=0)
    min_clk = m_all.min_state_ns / (plan.clk_ps / 1000.0)
    pm, ch = phase_meter(plan, res), characterizer(plan, res)
    vel = analyze_velocity(plan, res)
    verdicts = counter_verdicts(res, p, p2, min_clk) + [
        buffer_verdict(res, p2), pm["verdict"], ch["verdict"], qei_verdict(vel, p)]
    return dict(p=p, p2=p2, m_all=m_all, pm_rows=pm["rows"], pm_bound=pm["bound"],
                pm_in_contract=pm["in_contract"], ch_rows=ch["rows"], ch_tol=ch["tol"],
                verdicts=verdicts, min_clk=min_clk, vel=vel)
