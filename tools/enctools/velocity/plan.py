# SPDX-License-Identifier: Apache-2.0
"""What the benchmark runs: the speeds, the units, the timebase, and the jobs of the model layer
(constant speeds, scenarios, prescalers) and the cases of the simulated layer. Every random
draw (units, clock phases, read phases) comes from the seed."""

from __future__ import annotations

import math

from .config import (CPR, DETUNE, GOAL_BAND, GOAL_NONZERO_RPM, LATENCY_CLOCKS, PRESCALE_RPMS,
                     PRESCALES, READ_HZ, SCENARIOS, SIM_STALL_S, SIM_STOP_RPM, SIM_T0_MS, SIM_UNITS)


def speeds(args) -> list[float]:
    import numpy as np

    grid = np.exp(np.linspace(math.log(args.rpm_min), math.log(args.rpm_max), args.points))
    forced = {v for v in (GOAL_NONZERO_RPM, GOAL_BAND[0]) if args.rpm_min <= v <= args.rpm_max}
    forced |= {args.rpm_min, args.rpm_max}
    out = {float(f"{v:.3g}") for v in grid if all(abs(v / f - 1) > 0.1 for f in forced)}
    return sorted(out | forced)


def make_units(args):
    """[(name, EncoderUnit)]: the ideal unit, then typical and drawn ones."""
    import numpy as np

    from hedsmodel import EncoderUnit

    rng = np.random.default_rng(args.seed)
    units = [("ideal", EncoderUnit())]
    for i in range(args.units):
        if i % 2 == 0:
            units.append((f"typical {i // 2 + 1}", EncoderUnit.typical(rng)))
        else:
            units.append((f"drawn {i // 2 + 1}", EncoderUnit.draw(rng)))
    return units


def unit_summary(unit) -> dict:
    from hedsmodel import Profile, measure

    wf = unit.waveform(Profile().constant(600, 0.1))   # one revolution
    m = measure(wf)
    return {"state_error_deg": m.state_error_deg, "phase_error_deg": m.phase_error_deg,
            "pulse_error_deg": m.pulse_error_deg, "cycle_error_deg": m.cycle_error_deg,
            "ecc_mm": unit.eccentricity_mm}


def timebase(args, prescale=None):
    from hedsmodel.velocity import Timebase

    return Timebase(clk_hz=args.clk_mhz * 1e6,
                    prescale=args.prescale if prescale is None else prescale, ts_w=32,
                    latency_clocks=LATENCY_CLOCKS)


def build_profile(spec):
    from hedsmodel import Profile

    p = Profile()
    for seg in spec:
        getattr(p, seg[0])(*seg[1:])
    return p


def random_phase(tb, rng):
    """The timebase with a random clock phase and prescaler count (edges meet every phase)."""
    import dataclasses

    return dataclasses.replace(tb, phase=float(rng.uniform(0, 1)),
                               tb_offset=int(rng.integers(tb.prescale + 1)))


def _job(args, rng, tb, kind: str, unit_name: str, unit, spec, t_end: float, **extra) -> dict:
    """One model-layer job: a unit on a profile, read from a random phase of the timebase and of
    the read clock."""
    return {"kind": kind, **extra, "unit_name": unit_name, "unit": unit, "profile": spec,
            "tb": random_phase(tb, rng), "t0": float(rng.uniform(0, 1 / READ_HZ)),
            "t_end": t_end, "stall_s": args.stall_ms * 1e-3}


def constant_jobs(args, units, rpms, rng):
    dur_min, dur_max = (0.05, 2.0) if args.quick else (0.25, 60.0)
    jobs = []
    for rpm in rpms:
        dur = min(max(60.0 / rpm, dur_min), dur_max)    # one revolution when affordable
        for name, unit in units:
            jobs.append(_job(args, rng, timebase(args), "constant", name, unit,
                             [("constant", rpm * DETUNE, dur)], dur, rpm=rpm))
    return jobs


def scenario_jobs(args, units, rng):
    tb = timebase(args)
    jobs = []
    for sname, (spec, _) in SCENARIOS.items():
        dur = build_profile(spec).duration_s
        for name, unit in units:
            jobs.append(_job(args, rng, tb, sname, name, unit, spec, dur))
    return jobs


def prescale_jobs(args, units, rng):
    jobs = []
    for p in PRESCALES:
        tb = timebase(args, prescale=p)
        for rpm in PRESCALE_RPMS:
            dur = 0.3 if args.quick else max(60.0 / rpm, 0.5)
            for name, unit in units[:2]:
                jobs.append(_job(args, rng, tb, "prescale", name, unit,
                                 [("constant", rpm * DETUNE, dur)], dur, prescale=p, rpm=rpm))
    return jobs


def _sim_case(rng, case_id: str, kind: str, unit_name: str, rpm: float, edge: str, wf, spec,
              stall_s: float, n: int) -> dict:
    """One simulated case: ``n`` reads 1 ms apart from a random phase after SIM_T0_MS."""
    t0 = SIM_T0_MS + float(rng.uniform(0, 0.2))
    return {"id": case_id, "kind": kind, "unit": unit_name, "rpm": rpm, "edge_name": edge,
            "wf": wf, "profile": spec, "stall_s": stall_s,
            "reads_ns": [1e6 * (t0 + k) for k in range(n)]}


def sim_cases(args, units, rpms, rng):
    """Short windows: --sim-reads reads at 1 kHz, more where a cycle is long (at least two
    A-rising edges after the reference one); a stop, a ramp and a reversal."""
    cases = []
    sim_rpms = [r for r in rpms if r >= GOAL_BAND[0]]
    if args.quick:
        sim_rpms = [r for r in sim_rpms if r in (sim_rpms[0], sim_rpms[len(sim_rpms) // 2],
                                                   sim_rpms[-1])]
    stall_s = args.stall_ms * 1e-3
    for rpm in sim_rpms:
        cycle_ms = 60e3 / (rpm * CPR)
        n = max(args.sim_reads, int(math.ceil(3 * cycle_ms)) + 3)
        spec = [("constant", rpm * DETUNE, (SIM_T0_MS + n - 0.5) * 1e-3)]
        for name, unit in units[:SIM_UNITS]:
            wf = unit.waveform(build_profile(spec))
            for edge in ("any", "a_rising"):
                cases.append(_sim_case(rng, f"{name} {rpm:g} rpm {edge}", "constant", name, rpm,
                                       edge, wf, spec, stall_s, n))
    # a stop, with a short stall timeout (a 200 ms one would take 20 M clocks to simulate)
    name, unit = units[min(1, len(units) - 1)]
    spec = [("constant", SIM_STOP_RPM * DETUNE, 3e-3), ("stop", 6e-3)]
    wf = unit.waveform(build_profile(spec))
    for edge in ("any", "a_rising"):
        cases.append(_sim_case(rng, f"{name} stop after {SIM_STOP_RPM:g} rpm {edge}", "stop", name,
                               SIM_STOP_RPM, edge, wf, spec, SIM_STALL_S, 9))
    # a ramp and a reversal, short and steep
    for kind, spec, top, n in (
            ("ramp", [("ramp", 600.0 * DETUNE, 3000.0 * DETUNE, 8e-3)], 3000.0, 7),
            ("reversal", [("ramp", 150.0 * DETUNE, -150.0 * DETUNE, 16e-3)], 150.0, 15)):
        wf = unit.waveform(build_profile(spec))
        for edge in ("any", "a_rising"):
            cases.append(_sim_case(rng, f"{name} {kind} {edge}", kind, name, top, edge, wf, spec,
                                   stall_s, n))
    return cases
