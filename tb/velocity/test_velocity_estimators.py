# SPDX-License-Identifier: Apache-2.0
"""The host-side velocity estimators: Python (hedsmodel.velocity) against C
(sw/enc_qei_velocity.c, compiled here with gcc -std=c99 -Wall -Werror), and their rules.

Agreement: both run on the same snapshot streams -- ideal-peripheral snapshots of modelled
HEDS-5000 units (random seeds, logged) at constant speeds, a ramp, a reversal and a stop, both
edge types, several timebases (including TS_W = 16 with wraps) -- and must agree to a relative
1e-12 (they do the same double operations in the same order, so in practice bit for bit).
Rules: the standstill bound, the stall timeout, the reversal rule, period flags, timebase wrap at
TS_W bits and count wrap at COUNT_W bits, each on hand-made snapshots through both versions.
Every stream that goes through both() also goes through the fixed-point C
(sw/enc_qei_velocity_fx.c), held to one unit of the double C (test_velocity_fixed.py).
"""

from __future__ import annotations

import math
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from hedsmodel import EncoderUnit, Profile
from hedsmodel.velocity import (EstimatorConfig, Snapshot, Timebase, VelocityEstimator,
                                counts_per_edge, edge_table, ideal_snapshots, to_rpm)
from test_velocity_fixed import fixed_agrees

TOP = Path(__file__).resolve().parents[2]
SW = TOP / "sw"
REL_TOL = 1e-12


@dataclass(frozen=True)
class CEstimators:
    vel: Path   # vel_driver: sw/enc_qei_velocity.c
    fx: Path    # velfx_driver: sw/enc_qei_velocity_fx.c beside it


@pytest.fixture(scope="session")
def c_estimator(c_driver, c_fixed):
    return CEstimators(
        c_driver("vel_driver", [SW / "enc_qei_velocity.c", Path(__file__).parent / "vel_driver.c"]),
        c_fixed)


def run_c(exe: Path, cfg: EstimatorConfig, snaps) -> list[tuple[float, float, float]]:
    assert cfg.ts_w is not None and cfg.ts_w <= 32, "the C estimator takes TS_W <= 32"
    lines = [f"{cfg.tick_s!r} {cfg.ts_w} {cfg.count_w} {cfg.counts_per_edge} "
             f"{int(cfg.stall_ticks)} {int(cfg.delta_from_count)}"]
    for s in snaps:
        lines.append(f"{s.count} {s.time} {s.edge_time} {s.delta} {s.edge_delta} {s.period} "
                     f"{s.period_n} {s.period_ovf} {s.period_dir_change} {s.stalled}")
    res = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True,
                         text=True, check=True)
    return [tuple(float(x) for x in ln.split()) for ln in res.stdout.splitlines()]


def both(exe: CEstimators, cfg, snaps):
    """Readings (m, t, mt) per snapshot from Python, after checking that C agrees and that the
    fixed-point C is within one unit of it (test_velocity_fixed.py)."""
    py = [(r.m, r.t, r.mt) for r in VelocityEstimator(cfg).run(snaps)]
    c = run_c(exe.vel, cfg, snaps)
    fixed_agrees(exe.fx, cfg, snaps)
    assert len(c) == len(py), f"C gave {len(c)} readings for {len(py)} snapshots"
    for i, (rp, rc) in enumerate(zip(py, c)):
        for name, a, b in zip(("M", "T", "MT"), rp, rc):
            assert math.isclose(a, b, rel_tol=REL_TOL, abs_tol=1e-9), \
                f"snapshot {i} {name}: Python {a!r} C {b!r} ({snaps[i]})"
    return py


# ----------------------------------------------------------------------------- agreement

def _profiles(rng):
    rpm = float(np.exp(rng.uniform(np.log(2), np.log(12000))))
    return {
        f"constant {rpm:.1f} rpm": Profile().constant(rpm, 0.03 + 60 / rpm / 50),
        "ramp 0->1500 rpm": Profile().ramp(0, 1500, 0.05),
        "reversal 200->-200 rpm": Profile().ramp(200, -200, 0.06),
        "stop after 40 rpm": Profile().constant(40, 0.03).stop(0.08),
    }


