# SPDX-License-Identifier: Apache-2.0
"""The calibrated methods (hedsmodel.calibration, the same as sw/enc_qei_calib.c) on the modelled
units, pure Python: the entries an ideal enc_qei edge FIFO pushes
(hedsmodel.velocity.ideal_edge_entries, the same 100 MHz timebase and latency as the rest of the
bench) and reads at 1 kHz, through the calibrating estimator and through the same estimator with
calibration off (uncalibrated M/T on A-rising edges and on any edge, the same rules).

The units are the bench's: their code-wheel line errors repeat every revolution, their radial
and axial play is random, new every cycle (the note's random phase error, which no calibration
can learn); the any-edge figures are also given without play ("none"). Jobs: constant speeds,
the learning curve, the 6 rpm latency, and the disturbed runs of calib_disturb."""

from __future__ import annotations

import dataclasses
import math
import time
from concurrent.futures import ProcessPoolExecutor

from .config import CPR, DETUNE, GOAL_BAND, READ_HZ

LEARN_REVS = 8
LATENCY_RPM, LATENCY_STEP = 6.0, 1.1       # 6 rpm, steps of +-10 %


def _played(unit, play: str):
    """The unit as it is ("random" play) or without radial and axial play ("none")."""
    if play not in ("random", "none"):
        raise ValueError(f"play must be random or none, not {play!r}")
    return unit if play == "random" else dataclasses.replace(unit, radial_play_mm=0.0,
                                                             axial_play_mm=0.0)


def _cfg(tb, stall_s, use_index=True, learn_revs=LEARN_REVS):
    from hedsmodel.calibration import CalibConfig

    return CalibConfig(tick_s=tb.tick_s, ts_w=tb.ts_w, cycles=CPR, use_index=use_index,
                       learn_revs=learn_revs, stall_ticks=int(round(stall_s / tb.tick_s)))


def _profile(spec):
    from hedsmodel import Profile

    p = Profile()
    for seg in spec:
        getattr(p, seg[0])(*seg[1:])
    return p


def _readings(wf, tb, t0, t_end, cfgs):
    """Per config, (t_read, mt_a rpm, any rpm, calibrated, estimator)."""
    import numpy as np

    from hedsmodel.calibration import CalibratingEstimator, run_stream, stream_ops
    from hedsmodel.velocity import edge_entries_with_ticks

    ents, ticks = edge_entries_with_ticks(wf, tb)
    tr = np.arange(t0, t_end, 1.0 / READ_HZ)
    rt = tb.ticks(tb.clock_of(tr))
    k = 60.0 / (4 * CPR)
    out = []
    for cfg in cfgs:
        est = CalibratingEstimator(cfg)
        a, n, cal = run_stream(est, stream_ops(ents, ticks, rt, (1 << tb.ts_w) - 1))
        out.append((tr, np.array(a) * k, np.array(n) * k, np.array(cal), est))
    return out


def _rms(x, true, sel):
    import numpy as np

    if not sel.any():
        return math.nan
    return float(np.sqrt(np.mean((x[sel] / true[sel] - 1) ** 2)))


