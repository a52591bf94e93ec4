# SPDX-License-Identifier: Apache-2.0
"""The note's error-budget algebra, plus the decode-speed limit of this library's decoder.

Each function returns a dict holding the JSON keys of the matching ``scripts/error_budget.py``
subcommand (``count_limit`` adds its two partial limits for the table), and raises ``ValueError``
(one-line message) on input that is out of physical range. With default arguments each function
reproduces the note's worked example:

==================  =========================================================  ==============
function            note section                                               result
==================  =========================================================  ==============
position_error      "To calculate position error" (Table 2)                    15' / 6' / 27'
state_width_error   "Room temperature analysis example" (Tables 2, 3)          30 / 8.7 / 44
guardband           "Designing for temperature range"                          72 - 28 = 44
sampling_period     "Microprocessor interface", programmed input example       25 µs
sampling_speed      the same solved for speed (T_p = 25 µs)                    600 rpm
count_limit         (ours) speed limit of enc_conditioner + decoder            no example
==================  =========================================================  ==============

Statistics as the note does them: a vectorial combination takes the root-sum-square of the means,
an algebraic one their sum; standard deviations always combine root-sum-square.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from . import note

COUNT_MARGIN = 1.05  # the decoder contract's timing margin on states and filtered levels


def rss(values) -> float:
    return math.sqrt(sum(v * v for v in values))


def _check(ok: bool, message: str) -> None:
    if not ok:
        raise ValueError(message)


def _check_positive(name: str, value: float) -> None:
    _check(math.isfinite(value) and value > 0, f"{name} must be a positive number, got {value:g}")


def _check_state_error(state_error_deg: float) -> None:
    _check(math.isfinite(state_error_deg) and 0 <= state_error_deg < 90,
           f"state width error must be in 0 .. 90 e° (exclusive), got {state_error_deg:g}")


def frequency_hz(rpm: float, cpr: int = note.CPR) -> float:
    """Output frequency of one channel: f = rpm / 60 * N."""
    return rpm / 60.0 * cpr


def eccentricity_tir(factors: Sequence[tuple[float, float]]) -> tuple[float, float]:
    """(mean, sd) in mm TIR of independent eccentricity factors combined vectorially."""
    _check(len(factors) > 0, "need at least one eccentricity factor")
    for mean, sd in factors:
        _check(mean >= 0 and sd >= 0, f"eccentricity factors must be >= 0, got {mean:g} ± {sd:g}")
    return rss(m for m, _ in factors), rss(s for _, s in factors)


def position_error(factors: Sequence[tuple[float, float]] | None = None,
                   radius_mm: float = note.RADIUS_MM, cpr: int = note.CPR) -> dict:
    """Position error from cyclic eccentricity: E_T x Q_p; max = mean + 2 sigma."""
    _check_positive("radius", radius_mm)
    _check_positive("counts per revolution", cpr)
    mean_mm, sd_mm = eccentricity_tir(factors if factors is not None
                                      else [(m, s) for _, m, s in note.TABLE2])
    qp = note.q_p(radius_mm)
    mean_deg, sd_deg = mean_mm * qp, sd_mm * qp
    max_deg = mean_deg + 2 * sd_deg
    return {"mean_arcmin": 60 * mean_deg, "sd_arcmin": 60 * sd_deg,
            "max_arcmin": 60 * max_deg, "max_elec_deg": max_deg * cpr}


def state_width_error(ecc_mean_mm: float | None = None, ecc_sd_mm: float | None = None,
                      random_factors: Sequence[tuple[float, float, float]] | None = None,
                      internal: tuple[float, float] = note.INTERNAL,
                      q_e: float = note.Q_E) -> dict:
    """State-width error of a batch: ΔS1 eccentricity (TIR / 2 x Q_e), ΔS2 random phase (Table 3,
    vectorial), ΔS3 internal; means summed algebraically (worst case), sds root-sum-square.
    p95 = mean + 1.65 sigma. Eccentricity defaults to the Table 2 combination."""
    table2_mean, table2_sd = eccentricity_tir([(m, s) for _, m, s in note.TABLE2])
    ecc_mean = table2_mean if ecc_mean_mm is None else ecc_mean_mm
    ecc_sd = table2_sd if ecc_sd_mm is None else ecc_sd_mm
    factors = random_factors if random_factors is not None else [r[1:] for r in note.TABLE3]
    _check(ecc_mean >= 0 and ecc_sd >= 0, "eccentricity mean and sd must be >= 0")
    _check(all(m >= 0 and s >= 0 and q >= 0 for m, s, q in factors),
           "random factor means, sds and sensitivities must be >= 0")
    _check(internal[0] >= 0 and internal[1] >= 0, "internal error mean and sd must be >= 0")
    _check(q_e >= 0, "Q_e must be >= 0")
    s1 = (ecc_mean / 2 * q_e, ecc_sd / 2 * q_e)
    s2 = (rss(m * q for m, _, q in factors), rss(s * q for _, s, q in factors))
    mean = s1[0] + s2[0] + internal[0]
    sd = rss((s1[1], s2[1], internal[1]))
    return {"mean_deg": mean, "sd_deg": sd, "p95_deg": mean + 1.65 * sd}


def guardband(rpm: float = 3000.0, temp_c: float = 70.0, alpha: float = note.ALPHA_WORST,
              min_state_us: float = 2.0, cpr: int = note.CPR) -> dict:
    """Room-temperature state-width test limit that guarantees ``min_state_us`` at ``rpm`` and
    ``temp_c``: S_min = T_s f 360, ΔS_max = 90 - S_min, ΔS_temp = |α (T - 25) f| (below 25 °C
    the pulses narrow instead, which costs the same), limit = the difference. The note's example
    says 60 °C but computes with 70 °C; the default follows the computation. f is in Hz (the note writes 25 for 25 kHz, which only works with α in /kHz)."""
    _check_positive("speed (rpm)", rpm)
    _check_positive("minimum state time", min_state_us)
    _check_positive("counts per revolution", cpr)
    _check(note.ALPHA_RANGE[0] <= alpha <= note.ALPHA_RANGE[1],
           f"alpha must be in {note.ALPHA_RANGE[0]:g} .. {note.ALPHA_RANGE[1]:g} e°/(°C·Hz), "
           f"got {alpha:g}")
    _check(-273.15 < temp_c <= 500, f"temperature must be in -273.15 .. 500 °C, got {temp_c:g}")
    f = frequency_hz(rpm, cpr)
    s_min = min_state_us * 1e-6 * f * 360
    _check(s_min < 90, f"a {min_state_us:g} µs state is {s_min:.1f} e° at {rpm:g} rpm: longer "
                       "than the nominal 90 e° state")
    ds_max = 90 - s_min
    ds_temp = abs(alpha * (temp_c - note.T_REF_C) * f)
    return {"f_hz": f, "s_min_deg": s_min, "ds_max_deg": ds_max, "ds_temp_deg": ds_temp,
            "room_limit_deg": ds_max - ds_temp}


def sampling_period(rpm: float = 600.0, state_error_deg: float = 45.0,
                    cpr: int = note.CPR) -> dict:
    """Longest programmed-input sampling period that sees every state: T_p <= T_s (1 - ΔS/90),
    with T_s = 1 / (4 f) the nominal state time."""
    _check_positive("speed (rpm)", rpm)
    _check_positive("counts per revolution", cpr)
    _check_state_error(state_error_deg)
    f = frequency_hz(rpm, cpr)
    ts = 1 / (4 * f)
    return {"f_hz": f, "ts_s": ts, "tp_max_s": ts * (1 - state_error_deg / 90)}


def sampling_speed(tp_s: float, state_error_deg: float = 45.0, cpr: int = note.CPR) -> dict:
    """Highest speed a sampling period ``tp_s`` can follow: f_max = (1 - ΔS/90) / (4 T_p),
    ω_max = 2π f_max / N."""
    _check_positive("sampling period", tp_s)
    _check_positive("counts per revolution", cpr)
    _check_state_error(state_error_deg)
    f_max = (1 - state_error_deg / 90) / (4 * tp_s)
    return {"f_max_hz": f_max, "rpm_max": f_max * 60 / cpr,
            "omega_max_rad_s": 2 * math.pi * f_max / cpr}


def count_limit(clk_hz: float = 12e6, filter_len: int = 3, state_error_deg: float = 45.0,
                pulse_error_deg: float | None = None, cpr: int = note.CPR) -> dict:
    """Highest encoder frequency at which enc_conditioner + a decoder count exactly.

    The contract needs every state to last >= 1 clock and every level that spans a change of the
    other channel (a pulse of A or B) >= FILTER_LEN clocks, both with the 1.05 margin. The
    narrowest state is (90 - ΔS) e°, the narrowest pulse (180 - ΔP) e°. Without a pulse-width
    error figure ΔP defaults to 2 ΔS: a pulse is two adjacent states, so it can lose at most
    twice the state error. Returns ``binding`` ("state" or "level") besides the JSON keys."""
    _check_positive("clock frequency", clk_hz)
    _check_positive("counts per revolution", cpr)
    _check(isinstance(filter_len, int) and 1 <= filter_len <= 16,
           f"filter length must be an integer in 1 .. 16, got {filter_len}")
    _check_state_error(state_error_deg)
    dp = 2 * state_error_deg if pulse_error_deg is None else pulse_error_deg
    _check(math.isfinite(dp) and 0 <= dp < 180,
           f"pulse width error must be in 0 .. 180 e° (exclusive), got {dp:g}")
    period = 1 / clk_hz
    f_state = (90 - state_error_deg) / 360 / (COUNT_MARGIN * period)
    f_level = (180 - dp) / 360 / (COUNT_MARGIN * filter_len * period)
    f_max = min(f_state, f_level)
    return {"f_max_hz": f_max, "rpm_max": f_max * 60 / cpr,
            "f_state_hz": f_state, "f_level_hz": f_level, "pulse_error_deg": dp,
            "binding": "state" if f_state <= f_level else "level"}