TIMEBASES = {
    "100 MHz /1, TS_W 32": Timebase(prescale=0, ts_w=32),
    "100 MHz /10, TS_W 24, near wrap": Timebase(prescale=9, ts_w=24, tb_offset=(2**24 - 3000) * 10),
    "50 MHz /50, TS_W 16 (wraps every 65 ms)": Timebase(clk_hz=50e6, prescale=49, ts_w=16,
                                                        tb_offset=(2**16 - 40) * 50),
}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_c_and_python_agree_on_model_vectors(c_estimator, seed):
    rng = np.random.default_rng(seed)
    print(f"vector seed {seed}")
    units = {"ideal": EncoderUnit(), "typical": EncoderUnit.typical(rng),
             "drawn": EncoderUnit.draw(rng)}
    n = 0
    for pname, prof in _profiles(rng).items():
        for uname, unit in units.items():
            et = edge_table(unit.waveform(prof))
            for tbname, tb in TIMEBASES.items():
                edge = "any" if rng.random() < 0.5 else "a_rising"
                period_n = int(rng.choice([1, 2, 4]))
                snaps, _ = ideal_snapshots(et, edge=edge, period_n=period_n, timebase=tb,
                                           t0_s=float(rng.uniform(0, 1e-3)),
                                           t_end_s=prof.duration_s, count_w=32)
                cfg = EstimatorConfig(tick_s=tb.tick_s, ts_w=tb.ts_w, count_w=32,
                                      counts_per_edge=counts_per_edge(edge),
                                      stall_ticks=int(0.05 / tb.tick_s) % (1 << tb.ts_w),
                                      delta_from_count=bool(rng.random() < 0.3))
                both(c_estimator, cfg, snaps)
                n += len(snaps)
    print(f"seed {seed}: {n} snapshots, C and Python agree to {REL_TOL:g}")
    assert n > 1000


def test_c_rejects_bad_config(c_estimator):
    res = subprocess.run([str(c_estimator.vel)], input="1e-8 40 32 1 0 0\n", capture_output=True,
                         text=True)
    assert res.returncode == 2 and "out of range" in res.stderr


def test_python_rejects_bad_config():
    for bad in (dict(tick_s=0), dict(tick_s=1e-8, ts_w=0), dict(tick_s=1e-8, count_w=65),
                dict(tick_s=1e-8, counts_per_edge=0), dict(tick_s=1e-8, stall_ticks=-1)):
        with pytest.raises(ValueError):
            EstimatorConfig(**bad)


# ----------------------------------------------------------------------------- rules

TICK = 1e-6   # 1 MHz timebase in the hand-made cases


def snap(count, time, edge_time, delta, edge_delta, **kw):
    return Snapshot(count=count, time=time, edge_time=edge_time, delta=delta,
                    edge_delta=edge_delta, **kw)


def test_standstill_bound_never_zero_between_edges(c_estimator):
    """One count every 10 ms (any edge), read every 1 ms: between edges the M/T reading stays
    at the last measurement (100 counts/s) until the bound 1 / since falls below it, never 0;
    M reads 0 nine times out of ten (that is the unit-time method). The first edge (10 ms) is a
    reference only, the second (20 ms) gives the first measurement."""
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32, counts_per_edge=1, stall_ticks=50_000)
    snaps, count, prev_edge_count = [], 0, 0
    for k in range(0, 60):
        t = 1000 * k + 500
        new = t // 10_000 * 10_000
        c = new // 10_000
        delta = c - count
        snaps.append(snap(c, t, new, delta, c - prev_edge_count))
        count, prev_edge_count = c, c
    r = both(c_estimator, cfg, snaps)
    mt = np.array([x[2] for x in r])
    assert np.all(mt[:20] == 0), mt[:20]
    assert np.all(mt[20:] > 0), "M/T read 0 between edges at a constant slow speed"
    assert np.allclose(mt[20:], 100.0), mt[20:]   # since <= 9.5 ms: bound 105 > 100
    m = np.array([x[0] for x in r])
    assert np.sum(m[12:] == 0) >= 0.85 * len(m[12:])


