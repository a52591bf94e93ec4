# SPDX-License-Identifier: Apache-2.0
"""The model layer: the snapshots an ideal enc_qei latches (``hedsmodel.velocity.snapshot_trace``)
through every estimator variant, against the same estimator on the model's exact edge times (the
floor) and the true speed; run over the jobs in worker processes, one progress line per speed."""

from __future__ import annotations

import math
import time
from concurrent.futures import ProcessPoolExecutor

from .config import GOAL_NONZERO_RPM, READ_HZ, VARIANTS
from .plan import build_profile, constant_jobs, prescale_jobs, scenario_jobs, speeds


def read_model(job) -> dict:
    """One unit on one profile: readings of every variant, latched and floor, and the truth."""
    import numpy as np

    from hedsmodel.velocity import (EstimatorConfig, counts_per_edge, edge_table, estimate,
                                    exact_twin, snapshot_trace, true_rpm)

    t_start = time.perf_counter()
    unit, prof, tb, stall_s = job["unit"], build_profile(job["profile"]), job["tb"], job["stall_s"]
    et = edge_table(unit.waveform(prof))
    lat = tb.latency_clocks / tb.clk_hz
    out = {"t": None, "true": None, "readings": {}}
    for edge in ("any", "a_rising"):
        tr = snapshot_trace(et, READ_HZ, edge, 1, tb, job["t0"], job["t_end"])
        cpe = counts_per_edge(edge)
        cfg_q = EstimatorConfig(tick_s=tb.tick_s, ts_w=tb.ts_w, counts_per_edge=cpe,
                                stall_ticks=int(round(stall_s / tb.tick_s)))
        cfg_x = EstimatorConfig(tick_s=1e-9, ts_w=None, counts_per_edge=cpe,
                                stall_ticks=stall_s * 1e9)
        hw = estimate(tr.snaps, cfg_q)
        ex = estimate(exact_twin(tr, et, lat), cfg_x)
        for meth in ("M", "T", "MT"):
            if (meth, edge) in VARIANTS:
                out["readings"][f"{meth}/{edge}"] = {"hw": hw[meth], "floor": ex[meth]}
        if out["t"] is None:
            out["t"] = tr.t_latch_s
            out["true"] = true_rpm(prof, tr.t_latch_s - lat)
    # scoring starts one read after the third A-rising edge and from the third read on (every
    # estimator is warm then: the first read initialises, the first new edge is a reference)
    rises = et.t_s[et.a_rise]
    warm = (rises[2] if rises.size > 2 else math.inf) + 1.0 / READ_HZ
    out["score"] = (out["t"] >= warm + lat) & (np.arange(out["t"].size) >= 2)
    out["wall_s"] = time.perf_counter() - t_start
    out["edges"] = int(et.step.size)
    out["last_edge_s"] = float(et.t_s[-1]) if et.t_s.size else 0.0
    out["motion_end_s"] = max((pc.tb for pc in prof.pieces()), default=0.0)
    idx = np.searchsorted(et.t_s, out["t"] - lat, side="right") - 1
    out["last_dir"] = np.where(idx >= 0, np.sign(et.step[np.maximum(idx, 0)]), 0)
    return out


def score(res, band=None) -> dict:
    """Per variant: relative errors (latched and floor), added by the hardware, zero readings."""
    import numpy as np

    true = res["true"]
    sel = res["score"] & (np.abs(true) > 0)
    if band is not None:
        sel &= (np.abs(true) >= band[0]) & (np.abs(true) <= band[1])
    out = {}
    for key, r in res["readings"].items():
        hw, fl = r["hw"][sel], r["floor"][sel]
        u = np.abs(true[sel])
        if u.size == 0:
            continue
        e_hw, e_fl = np.abs(hw - true[sel]) / u, np.abs(fl - true[sel]) / u
        add = np.abs(hw - fl) / u
        out[key] = {"n": int(u.size), "rms": float(np.sqrt(np.mean(e_hw ** 2))),
                    "max": float(e_hw.max()), "floor_rms": float(np.sqrt(np.mean(e_fl ** 2))),
                    "floor_max": float(e_fl.max()), "added_max": float(add.max()),
                    "added_rms": float(np.sqrt(np.mean(add ** 2))),
                    "zeros": int(np.sum(hw == 0))}
    return out