def run_constant(job) -> dict:
    """One unit at one constant speed: learn, then score calibrated and uncalibrated readings
    over the same window after the table is learnt (every read: a read the estimator does not
    trust the table for is its uncalibrated reading)."""
    import numpy as np

    from hedsmodel.velocity import true_rpm

    t_start = time.perf_counter()
    rpm, tb, stall_s = job["rpm"], job["tb"], job["stall_s"]
    rev = 60.0 / rpm
    learn = job.get("learn_revs", LEARN_REVS)
    t_meas = max(2 * rev, job["meas_s"])
    dur = (learn + 3.2) * rev + t_meas
    prof = _profile([("constant", rpm * DETUNE, dur)])
    res = {"rpm": rpm, "unit": job["unit_name"], "learn_revs": learn}
    for play in job["plays"]:
        wf = _played(job["unit"], play).waveform(prof, index=True)
        cfgs = [_cfg(tb, stall_s, learn_revs=learn), _cfg(tb, stall_s, learn_revs=10**9)]
        if play == "random" and job.get("no_index"):
            cfgs.append(_cfg(tb, stall_s, use_index=False, learn_revs=learn))
        runs = _readings(wf, tb, job["t0"], dur, cfgs)
        tr, true = runs[0][0], true_rpm(prof, runs[0][0])
        cal = runs[0][3]
        t_cal = float(tr[np.argmax(cal)]) if cal.any() else math.nan
        sel = tr >= dur - t_meas
        r = {"revs_to_cal": t_cal / rev, "n": int(sel.sum()),
             "cal_share": float(np.mean(cal[sel])),
             "A cal": _rms(runs[0][1], true, sel), "any cal": _rms(runs[0][2], true, sel),
             "A uncal": _rms(runs[1][1], true, sel), "any uncal": _rms(runs[1][2], true, sel),
             "A cal max": float(np.max(np.abs(runs[0][1][sel] / true[sel] - 1)))}
        if len(runs) > 2:
            r["A noidx"] = _rms(runs[2][1], true, sel)
            r["any noidx"] = _rms(runs[2][2], true, sel)
            r["revs_to_cal noidx"] = float(tr[np.argmax(runs[2][3])]) / rev \
                if runs[2][3].any() else math.nan
        res[play] = r
    res["wall_s"] = time.perf_counter() - t_start
    return res


def run_latency(job) -> dict:
    """Learn at 60 rpm, settle at 6 rpm, then speed steps of +-10 % every ``hold`` s: per step,
    the time until the readings are within 1 % of the new speed and stay there."""
    import numpy as np

    from hedsmodel.velocity import true_rpm

    tb, stall_s = job["tb"], job["stall_s"]
    v0, v1, hold, n_steps = LATENCY_RPM, LATENCY_RPM * LATENCY_STEP, job["hold_s"], job["steps"]
    spec = [("constant", 60.0 * DETUNE, (LEARN_REVS + 4.2) * 1.0),
            ("ramp", 60.0 * DETUNE, v0 * DETUNE, 1.0), ("constant", v0 * DETUNE, 1.0)]
    for i in range(n_steps):
        spec.append(("constant", (v1 if i % 2 == 0 else v0) * DETUNE, hold))
    prof = _profile(spec)
    t_first = (LEARN_REVS + 4.2) + 2.0
    out = {"unit": job["unit_name"]}
    for play in job["plays"]:
        wf = _played(job["unit"], play).waveform(prof, index=True)
        runs = _readings(wf, tb, job["t0"], prof.duration_s,
                         [_cfg(tb, stall_s), _cfg(tb, stall_s, learn_revs=10**9)])
        tr = runs[0][0]
        true = true_rpm(prof, tr)
        lat = {}
        for name, x in (("any cal", runs[0][2]), ("A uncal", runs[1][1]),
                        ("A cal", runs[0][1]), ("any uncal", runs[1][2])):
            ok = np.abs(x / np.where(true == 0, 1, true) - 1) <= 0.01
            ts = []
            for i in range(n_steps):
                ta, tb_ = t_first + i * hold, t_first + (i + 1) * hold
                w = (tr > ta) & (tr < tb_)
                okw = ok[w]
                bad = np.flatnonzero(~okw)
                j = bad[-1] + 1 if bad.size else 0
                ts.append(float(tr[w][j] - ta) if j < okw.size else math.nan)
            lat[name] = ts
        out[play] = lat
    return out


def run_learning(job) -> dict:
    """Error after learning from 1 .. 10 revolutions (0: uncalibrated), one unit and speed."""
    res = {}
    for k in job["ks"]:
        r = run_constant({**job, "learn_revs": max(k, 1)})
        res[k] = {p: r[p] for p in job["plays"]}
    return {"unit": job["unit_name"], "rpm": job["rpm"], "by_k": res}


def run_disturbed(job) -> dict:
    """One disturbed run (calib_disturb.CASES) on one unit."""
    from .calib_disturb import run_case

    t_start = time.perf_counter()
    r = run_case({**job, "cfg": _cfg(job["tb"], job["stall_s"])})
    r["wall_s"] = time.perf_counter() - t_start
    return r


