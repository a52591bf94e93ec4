# SPDX-License-Identifier: Apache-2.0
"""scripts/velocity_bench.py: argument checks (one-line errors), and the simulated layer's
analysis fed with the registers an ideal enc_qei would give (from hedsmodel.velocity's
snapshot_trace), so the edge matching and the consistency checks are known to work before the
RTL's timing registers exist: no inconsistency, and what the timebase adds equals the model
layer's figure."""

from __future__ import annotations

import argparse
import subprocess
import sys

import numpy as np
import pytest

from enctools.paths import TOP
from enctools.velocity import analyse, plan, sim_table, simulate
from hedsmodel import EncoderUnit
from hedsmodel.velocity import Timebase, edge_table, snapshot_trace

SCRIPT = TOP / "scripts" / "velocity_bench.py"


@pytest.mark.parametrize("argv,fragment", [
    (["--rpm-min", "0"], "--rpm-min"),
    (["--rpm-min", "100", "--rpm-max", "50"], "must be below --rpm-max"),
    (["--units", "-1"], "--units"),
    (["--seed", "x"], "--seed"),
    (["--jobs", "0"], "--jobs"),
    (["--quick", "yes"], "unrecognized arguments"),
    (["--prescale", "70000"], "--prescale"),
    (["--prescale", "20000"], "too coarse"),
    (["--sim", "modelsim"], "--sim"),
])
def test_bad_arguments_give_one_line(argv, fragment):
    res = subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True,
                         timeout=60)
    assert res.returncode == 2, res
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("velocity_bench: ") and fragment in lines[0], \
        res.stderr


