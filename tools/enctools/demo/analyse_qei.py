# SPDX-License-Identifier: Apache-2.0
"""enc_qei_wb's snapshots, read over Wishbone by the bench, against the model: velocity rows and
the verdict.

Every read gives a latched :class:`hedsmodel.velocity.Snapshot`; the project's estimator turns
the stream into M/T (SNAP_EDGE_DELTA / delta SNAP_EDGE_TIME, A-rising edges, with the standstill
rule and STATUS.STALLED) and M readings. Checks:

- *truth*: where the two A-rising edges of a M/T measurement and the read lie in a constant-speed
  segment (hold, back), the reading is within VEL_TOL_PCT of the model's true speed (what is left
  is the encoder's own error: cycle error and eccentricity);
- *registers*: every reading equals, within VEL_HW_TICKS of timestamp quantisation, the same
  estimator on the same snapshots with each SNAP_EDGE_TIME replaced by the model's exact pin time
  of that edge plus one constant (the median offset, i.e. the pipeline latency measured here,
  whatever it is); SNAP_EDGE_DELTA equals the model's count between the two edges.

Each SNAP_EDGE_TIME is matched to the model's last A-rising edge at the pins before it (its time
in the simulation: the read's acknowledge less SNAP_TIME - SNAP_EDGE_TIME ticks; the pipeline
only delays it, by far less than a cycle).
"""

from __future__ import annotations

from ..qei.bus import signed
from .config import (READ_TAU, VEL_EDGE, VEL_HW_TICKS, VEL_MATCH_CLOCKS, VEL_SHOW_PCT,
                     VEL_TOL_PCT)
from .plan import Plan, a_rises, qei_stall_ticks, tau_ns


def _latched(r: dict):
    from hedsmodel.velocity import Snapshot
    return Snapshot(count=r["SNAP_COUNT_LO"], time=r["SNAP_TIME"], edge_time=r["SNAP_EDGE_TIME"],
                    delta=signed(r["SNAP_DELTA"]), edge_delta=signed(r["SNAP_EDGE_DELTA"]),
                    stalled=r["stalled"])


def _match_pins(reads, latched, rise_ps, tick_ps: float):
    """For each read, the index of the model's A-rising edge its SNAP_EDGE_TIME stamped (None:
    none), and how many timestamps match no edge."""
    import numpy as np

    pins, unmatched = [], 0
    for r, s in zip(reads, latched):
        e_ps = r["t_ack_ps"] - ((s.time - s.edge_time) % (1 << 32)) * tick_ps
        j = int(np.searchsorted(rise_ps, e_ps + 0.5 * tick_ps, side="right")) - 1
        if j < 0:
            pins.append(None)              # no A-rising edge yet (SNAP_EDGE_TIME at reset)
            unmatched += s.edge_time != 0
        elif e_ps - rise_ps[j] > VEL_MATCH_CLOCKS * tick_ps:
            pins.append(None)              # a timestamp long after any edge: matches none
            unmatched += 1
        else:
            pins.append(j)
    return pins, unmatched


def _exact_twin(latched, pins, rise_ps, tick_ps: float):
    """The snapshots with each matched SNAP_EDGE_TIME replaced by its edge's exact pin time plus
    one constant offset (SNAP_EDGE_TIME - pin time, ticks: the pipeline latency and the
    timebase's origin; the median, so no latency is assumed). Returns (twin, offset)."""
    import numpy as np
    from hedsmodel.velocity import Snapshot

    offs = [latched[k].edge_time - rise_ps[j] / tick_ps for k, j in enumerate(pins) if j is not None]
    off = float(np.median(offs)) if offs else 0.0
    twin = [Snapshot(count=s.count, time=float(s.time),
                     edge_time=(rise_ps[j] / tick_ps + off) if j is not None else float(s.edge_time),
                     delta=s.delta, edge_delta=s.edge_delta, stalled=s.stalled)
            for s, j in zip(latched, pins)]
    return twin, off


def _segment_of(plan: Plan, t_ns: float) -> str:
    return next((n for n, (a0, b0) in plan.seg.items() if a0 <= t_ns < b0), "end")


def _constant_span(plan: Plan, e0_ns: float, e1_ns: float, read_ns: float) -> bool:
    """Both edges of a measurement and the read inside one constant-speed segment."""
    return any(a0 <= e0_ns and e1_ns <= b0 and a0 <= read_ns <= b0
               for a0, b0 in (plan.seg["hold"], plan.seg["back"]))


