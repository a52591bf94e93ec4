# SPDX-License-Identifier: Apache-2.0
"""The demo's printed report: the run's header, the position table (every counter, the phase
meter, the characterizer, the narrowest state), the velocity table, the verdicts."""

from __future__ import annotations

from .config import (CPR, DITHER_PERIODS, LEVEL_LIMIT, READ_TAU, SAMPLING_LIMIT, STALL_TAU,
                     TEST_LIMIT_DEG, VEL_HW_TICKS, VEL_SHOW_PCT, VEL_TOL_PCT)
from .plan import Plan

LINE = "-" * 106


def _row(name, reads="", truth="", flags=""):
    print(f"{name:<24}{reads:<34}{truth:<32}{flags}".rstrip())


def _header(plan: Plan) -> None:
    o, u = plan.opts, plan.unit
    pa, pb = u.pulse_error_deg
    f = o.rpm / 60 * CPR
    print(f"HEDS-5000 demo: {o.rpm:g} rpm peak ({f / 1e3:g} kHz, 4X {4 * f / 1e3:g} kHz), "
          f"reverse {-o.rpm / 5:g} rpm, {o.temp_c:g} degC, clock {plan.clk_hz / 1e6:.4g} MHz "
          f"({plan.cpc:.1f} clocks/cycle), seed {o.seed}")
    print(f"unit (typical: the note's table means): phase {u.phase_error_deg:+.1f}, pulse A "
          f"{pa:+.1f} / B {pb:+.1f} e-deg, eccentricity {u.eccentricity_mm * 1000:.0f} um TIR, "
          f"radial play {u.radial_play_mm * 1000:.0f} um, axial {u.axial_play_mm * 1000:.0f} um")
    print(f"profile: {plan.profile.duration_s * 1e3:.2f} ms, {len(plan.wf.events) - 1} transitions"
          f" (0 -> {o.rpm:g} -> hold -> {-o.rpm / 5:g} rpm -> stop -> dither {DITHER_PERIODS} x "
          f"+-{plan.dither_amp:.0f} e-deg about A-fall edge m={plan.dither_edge})")


def _counter_rows(res: dict, an: dict) -> None:
    fin, dith, ht = res["final"], res["dither"], res["hold_test"]
    p, p2 = an["p"], an["p2"]
    _row("true position", "", f"4X {p}, 2X {p2}, {p / 4:.2f} cycles")
    _row("enc_x4_decoder (4X)", f"count {fin['x4_count']}", f"{p}", f"error x{fin['n_x4_err']}")
    _row("enc_qei_wb (x4, bus)", f"COUNT {an['vel']['count']} (read over Wishbone)", f"{p}")
    _row("enc_x2_xor (2X)", f"count {fin['x2_count']}", f"{p2}", f"error x{fin['n_x2_err']}")
    n1 = fin["x1_count"]
    _row("enc_x1_hysteresis (1X)", f"count {n1} (4n - p = {4 * n1 - p:+d})",
         f"{p / 4:.2f} cycles; |4n - p| < 8", f"error x{fin['n_x1_err']}")
    _row("  while dithering", f"1X pulses {dith['x1_pulses']}, net {dith['x1_net']:+d}",
         f"4X pulses {dith['x4_pulses']}, net {dith['x4_net']:+d}", f"2X net {dith['x2_net']:+d}")
    bcd = fin["bcd_count"]
    _row("enc_updown_buffer", f"BCD {bcd:04x}, rd_data {fin['bcd_rd']:04x}",
         f"{p2 % 10000:04d} (2X mod 10^4)", f"glitch/error x{fin['n_bcd_flag']}")
    _row("  hold (inhibit) test", f"rd_data {'frozen' if ht['frozen'] else 'MOVED'} {ht['clocks']} clk",
         f"count moved {ht['moved']} meanwhile",
         "caught up <= 2 clk" if ht["caught_up"] else "caught up LATE")


def _meter_rows(plan: Plan, res: dict, an: dict) -> None:
    leds = res["leds"]
    for rd, tp, err in an["pm_rows"]:
        _row("enc_phase_meter", f"phase_err {rd['phase_err'] / 256:+.3f} deg",
             f"{tp['phase'] - 90:+.3f} deg ({tp['cycles']} cycles)",
             f"error {err:+.3f} (<= {an['pm_bound']:.2f})")
    led = {(1, 0): "A leads (red LED)", (0, 1): "B leads"}
    _row("  LEDs fwd / reverse", f"{led.get(tuple(leds['hold']), leds['hold'])} / "
         f"{led.get(tuple(leds['back']), leds['back'])}", "A leads / B leads",
         "" if an["pm_in_contract"] else f"{plan.cpc:.0f} clk/cycle < 100")
    for rd, pairs, dev, _ in an["ch_rows"]:
        _row("enc_characterizer", "max error, e-deg:", "model, same cycles:", f"pass={rd['pass']}")
        for k, (a, b) in pairs.items():
            _row(f"  {k}", f"{a:.2f}", f"{b:.2f}",
                 f"(limit {TEST_LIMIT_DEG:g})" if k == "min state" else "")
    _row("narrowest state", f"{an['m_all'].min_state_ns:.1f} ns = {an['min_clk']:.1f} clocks",
         f"limit {SAMPLING_LIMIT} / {LEVEL_LIMIT:.2f} clk (level)", f"glitch x{res['final']['n_glitch']}")


