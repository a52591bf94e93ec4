#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`make demo`: a modeled HEDS-5000 on a motor driving every circuit of the library at once.

What it does:
  1. Draws one encoder unit with every error factor at the application note's table mean
     (``EncoderUnit.typical``; directions and signs from ``--seed``), at ``--temp-c``.
  2. Runs it through a motion profile: ramp up to RPM, hold (long enough for two phase-meter
     readings), slow down and reverse to -RPM/5, stop, creep to one transition of channel A and
     dither about it (the note's "stationary shaft oscillating slightly about a transition").
  3. Simulates tb/hdl/demo_top.v (conditioner, 1X Figure 14, 2X Figure 15, 4X look-up table,
     Figure 17 BCD up/down buffer, Figure 11 phase meter, characterizer, and the bus peripheral
     enc_qei_wb) with cocotb (enctools.benches.demo_bench) at ``--clk-hz``, printing a progress
     line: on Icarus for short runs (it starts at once), on Verilator for long ones (faster once
     its C++ build is done). The bench reads enc_qei_wb over Wishbone as a host would: a snapshot
     (SNAP_CTRL.CMD, SNAP_CTRL.EDGE = a_rising) every READ_TAU encoder cycles at the peak speed
     (10 cycles: 400 us = 2.5 kHz at 3000 rpm, ~40 reads over the profile at any speed; the
     issue's 1 kHz would give a handful in a 15 ms profile), and COUNT at the end.
  4. Prints the position table: the true position against every count (enc_qei_wb's COUNT too),
     the phase meter against the model's true phase over the same cycles, the characterizer
     against the model, the narrowest state against the decoder's limit; then the velocity table:
     per read the model's true speed, the timestamp (M/T, A-rising edges) and unit-time (M)
     readings of hedsmodel.velocity on the registers, and the M/T error; then a verdict per
     circuit. Exit status 1 if any verdict fails.
  5. Leaves sim/waves/demo.vcd and a GTKWave save file for it, sim/waves/demo.gtkw (``make
     waves`` opens both): sim/demo.gtkw's signals, opening on three encoder cycles at the peak
     speed of this run, markers A to D on the rising edges of A that bound them (``--gtkw`` to
     choose the file; sim/demo.gtkw itself is ``--gtkw sim/demo.gtkw`` with the default options).
     Renders a short window of the VCD to sim/waves/demo_waves.png (``--png`` to choose the file;
     the README picture is ``--png sim/figures/demo_waves.png`` with the default options).

Options (``make demo RPM=... TEMP_C=... CLK_HZ=... SEED=...``; an empty value means the default):
  --rpm     peak shaft speed, rpm (default 3000); the reverse speed is -rpm/5
  --temp-c  encoder temperature, deg C, -40 .. 125 (default 25)
  --clk-hz  sampling clock of the circuits, Hz (default 12e6)
  --seed    non-negative integer (default 1)
A bad value stops the demo with a one-line message before anything is built or simulated.

``--view`` (``make waves``): open sim/waves/demo.vcd with its save file (sim/waves/demo.gtkw,
else sim/demo.gtkw) in GTKWave when there is a display and gtkwave is installed, otherwise print
where the files are and the command.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import shutil
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .paths import TOP

NAME = "demo"
VCD = TOP / "sim" / "waves" / "demo.vcd"
GTKW = TOP / "sim" / "demo.gtkw"
DEFAULT_PNG = TOP / "sim" / "waves" / "demo_waves.png"
# The save file's view: GTKW_CYCLES cycles at the peak speed from the first rising edge of A after
# the middle of the hold (where the README picture's left panel starts), with half a cycle either
# side. GTKWave's zoom is time per pixel, so the visible span follows the window: GTKW_WAVE_PX is
# the width of GTKWave 3.3's wave pane at the save file's [size] (measured under Xvfb; the signal
# pane takes the rest). A window narrower by up to a quarter still shows the three cycles.
GTKW_CYCLES = 3
GTKW_VIEW_CYCLES = GTKW_CYCLES + 1.0
GTKW_WAVE_PX = 800
README_PNG = TOP / "sim" / "figures" / "demo_waves.png"

# ---------------------------------------------------------------------------------------------
# Fixed design choices of the demo
# ---------------------------------------------------------------------------------------------
CPR = 500                  # HEDS-5000 code wheel count
FILTER_LEN = 3             # the conditioner's filter (the HCTL-2016's 3 samples)
SAMPLING_LIMIT = 1.05      # clocks: narrowest state a decoder counts (any sampler needs > 1)
LEVEL_LIMIT = 1.05 * FILTER_LEN  # clocks: narrowest state that passes the FILTER_LEN filter
NOTE_STATE_ERR = 44.0      # e-degrees: the note's 95 % state-width error at room temperature
ALPHA = 1.0e-5             # e-degree / (degC Hz): the note's typical pulse-width temperature coeff.
TEST_LIMIT_DEG = 46.0      # characterizer pass limit: 90 - 44 (the note's room-temperature limit)
CHAR_CYCLES = 64           # characterizer window, cycles
CHAR_CNT_W = 16
PM_MIN_CYCLES = 64         # phase meter contract: >= 64 cycles per window ...
PM_MIN_CPC = 100           # ... and >= 100 clocks per cycle for its 0.25 degree accuracy
PM_BOUND = 0.25
# enc_qei_wb velocity (issue 13): reads, estimator and the two checks
READ_TAU = 10.0            # a snapshot every 10 encoder cycles at the peak speed (tau each)
STALL_TAU = 8.0            # STALL_TIMEOUT: 8 tau without a count edge (longer than a cycle at
                           # -rpm/5, shorter than the stop's 5-tau rest after the last edge)
VEL_EDGE = "a_rising"      # SNAP_CTRL.EDGE for the recommended M/T method
VEL_TOL_PCT = 1.2          # M/T vs the true speed at constant speed: the encoder's own error floor
                           # for M/T on A-rising edges is at most 1.17 % (worst modelled unit, one
                           # cycle per reading; 0.3-0.4 % rms), doc/results/velocity_methods.md
VEL_HW_TICKS = 2.0         # registers vs the same estimator on the model's exact edge times: each
                           # timestamp is quantised to one clock, so a span is off by < 2 ticks
VEL_MATCH_CLOCKS = 48      # a timestamp is at most this far behind its edge at the pins (the
                           # synchroniser, filter and pipeline: ~FILTER_LEN + 5 clocks)
VEL_SHOW_PCT = 5.0         # error % shown where |true speed| >= 5 % of the peak
# Measured: Icarus runs demo_top at ~18k clocks/s and builds at once; Verilator ~150k clocks/s
# after a ~20 s C++ build.
ICARUS_MAX_CLOCKS = 350_000   # --sim auto takes Icarus up to here (~20 s), Verilator beyond
MAX_CLOCKS = 1_000_000     # runtime and VCD budget: ~40 bytes of VCD per simulated clock
TEMP_RANGE = (-40.0, 125.0)
CLK_RANGE = (1.0e5, 2.0e8)  # 100 kHz .. 200 MHz
DEFAULTS = {"rpm": 3000.0, "temp_c": 25.0, "clk_hz": 12.0e6, "seed": 1}

# Profile, in periods tau of one encoder cycle at the peak speed (tau = 40 us at 3000 rpm).
TAU_RAMP_UP = 50.0         # 0 -> rpm                (25 cycles)
TAU_REVERSE = 60.0         # rpm -> -rpm/5
TAU_BACK = 25.0            # -rpm/5 constant         (5 cycles)
TAU_STOP_RAMP = 25.0       # -rpm/5 -> 0
TAU_REST = 5.0             # standstill between moves
CREEP_DIV = 20.0           # creep to the dither transition at rpm/20
DITHER_PERIODS = 8
TAU_DITHER = 5.0           # one dither period
DITHER_AMP_DEG = 20.0
DITHER_OFFSET_DEG = 2.0    # dither centre: this far on the near side of the transition


class OptionError(ValueError):
    """A bad command-line value; the message is the one line printed."""


# ---------------------------------------------------------------------------------------------
# Options
# ---------------------------------------------------------------------------------------------
def f_max_hz(clk_hz: float, temp_c: float) -> float:
    """Highest output frequency the 4X decoder counts at this clock and temperature: the narrowest
    state of a unit at the note's state-width limit (90 - 44 e-degrees, less the temperature term
    alpha |T - 25| f of the note's guard-band example) must last LEVEL_LIMIT clocks:
        (90 - 44 - alpha |dT| f) / (360 f) >= LEVEL_LIMIT / clk."""
    return (90.0 - NOTE_STATE_ERR) / (360.0 * LEVEL_LIMIT / clk_hz + ALPHA * abs(temp_c - 25.0))


def rpm_of(f_hz: float) -> float:
    return f_hz * 60.0 / CPR


def _number(name: str, text, integer: bool = False):
    if text is None or (isinstance(text, str) and text.strip() == ""):
        return DEFAULTS[name.replace("-", "_")]
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise OptionError(f"{name.upper().replace('-', '_')}={text!r} is not a number") from None
    if not math.isfinite(value):
        raise OptionError(f"{name.upper().replace('-', '_')}={text!r} must be finite")
    if integer:
        if value != int(value) or value < 0 or not str(text).strip().lstrip("+").isdigit():
            raise OptionError(f"SEED={text!r} must be a non-negative integer")
        return int(value)
    return value


@dataclass
class Options:
    rpm: float
    temp_c: float
    clk_hz: float
    seed: int


def validate(rpm=None, temp_c=None, clk_hz=None, seed=None) -> Options:
    """Check the four options (strings or numbers; None or '' = default). Raises OptionError."""
    temp = _number("temp-c", temp_c)
    if not TEMP_RANGE[0] <= temp <= TEMP_RANGE[1]:
        raise OptionError(f"TEMP_C={temp:g} is outside the HEDS-5000's -40 .. 125 degC")
    clk = _number("clk-hz", clk_hz)
    if clk <= 0:
        raise OptionError(f"CLK_HZ={clk:g} must be positive")
    if not CLK_RANGE[0] <= clk <= CLK_RANGE[1]:
        raise OptionError(f"CLK_HZ={clk:g} is outside the demo's {CLK_RANGE[0]:g} .. {CLK_RANGE[1]:g} Hz")
    r = _number("rpm", rpm)
    if r <= 0:
        raise OptionError(f"RPM={r:g} must be positive (it is the peak speed; the reverse speed is -RPM/5)")
    rmax = rpm_of(f_max_hz(clk, temp))
    if r > rmax:
        raise OptionError(f"RPM={r:g} is above what the 4X decoder can count at CLK_HZ={clk:g} and "
                          f"TEMP_C={temp:g}: at most {math.floor(rmax):d} rpm (states of "
                          f"{90 - NOTE_STATE_ERR:g} e-deg must last {LEVEL_LIMIT:.2f} clocks)")
    rmin = rpm_min(clk)
    if r < rmin:
        raise OptionError(f"RPM={r:g} at CLK_HZ={clk:g} needs more than {MAX_CLOCKS:,} simulated clocks "
                          f"(the demo's runtime budget): use RPM >= {math.ceil(rmin):d}")
    s = _number("seed", seed, integer=True)
    return Options(r, temp, clk, s)


def pm_window_log2(cpc: float) -> int:
    """Phase meter window: at least PM_MIN_CYCLES cycles (8 .. 24)."""
    return int(min(24, max(8, math.ceil(math.log2(PM_MIN_CYCLES * cpc)))))


def hold_cycles(cpc: float, readings: int = 2) -> int:
    """Constant-speed cycles: room for ``readings`` phase-meter windows (each opens on an A rise
    after the previous reading) and as many characterizer windows."""
    w = 2 ** pm_window_log2(cpc)
    pm = readings * (w / cpc + 2 + (pm_window_log2(cpc) + 40) / cpc)
    return int(math.ceil(max(pm, readings * (CHAR_CYCLES + 2)) + 4))


def estimate_clocks(rpm: float, clk_hz: float, readings: int | None = None) -> float:
    """Simulated clocks of the whole profile; ``readings`` None: as many as the budget allows."""
    if readings is None:
        readings = 2 if estimate_clocks(rpm, clk_hz, 2) <= MAX_CLOCKS else 1
    cpc = clk_hz / (rpm / 60.0 * CPR)
    taus = (TAU_RAMP_UP + TAU_REVERSE + TAU_BACK + TAU_STOP_RAMP + 4 * TAU_REST + CREEP_DIV
            + DITHER_PERIODS * TAU_DITHER)
    return (taus + hold_cycles(cpc, readings)) * cpc


def rpm_min(clk_hz: float) -> float:
    lo, hi = 1e-3, 1e7
    for _ in range(100):  # estimate_clocks falls with rpm (stepwise): bisect
        mid = math.sqrt(lo * hi)
        if estimate_clocks(mid, clk_hz, 1) > MAX_CLOCKS:
            lo = mid
        else:
            hi = mid
    return hi


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rpm", default=None, help="peak speed, rpm (default 3000)")
    ap.add_argument("--temp-c", default=None, help="temperature, degC, -40..125 (default 25)")
    ap.add_argument("--clk-hz", default=None, help="circuit clock, Hz (default 12e6)")
    ap.add_argument("--seed", default=None, help="unit seed, integer >= 0 (default 1)")
    ap.add_argument("--sim", default="auto", choices=("auto", "verilator", "icarus"),
                    help="simulator (default auto: Icarus for short runs, which needs no C++ "
                         "build; Verilator, faster per clock, for long ones)")
    ap.add_argument("--png", default=str(DEFAULT_PNG),
                    help="where to render the waveform picture ('' = none)")
    ap.add_argument("--gtkw", default=None,
                    help="where to write the GTKWave save file for this run (default "
                         "sim/waves/NAME.gtkw beside the VCD; '' = none)")
    ap.add_argument("--view", action="store_true", help="open the demo's VCD in GTKWave (make waves)")
    ap.add_argument("--name", default=NAME, help=argparse.SUPPRESS)  # build dir and VCD name (tests)
    args = ap.parse_args(argv)
    return args


# ---------------------------------------------------------------------------------------------
# The model side: unit, profile, waveform, timeline
# ---------------------------------------------------------------------------------------------
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


def make_plan(opts: Options) -> Plan:
    import numpy as np
    from hedsmodel import EncoderUnit, Profile

    rng = np.random.default_rng(opts.seed)
    unit = EncoderUnit.typical(rng, temp_c=opts.temp_c)
    clk_ps = 2 * int(round(1e12 / opts.clk_hz / 2))  # even: the clock's two halves are equal
    clk_hz = 1e12 / clk_ps
    f = opts.rpm / 60.0 * CPR
    tau = 1.0 / f
    cpc = clk_hz / f
    wl2 = pm_window_log2(cpc)
    readings = 2 if estimate_clocks(opts.rpm, clk_hz, 2) <= MAX_CLOCKS else 1
    n_hold = hold_cycles(cpc, readings)

    # start in the middle of the unit's own state 00 before cycle 0, so the reset state (00) of
    # the conditioner is the true first state and position 0 is where the count starts
    e = unit.edges(-1, 1)                      # edges m = -4 .. 3
    start_x = (e[3] + e[4]) / 2
    p = Profile(start_deg=start_x * 360.0)
    seg = {}

    def mark(name, t0):
        seg[name] = (t0 * 1e9, p.duration_s * 1e9)

    t = p.duration_s
    p.ramp(0.0, opts.rpm, TAU_RAMP_UP * tau); mark("ramp up", t); t = p.duration_s
    p.constant(opts.rpm, n_hold * tau); mark("hold", t); t = p.duration_s
    p.ramp(opts.rpm, -opts.rpm / 5, TAU_REVERSE * tau); mark("reverse", t); t = p.duration_s
    p.constant(-opts.rpm / 5, TAU_BACK * tau); mark("back", t); t = p.duration_s
    p.ramp(-opts.rpm / 5, 0.0, TAU_STOP_RAMP * tau); p.stop(TAU_REST * tau); mark("stop", t)
    t = p.duration_s
    # creep (reverse, as the last motion) to the nearest A-fall edge (m = 2 mod 4) below
    x_now = p.end_deg / 360.0
    k = math.floor(x_now)
    edges = unit.edges(k - 2, k + 2)
    ms = np.arange(4 * (k - 2), 4 * (k + 2))
    off = DITHER_OFFSET_DEG / 360.0
    cand = [(x, m) for x, m in zip(edges, ms) if m % 4 == 2 and x + off < x_now - 1e-6]
    x_edge, m_edge = max(cand)
    i = int(np.flatnonzero(ms == m_edge)[0])
    room = min(edges[i] - edges[i - 1], edges[i + 1] - edges[i]) * 360.0  # adjacent states, e-deg
    amp = min(DITHER_AMP_DEG, 0.4 * room)
    creep_rpm = opts.rpm / CREEP_DIV
    dist = x_now - (x_edge + off)
    p.constant(-creep_rpm, dist / (creep_rpm / 60.0 * CPR)); p.stop(TAU_REST * tau)
    mark("creep", t); t = p.duration_s
    p.dither(amp, DITHER_PERIODS, TAU_DITHER * tau); mark("dither", t); t = p.duration_s
    p.stop(TAU_REST * tau); mark("rest", t)
    wf = unit.waveform(p)
    return Plan(opts, unit, wf, clk_ps, cpc, wl2, seg, int(m_edge), int(wf.positions[0]), amp, p)


def tau_ns(plan: Plan) -> float:
    """One encoder cycle at the peak speed, ns."""
    return 1e9 / (plan.opts.rpm / 60.0 * CPR)


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
    data = {
        "clk_ps": plan.clk_ps,
        "events": [[round(t, 4), a, b] for t, a, b in plan.wf.events],
        "seg": plan.seg,
        "meas_rst_ns": plan.seg["hold"][0] + 2e9 / (plan.opts.rpm / 60 * CPR),
        "hold_test_ns": plan.seg["hold"][0] + 0.5 * (plan.seg["hold"][1] - plan.seg["hold"][0]),
        "hold_test_clocks": int(5 * plan.cpc),
        "back_mid_ns": sum(plan.seg["back"]) / 2,
        "qei": {"reads_ns": qei_reads_ns(plan), "edge": VEL_EDGE,
                "stall_ticks": qei_stall_ticks(plan)},
    }
    path.write_text(json.dumps(data))


# ---------------------------------------------------------------------------------------------
# Simulation
# ---------------------------------------------------------------------------------------------
def _progress(progress_file: Path, stop: threading.Event, tty: bool) -> None:
    last_pct = -1
    shown = -25
    while not stop.wait(0.2):
        try:
            text = progress_file.read_text().split()
            now, total, label = float(text[0]), float(text[1]), " ".join(text[2:])
        except (OSError, ValueError, IndexError):
            continue
        pct = int(100 * now / total) if total else 0
        if pct == last_pct:
            continue
        last_pct = pct
        line = (f"demo: simulating {now / 1e6:6.2f} of {total / 1e6:.2f} ms  "
                f"[{'#' * (pct // 5):<20}] {pct:3d}%  {label}")
        if tty:
            print("\r" + line.ljust(88), end="", flush=True)
        elif pct >= shown + 25:
            shown = pct - pct % 25
            print(line, flush=True)
    if tty:
        print("\r" + " " * 88 + "\r", end="", flush=True)


def simulate(plan: Plan, sim: str, name: str = NAME) -> dict:
    """Run the plan on demo_top through the harness (the same path as every test): the bench
    enctools.benches.demo_bench reads the plan and writes its result; the VCD (demo_top's own
    signals) goes to sim/waves/<name>.vcd."""
    from . import harness

    logging.getLogger("cocotb").setLevel(logging.WARNING)
    os.environ["SIM"] = sim
    io_dir = TOP / "sim" / "build" / sim / f"{name}-io"
    vcd = VCD.with_name(f"{name}.vcd")
    io_dir.mkdir(parents=True, exist_ok=True)
    plan_file, result_file, progress_file = (io_dir / n for n in
                                             ("plan.json", "result.json", "progress.txt"))
    for fpath in (result_file, progress_file):
        fpath.unlink(missing_ok=True)
    write_plan(plan, plan_file)
    params = {"FILTER_LEN": FILTER_LEN, "WINDOW_LOG2": plan.window_log2, "CNT_W": CHAR_CNT_W,
              "WINDOW_CYCLES": CHAR_CYCLES, "MIN_STATE": int(round(TEST_LIMIT_DEG * 256))}
    vcd.parent.mkdir(parents=True, exist_ok=True)
    vcd.unlink(missing_ok=True)
    env = {"ENC_DEMO_PLAN": str(plan_file), "ENC_DEMO_RESULT": str(result_file),
           "ENC_DEMO_PROGRESS": str(progress_file)}
    if sim == "icarus":
        env["COCOTB_RESOLVE_X"] = "ZEROS"
    print(f"demo: building and running demo_top with {sim}", flush=True)
    stop = threading.Event()
    th = threading.Thread(target=_progress, args=(progress_file, stop, sys.stdout.isatty()),
                          daemon=True)
    th.start()
    try:
        # demo_top's own signals only (wave_depth 1): every signal the review needs is one of them
        out = harness.run("demo_top", "enctools.benches.demo_bench", name=name, parameters=params,
                          tb_sources=("demo_top.v",), extra_env=env, quiet=True, waves=True,
                          wave_depth=1, vcd=vcd, seed=str(plan.opts.seed))
    except RuntimeError as exc:
        raise SystemExit(f"demo: simulation failed ({exc})")
    finally:
        stop.set()
        th.join()
    if not result_file.exists():
        log = out.test_dir / "test.log"
        tail = "".join(log.read_text(errors="replace").splitlines(True)[-20:])
        raise SystemExit(f"demo: the bench wrote no result; last lines of {log}:\n{tail}")
    res = json.loads(result_file.read_text())
    res["t_build"], res["t_sim"] = out.build_s, out.run_s
    return res


# ---------------------------------------------------------------------------------------------
# Analysis
# ---------------------------------------------------------------------------------------------
def a_edges(p: int) -> int:
    """Net transitions of A from position 0 to 4X position p (edges m = 0, 2 mod 4 are A's)."""
    return -(-p // 2)


def _events_between(wf, i0: int, i1: int):
    from hedsmodel.waveform import Waveform
    return Waveform(events=wf.events[i0:i1 + 1], positions=wf.positions[i0:i1 + 1])


def _a_rises(wf, t0_ps: float):
    """(sim time ps, event index) of every rising edge of A in the model waveform."""
    out = []
    prev = wf.events[0][1]
    for i, (t, a, _) in enumerate(wf.events):
        if a and not prev:
            out.append((t0_ps + t * 1000.0, i))
        prev = a
    return out


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


def true_phase(plan: Plan, res: dict, reading_ps: float):
    """The model's phase over the cycles of the phase-meter window that produced the reading at
    ``reading_ps``: measure() over those whole cycles (mean of the per-cycle phase, each cycle
    converted with the window's mean period = 180 x XOR-high time / span, what the meter reads)."""
    from hedsmodel import measure
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
    mapping = _match_rises(rises, _a_rises(plan.wf, res["t0_ps"]), clk)
    if rises[0] not in mapping or rises[-1] not in mapping:
        return None
    i0, i1 = mapping[rises[0]], mapping[rises[-1]]
    m = measure(_events_between(plan.wf, i0 - 1, i1), window=10**6)
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
    from hedsmodel import measure
    clk = plan.clk_ps
    before = [r for r in res["a_rises_ps"] if r <= valid_ps - 8 * char_wide_w() * clk]
    if len(before) < CHAR_CYCLES + 1:
        return None
    rises = before[-(CHAR_CYCLES + 1):]
    mapping = _match_rises(rises, _a_rises(plan.wf, res["t0_ps"]), clk)
    if rises[0] not in mapping or rises[-1] not in mapping:
        return None
    m = measure(_events_between(plan.wf, mapping[rises[0]] - 1, mapping[rises[-1]]), window=10**6)
    return {"m": m, "first_ns": (rises[0] - res["t0_ps"]) / 1000,
            "last_ns": (rises[-1] - res["t0_ps"]) / 1000}


def _s32(x: int) -> int:
    return x - (1 << 32) if x >= 1 << 31 else x


def analyze_velocity(plan: Plan, res: dict) -> dict:
    """enc_qei_wb's snapshots -> velocity rows and the two checks.

    Every read gives a latched :class:`hedsmodel.velocity.Snapshot`; the project's estimator
    turns the stream into M/T (SNAP_EDGE_DELTA / delta SNAP_EDGE_TIME, A-rising edges, with the
    standstill rule and STATUS.STALLED) and M readings. Checks:

    - *truth*: where the two A-rising edges of a M/T measurement and the read lie in a
      constant-speed segment (hold, back), the reading is within VEL_TOL_PCT of the model's true
      speed (what is left is the encoder's own error: cycle error and eccentricity);
    - *registers*: every reading equals, within VEL_HW_TICKS of timestamp quantisation, the same
      estimator on the same snapshots with each SNAP_EDGE_TIME replaced by the model's exact pin
      time of that edge plus one constant (the median offset, i.e. the pipeline latency measured
      here, whatever it is); SNAP_EDGE_DELTA equals the model's count between the two edges.

    Each SNAP_EDGE_TIME is matched to the model's last A-rising edge at the pins before it (its
    time in the simulation: the read's acknowledge less SNAP_TIME - SNAP_EDGE_TIME ticks; the
    pipeline only delays it, by far less than a cycle)."""
    import numpy as np
    from hedsmodel.velocity import (EstimatorConfig, Snapshot, VelocityEstimator, counts_per_edge,
                                    to_rpm, true_rpm)

    q = res["qei"]
    reads = q["reads"]
    t0 = res["t0_ps"]
    tick_ps = float(plan.clk_ps)           # TB_PRESCALE 0
    tick_s = tick_ps * 1e-12
    cpe = counts_per_edge(VEL_EDGE)
    rises = _a_rises(plan.wf, t0)
    rise_ps = np.array([t for t, _ in rises])
    latched, pins, unmatched = [], [], 0
    for r in reads:
        s = Snapshot(count=r["SNAP_COUNT_LO"], time=r["SNAP_TIME"], edge_time=r["SNAP_EDGE_TIME"],
                     delta=_s32(r["SNAP_DELTA"]), edge_delta=_s32(r["SNAP_EDGE_DELTA"]),
                     stalled=r["stalled"])
        latched.append(s)
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
    # one constant offset, ticks: SNAP_EDGE_TIME - pin time (the pipeline latency + the timebase's
    # origin); the median, so no latency is assumed
    offs = [latched[k].edge_time - rise_ps[j] / tick_ps for k, j in enumerate(pins) if j is not None]
    off = float(np.median(offs)) if offs else 0.0
    twin = [Snapshot(count=s.count, time=float(s.time),
                     edge_time=(rise_ps[j] / tick_ps + off) if j is not None else float(s.edge_time),
                     delta=s.delta, edge_delta=s.edge_delta, stalled=s.stalled)
            for s, j in zip(latched, pins)]
    est = VelocityEstimator(EstimatorConfig(tick_s=tick_s, ts_w=32, count_w=32, counts_per_edge=cpe))
    est_x = VelocityEstimator(EstimatorConfig(tick_s=tick_s, ts_w=None, count_w=32, counts_per_edge=cpe))
    rd, rdx = est.run(latched), est_x.run(twin)
    t_s = np.array([(r["t_ack_ps"] - t0) * 1e-12 for r in reads])
    truth = true_rpm(plan.profile, t_s)
    const = {k: plan.seg[k] for k in ("hold", "back")}
    pos = plan.wf.positions
    rows, n_hw_bad, n_cnt_bad, n_cnt = [], 0, 0, 0
    worst_hw, hw_allow_at_worst = 0.0, 0.0
    prev_j = None
    for k, (r, s, a, x) in enumerate(zip(reads, latched, rd, rdx)):
        j = pins[k]
        mt, mtx, m = to_rpm(a.mt), to_rpm(x.mt), to_rpm(a.m)
        allow = VEL_HW_TICKS * tick_s * x.mt ** 2 / cpe + 1e-9 * abs(x.mt)   # counts/s
        hw_ok = abs(a.mt - x.mt) <= allow
        n_hw_bad += not hw_ok
        if x.mt and abs(a.mt - x.mt) / abs(x.mt) > worst_hw:
            worst_hw, hw_allow_at_worst = abs(a.mt - x.mt) / abs(x.mt), allow / abs(x.mt)
        # SNAP_EDGE_DELTA against the model's count between the two matched edges
        if k > 0 and j is not None and prev_j is not None:
            n_cnt += 1
            n_cnt_bad += s.edge_delta != pos[rises[j][1]] - pos[rises[prev_j][1]]
        seg = next((n for n, (a0, b0) in plan.seg.items() if a0 <= t_s[k] * 1e9 < b0), "end")
        checked = False
        if k > 0 and s.edge_delta != 0 and j is not None and prev_j is not None:
            e0, e1 = (rises[prev_j][0] - t0) / 1e3, (rises[j][0] - t0) / 1e3   # ns
            for a0, b0 in const.values():
                if a0 <= e0 and e1 <= b0 and a0 <= t_s[k] * 1e9 <= b0:
                    checked = True
        tr = float(truth[k])
        err = (mt - tr) / abs(tr) * 100.0 if abs(tr) >= VEL_SHOW_PCT / 100 * plan.opts.rpm else None
        rows.append(dict(k=k, t_ms=t_s[k] * 1e3, seg=seg, true=tr, mt=mt, mt_exact=mtx, m=m,
                         err=err, edge_delta=s.edge_delta, stalled=s.stalled, checked=checked,
                         ok=checked and err is not None and abs(err) <= VEL_TOL_PCT and mt != 0,
                         hw_ok=hw_ok))
        prev_j = j
    chk = [r for r in rows if r["checked"]]
    errs = np.array([r["err"] for r in chk if r["err"] is not None])
    cnt = _s32(q["count"] & 0xFFFFFFFF)
    p = plan.wf.final_position - plan.start_pos
    ok = (cnt == p and n_hw_bad == 0 and n_cnt_bad == 0 and unmatched == 0 and chk
          and all(r["ok"] for r in chk))
    return dict(rows=rows, checked=len(chk), bad=sum(not r["ok"] for r in chk),
                rms=float(np.sqrt(np.mean(errs ** 2))) if errs.size else float("nan"),
                max=float(np.max(np.abs(errs))) if errs.size else float("nan"),
                n_hw_bad=n_hw_bad, worst_hw=worst_hw * 100, hw_allow=hw_allow_at_worst * 100,
                n_cnt=n_cnt, n_cnt_bad=n_cnt_bad, unmatched=unmatched, count=cnt, p=p, ok=bool(ok),
                offset_ticks=off, stall_ticks=qei_stall_ticks(plan),
                read_us=READ_TAU * tau_ns(plan) / 1e3, n_reads=len(reads),
                zeros=sum(1 for r in rows if r["k"] > 0 and r["mt"] == 0
                          and abs(r["true"]) >= VEL_SHOW_PCT / 100 * plan.opts.rpm))


def analyze(plan: Plan, res: dict):
    """Rows of the table and the verdicts."""
    from hedsmodel import measure

    wf = plan.wf
    p = wf.final_position - plan.start_pos
    p2 = a_edges(wf.final_position) - a_edges(plan.start_pos)
    clk_ns = plan.clk_ps / 1000.0
    m_all = measure(wf, window=0)
    hold0, hold1 = plan.seg["hold"]
    rows, verdicts = [], []

    def verdict(name, ok, why):
        verdicts.append((name, ok, why))

    fin = res["final"]
    # --- conditioner ---------------------------------------------------------------------
    min_clk = m_all.min_state_ns / clk_ns
    ok = fin["n_glitch"] == 0 and min_clk >= LEVEL_LIMIT
    verdict("enc_conditioner", ok,
            "no glitch flagged; every state wider than the filter" if ok else
            f"{fin['n_glitch']} glitches flagged" if fin["n_glitch"] else
            f"narrowest state {min_clk:.2f} clocks < {LEVEL_LIMIT:.2f}")
    # --- 4X ------------------------------------------------------------------------------
    ok = fin["x4_count"] == p and fin["n_x4_err"] == 0
    verdict("enc_x4_decoder", ok, "count = true 4X position, no error pulse" if ok else
            f"count {fin['x4_count']} vs {p}, {fin['n_x4_err']} error pulses")
    # --- 2X ------------------------------------------------------------------------------
    ok = fin["x2_count"] == p2 and fin["n_x2_err"] == 0
    verdict("enc_x2_xor", ok, "count = true 2X position, no error pulse" if ok else
            f"count {fin['x2_count']} vs {p2}, {fin['n_x2_err']} error pulses")
    # --- 1X ------------------------------------------------------------------------------
    n1 = fin["x1_count"]
    d = p - 4 * n1
    dith = res["dither"]
    ok = -1 <= d <= 3 and fin["n_x1_err"] == 0 and dith["x1_pulses"] <= 1
    verdict("enc_x1_hysteresis", ok,
            f"p - 4n = {d} in -1..3; {dith['x1_pulses']} pulse(s) in the dither" if ok else
            f"p - 4n = {d} (band -1..3), {fin['n_x1_err']} errors, "
            f"{dith['x1_pulses']} pulses while dithering")
    # --- BCD buffer ----------------------------------------------------------------------
    bcd = fin["bcd_count"]
    bcd_ok_digits = all(c in "0123456789" for c in f"{bcd:04x}")
    bcd_val = int(f"{bcd:04x}") if bcd_ok_digits else None
    want = p2 % 10000
    ht = res["hold_test"]
    ok = (bcd_val == want and fin["bcd_rd"] == bcd and fin["n_bcd_flag"] == 0 and ht["frozen"]
          and ht["moved"] > 0 and ht["caught_up"])
    verdict("enc_updown_buffer", ok,
            f"BCD = 2X mod 10^4; rd_data frozen during hold while the count moved {ht['moved']}"
            if ok else
            f"BCD {bcd:04x} vs {want:04d}, rd {fin['bcd_rd']:04x}, flags {fin['n_bcd_flag']}, "
            f"hold frozen={ht['frozen']} moved={ht['moved']} caught_up={ht['caught_up']}")
    # --- phase meter ---------------------------------------------------------------------
    pm_rows = []
    in_contract = plan.cpc >= PM_MIN_CPC
    bound = PM_BOUND if in_contract else max(PM_BOUND, 360.0 / plan.cpc)
    worst = None
    misaligned = 0
    for rd in res["pm_readings"]:
        tp = true_phase(plan, res, rd["t_ps"])
        if tp is None or not (hold0 <= tp["first_ns"] and tp["last_ns"] <= hold1):
            continue
        if not tp["aligned"]:
            misaligned += 1  # the window's opening edge is not where the contract timing says
            continue
        err = rd["phase_err"] / 256.0 - (tp["phase"] - 90.0)
        pm_rows.append((rd, tp, err))
        if worst is None or abs(err) > abs(worst[2]):
            worst = (rd, tp, err)
    leds = res["leds"]
    leds_ok = leds["hold"] == [1, 0] and leds["back"] == [0, 1]
    if worst is None:
        verdict("enc_phase_meter", False, "no reading from a constant-speed window" +
                (f" ({misaligned} window(s) not where the contract's timing puts them)"
                 if misaligned else ""))
    else:
        ok = abs(worst[2]) <= bound and leds_ok
        verdict("enc_phase_meter", ok,
                f"|error| {abs(worst[2]):.3f} <= {bound:.2f} deg over {len(pm_rows)} reading(s); "
                f"LEDs follow the direction" if ok else
                f"error {worst[2]:+.3f} deg (bound {bound:.2f}); LEDs hold {leds['hold']} "
                f"reverse {leds['back']}")
    # --- characterizer -------------------------------------------------------------------
    ch_rows = []
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
        ch_rows.append((rd, pairs, dev, pass_ok))
    if not ch_rows:
        verdict("enc_characterizer", False, "no result from a constant-speed window")
    else:
        dev = max(r[2] for r in ch_rows)
        ok = dev <= tol and all(r[3] for r in ch_rows)
        verdict("enc_characterizer", ok,
                f"all within {dev:.2f} <= {tol:.2f} deg (1 clock) of the model, "
                f"{len(ch_rows)} window(s)" if ok else
                f"off by {dev:.2f} deg (tolerance {tol:.2f}) or pass flag wrong")
    # --- enc_qei_wb (count and velocity over the bus) --------------------------------------
    vel = analyze_velocity(plan, res)
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
    verdict("enc_qei_wb", vel["ok"],
            f"COUNT = true 4X position; M/T within {vel['max']:.2f} <= {VEL_TOL_PCT:g} % of the "
            f"true speed ({vel['checked']} constant-speed reads); all {vel['n_reads']} reads = "
            f"model edges within {VEL_HW_TICKS:g} ticks" if vel["ok"] else "; ".join(why))
    return dict(p=p, p2=p2, m_all=m_all, pm_rows=pm_rows, pm_bound=bound, pm_in_contract=in_contract,
                ch_rows=ch_rows, ch_tol=tol, verdicts=verdicts, min_clk=min_clk, vel=vel)


def print_report(plan: Plan, res: dict, an: dict) -> None:
    o, u = plan.opts, plan.unit
    fin, dith, leds, ht = res["final"], res["dither"], res["leds"], res["hold_test"]
    p, p2 = an["p"], an["p2"]
    m = an["m_all"]
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
    line = "-" * 106

    def row(name, reads="", truth="", flags=""):
        print(f"{name:<24}{reads:<34}{truth:<32}{flags}".rstrip())

    print(line)
    row("", "circuit reads", "truth (model) / limit", "flags")
    print(line)
    row("true position", "", f"4X {p}, 2X {p2}, {p / 4:.2f} cycles")
    row("enc_x4_decoder (4X)", f"count {fin['x4_count']}", f"{p}", f"error x{fin['n_x4_err']}")
    row("enc_qei_wb (x4, bus)", f"COUNT {an['vel']['count']} (read over Wishbone)", f"{p}")
    row("enc_x2_xor (2X)", f"count {fin['x2_count']}", f"{p2}", f"error x{fin['n_x2_err']}")
    n1 = fin["x1_count"]
    row("enc_x1_hysteresis (1X)", f"count {n1} (4n - p = {4 * n1 - p:+d})",
        f"{p / 4:.2f} cycles; |4n - p| < 8", f"error x{fin['n_x1_err']}")
    row("  while dithering", f"1X pulses {dith['x1_pulses']}, net {dith['x1_net']:+d}",
        f"4X pulses {dith['x4_pulses']}, net {dith['x4_net']:+d}", f"2X net {dith['x2_net']:+d}")
    bcd = fin["bcd_count"]
    row("enc_updown_buffer", f"BCD {bcd:04x}, rd_data {fin['bcd_rd']:04x}",
        f"{p2 % 10000:04d} (2X mod 10^4)", f"glitch/error x{fin['n_bcd_flag']}")
    row("  hold (inhibit) test", f"rd_data {'frozen' if ht['frozen'] else 'MOVED'} {ht['clocks']} clk",
        f"count moved {ht['moved']} meanwhile",
        "caught up <= 2 clk" if ht["caught_up"] else "caught up LATE")
    for rd, tp, err in an["pm_rows"]:
        row("enc_phase_meter", f"phase_err {rd['phase_err'] / 256:+.3f} deg",
            f"{tp['phase'] - 90:+.3f} deg ({tp['cycles']} cycles)",
            f"error {err:+.3f} (<= {an['pm_bound']:.2f})")
    led = {(1, 0): "A leads (red LED)", (0, 1): "B leads"}
    row("  LEDs fwd / reverse", f"{led.get(tuple(leds['hold']), leds['hold'])} / "
        f"{led.get(tuple(leds['back']), leds['back'])}", "A leads / B leads",
        "" if an["pm_in_contract"] else f"{plan.cpc:.0f} clk/cycle < 100")
    for rd, pairs, dev, _ in an["ch_rows"]:
        row("enc_characterizer", "max error, e-deg:", "model, same cycles:", f"pass={rd['pass']}")
        for k, (a, b) in pairs.items():
            row(f"  {k}", f"{a:.2f}", f"{b:.2f}",
                f"(limit {TEST_LIMIT_DEG:g})" if k == "min state" else "")
    row("narrowest state", f"{m.min_state_ns:.1f} ns = {an['min_clk']:.1f} clocks",
        f"limit {SAMPLING_LIMIT} / {LEVEL_LIMIT:.2f} clk (level)", f"glitch x{fin['n_glitch']}")
    print(line)
    print_velocity(plan, an["vel"], line)
    print(line)
    for name, ok, why in an["verdicts"]:
        print(f"  {'PASS' if ok else 'FAIL'}  {name:<20} {why}")
    print(line)


def print_velocity(plan: Plan, vel: dict, line: str) -> None:
    """The velocity table: one row per read (the hold's middle rows summed up in one line)."""
    f_read = 1e3 / vel["read_us"]
    print(f"velocity: enc_qei_wb read over Wishbone every {READ_TAU:g} cycles at the peak speed "
          f"({vel['read_us']:.4g} us, {f_read:.4g} kHz; {vel['n_reads']} reads, the first only "
          f"initialises); hedsmodel.velocity")
    print(f"  M/T = SNAP_EDGE_DELTA / dSNAP_EDGE_TIME on A-rising edges, standstill rule, STALL_TIMEOUT "
          f"{vel['stall_ticks']} ticks ({STALL_TAU:g} cycles); M = SNAP_DELTA / dSNAP_TIME")
    print(line)
    hdr = (f"{'t (ms)':>8}  {'segment':<9}{'true rpm':>10}{'M/T A-rise':>12}{'error %':>9}"
           f"{'M rpm':>10}{'SNAP_EDGE_DELTA':>17}  check")
    print(hdr)
    print(line)

    def show(r):
        err = f"{r['err']:+.2f}" if r["err"] is not None else "-"
        check = (("ok" if r["ok"] else "FAIL") + f" (<= {VEL_TOL_PCT:g} %)") if r["checked"] else ""
        if not r["hw_ok"]:
            check = (check + " " if check else "") + f"REGISTERS != MODEL EDGES ({r['mt_exact']:.1f})"
        if r["stalled"]:
            check = (check + " " if check else "") + "STALLED"
        print(f"{r['t_ms']:8.3f}  {r['seg']:<9}{r['true'] + 0.0:10.1f}{r['mt'] + 0.0:12.1f}{err:>9}"
              f"{r['m'] + 0.0:10.1f}{r['edge_delta']:17d}  {check}".rstrip())

    rows = vel["rows"][1:]
    hold = [r for r in rows if r["seg"] == "hold"]
    middle = hold[2:-1] if len(hold) > 4 else []
    mid_ids = {r["k"] for r in middle}
    for r in rows:
        if r["k"] in mid_ids:
            if r is middle[0]:
                e = [x["err"] for x in middle if x["err"] is not None]
                bad = sum(1 for x in middle if (x["checked"] and not x["ok"]) or not x["hw_ok"])
                print(f"{'':8}  {'hold':<9}... {len(middle)} more reads at {plan.opts.rpm:g} rpm: "
                      f"M/T error {min(e):+.2f} .. {max(e):+.2f} %"
                      + (f", {bad} FAILED" if bad else ", all ok"))
            continue
        show(r)
    print(line)
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


# ---------------------------------------------------------------------------------------------
# GTKWave save file
# ---------------------------------------------------------------------------------------------
def gtkw_view(plan: Plan) -> dict:
    """The save file's view of this run, in simulation ps (``plan.t0_ps`` set from the bench):
    ``rises`` the GTKW_CYCLES + 1 rising edges of A (the encoder's output) that bound the cycles,
    ``start``/``end`` the span meant to be visible, ``zoom`` GTKWave's zoom for it."""
    tau_ps = 1e12 / (plan.opts.rpm / 60.0 * CPR)
    h0, h1 = plan.seg["hold"]
    mid = plan.t0_ps + (h0 + h1) / 2 * 1000.0
    rises = [int(round(t)) for t, _ in _a_rises(plan.wf, plan.t0_ps) if t >= mid][:GTKW_CYCLES + 1]
    start = int(rises[0] - (GTKW_VIEW_CYCLES - GTKW_CYCLES) / 2 * tau_ps)
    end = int(start + GTKW_VIEW_CYCLES * tau_ps)
    # GTKWave 3.3: time per pixel = 2 ** -zoom / 200 (its 200 pixels per zoom frame)
    zoom = -math.log2((end - start) * 200.0 / GTKW_WAVE_PX)
    return {"rises": rises, "start": start, "end": end, "zoom": zoom, "tau_ps": tau_ps}


def gtkw_text(plan: Plan, vcd: Path, gtkw: Path) -> str:
    """sim/demo.gtkw (signals, groups, layout) with this run's dump file and view: timestart and
    zoom from gtkw_view, named markers A.. on the rising edges of A that bound the cycles."""
    v = gtkw_view(plan)
    o = plan.opts
    named = v["rises"] + [-1] * (26 - len(v["rises"]))
    out = []
    for line in GTKW.read_text().splitlines():
        if line.startswith("[*] Opens on"):
            line = (f"[*] Opens on {GTKW_CYCLES} encoder cycles at {o.rpm:g} rpm ({o.temp_c:g} degC, "
                    f"{o.clk_hz / 1e6:g} MHz clock, seed {o.seed}), markers A-"
                    f"{chr(ord('A') + GTKW_CYCLES)} on A's rising edges; Zoom Full: the whole run.")
        elif line.startswith("[dumpfile]"):
            line = f'[dumpfile] "{os.path.relpath(vcd, gtkw.parent)}"'
        elif line.startswith("[savefile]"):
            line = f'[savefile] "{gtkw.name}"'
        elif line.startswith("[timestart]"):
            line = f"[timestart] {v['start']}"
        elif line.startswith("*"):
            # zoom, primary marker (none), then the named markers A..Z
            line = f"*{v['zoom']:.6f} -1 " + " ".join(str(t) for t in named)
        out.append(line)
    return "\n".join(out) + "\n"


def write_gtkw(plan: Plan, vcd: Path, gtkw: Path) -> None:
    text = gtkw_text(plan, vcd, gtkw)
    gtkw.parent.mkdir(parents=True, exist_ok=True)
    gtkw.write_text(text)


def gtkw_view_lines(text: str) -> list:
    """A save file's lines less its own and its dump's name: equal for two files with one view."""
    return [ln for ln in text.splitlines() if not ln.startswith(("[dumpfile]", "[savefile]"))]


# ---------------------------------------------------------------------------------------------
# make waves
# ---------------------------------------------------------------------------------------------
def open_waves() -> int:
    # sim/demo.gtkw, whose view is the default run's; after a run with other options, the save file
    # written with its dump (same signals, the view of that run)
    gtkw, run_gtkw = GTKW, VCD.with_suffix(".gtkw")
    if run_gtkw.exists() and gtkw_view_lines(run_gtkw.read_text()) != gtkw_view_lines(GTKW.read_text()):
        gtkw = run_gtkw
    rel_vcd, rel_gtkw = VCD.relative_to(TOP), gtkw.relative_to(TOP)
    cmd = ["gtkwave", str(rel_vcd), str(rel_gtkw)]
    if not VCD.exists():
        print(f"waves: {rel_vcd} does not exist yet; run 'make demo' first, then: {' '.join(cmd)}")
        return 1
    size = VCD.stat().st_size / 1e6
    if shutil.which("gtkwave") and (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        print(f"waves: {' '.join(cmd)}")
        return subprocess.call(cmd, cwd=TOP)
    why = "gtkwave is not installed" if not shutil.which("gtkwave") else "no display ($DISPLAY)"
    print(f"waves: {why}. The files:\n"
          f"  dump:       {rel_vcd} ({size:.1f} MB)\n"
          f"  save file:  {rel_gtkw} (signals grouped and named after the note)\n"
          f"  picture:    {DEFAULT_PNG.relative_to(TOP)} (README copy: {README_PNG.relative_to(TOP)})\n"
          f"Open them with: {' '.join(cmd)}   (gtkwave: e.g. 'apt-get install gtkwave')")
    return 0


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.view:
        return open_waves()
    try:
        opts = validate(args.rpm, args.temp_c, args.clk_hz, args.seed)
    except OptionError as exc:
        print(f"make demo: {exc}", file=sys.stderr)
        return 2
    t0 = time.monotonic()
    plan = make_plan(opts)
    sim = args.sim
    if sim == "auto":
        sim = "icarus" if estimate_clocks(opts.rpm, plan.clk_hz) <= ICARUS_MAX_CLOCKS else "verilator"
    res = simulate(plan, sim, args.name)
    vcd = VCD.with_name(f"{args.name}.vcd")
    plan.t0_ps = res["t0_ps"]
    an = analyze(plan, res)
    print_report(plan, res, an)
    vcd_mb = vcd.stat().st_size / 1e6 if vcd.exists() else 0.0
    gtkw = vcd.with_suffix(".gtkw") if args.gtkw is None else Path(args.gtkw) if args.gtkw else None
    shown = ""
    if gtkw is not None:
        gtkw = gtkw if gtkw.is_absolute() else Path.cwd() / gtkw
        write_gtkw(plan, vcd, gtkw)
        shown = f", save file {gtkw.relative_to(TOP) if gtkw.is_relative_to(TOP) else gtkw}"
    if args.png:
        from . import vcd_png as vcd_to_png
        png = Path(args.png)
        png = png if png.is_absolute() else Path.cwd() / png
        vcd_to_png.demo_figure(vcd, png, plan)
        print(f"waves: {vcd.relative_to(TOP)} ({vcd_mb:.1f} MB){shown}, picture {png.relative_to(TOP) if png.is_relative_to(TOP) else png}; "
              f"'make waves' opens them")
    else:
        print(f"waves: {vcd.relative_to(TOP)} ({vcd_mb:.1f} MB){shown}; 'make waves' opens it")
    n_fail = sum(not ok for _, ok, _ in an["verdicts"])
    print(f"demo: {'all circuits PASS' if not n_fail else f'{n_fail} FAIL'} "
          f"(build {res['t_build']:.1f} s, simulation {res['t_sim']:.1f} s, "
          f"total {time.monotonic() - t0:.1f} s)")
    return 1 if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