def test_standstill_bound_decays_then_stall_reads_zero(c_estimator):
    """The shaft stops after its last edge at t = 10 ms (1000 counts/s before): readings follow
    min(1000, 1 / since) and are exactly 0 from since >= stall_ticks (30 ms) on; STATUS.STALLED
    also forces 0."""
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32, counts_per_edge=1, stall_ticks=30_000)
    snaps = [snap(8, 8_500, 8_000, 0, 0), snap(9, 9_500, 9_000, 1, 1),
             snap(10, 10_500, 10_000, 1, 1)]
    for k in range(11, 50):
        snaps.append(snap(10, 1000 * k + 500, 10_000, 0, 0))
    r = both(c_estimator, cfg, snaps)
    mt = [x[2] for x in r]
    assert mt[1] == 0.0                     # the first edge is a reference only
    assert mt[2] == pytest.approx(1000.0)
    for k, s in enumerate(snaps[3:], start=3):
        since = s.time - 10_000
        want = 0.0 if since >= 30_000 else min(1000.0, 1 / (since * TICK))
        assert mt[k] == pytest.approx(want), (k, since, mt[k], want)
    assert mt[-1] == 0.0 and mt[2] > 0
    stalled = snaps[:3] + [snap(10, 11_500, 10_000, 0, 0, stalled=1)]
    assert both(c_estimator, cfg, stalled)[-1][2] == 0.0


def test_one_edge_reversal_reads_zero(c_estimator):
    """Forward at 1000 counts/s, then one edge back: that reading is 0 (reversal rule), the next
    backward edge reads the backward speed."""
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32, counts_per_edge=1)
    snaps = [snap(0, 0, 0, 0, 0), snap(1, 1_100, 1_000, 1, 1), snap(2, 2_100, 2_000, 1, 1),
             snap(1, 3_100, 3_000, -1, -1), snap(0, 4_100, 3_500, -1, -1),
             snap(0, 5_100, 3_500, 0, 0)]
    r = both(c_estimator, cfg, snaps)
    mt = [x[2] for x in r]
    assert mt[1] == 0.0                     # first edge: reference
    assert mt[2] == pytest.approx(1000.0)
    assert mt[3] == 0.0, "a one-edge reversal must read 0"
    assert mt[4] == pytest.approx(-2000.0)
    assert mt[5] == pytest.approx(-1 / (1600 * TICK))   # standstill bound, backwards
    # there and back between two reads: a new edge with edge_delta 0 reads 0
    snaps2 = snaps[:3] + [snap(2, 3_100, 2_900, 0, 0)]
    assert both(c_estimator, cfg, snaps2)[-1][2] == 0.0


def test_reversal_seen_in_the_counts_before_an_a_rising_edge(c_estimator):
    """A rising only (4 counts per edge): forward at 4000 counts/s, then the counts go back
    (delta < 0) with no A-rising edge yet: the reading drops to 0 at once (not the old direction
    under the standstill bound), the first backward A-rising edge is a reference only (its
    edge_delta of +1 spans the reversal), the second reads the backward speed. T reads 0 from the
    reversal until a new edge."""
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32, counts_per_edge=4)
    snaps = [snap(0, 0, 0, 0, 0), snap(4, 1_100, 1_000, 4, 4, period=1000),
             snap(8, 2_100, 2_000, 4, 4, period=1000),
             snap(9, 3_100, 2_000, 1, 0, period=1000),        # forward, no edge
             snap(7, 4_100, 2_000, -2, 0, period=1000),       # the counts reverse
             snap(5, 5_100, 4_800, -2, 1, period=2800, period_dir_change=1),  # A rises backward
             snap(1, 6_100, 5_800, -4, -4, period=1000),      # next one backward
             ]
    r = both(c_estimator, cfg, snaps)
    mt, t = [x[2] for x in r], [x[1] for x in r]
    assert mt[2] == pytest.approx(4000.0)
    assert mt[3] == pytest.approx(4 / 1.1e-3)              # standstill bound 4 / 1.1 ms
    assert mt[4] == 0.0 and t[4] == 0.0, "the counts reversed: must not read forward"
    assert mt[5] == 0.0 and t[5] == 0.0
    assert mt[6] == pytest.approx(-4000.0) and t[6] == pytest.approx(-4000.0)
    assert all(x <= 0 for x in mt[4:]) and all(x <= 0 for x in t[4:])