def print_report(plan: Plan, res: dict, an: dict) -> None:
    _header(plan)
    print(LINE)
    _row("", "circuit reads", "truth (model) / limit", "flags")
    print(LINE)
    _counter_rows(res, an)
    _meter_rows(plan, res, an)
    print(LINE)
    print_velocity(plan, an["vel"])
    print(LINE)
    for name, ok, why in an["verdicts"]:
        print(f"  {'PASS' if ok else 'FAIL'}  {name:<20} {why}")
    print(LINE)


def _velocity_row(r: dict) -> None:
    err = f"{r['err']:+.2f}" if r["err"] is not None else "-"
    check = (("ok" if r["ok"] else "FAIL") + f" (<= {VEL_TOL_PCT:g} %)") if r["checked"] else ""
    if not r["hw_ok"]:
        check = (check + " " if check else "") + f"REGISTERS != MODEL EDGES ({r['mt_exact']:.1f})"
    if r["stalled"]:
        check = (check + " " if check else "") + "STALLED"
    print(f"{r['t_ms']:8.3f}  {r['seg']:<9}{r['true'] + 0.0:10.1f}{r['mt'] + 0.0:12.1f}{err:>9}"
          f"{r['m'] + 0.0:10.1f}{r['edge_delta']:17d}  {check}".rstrip())


def _velocity_rows(plan: Plan, vel: dict) -> None:
    """One row per read, the hold's middle rows summed up in one line."""
    rows = vel["rows"][1:]
    hold = [r for r in rows if r["seg"] == "hold"]
    middle = hold[2:-1] if len(hold) > 4 else []
    mid_ids = {r["k"] for r in middle}
    for r in rows:
        if r["k"] not in mid_ids:
            _velocity_row(r)
        elif r is middle[0]:
            e = [x["err"] for x in middle if x["err"] is not None]
            bad = sum(1 for x in middle if (x["checked"] and not x["ok"]) or not x["hw_ok"])
            print(f"{'':8}  {'hold':<9}... {len(middle)} more reads at {plan.opts.rpm:g} rpm: "
                  f"M/T error {min(e):+.2f} .. {max(e):+.2f} %"
                  + (f", {bad} FAILED" if bad else ", all ok"))


def print_velocity(plan: Plan, vel: dict) -> None:
    """The velocity table: how enc_qei_wb is read, one row per read, the summary."""
    f_read = 1e3 / vel["read_us"]
    print(f"velocity: enc_qei_wb read over Wishbone every {READ_TAU:g} cycles at the peak speed "
          f"({vel['read_us']:.4g} us, {f_read:.4g} kHz; {vel['n_reads']} reads, the first only "
          f"initialises); hedsmodel.velocity")
    print(f"  M/T = SNAP_EDGE_DELTA / dSNAP_EDGE_TIME on A-rising edges, standstill rule, STALL_TIMEOUT "
          f"{vel['stall_ticks']} ticks ({STALL_TAU:g} cycles); M = SNAP_DELTA / dSNAP_TIME")
    print(LINE)
    print(f"{'t (ms)':>8}  {'segment':<9}{'true rpm':>10}{'M/T A-rise':>12}{'error %':>9}"
          f"{'M rpm':>10}{'SNAP_EDGE_DELTA':>17}  check")
    print(LINE)
    _velocity_rows(plan, vel)
    print(LINE)
    print(f"  M/T at constant speed (both edges and the read in the hold or the back): "
          f"{vel['checked']} reads, error rms {vel['rms']:.2f} %, max {vel['max']:.2f} % "
          f"(tolerance {VEL_TOL_PCT:g} %: the encoder's own floor)")
    print(f"  registers vs the same estimator on the model's exact edge times: max "
          f"{vel['worst_hw']:.3g} % of the reading (allowed there {vel['hw_allow']:.2g} %, "
          f"{VEL_HW_TICKS:g} ticks); SNAP_EDGE_DELTA = model count {vel['n_cnt'] - vel['n_cnt_bad']}/"
          f"{vel['n_cnt']}; readings of 0 while turning (>= {VEL_SHOW_PCT:g} % of peak): "
          f"{vel['zeros']}")
    print("  error % is against the speed at the read: in ramps it is mostly the method's lag (a "
          "reading is the mean speed between two A-rising edges)")
