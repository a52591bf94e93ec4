# SPDX-License-Identifier: Apache-2.0
"""The demo's four options, checked before anything is built or simulated (a bad value is one
OptionError line), and the run-length arithmetic the checks need: the phase meter's window, the
hold's length, the simulated clocks of the whole profile."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .config import (ALPHA, CHAR_CYCLES, CLK_RANGE, CPR, CREEP_DIV, DEFAULTS, DITHER_PERIODS,
                     LEVEL_LIMIT, MAX_CLOCKS, NOTE_STATE_ERR, PM_MIN_CYCLES, TAU_BACK, TAU_DITHER,
                     TAU_RAMP_UP, TAU_REST, TAU_REVERSE, TAU_STOP_RAMP, TEMP_RANGE)


class OptionError(ValueError):
    """A bad command-line value; the message is the one line printed."""


@dataclass
class Options:
    rpm: float
    temp_c: float
    clk_hz: float
    seed: int


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


def hold_readings(rpm: float, clk_hz: float) -> int:
    """Phase-meter (and characterizer) readings the hold makes room for: two when the budget
    allows, else one."""
    return 2 if estimate_clocks(rpm, clk_hz, 2) <= MAX_CLOCKS else 1


def estimate_clocks(rpm: float, clk_hz: float, readings: int | None = None) -> float:
    """Simulated clocks of the whole profile; ``readings`` None: as many as the budget allows."""
    if readings is None:
        readings = hold_readings(rpm, clk_hz)
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