def fake_raw(case, tb: Timebase, start_s: float, bits: dict):
    """What enctools.benches.velocity_sim would record from an ideal enc_qei (clock 0 at sim time 0,
    the waveform started at ``start_s``, a multiple of the clock period)."""
    clk = 1 / tb.clk_hz
    k0 = int(round(start_s / clk))
    tbx = Timebase(clk_hz=tb.clk_hz, prescale=tb.prescale, ts_w=32,
                   latency_clocks=tb.latency_clocks, tb_offset=k0)
    reads = np.array(case["reads_ns"]) * 1e-9
    tr = snapshot_trace(case["wf"], 1000.0, case["edge_name"], 1, tbx, reads[0], reads[-1] + 1e-9)
    cal_s = start_s - 30 * clk
    steps = edge_table(case["wf"]).t_s + tb.latency_clocks * clk
    out = []
    for s, t in zip(tr.snaps, tr.t_read_s):
        before = steps[steps <= t]
        stalled = int(before.size > 0 and t - before[-1] >= case["stall_s"])
        out.append({"t_ack_ps": (start_s + t) * 1e12, "SNAP_COUNT_LO": s.count,
                    "SNAP_TIME": s.time, "SNAP_EDGE_TIME": s.edge_time,
                    "SNAP_DELTA": s.delta & 0xFFFFFFFF, "SNAP_EDGE_DELTA": s.edge_delta & 0xFFFFFFFF,
                    "PERIOD": s.period,
                    "PERIOD_CTRL": (s.period_ovf << bits["PERIOD_CTRL.OVERFLOW"])
                    | (s.period_dir_change << bits["PERIOD_CTRL.DIR_CHANGE"]),
                    "STATUS": stalled << bits["STATUS.STALLED"]})
    return {"t_start_ps": start_s * 1e12, "t_cal0_ps": cal_s * 1e12, "t_cal1_ps": cal_s * 1e12,
            "tb_cal": (k0 - 30) // (tb.prescale + 1), "reads": out}


def test_sim_analysis_on_ideal_registers():
    args = argparse.Namespace(quick=True, sim_reads=6, stall_ms=200.0, prescale=0, clk_mhz=100.0,
                              seed=7, jobs=1)
    regs, bits, a_rising = simulate.reg_layout()
    assert a_rising == 1 and "SNAP_EDGE_DELTA" in regs
    units = [("ideal", EncoderUnit()), ("typical 1", EncoderUnit.typical(np.random.default_rng(7)))]
    rng = np.random.default_rng(7)
    cases = plan.sim_cases(args, units, [30.0, 394.0, 12000.0], rng)
    tb = plan.timebase(args)
    results = []
    for c in cases:
        raw = fake_raw(c, tb, start_s=0.0123, bits=bits)
        r = analyse.analyse_case(c, raw, args, tb, bits)
        results.append(r)
        print(c["id"], r["latency_ticks"], r["checked"], {k: v.get("added_max")
                                                         for k, v in r["methods"].items()})
        assert r["unmatched"] == 0 and r["bad_edge_delta"] == 0 and r["bad_period"] == 0 \
            and r["bad_delta"] == 0, r
        assert r["checked"]["edge_delta"] > 0 and r["checked"]["delta"] > 0
        assert abs(r["latency_ticks"] - tb.latency_clocks) <= 1.5
        if c["kind"] == "stop":
            st, mt = r["stop"], r["methods"]["MT"]
            assert not st["stalled_before_timeout"]
            assert 0 < st["stalled_at_s"] - st["last_step_s"] <= c["stall_s"] + 1.1e-3
            assert mt["t_zero_after_stop_s"] <= c["stall_s"] + 1.1e-3 and mt["moving_zeros"] == 0
            continue
        mt = r["methods"]["MT"]
        assert mt["n"] >= 1, r
        assert mt["added_max"] < 2e-4, r
        assert mt["wrong_sign"] == 0, r
        if c["kind"] == "constant":
            assert mt["zeros"] == 0
        else:
            assert r["checked"]["dir_flag"] > 0
    rep = sim_table.sim_report(args, units, results, 1.0, "ideal registers", {})
    print("\n".join(rep["lines"] + rep["goals"]))
    assert rep["goals"] and all(g.startswith(("MET", "INFO")) for g in rep["goals"]), rep["goals"]
    assert len(rep["points"]) == 6


def test_calibrated_rows_quick(tmp_path):
    """The calibrated methods' part of the bench (enctools.velocity.calib), --quick, one
    non-ideal unit: calibrated M/T A↑ far below the uncalibrated one, the disturbed runs never
    worse than uncalibrated, the goal lines and tables written."""
    from enctools.velocity import calib, calib_disturb, calib_report

    args = argparse.Namespace(quick=True, seed=5, units=1, jobs=1, stall_ms=200.0, prescale=0,
                              clk_mhz=100.0, rpm_min=1.0, rpm_max=12000.0, points=12)
    print("seed 5")
    units = plan.make_units(args)
    res = calib.run_calibration(args, units)
    goals = calib_report.write_calibration(args, units, res, tmp_path / "cal.md",
                                           tmp_path / "cal.png", res["wall_s"])
    print("\n".join(goals))
    rows = [r for r in res["constant"] if r["unit"] != "ideal"]
    assert len(rows) == 3
    for r in rows:
        assert r["random"]["A cal"] < 5e-4 and r["random"]["A cal"] < r["random"]["A uncal"] / 10
        assert r["none"]["any cal"] < 1e-3 < r["none"]["any uncal"]
        assert r["random"]["cal_share"] == 1.0
    assert len(res["disturbed"]) == len(calib_disturb.QUICK_CASES)
    assert goals[0].startswith("MET")
    assert any(g.startswith("MET: never worse, M/T A↑") for g in goals), goals
    text = (tmp_path / "cal.md").read_text()
    assert "## Error against revolutions of learning" in text and "## Disturbed runs" in text
    assert (tmp_path / "cal.png").exists()


def test_calibration_table_is_current():
    """doc/results/velocity_calibration.md names the code it was made with: rerun
    `make velocity` (or scripts/velocity_bench.py --calib only) when that code changes."""
    from enctools.velocity.calib_report import SOURCES, TABLE, source_hash

    text = TABLE.read_text()
    assert f"<!-- source {source_hash()} -->" in text, \
        f"{TABLE.relative_to(TOP)} is stale: {', '.join(SOURCES)} changed since it was written"