def plan(args, units, rng):
    """The jobs: constant speeds (30 .. 12,000 rpm), learning curves, 6 rpm latency, disturbed
    runs (every case on every non-ideal unit). ``--quick``: fewer of each."""
    from .calib_disturb import CASES, QUICK_CASES
    from .plan import random_phase, speeds, timebase

    tb = timebase(args)
    stall = args.stall_ms * 1e-3
    rpms = [r for r in speeds(args) if GOAL_BAND[0] <= r <= GOAL_BAND[1]]
    if args.quick:
        rpms = [r for r in rpms if r in (rpms[0], rpms[len(rpms) // 2], rpms[-1])]
    real = [(n, u) for n, u in units if n != "ideal"] or units
    few = real[:1] if args.quick else real
    base = lambda: {"tb": random_phase(tb, rng), "t0": float(rng.uniform(0, 1 / READ_HZ)),
                    "stall_s": stall}
    meas = 0.05 if args.quick else 0.3
    jobs = []
    for rpm in rpms:
        for name, unit in units:
            jobs.append(("constant", {**base(), "rpm": rpm, "unit_name": name, "unit": unit,
                                      "meas_s": meas, "plays": ("random", "none"),
                                      "no_index": True}))
    ks = (0, 1, 2, 4, 8) if args.quick else tuple(range(0, 11)) + (14,)
    for rpm in ((394.0,) if args.quick else (30.0, 2180.0)):
        for name, unit in few:
            jobs.append(("learning", {**base(), "rpm": rpm, "unit_name": name, "unit": unit,
                                      "meas_s": meas, "ks": ks, "plays": ("random", "none")}))
    for name, unit in few:
        jobs.append(("latency", {**base(), "unit_name": name, "unit": unit,
                                 "hold_s": 0.3, "steps": 4 if args.quick else 12,
                                 "plays": ("random", "none")}))
    for case in (QUICK_CASES if args.quick else tuple(CASES)):
        for name, unit in few:
            jobs.append(("disturbed", {**base(), "case": case, "unit_name": name, "unit": unit,
                                       "seed": int(rng.integers(2**31))}))
    return jobs


RUNNERS = {"constant": run_constant, "learning": run_learning, "latency": run_latency,
           "disturbed": run_disturbed}


def _line(kind, r) -> str:
    """The progress line of a finished job."""
    if kind == "constant":
        rr = r["random"]
        return (f"calibrated {r['unit']} {r['rpm']:g} rpm: M/T A↑ {100 * rr['A cal']:.4f} % "
                f"(uncalibrated {100 * rr['A uncal']:.3f} %), any edge {100 * rr['any cal']:.3f} % "
                f"(uncalibrated {100 * rr['any uncal']:.1f} %), learnt after "
                f"{rr['revs_to_cal']:.1f} rev, table in use {100 * rr['cal_share']:.0f} %")
    if kind == "disturbed":
        a, n = r["A"], r["any"]
        return (f"disturbed {r['unit']}, {r['what']}: worst 1 s window from {a['worst_at_s']:.1f} s"
                f", M/T A↑ calibrated {100 * a['worst_cal']:.4f} % / uncalibrated "
                f"{100 * a['worst_uncal']:.4f} % = {a['worst_ratio']:.3f}; any edge "
                f"{n['worst_ratio']:.3f}; last second {100 * a['end_cal']:.4f} % / "
                f"{100 * a['end_uncal']:.4f} %")
    return f"calibrated {kind} {r['unit']}: done"


def run_calibration(args, units):
    """Every job on ``args.jobs`` processes: {"constant": [...], "learning": [...], ...}."""
    import numpy as np

    rng = np.random.default_rng([args.seed, 7])
    jobs = plan(args, units, rng)
    out = {k: [] for k in RUNNERS}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        futs = [(kind, ex.submit(RUNNERS[kind], j)) for kind, j in jobs]
        for i, (kind, f) in enumerate(futs):
            r = f.result()
            out[kind].append(r)
            print(f"[{i + 1}/{len(futs)}] {_line(kind, r)}", flush=True)
    out["wall_s"] = time.perf_counter() - t0
    return out
