# SPDX-License-Identifier: Apache-2.0
"""Numbers from the HEDS-5000 application note, in one place.

Lengths in mm, angles in electrical degrees (e°) unless a name says otherwise. Every table row is
``(mean, sd)`` or ``(mean, sd, sensitivity)`` where the mean is the average of the absolute value,
as the note defines it ("Statistical nature of errors").
"""

from __future__ import annotations

import math

CPR = 500                 # N, code wheel count (cycles per revolution)
RADIUS_MM = 10.9          # R, code wheel radius
Q_E = 550.0               # phase sensitivity to radial movement, e°/mm
Q_MA = 20.0               # phase sensitivity to axial movement (misalignment factor), e°/mm
ALPHA_TYPICAL = 1.0e-5    # pulse-width temperature coefficient, e°/(°C·Hz)
ALPHA_WORST = 2.5e-5
ALPHA_RANGE = (0.0, 1.0e-3)  # accepted by the calculators: 40x the worst case is already absurd
T_REF_C = 25.0            # the propagation delays are equal at 25 °C

# Table 2: cyclic eccentricity factors, TIR (mm).
TABLE2 = (
    ("code wheel/hub assembly", 0.040, 0.015),
    ("shaft eccentricity", 0.020, 0.005),
    ("shaft undersize", 0.015, 0.010),
)
# Table 3: random phase factors (mean, sd, sensitivity Q in e° per unit of the factor).
TABLE3 = (
    ("shaft axial play (mm)", 0.1, 0.06, Q_MA),
    ("shaft radial play (mm)", 0.006, 0.003, Q_E),
    ("assembly adjustment (e°)", 3.0, 3.0, 1.0),
)
INTERNAL = (12.0, 6.0)    # ΔS3, internal state-width error (mean, sd)
STATE_LIMIT = 44.0        # the note's 95 % room-temperature state-width error


def q_p(radius_mm: float = RADIUS_MM) -> float:
    """Position sensitivity Q_p = k / R, angular degrees per mm of eccentricity (5.3 at 10.9 mm)."""
    return 360.0 / (2.0 * math.pi * radius_mm)