def _moving_metrics(res) -> dict:
    """Ramp, reversal: errors where |true| >= 30 rpm; wrong-sign and zero readings where
    |true| >= 6 rpm."""
    import numpy as np

    true = res["true"]
    sc = score(res, band=(30.0, 1e9))
    out = {}
    for key, r in res["readings"].items():
        hw = r["hw"]
        big = res["score"] & (np.abs(true) >= GOAL_NONZERO_RPM)
        told = res["last_dir"] == np.sign(true)     # the encoder has shown the direction
        wrong = int(np.sum(big & told & (np.sign(hw) != np.sign(true)) & (hw != 0)))
        zeros = int(np.sum(big & (hw == 0)))
        out[key] = {**sc.get(key, {}), "wrong_sign": wrong, "zeros_moving": zeros,
                    "n_moving": int(np.sum(big))}
    return out


def _stop_metrics(res) -> dict:
    """Stop: time from the stop to the first 0 of each variant that stays 0, zeros while turning."""
    import numpy as np

    t, true = res["t"], res["true"]
    moving = np.abs(true) > 0
    t_stop = res["motion_end_s"]
    out = {}
    for key, r in res["readings"].items():
        hw = r["hw"]
        after = t > t_stop
        nz = np.flatnonzero(after & (hw != 0))
        t_zero = float(t[nz[-1] + 1]) if nz.size and nz[-1] + 1 < t.size else (
            float(t[after][0]) if not nz.size and after.any() else math.nan)
        run = res["score"] & moving
        out[key] = {"t_to_zero_s": t_zero - t_stop, "since_last_edge_s":
                    t_zero - res["last_edge_s"], "zeros_moving": int(np.sum(run & (hw == 0))),
                    "n_moving": int(np.sum(run))}
    return out


def scenario_metrics(kind, res) -> dict:
    """Ramp and reversal: errors, wrong sign and zeros while moving. Stop: time to 0."""
    return _moving_metrics(res) if kind in ("ramp", "reversal") else _stop_metrics(res)


def _speed_done(results, rows: dict, rpm: float, n_done: int, n_rpms: int) -> None:
    """Record one speed's scores (all units in) and print its progress line."""
    results["constant"][rpm] = {u: s for u, (s, _) in rows.items()}
    worst = max((s.get("MT/a_rising", {}).get("rms", math.nan)
                 for u, (s, _) in rows.items() if u != "ideal"), default=math.nan)
    added = max(s.get("MT/a_rising", {}).get("added_max", 0.0) for s, _ in rows.values())
    zeros = sum(s.get("MT/a_rising", {}).get("zeros", 0) for s, _ in rows.values())
    print(f"model {n_done:2d}/{n_rpms} {rpm:>8g} rpm: "
          f"M/T A↑ worst rms {100 * worst:.3f} %, hardware adds <= "
          f"{100 * added:.4f} %, zero readings {zeros} "
          f"({sum(w for _, w in rows.values()):.1f} s cpu)", flush=True)


def run_model(args, units):
    """Every job of the model layer on ``args.jobs`` processes: {"constant": {rpm: {unit:
    score}}, "scenario": {kind: {unit: metrics}}, "prescale": {p: {rpm: {unit: score}}}, ...}."""
    import numpy as np

    rng = np.random.default_rng([args.seed, 1])
    rpms = speeds(args)
    jobs = constant_jobs(args, units, rpms, rng) + scenario_jobs(args, units, rng) \
        + prescale_jobs(args, units, rng)
    results = {"constant": {}, "scenario": {}, "prescale": {}}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        futs = [(j, ex.submit(read_model, j)) for j in jobs]
        by_rpm: dict = {}
        for j, f in futs:
            res = f.result()
            if j["kind"] == "constant":
                by_rpm.setdefault(j["rpm"], {})[j["unit_name"]] = (score(res), res["wall_s"])
                if len(by_rpm[j["rpm"]]) == len(units) and j["rpm"] not in results["constant"]:
                    _speed_done(results, by_rpm[j["rpm"]], j["rpm"], len(results["constant"]) + 1,
                                len(rpms))
            elif j["kind"] == "prescale":
                results["prescale"].setdefault(j["prescale"], {}).setdefault(
                    j["rpm"], {})[j["unit_name"]] = score(res)
            else:
                results["scenario"].setdefault(j["kind"], {})[j["unit_name"]] = \
                    scenario_metrics(j["kind"], res)
                if j["unit_name"] == units[-1][0]:
                    print(f"model scenario {j['kind']}: done", flush=True)
    results["wall_s"] = time.perf_counter() - t0
    results["rpms"] = rpms
    return results