def test_timebase_wrap(c_estimator):
    """The same motion with the timebase starting 2.5 ms before a TS_W = 16 wrap reads the same
    as without the wrap."""
    def make(offset, ts_w):
        m = (1 << ts_w) - 1
        out = []
        for k in range(8):
            t, te = 1000 * k + 700, 1000 * k + 300
            out.append(snap(3 * k, (t + offset) & m, (te + offset) & m, 3 if k else 0,
                            3 if k else 0, period=333, period_n=1))
        return out
    ref = both(c_estimator, EstimatorConfig(tick_s=TICK, ts_w=32), make(0, 32))
    for ts_w in (16, 20, 32):
        offset = (1 << ts_w) - 2_500
        got = both(c_estimator, EstimatorConfig(tick_s=TICK, ts_w=ts_w), make(offset, ts_w))
        assert np.allclose(got, ref, rtol=1e-12), (ts_w, got, ref)
    assert ref[-1][2] == pytest.approx(3000.0) and ref[-1][0] == pytest.approx(3000.0)


def test_count_wrap(c_estimator):
    """delta_from_count: the count difference is taken modulo 2^COUNT_W, signed."""
    for count_w in (8, 16, 32, 64):
        top = (1 << count_w) - 1
        cfg = EstimatorConfig(tick_s=TICK, ts_w=32, count_w=count_w, delta_from_count=True)
        up = [snap(top - 3, 0, 0, 0, 0), snap(2, 1000, 990, 99, 6)]   # +6 across the wrap
        down = [snap(2, 0, 0, 0, 0), snap(top - 3, 1000, 990, 99, -6)]
        assert both(c_estimator, cfg, up)[-1][0] == pytest.approx(6000.0)
        assert both(c_estimator, cfg, down)[-1][0] == pytest.approx(-6000.0)
    # SNAP_DELTA itself (default) is used as given
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32)
    assert both(c_estimator, cfg, [snap(0, 0, 0, 0, 0), snap(5, 1000, 900, -7, 5)])[-1][0] \
        == pytest.approx(-7000.0)


def test_period_method_flags_and_direction(c_estimator):
    cfg = EstimatorConfig(tick_s=TICK, ts_w=32, counts_per_edge=4)
    base = [snap(0, 0, 0, 0, 0), snap(8, 1000, 950, 8, 8, period=500, period_n=1)]
    assert both(c_estimator, cfg, base)[-1][1] == pytest.approx(4 / 500e-6)
    n4 = [snap(0, 0, 0, 0, 0), snap(8, 1000, 950, 8, 8, period=2000, period_n=4)]
    assert both(c_estimator, cfg, n4)[-1][1] == pytest.approx(16 / 2000e-6)
    back = [snap(0, 0, 0, 0, 0), snap(-8 & 0xFFFFFFFF, 1000, 950, -8, -8, period=500)]
    assert both(c_estimator, cfg, back)[-1][1] == pytest.approx(-4 / 500e-6)
    for flag in (dict(period_ovf=1), dict(period_dir_change=1), dict(period=0)):
        s = snap(8, 1000, 950, 8, 8, **({"period": 500} | flag))
        assert both(c_estimator, cfg, [snap(0, 0, 0, 0, 0), s])[-1][1] == 0.0


def test_first_snapshot_initialises():
    est = VelocityEstimator(EstimatorConfig(tick_s=TICK))
    r = est.update(snap(100, 5000, 4000, 100, 100, period=10))
    assert (r.m, r.t, r.mt) == (0.0, 0.0, 0.0)


# ----------------------------------------------------------------------------- on the model

