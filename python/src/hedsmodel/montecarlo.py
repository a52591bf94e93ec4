# SPDX-License-Identifier: Apache-2.0
"""Monte Carlo batch for Figure 7: the distribution of the worst state-width error per unit.

Each unit is drawn with :meth:`EncoderUnit.draw` (Tables 2 and 3, internal error), turned through
one revolution at constant speed, and its own waveform measured with :func:`measure`; the unit's
figure is the largest |state - 90| over that revolution, as the note defines the error.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import note
from .measurement import measure
from .profile import Profile
from .unit import EncoderUnit


@dataclass
class Batch:
    errors_deg: np.ndarray      # max state-width error of each unit over one revolution
    seed: int
    rpm: float
    temp_c: float
    alpha: float

    @property
    def mean_deg(self) -> float:
        return float(np.mean(self.errors_deg))

    @property
    def sd_deg(self) -> float:
        return float(np.std(self.errors_deg, ddof=1))

    @property
    def p95_deg(self) -> float:
        return float(np.percentile(self.errors_deg, 95))

    def fraction_under(self, limit_deg: float = note.STATE_LIMIT) -> float:
        return float(np.mean(self.errors_deg < limit_deg))


def state_width_batch(units: int, seed: int, rpm: float = 60.0, temp_c: float = note.T_REF_C,
                      alpha: float = note.ALPHA_TYPICAL,
                      progress: Callable[[int, int], None] | None = None) -> Batch:
    """Draw ``units`` encoders from ``seed`` and measure each over one revolution at ``rpm`` and
    ``temp_c``; ``progress(done, total)`` is called after each unit if given."""
    if units < 2 or rpm <= 0:
        raise ValueError("need at least 2 units and a positive speed")
    rng = np.random.default_rng(seed)
    revolution = Profile().constant(rpm, 60.0 / rpm * (1 + 2 / note.CPR))
    errors = np.empty(units)
    for i in range(units):
        unit = EncoderUnit.draw(rng, temp_c=temp_c, alpha=alpha)
        errors[i] = measure(unit.waveform(revolution)).state_error_deg
        if progress:
            progress(i + 1, units)
    return Batch(errors, seed, rpm, temp_c, alpha)
