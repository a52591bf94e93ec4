# SPDX-License-Identifier: Apache-2.0
"""One simulated case's register words against the model: each SNAP_EDGE_TIME matched to its
model edge, the readings of the simulated registers against the floor on the same edges (the
same estimator on the model's exact edge times), and consistency checks of the latched values
(SNAP_EDGE_DELTA, PERIOD, PERIOD_CTRL.DIR_CHANGE, SNAP_DELTA) against the model."""

from __future__ import annotations

import math

from ..qei.bus import signed
from .config import DETUNE, GOAL_NONZERO_RPM, VARIANTS
from .plan import build_profile

MOD = 1 << 32   # the 32-bit timebase


def _times(raw, tb, et, edge: str) -> dict:
    """The case's clock on the model's time axis (from the calibration read of TIMEBASE): latch
    and read times of every snapshot, the selected edges and their predicted ticks (without the
    latency), the unwrapped SNAP_EDGE_TIMEs."""
    import numpy as np

    tick = tb.tick_s
    t_start = raw["t_start_ps"] * 1e-12
    t_cal = 0.5 * (raw["t_cal0_ps"] + raw["t_cal1_ps"]) * 1e-12 - t_start
    tb_cal = raw["tb_cal"]
    reads = raw["reads"]

    def unwrap(x):
        return tb_cal + ((x - tb_cal) % MOD)

    snap_u = np.array([unwrap(r["SNAP_TIME"]) for r in reads], float)
    sel = np.flatnonzero(et.a_rise) if edge == "a_rising" else np.arange(et.step.size)
    e_u = np.array([unwrap(r["SNAP_EDGE_TIME"]) for r in reads], float)
    return {"t_latch": t_cal + (snap_u - tb_cal) * tick,
            "t_read": np.array([r["t_ack_ps"] * 1e-12 - t_start for r in reads]),
            "sel": sel, "p_tick": tb_cal + (et.t_s[sel] - t_cal) / tick, "e_u": e_u,
            "fresh": e_u <= snap_u}     # else: an edge from before this case


def _match_edges(tm: dict, tick: float, clk: float, n: int):
    """Each fresh SNAP_EDGE_TIME matched to a selected model edge, nearest to the median offset
    (the latency, ticks): (median, model edge index per read, index among the selected, unmatched
    count); -1 where none."""
    import numpy as np

    e_u, p_tick, sel = tm["e_u"], tm["p_tick"], tm["sel"]
    offs = []
    for i in np.flatnonzero(tm["fresh"]):
        o = e_u[i] - p_tick
        ok = np.flatnonzero((o > -5) & (o < 100 * clk / tick + 5))
        if ok.size:
            offs.append(o[ok[np.argmin(np.abs(o[ok]))]])
    med = float(np.median(offs)) if offs else 0.0
    tol = max(3.0, 3 * clk / tick)
    last_edge = np.full(n, -1, np.int64)
    jsel = np.full(n, -1, np.int64)
    unmatched = 0
    for i in np.flatnonzero(tm["fresh"]):
        o = e_u[i] - p_tick - med
        j = int(np.argmin(np.abs(o))) if o.size else -1
        if j >= 0 and abs(o[j]) <= tol:
            last_edge[i], jsel[i] = sel[j], j
        else:
            unmatched += 1
    return med, last_edge, jsel, unmatched


def _period_pairs(reads, et, sel, jsel, t_read, tick: float):
    """The model edges each PERIOD measured. PERIOD is a live register read a few clocks after
    the snapshot: it may already hold the measurement ended by the next selected edge. Take the
    pair (j-1, j) or (j, j+1) it fits. Returns (from, to, how many were the newer pair)."""
    import numpy as np

    p_from = np.full(len(reads), -1, np.int64)
    p_to = np.full(len(reads), -1, np.int64)
    newer = 0
    for i in np.flatnonzero(jsel >= 1):
        j = int(jsel[i])
        p_from[i], p_to[i] = sel[j - 1], sel[j]
        if j + 1 < sel.size:
            fits = abs(reads[i]["PERIOD"] - (et.t_s[sel[j]] - et.t_s[sel[j - 1]]) / tick) <= 2
            fits_next = abs(reads[i]["PERIOD"] - (et.t_s[sel[j + 1]] - et.t_s[sel[j]]) / tick) <= 2
            if fits_next and not fits and et.t_s[sel[j + 1]] < t_read[i] + 2e-6:
                p_from[i], p_to[i] = sel[j], sel[j + 1]
                newer += 1
    return p_from, p_to, newer


