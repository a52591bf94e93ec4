# SPDX-License-Identifier: Apache-2.0
"""hedsmodel: a behavioural model of one HP HEDS-5000 shaft encoder, after the application note.

Public API (everything else is internal)::

    from hedsmodel import EncoderUnit, Profile, measure, unit_waveform

    unit = EncoderUnit(phase_error_deg=20)             # configure errors by hand, or
    unit = EncoderUnit.draw(rng, temp_c=70, alpha=2.5e-5)  # draw one from Tables 2 and 3, or
    unit = EncoderUnit.typical(rng)                    # every factor at its table mean
    profile = Profile().constant(3000, 0.02).ramp(3000, -600, 0.01).stop(1e-3)
    wf = unit.waveform(profile)                        # hedsmodel.Waveform (events, positions)
    wf, index = unit.waveform(profile, index=True)     # + index channel [(t_ns, level)]
    m = measure(wf)                                    # Measurement (Figure 3 definitions)
    m = measure(wf, window=0)                          # ramps: each cycle's own period
    wf, m = unit_waveform(unit, profile)               # both at once
    m.min_state_ns, m.state_error_deg, m.phase_deg, m.pulse_a_deg, m.state_deg, m.freq_hz
    print(m.summary())                                 # one line for a test log
    profile.duration_s, profile.end_deg                # how long to play it, where it stops
    unit.edges(k0, k1)                                 # where the unit's transitions sit (cycles)

``EncoderUnit`` fields (all optional): phase_error_deg, pulse_error_deg (one value or (A, B)),
eccentricity_mm (TIR), eccentricity_angle_deg, radial_play_mm, axial_play_mm, cycle_error_deg,
jitter_ns, temp_c, alpha, seed, cpr, radius_mm, q_e, q_ma. ``Profile(start_deg=-45, cpr=500)``
segments: ``.constant(rpm, s)``, ``.ramp(rpm0, rpm1, s)``, ``.stop(s)``,
``.dither(amplitude_deg, cycles, period_s)``.

Modules: :mod:`.note` (the note's numbers), :mod:`.budget` (its error-budget algebra, shared with
``scripts/error_budget.py``), :mod:`.profile`, :mod:`.unit` (the physics, described there),
:mod:`.measurement`, :mod:`.montecarlo` (Figure 7 batch, used by ``scripts/monte_carlo.py``),
:mod:`.velocity` (host-side M, T and M/T velocity estimators for enc_qei snapshots, mirrored in C
by ``sw/enc_qei_velocity.c``, the snapshots an ideal peripheral latches from a waveform, and
the entries of enc_qei's edge FIFO: ``EdgeEntry``, ``ideal_edge_entries``), :mod:`.calibration`
(a self-calibrating estimator fed by those entries, mirrored by ``sw/enc_qei_calib.c``).
Waveforms: :mod:`.waveform` (``Waveform``, ``walk``, ``random_walk``, ``with_glitches``, ``QUAD``,
``STATE_TO_POS``, ``state_of``) -- the event-list format every generator here produces and the
cocotb driver in :mod:`cocotbext.quadrature` plays. Nothing in this package imports cocotb.
"""

import importlib

_EXPORTS = {"EncoderUnit": ".unit", "Profile": ".profile", "Measurement": ".measurement",
            "measure": ".measurement", "unit_waveform": ".measurement",
            "Waveform": ".waveform", "walk": ".waveform", "random_walk": ".waveform",
            "with_glitches": ".waveform", "QUAD": ".waveform", "STATE_TO_POS": ".waveform",
            "state_of": ".waveform"}
__all__ = sorted(_EXPORTS)


def __getattr__(name):
    """Import the waveform side (numpy) only when it is used, so the error-budget
    calculator starts fast."""
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