def test_ideal_unit_reads_its_speed_exactly():
    """Exact edge times of the ideal unit: M/T and T give the shaft speed to rounding."""
    for rpm in (7.0, 450.0, 9000.0):
        prof = Profile().constant(rpm, max(0.05, 3 * 60 / rpm / 500))
        et = edge_table(EncoderUnit().waveform(prof))
        for edge in ("any", "a_rising"):
            snaps, _ = ideal_snapshots(et, edge=edge, t0_s=0.0004, t_end_s=prof.duration_s)
            cfg = EstimatorConfig(tick_s=1e-9, ts_w=None, counts_per_edge=counts_per_edge(edge))
            rd = VelocityEstimator(cfg).run(snaps)[len(snaps) // 2:]
            for r in rd:
                assert to_rpm(r.mt) == pytest.approx(rpm, rel=1e-9)
                assert to_rpm(r.t) == pytest.approx(rpm, rel=1e-9)


@pytest.mark.parametrize("seed", [5, 6])
def test_goals_on_a_typical_unit(seed):
    """No 0 at 6 rpm (M/T, A rising, 100 ms stall timeout); after a stop the reading is 0 within
    the timeout; at 30 rpm the 10 ns timebase adds < 0.1 % to the exact-edge reading."""
    print(f"unit seed {seed}")
    unit = EncoderUnit.typical(np.random.default_rng(seed))
    tb = Timebase(prescale=0)
    stall_s = 0.1
    prof = Profile().constant(6, 0.4).stop(0.3)
    et = edge_table(unit.waveform(prof))
    snaps, t_read = ideal_snapshots(et, edge="a_rising", timebase=tb, t0_s=0.0002,
                                    t_end_s=prof.duration_s)
    cfg = EstimatorConfig(tick_s=tb.tick_s, ts_w=32, counts_per_edge=4,
                          stall_ticks=int(stall_s / tb.tick_s))
    mt = np.array([to_rpm(r.mt) for r in VelocityEstimator(cfg).run(snaps)])
    running = (t_read > 0.05) & (t_read < 0.4)
    assert np.all(mt[running] > 0), "M/T read 0 at a constant 6 rpm"
    last_edge = et.t_s[et.a_rise][-1]
    after = t_read > last_edge + stall_s + 2 / 1000
    assert np.all(mt[after] == 0)
    # hardware quantisation at 30 rpm
    prof = Profile().constant(30, 0.3)
    et = edge_table(unit.waveform(prof))
    lat = tb.latency_clocks / tb.clk_hz
    hw, _ = ideal_snapshots(et, edge="a_rising", timebase=tb, t0_s=0.0002, t_end_s=0.3)
    ex, _ = ideal_snapshots(et, edge="a_rising", t0_s=0.0002 - lat, t_end_s=0.3 - lat)
    r_hw = [to_rpm(r.mt) for r in VelocityEstimator(cfg).run(hw)]
    r_ex = [to_rpm(r.mt) for r in VelocityEstimator(
        EstimatorConfig(tick_s=1e-9, ts_w=None, counts_per_edge=4, stall_ticks=stall_s * 1e9)
    ).run(ex)]
    added = np.max(np.abs(np.subtract(r_hw, r_ex))[20:]) / 30
    assert added < 1e-3, added


def test_register_reader_with_the_generated_header(tmp_path):
    """qei_vel_read_snapshot() (defined when sw/enc_qei_regs.h is included first) writes
    SNAP_CTRL.CMD keeping EDGE and fills the snapshot from the generated register struct."""
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found")
    if not (SW / "enc_qei_regs.h").exists():
        pytest.skip("sw/enc_qei_regs.h is not generated")
    exe = tmp_path / "vel_regs_check"
    cmd = [gcc, "-std=c11", "-Wall", "-Wextra", "-Werror", f"-I{SW}",
           str(Path(__file__).parent / "vel_regs_check.c"), str(SW / "enc_qei_velocity.c"),
           "-o", str(exe)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    assert res.returncode == 0, f"gcc failed:\n{' '.join(cmd)}\n{res.stderr}"
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split("\n")
    # SNAP_CTRL = EDGE | CMD; count 64-bit; delta -5; edge delta -4; PERIOD 77, N 3, flags 0 1; stalled
    assert out[0] == "9 2fffffff0 1000 900 -5 -4 77 3 0 1 1", out
    assert out[1] == "fffffff0", out
