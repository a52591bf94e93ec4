# SPDX-License-Identifier: Apache-2.0
"""Motion profiles: the shaft angle as a function of time, built from segments.

A :class:`Profile` starts at ``start_deg`` (electrical degrees of shaft position; the default
-45 e° is the middle of state 00 just before cycle 0, 4X position 0) and appends segments, each
starting where the last one ended::

    Profile().constant(3000, 0.02).ramp(3000, -3000, 0.01).stop(1e-3).dither(20, 50, 1e-4)

Speeds are shaft rpm (negative = reverse); dither amplitudes are electrical degrees. Internally the
position is in electrical cycles (x = e° / 360). The encoder model only needs
:meth:`Profile.pieces`: the motion split into monotone pieces, each able to invert position to time in closed form
(polynomial segments by the quadratic formula, dither by arcsin).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import note


@dataclass(frozen=True)
class Piece:
    """A monotone stretch of motion from ``(ta, xa)`` to ``(tb, xb)`` (seconds, cycles)."""

    ta: float
    tb: float
    xa: float
    xb: float
    kind: str   # "poly": x = xa + v (t-ta) + a (t-ta)^2 / 2;  "sine": x = xc + amp sin(w (t-t0))
    p: tuple    # poly: (v, a);  sine: (xc, amp, w, t0, k), w (t-t0) in [k pi - pi/2, k pi + pi/2]

    def times(self, x: np.ndarray) -> np.ndarray:
        """Times (s) at which this piece passes the positions ``x`` (all within [xa, xb])."""
        if self.kind == "poly":
            v, a = self.p
            d = x - self.xa
            s = 1.0 if self.xb > self.xa else -1.0
            q = v + s * np.sqrt(np.maximum(v * v + 2 * a * d, 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                dt = np.where(q != 0, 2 * d / q, 0.0)   # stable for a -> 0 (v and q share a sign)
        else:
            xc, amp, w, t0, k = self.p
            sign = -1.0 if k % 2 else 1.0
            phase = k * math.pi + np.arcsin(np.clip(sign * (x - xc) / amp, -1.0, 1.0))
            dt = t0 + phase / w - self.ta
        return self.ta + np.clip(dt, 0.0, self.tb - self.ta)


class Profile:
    """Chainable motion profile; see the module docstring."""

    def __init__(self, start_deg: float = -45.0, cpr: int = note.CPR):
        self.cpr = cpr
        self.start_x = start_deg / 360.0
        self._pieces: list[Piece] = []
        self._t = 0.0
        self._x = self.start_x

    @property
    def duration_s(self) -> float:
        return self._t

    @property
    def end_deg(self) -> float:
        return self._x * 360.0

    def _cycles_per_s(self, rpm: float) -> float:
        return rpm / 60.0 * self.cpr

    @staticmethod
    def _check_time(seconds: float) -> None:
        if not (math.isfinite(seconds) and seconds > 0):
            raise ValueError(f"segment duration must be > 0 s, got {seconds!r}")

    def _poly(self, v: float, a: float, seconds: float) -> None:
        """Append x = x0 + v t + a t^2 / 2, split at a reversal (v + a t = 0) if there is one."""
        cuts = [0.0, seconds]
        if a != 0 and 0 < -v / a < seconds:
            cuts.insert(1, -v / a)
        for ta, tb in zip(cuts, cuts[1:]):
            va = v + a * ta
            xa = self._x
            xb = xa + va * (tb - ta) + a * (tb - ta) ** 2 / 2
            if xb != xa:
                self._pieces.append(Piece(self._t, self._t + tb - ta, xa, xb, "poly", (va, a)))
            self._t += tb - ta
            self._x = xb

    def constant(self, rpm: float, seconds: float) -> "Profile":
        """Turn at a constant ``rpm`` for ``seconds``."""
        self._check_time(seconds)
        self._poly(self._cycles_per_s(rpm), 0.0, seconds)
        return self

    def ramp(self, rpm0: float, rpm1: float, seconds: float) -> "Profile":
        """Constant acceleration from ``rpm0`` to ``rpm1``; passing through 0 reverses the shaft."""
        self._check_time(seconds)
        v0, v1 = self._cycles_per_s(rpm0), self._cycles_per_s(rpm1)
        self._poly(v0, (v1 - v0) / seconds, seconds)
        return self

    def stop(self, seconds: float) -> "Profile":
        """Stand still for ``seconds``."""
        self._check_time(seconds)
        self._t += seconds
        return self

    def dither(self, amplitude_deg: float, cycles: int, period_s: float) -> "Profile":
        """Oscillate sinusoidally about the current position, ``amplitude_deg`` e° each way, for
        ``cycles`` whole periods (ends where it began). Start the profile on a transition (for
        example ``Profile(start_deg=0)``, the nominal A rise) to dither about it."""
        self._check_time(period_s)
        if not (amplitude_deg > 0 and int(cycles) == cycles and cycles > 0):
            raise ValueError("dither needs amplitude_deg > 0 and a positive whole number of cycles")
        xc, amp, w, t0 = self._x, amplitude_deg / 360.0, 2 * math.pi / period_s, self._t
        bounds = [0.0] + [(j + 0.5) * math.pi for j in range(2 * int(cycles))] \
            + [2 * math.pi * cycles]
        for k, (pa, pb) in enumerate(zip(bounds, bounds[1:])):
            self._pieces.append(Piece(t0 + pa / w, t0 + pb / w, xc + amp * math.sin(pa),
                                      xc + amp * math.sin(pb), "sine", (xc, amp, w, t0, k)))
        self._t = t0 + 2 * math.pi * cycles / w
        return self

    def pieces(self) -> list[Piece]:
        return list(self._pieces)

    def extent(self) -> tuple[float, float]:
        """Lowest and highest position reached, in cycles."""
        xs = [self.start_x] + [x for p in self._pieces for x in (p.xa, p.xb)]
        return min(xs), max(xs)