def _snapshots(reads, bits: dict) -> list:
    from hedsmodel.velocity import Snapshot

    def flag(word, name):
        return (word >> bits[name]) & 1

    return [Snapshot(count=r["SNAP_COUNT_LO"], time=r["SNAP_TIME"], edge_time=r["SNAP_EDGE_TIME"],
                     delta=signed(r["SNAP_DELTA"]), edge_delta=signed(r["SNAP_EDGE_DELTA"]),
                     period=r["PERIOD"], period_n=1,
                     period_ovf=flag(r["PERIOD_CTRL"], "PERIOD_CTRL.OVERFLOW"),
                     period_dir_change=flag(r["PERIOD_CTRL"], "PERIOD_CTRL.DIR_CHANGE"),
                     stalled=flag(r["STATUS"], "STATUS.STALLED"))
            for r in reads]


def _edge_checks(et, snaps, last_edge, jsel, p_from, p_to, tick: float):
    """SNAP_EDGE_DELTA against the model's count between the matched edges, PERIOD against the
    time between them (+-2 ticks), PERIOD_CTRL.DIR_CHANGE against a direction change among the
    steps they span: (failed by check, checked by check)."""
    import numpy as np

    bad = {"edge_delta": 0, "period": 0, "dir": 0}
    checked = {"edge_delta": 0, "period": 0, "dir_flag": 0, "delta": 0}
    d = np.sign(et.step)
    chg = np.concatenate([[0], np.cumsum(d[1:] != d[:-1])]) if d.size else np.zeros(0)
    for i in range(1, len(snaps)):
        if jsel[i] >= 0 and jsel[i - 1] >= 0:
            checked["edge_delta"] += 1
            want = int(et.pos[last_edge[i]] - et.pos[last_edge[i - 1]])
            bad["edge_delta"] += snaps[i].edge_delta != want
        if p_to[i] >= 0:
            checked["period"] += 1
            want_p = (et.t_s[p_to[i]] - et.t_s[p_from[i]]) / tick
            bad["period"] += abs(snaps[i].period - want_p) > 2
            checked["dir_flag"] += 1
            bad["dir"] += snaps[i].period_dir_change != int(chg[p_to[i]] > chg[p_from[i]])
    return bad, checked


def _delta_check(et, snaps, seen, t_latch, n_at, clk: float, checked: dict) -> int:
    """SNAP_DELTA against the model's steps between the latching clocks (edges ``seen`` the
    latency late), where no step is within 4 clocks of either latch: how many failed."""
    import numpy as np

    bad = 0
    for i in range(1, len(snaps)):
        near = np.any(np.abs(seen - t_latch[i]) < 4 * clk) or np.any(np.abs(seen - t_latch[i - 1]) < 4 * clk)
        if near:
            continue
        checked["delta"] += 1
        want = int((et.pos[n_at[i] - 1] if n_at[i] else 0) - (et.pos[n_at[i - 1] - 1] if n_at[i - 1] else 0))
        bad += snaps[i].delta != want
    return bad


def _stop_metrics(case, et, snaps, hw, t_latch, true_t, tick: float, edge: str):
    """After the stop: when STATUS.STALLED was first seen (and not before the timeout), and when
    each method's reading went to 0 for good."""
    import numpy as np

    t_stop = max(pc.tb for pc in build_profile(case["profile"]).pieces())
    stall_s = case["stall_s"]
    stalled = np.array([sn.stalled for sn in snaps], bool)
    last_step = float(et.t_s[-1]) if et.t_s.size else 0.0
    stop = {"stall_s": stall_s, "t_stop_s": t_stop, "last_step_s": last_step,
            "stalled_at_s": float(t_latch[stalled][0]) if stalled.any() else math.nan,
            "stalled_before_timeout": bool(np.any(stalled & (t_latch < last_step + stall_s - 2 * tick)))}
    methods = {}
    for meth in ("M", "T", "MT"):
        if (meth, edge) not in VARIANTS:
            continue
        h = hw[meth]
        nz = np.flatnonzero(h != 0)
        t_zero = float(t_latch[nz[-1] + 1]) if nz.size and nz[-1] + 1 < h.size else math.nan
        methods[meth] = {"t_zero_after_stop_s": t_zero - t_stop,
                         "moving_zeros": int(np.sum((h == 0) & (true_t > 0) & (np.arange(h.size) >= 2)))}
    return stop, methods


