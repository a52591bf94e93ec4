# SPDX-License-Identifier: Apache-2.0
"""Measure a quadrature waveform with the note's definitions (Figure 3).

Works on any :class:`hedsmodel.waveform.Waveform` (from the model or not). The waveform is cut into monotone
runs: consecutive single-channel transitions in one direction. Within a run, every complete
cycle (A rise .. next A rise in the direction of motion; a reverse run is read backwards, so its
numbers mean the same as forward ones) gives, in electrical degrees:

- ``cycle_deg``: its length,
- ``pulse_a_deg`` / ``pulse_b_deg``: the A and B high pulses,
- ``phase_deg``: centre of the A pulse to centre of the corresponding B pulse,
- ``state_deg``: the four states 10, 11, 01, 00 in order of motion.

Time converts to degrees with the local cycle period: the mean period of the cycles within
``window`` cycles either side in the same run. At constant speed that is the speed, so cycle
length shows the cycle-to-cycle error; the slow once-per-revolution eccentricity term shows up as
``position_pp_deg``: peak-to-peak deviation of the A-rise times of the longest run from a uniform
rate, in e°. That rate is taken over whole revolutions (``cpr`` cycles, over which the position
error repeats) when the run has one, else from a straight-line fit; meaningful at constant speed. With ``window=0`` each cycle is converted with its own period, which
suits ramps (cycle length then always reads 360); cycles next to a reversal, where the speed
changes within the cycle, measure the motion rather than the encoder.

``min_state_ns`` is the shortest time between two consecutive transitions anywhere in the
waveform, including stops and reversals: the narrowest state a test actually drove (the stretch
from t = 0 to the first transition is not counted: it is only the starting level).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import note


def _max_abs(values: np.ndarray, nominal: float) -> float:
    return float(np.max(np.abs(values - nominal))) if values.size else float("nan")


@dataclass
class Measurement:
    cycle_deg: np.ndarray
    pulse_a_deg: np.ndarray
    pulse_b_deg: np.ndarray
    phase_deg: np.ndarray
    state_deg: np.ndarray        # shape (cycles, 4)
    freq_hz: np.ndarray          # local output frequency of each cycle
    position_pp_deg: float
    min_state_ns: float
    min_state_at_ns: float       # start time of that narrowest state
    invalid_transitions: int     # events where both channels changed at once

    @property
    def cycles(self) -> int:
        return int(self.cycle_deg.size)

    @property
    def cycle_error_deg(self) -> float:
        return _max_abs(self.cycle_deg, 360.0)

    @property
    def pulse_error_deg(self) -> float:
        return max(_max_abs(self.pulse_a_deg, 180.0), _max_abs(self.pulse_b_deg, 180.0))

    @property
    def phase_error_deg(self) -> float:
        return _max_abs(self.phase_deg, 90.0)

    @property
    def state_error_deg(self) -> float:
        return _max_abs(self.state_deg, 90.0)

    @property
    def min_state_deg(self) -> float:
        return float(self.state_deg.min()) if self.state_deg.size else float("nan")

    def summary(self) -> str:
        return (f"{self.cycles} cycles, f {np.median(self.freq_hz) if self.cycles else 0:.6g} Hz; "
                f"max errors (e°): cycle {self.cycle_error_deg:.2f}, "
                f"pulse {self.pulse_error_deg:.2f}, phase {self.phase_error_deg:.2f}, state {self.state_error_deg:.2f}; "
                f"min state {self.min_state_ns:.1f} ns")


def _local_mean(x: np.ndarray, window: int) -> np.ndarray:
    """Mean of ``x`` over ``window`` samples either side (fewer at the ends)."""
    cs = np.concatenate([[0.0], np.cumsum(x)])
    i = np.arange(x.size)
    lo, hi = np.maximum(i - window, 0), np.minimum(i + window + 1, x.size)
    return (cs[hi] - cs[lo]) / (hi - lo)


def _position_pp(rise_ns: np.ndarray, cpr: int) -> float:
    """Peak-to-peak position error (e°) of successive A-rise times (ns, increasing)."""
    c = np.arange(rise_ns.size)
    whole = (rise_ns.size - 1) // cpr * cpr
    period = (rise_ns[whole] - rise_ns[0]) / whole if whole else np.polyfit(c, rise_ns, 1)[0]
    return float(np.ptp(rise_ns - c * period) * 360.0 / period)


def _runs(positions: list) -> list[tuple[int, int, int]]:
    """(first, last, direction) event index ranges of consecutive ±1 steps in one direction."""
    steps = [0] + [(q - p) if p is not None and q is not None and abs(q - p) == 1 else 0
                   for p, q in zip(positions, positions[1:])]
    runs, start = [], None
    for i, s in enumerate(steps + [0]):
        if start is not None and s != steps[start]:
            runs.append((start, i - 1, steps[start]))
            start = None
        if start is None and s != 0:
            start = i
    return runs


def measure(waveform, window: int = 16, cpr: int = note.CPR) -> Measurement:
    """Measure ``waveform`` (see the module docstring)."""
    t = np.array([e[0] for e in waveform.events], dtype=float)
    gaps = np.diff(t[1:])
    at = int(np.argmin(gaps)) + 1 if gaps.size else 0
    cols = {k: [] for k in ("cycle", "pa", "pb", "phase", "state", "freq")}
    position_pp, longest = float("nan"), 0
    for first, last, d in _runs(waveform.positions):
        pos = np.array(waveform.positions[first:last + 1])
        edge = pos - 1 if d > 0 else pos                  # edge index m crossed by each event
        tt = t[first:last + 1]
        if d < 0:
            edge, tt = edge[::-1], tt[::-1]
        j = np.arange((-edge[0]) % 4, edge.size - 4, 4)  # events that are A rises (m = 4c)
        if j.size == 0:
            continue
        e = tt[j[:, None] + np.arange(5)] * d             # times along the motion, increasing
        period = e[:, 4] - e[:, 0]
        ref = _local_mean(period, window)
        scale = 360.0 / ref
        cols["cycle"].append(period * scale)
        cols["pa"].append((e[:, 2] - e[:, 0]) * scale)
        cols["pb"].append((e[:, 3] - e[:, 1]) * scale)
        cols["phase"].append(((e[:, 1] + e[:, 3]) - (e[:, 0] + e[:, 2])) / 2 * scale)
        cols["state"].append(np.diff(e, axis=1) * scale[:, None])
        cols["freq"].append(1e9 / ref)
        if j.size > longest and j.size > 2:
            longest = j.size
            position_pp = _position_pp(e[:, 0], cpr)
    cat = {k: (np.concatenate(v) if v else np.zeros((0, 4) if k == "state" else 0))
           for k, v in cols.items()}
    return Measurement(
        cycle_deg=cat["cycle"], pulse_a_deg=cat["pa"], pulse_b_deg=cat["pb"],
        phase_deg=cat["phase"], state_deg=cat["state"], freq_hz=cat["freq"],
        position_pp_deg=position_pp,
        min_state_ns=float(gaps[at - 1]) if gaps.size else float("inf"),
        min_state_at_ns=float(t[at]),
        invalid_transitions=sum(p is None for p in waveform.positions))


def unit_waveform(unit, profile):
    """``(waveform, measurement)`` of an :class:`EncoderUnit` driven through ``profile``."""
    wf = unit.waveform(profile)
    return wf, measure(wf)