def _rows(plan: Plan, reads, latched, pins, readings, t_s, truth, rises, t0, tick_s, cpe):
    """One row per read; also the register checks' counts and worst case."""
    from hedsmodel.velocity import to_rpm

    pos = plan.wf.positions
    rows, prev_j = [], None
    st = dict(n_hw_bad=0, n_cnt_bad=0, n_cnt=0, worst_hw=0.0, hw_allow=0.0)
    for k, (s, (a, x)) in enumerate(zip(latched, readings)):
        j = pins[k]
        mt = to_rpm(a.mt)
        allow = VEL_HW_TICKS * tick_s * x.mt ** 2 / cpe + 1e-9 * abs(x.mt)   # counts/s
        hw_ok = abs(a.mt - x.mt) <= allow
        st["n_hw_bad"] += not hw_ok
        if x.mt and abs(a.mt - x.mt) / abs(x.mt) > st["worst_hw"]:
            st["worst_hw"], st["hw_allow"] = abs(a.mt - x.mt) / abs(x.mt), allow / abs(x.mt)
        both = k > 0 and j is not None and prev_j is not None
        if both:   # SNAP_EDGE_DELTA against the model's count between the two matched edges
            st["n_cnt"] += 1
            st["n_cnt_bad"] += s.edge_delta != pos[rises[j][1]] - pos[rises[prev_j][1]]
        checked = both and s.edge_delta != 0 and _constant_span(
            plan, (rises[prev_j][0] - t0) / 1e3, (rises[j][0] - t0) / 1e3, t_s[k] * 1e9)
        tr = float(truth[k])
        err = (mt - tr) / abs(tr) * 100.0 if abs(tr) >= VEL_SHOW_PCT / 100 * plan.opts.rpm else None
        rows.append(dict(k=k, t_ms=t_s[k] * 1e3, seg=_segment_of(plan, t_s[k] * 1e9), true=tr,
                         mt=mt, mt_exact=to_rpm(x.mt), m=to_rpm(a.m), err=err,
                         edge_delta=s.edge_delta, stalled=s.stalled, checked=checked,
                         ok=checked and err is not None and abs(err) <= VEL_TOL_PCT and mt != 0,
                         hw_ok=hw_ok))
        prev_j = j
    return rows, st


def analyze_velocity(plan: Plan, res: dict) -> dict:
    """enc_qei_wb's snapshots -> velocity rows and the two checks (see the module's docstring)."""
    import numpy as np
    from hedsmodel.velocity import EstimatorConfig, VelocityEstimator, counts_per_edge, true_rpm

    q = res["qei"]
    reads = q["reads"]
    t0 = res["t0_ps"]
    tick_ps = float(plan.clk_ps)           # TB_PRESCALE 0
    tick_s = tick_ps * 1e-12
    cpe = counts_per_edge(VEL_EDGE)
    rises = a_rises(plan.wf, t0)
    rise_ps = np.array([t for t, _ in rises])
    latched = [_latched(r) for r in reads]
    pins, unmatched = _match_pins(reads, latched, rise_ps, tick_ps)
    twin, off = _exact_twin(latched, pins, rise_ps, tick_ps)
    est = VelocityEstimator(EstimatorConfig(tick_s=tick_s, ts_w=32, count_w=32, counts_per_edge=cpe))
    est_x = VelocityEstimator(EstimatorConfig(tick_s=tick_s, ts_w=None, count_w=32, counts_per_edge=cpe))
    t_s = np.array([(r["t_ack_ps"] - t0) * 1e-12 for r in reads])
    rows, st = _rows(plan, reads, latched, pins, list(zip(est.run(latched), est_x.run(twin))),
                     t_s, true_rpm(plan.profile, t_s), rises, t0, tick_s, cpe)
    chk = [r for r in rows if r["checked"]]
    errs = np.array([r["err"] for r in chk if r["err"] is not None])
    cnt = signed(q["count"])
    p = plan.wf.final_position - plan.start_pos
    ok = (cnt == p and st["n_hw_bad"] == 0 and st["n_cnt_bad"] == 0 and unmatched == 0 and chk
          and all(r["ok"] for r in chk))
    return dict(rows=rows, checked=len(chk), bad=sum(not r["ok"] for r in chk),
                rms=float(np.sqrt(np.mean(errs ** 2))) if errs.size else float("nan"),
                max=float(np.max(np.abs(errs))) if errs.size else float("nan"),
                n_hw_bad=st["n_hw_bad"], worst_hw=st["worst_hw"] * 100, hw_allow=st["hw_allow"] * 100,
                n_cnt=st["n_cnt"], n_cnt_bad=st["n_cnt_bad"], unmatched=unmatched, count=cnt, p=p,
                ok=bool(ok), offset_ticks=off, stall_ticks=qei_stall_ticks(plan),
                read_us=READ_TAU * tau_ns(plan) / 1e3, n_reads=len(reads),
                zeros=sum(1 for r in rows if r["k"] > 0 and r["mt"] == 0
                          and abs(r["true"]) >= VEL_SHOW_PCT / 100 * plan.opts.rpm))


def qei_verdict(vel: dict, p: int) -> tuple:
    """enc_qei_wb: COUNT over the bus = the true 4X position, M/T at constant speed within the
    encoder's floor of the true speed, and every read = the model's edges."""
    why = []
    if vel["count"] != p:
        why.append(f"COUNT {vel['count']} vs {p}")
    if not vel["checked"]:
        why.append("no M/T reading at constant speed")
    elif vel["bad"]:
        why.append(f"{vel['bad']} of {vel['checked']} M/T readings at constant speed off the true "
                   f"speed by > {VEL_TOL_PCT:g} % (max {vel['max']:.2f} %)")
    if vel["n_hw_bad"] or vel["n_cnt_bad"] or vel["unmatched"]:
        why.append(f"registers vs the model's exact edges: {vel['n_hw_bad']} readings off by "
                   f"> {VEL_HW_TICKS:g} ticks, {vel['n_cnt_bad']}/{vel['n_cnt']} SNAP_EDGE_DELTA "
                   f"wrong, {vel['unmatched']} SNAP_EDGE_TIME matching no edge")
    return ("enc_qei_wb", vel["ok"],
            f"COUNT = true 4X position; M/T within {vel['max']:.2f} <= {VEL_TOL_PCT:g} % of the "
            f"true speed ({vel['checked']} constant-speed reads); all {vel['n_reads']} reads = "
            f"model edges within {VEL_HW_TICKS:g} ticks" if vel["ok"] else "; ".join(why))