def _method_metrics(hw, fl, true_s, denom, last_edge, last_dir, edge: str) -> dict:
    """Per method: added (registers - floor), error and floor against the truth, relative to
    ``denom``; zeros and wrong-sign readings while moving."""
    import numpy as np

    out = {}
    n = len(true_s)
    true_t = np.abs(true_s)
    for meth in ("M", "T", "MT"):
        if (meth, edge) not in VARIANTS:
            continue
        h, f = hw[meth], fl[meth]
        use = (np.arange(n) >= 2) & (f != 0) & (last_edge >= 0)
        if meth == "M":
            use = np.arange(n) >= 1
        if not use.any():
            out[meth] = {"n": 0}
            continue
        told = last_dir == np.sign(true_s)  # the encoder has shown the direction
        moving = use & (true_t >= GOAL_NONZERO_RPM) & told
        out[meth] = {   # estimate() gives rpm
            "n": int(use.sum()),
            "added_max": float(np.max(np.abs(h[use] - f[use]) / denom[use])),
            "err_max": float(np.max(np.abs(h[use] - true_s[use]) / denom[use])),
            "floor_max": float(np.max(np.abs(f[use] - true_s[use]) / denom[use])),
            "zeros": int(np.sum(h[use] == 0)),
            "wrong_sign": int(np.sum(moving & (h * true_s < 0)))}
    return out


def analyse_case(case, raw, args, tb, bits) -> dict:
    """Readings from the simulated registers against the floor on the same edges (each
    SNAP_EDGE_TIME matched to its model edge), and consistency checks of the latched values."""
    import numpy as np

    from hedsmodel.velocity import (EstimatorConfig, SnapTrace, counts_per_edge, edge_table,
                                    estimate, exact_twin, true_rpm)

    et = edge_table(case["wf"])
    edge = case["edge_name"]
    tick, clk = tb.tick_s, 1.0 / tb.clk_hz
    reads = raw["reads"]
    tm = _times(raw, tb, et, edge)
    t_latch = tm["t_latch"]
    med, last_edge, jsel, unmatched = _match_edges(tm, tick, clk, len(reads))
    p_from, p_to, period_newer = _period_pairs(reads, et, tm["sel"], jsel, tm["t_read"], tick)
    snaps = _snapshots(reads, bits)
    trace = SnapTrace(snaps, tm["t_read"], t_latch, last_edge, p_from, p_to)
    cpe = counts_per_edge(edge)
    stall_s = case["stall_s"]
    hw = estimate(snaps, EstimatorConfig(tick_s=tick, ts_w=32, counts_per_edge=cpe,
                                         stall_ticks=int(round(stall_s / tick))))
    fl = estimate(exact_twin(trace, et, med * tick), EstimatorConfig(
        tick_s=1e-9, ts_w=None, counts_per_edge=cpe, stall_ticks=stall_s * 1e9))
    bad, checked = _edge_checks(et, snaps, last_edge, jsel, p_from, p_to, tick)
    seen = et.t_s + med * tick      # edges as the peripheral sees them
    n_at = np.searchsorted(seen, t_latch, side="right")
    bad_delta = _delta_check(et, snaps, seen, t_latch, n_at, clk, checked)
    true_s = true_rpm(build_profile(case["profile"]), t_latch - med * tick)
    last_dir = np.where(n_at > 0, np.sign(et.step[np.maximum(n_at - 1, 0)]), 0)
    true_t = np.abs(true_s)
    # relative to: the speed (constant, ramp) or the top speed (reversal, which passes 0)
    denom = np.full(len(reads), case["rpm"] * DETUNE) if case["kind"] == "constant" else (
        np.maximum(true_t, 1e-9) if case["kind"] == "ramp" else np.full(len(reads), true_t.max()))
    res = {"unit": case["unit"], "rpm": case["rpm"], "edge": edge, "reads": len(reads),
           "kind": case["kind"], "bad_dir": bad["dir"],
           "unmatched": unmatched, "bad_edge_delta": bad["edge_delta"], "bad_period": bad["period"],
           "bad_delta": bad_delta, "checked": checked, "latency_ticks": med,
           "period_newer": period_newer, "methods": {}}
    if case["kind"] == "stop":
        res["stop"], res["methods"] = _stop_metrics(case, et, snaps, hw, t_latch, true_t, tick, edge)
    else:
        res["methods"] = _method_metrics(hw, fl, true_s, denom, last_edge, last_dir, edge)
    return res
