# SPDX-License-Identifier: Apache-2.0
"""The model side of the demo: one HEDS-5000 unit, the motion profile and its waveform, the
segments' times, and the plan file the cocotb bench (enctools.benches.demo_bench) reads."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from .config import (CPR, CREEP_DIV, DITHER_AMP_DEG, DITHER_OFFSET_DEG, DITHER_PERIODS, READ_TAU,
                     STALL_TAU, TAU_BACK, TAU_DITHER, TAU_RAMP_UP, TAU_REST, TAU_REVERSE,
                     TAU_STOP_RAMP, VEL_EDGE)
from .options import Options, hold_cycles, hold_readings, pm_window_log2


@dataclass
class Plan:
    opts: Options
    unit: object
    wf: object
    clk_ps: int
    cpc: float                   # clocks per cycle at the peak speed
    window_log2: int
    seg: dict = field(default_factory=dict)   # name -> (t0_ns, t1_ns)
    dither_edge: int = 0         # 4X edge index m the dither crosses
    start_pos: int = 0
    dither_amp: float = 0.0      # e-degrees
    profile: object = None
    t0_ps: float = 0.0           # simulation time at which the waveform starts (from the bench)

    @property
    def clk_hz(self) -> float:
        return 1e12 / self.clk_ps


def cycle_hz(rpm: float) -> float:
    """Encoder output frequency (cycles per second) at ``rpm``."""
    return rpm / 60.0 * CPR


def tau_ns(plan: Plan) -> float:
    """One encoder cycle at the peak speed, ns."""
    return 1e9 / cycle_hz(plan.opts.rpm)


def tau_ps(plan: Plan) -> float:
    """One encoder cycle at the peak speed, ps."""
    return 1e12 / cycle_hz(plan.opts.rpm)


def _segment(p, seg: dict, name: str, *moves) -> None:
    """Append ``moves`` [(Profile method, args...)] to the profile as segment ``name``."""
    t = p.duration_s
    for method, *args in moves:
        getattr(p, method)(*args)
    seg[name] = (t * 1e9, p.duration_s * 1e9)


def _dither_target(unit, x_now: float):
    """The nearest A-fall edge (m = 2 mod 4) more than DITHER_OFFSET_DEG below the shaft's
    position ``x_now`` (cycles): (its position in cycles, m, the dither amplitude that stays within
    its two adjacent states, e-degrees)."""
    import numpy as np

    k = math.floor(x_now)
    edges = unit.edges(k - 2, k + 2)
    ms = np.arange(4 * (k - 2), 4 * (k + 2))
    off = DITHER_OFFSET_DEG / 360.0
    cand = [(x, m) for x, m in zip(edges, ms) if m % 4 == 2 and x + off < x_now - 1e-6]
    x_edge, m_edge = max(cand)
    i = int(np.flatnonzero(ms == m_edge)[0])
    room = min(edges[i] - edges[i - 1], edges[i + 1] - edges[i]) * 360.0  # adjacent states, e-deg
    return x_edge, m_edge, min(DITHER_AMP_DEG, 0.4 * room)


def make_plan(opts: Options) -> Plan:
    """Unit (the note's table means, directions from the seed), profile, waveform and segments:
    ramp up, hold, reverse, back, stop, creep to an A-fall edge, dither about it, rest."""
    import numpy as np
    from hedsmodel import EncoderUnit, Profile

    unit = EncoderUnit.typical(np.random.default_rng(opts.seed), temp_c=opts.temp_c)
    clk_ps = 2 * int(round(1e12 / opts.clk_hz / 2))  # even: the clock's two halves are equal
    clk_hz = 1e12 / clk_ps
    f = cycle_hz(opts.rpm)
    tau = 1.0 / f
    cpc = clk_hz / f
    n_hold = hold_cycles(cpc, hold_readings(opts.rpm, clk_hz))
    # start in the middle of the unit's own state 00 before cycle 0, so the reset state (00) of
    # the conditioner is the true first state and position 0 is where the count starts
    e = unit.edges(-1, 1)                      # edges m = -4 .. 3
    p = Profile(start_deg=(e[3] + e[4]) / 2 * 360.0)
    seg: dict = {}
    back = -opts.rpm / 5
    _segment(p, seg, "ramp up", ("ramp", 0.0, opts.rpm, TAU_RAMP_UP * tau))
    _segment(p, seg, "hold", ("constant", opts.rpm, n_hold * tau))
    _segment(p, seg, "reverse", ("ramp", opts.rpm, back, TAU_REVERSE * tau))
    _segment(p, seg, "back", ("constant", back, TAU_BACK * tau))
    _segment(p, seg, "stop", ("ramp", back, 0.0, TAU_STOP_RAMP * tau), ("stop", TAU_REST * tau))
    # creep (reverse, as the last motion) to the nearest A-fall edge below, dither about it
    x_now = p.end_deg / 360.0
    x_edge, m_edge, amp = _dither_target(unit, x_now)
    creep_rpm = opts.rpm / CREEP_DIV
    dist = x_now - (x_edge + DITHER_OFFSET_DEG / 360.0)
    _segment(p, seg, "creep", ("constant", -creep_rpm, dist / cycle_hz(creep_rpm)),
             ("stop", TAU_REST * tau))
    _segment(p, seg, "dither", ("dither", amp, DITHER_PERIODS, TAU_DITHER * tau))
    _segment(p, seg, "rest", ("stop", TAU_REST * tau))
    wf = unit.waveform(p)
    return Plan(opts, unit, wf, clk_ps, cpc, pm_window_log2(cpc), seg, int(m_edge),
                int(wf.positions[0]), amp, p)


def a_rises(wf, t0_ps: float) -> list:
    """(sim time ps, event index) of every rising edge of A in the model waveform, which starts at
    simulation time ``t0_ps``."""
    out = []
    prev = wf.events[0][1]
    for i, (t, a, _) in enumerate(wf.events):
        if a and not prev:
            out.append((t0_ps + t * 1000.0, i))
        prev = a
    return out


def events_between(wf, i0: int, i1: int):
    """The waveform's events i0 .. i1 (inclusive) as a waveform of their own."""
    from hedsmodel.waveform import Waveform
    return Waveform(events=wf.events[i0:i1 + 1], positions=wf.positions[i0:i1 + 1])


def qei_reads_ns(plan: Plan) -> list:
    """When the bench commands enc_qei_wb's snapshots: from the waveform start (the first read
    only initialises the estimator) every READ_TAU cycles at the peak speed, to the profile's end."""
    step = READ_TAU * tau_ns(plan)
    end = plan.profile.duration_s * 1e9
    return [k * step for k in range(int(end // step) + 1)]


def qei_stall_ticks(plan: Plan) -> int:
    """STALL_TIMEOUT in timebase ticks (TB_PRESCALE 0: one tick per clock)."""
    return int(round(STALL_TAU * tau_ns(plan) * 1000.0 / plan.clk_ps))


def write_plan(plan: Plan, path: Path) -> None:
    """The bench's plan file (the format is in enctools.benches.demo_bench's docstring)."""
    h0, h1 = plan.seg["hold"]
    data = {
        "clk_ps": plan.clk_ps,
        "events": [[round(t, 4), a, b] for t, a, b in plan.wf.events],
        "seg": plan.seg,
        "meas_rst_ns": h0 + 2 * tau_ns(plan),
        "hold_test_ns": h0 + 0.5 * (h1 - h0),
        "hold_test_clocks": int(5 * plan.cpc),
        "back_mid_ns": sum(plan.seg["back"]) / 2,
        "qei": {"reads_ns": qei_reads_ns(plan), "edge": VEL_EDGE,
                "stall_ticks": qei_stall_ticks(plan)},
    }
    path.write_text(json.dumps(data))
