# SPDX-License-Identifier: Apache-2.0
"""The HEDS-5000 model (the hedsmodel package, python/): configured errors come back out of measure().

Plain pytest, no simulator. Single error sources are configured one at a time and measured from
the generated waveform with the note's Figure 3 definitions; motion profiles (ramps, reversals,
stops, dither) must give valid quadrature whose positions agree with the states shown and with
the shaft's true position; the Monte Carlo batch is reproducible. Random draws use the fixed seeds
named in each test (printed, so a failure shows them).
"""

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from hedsmodel import EncoderUnit, Profile, measure, note, unit_waveform
from hedsmodel.montecarlo import state_width_batch
from hedsmodel.waveform import STATE_TO_POS

RPM = 600                  # 5 kHz output: one cycle = 200 µs
F_HZ = RPM / 60 * 500


def one_revolution(rpm=RPM):
    return Profile().constant(rpm, 60 / rpm * 1.004)


def assert_valid_quadrature(wf):
    """Every event changes exactly one channel and its position steps by one, in the direction
    that state change means."""
    ev, pos = wf.events, wf.positions
    assert STATE_TO_POS[ev[0][1:]] == pos[0] % 4
    for i in range(1, len(ev)):
        changed = (ev[i][1] != ev[i - 1][1]) + (ev[i][2] != ev[i - 1][2])
        assert changed == 1, f"event {i} at {ev[i][0]:.1f} ns changes {changed} channels"
        assert ev[i][0] > ev[i - 1][0]
        assert STATE_TO_POS[ev[i][1:]] == pos[i] % 4 and abs(pos[i] - pos[i - 1]) == 1


def true_position(unit, x_deg):
    """4X position of the region the shaft is in at ``x_deg`` e°, from the unit's own edges."""
    k0 = math.floor(x_deg / 360) - 3
    return 4 * k0 + int(np.searchsorted(unit.edges(k0, k0 + 7), x_deg / 360, "right"))


def test_ideal_unit_at_constant_speed():
    wf, m = unit_waveform(EncoderUnit(), Profile().constant(RPM, 0.02))
    assert_valid_quadrature(wf)
    assert m.cycles == 99
    assert np.allclose(m.freq_hz, F_HZ)
    assert np.allclose(m.state_deg, 90) and np.allclose(m.cycle_deg, 360)
    assert np.allclose(m.pulse_a_deg, 180) and np.allclose(m.pulse_b_deg, 180)
    assert np.allclose(m.phase_deg, 90)
    assert m.min_state_ns == pytest.approx(1e9 / F_HZ / 4)
    assert wf.final_position == 4 * 100   # -45 e° + 100 cycles: state 00 again, 100 cycles on


def test_phase_error_moves_b():
    wf, m = unit_waveform(EncoderUnit(phase_error_deg=20), Profile().constant(RPM, 0.02))
    assert np.allclose(m.phase_deg, 110)
    assert np.allclose(m.state_deg, [110, 70, 110, 70])
    assert m.min_state_deg == pytest.approx(70) and m.state_error_deg == pytest.approx(20)
    assert m.min_state_ns == pytest.approx(70 / 360 * 1e9 / F_HZ)
    assert np.allclose(m.pulse_a_deg, 180) and np.allclose(m.pulse_b_deg, 180)


def test_pulse_errors_add_to_state_error_algebraically():
    """Static pulse errors (the internal error) with zero phase: ΔS = (|ΔP_A| + |ΔP_B|) / 2."""
    _, m = unit_waveform(EncoderUnit(pulse_error_deg=(10, -6)), Profile().constant(RPM, 0.02))
    assert np.allclose(m.pulse_a_deg, 190) and np.allclose(m.pulse_b_deg, 174)
    assert np.allclose(m.phase_deg, 90)
    assert np.allclose(m.state_deg, [98, 92, 82, 88])
    _, m = unit_waveform(EncoderUnit(pulse_error_deg=8, phase_error_deg=-5),
                         Profile().constant(RPM, 0.02))
    assert m.state_error_deg == pytest.approx(8 / 2 + 8 / 2 + 5)


@pytest.mark.parametrize("temp_c,alpha,rpm", [(70, 2.5e-5, 3000), (70, 1e-5, 3000),
                                              (0, 2.5e-5, 1500), (25, 2.5e-5, 3000)])
def test_pulse_width_follows_alpha_dt_f(temp_c, alpha, rpm):
    f = rpm / 60 * 500
    dp = alpha * (temp_c - 25) * f
    wf, m = unit_waveform(EncoderUnit(temp_c=temp_c, alpha=alpha), Profile().constant(rpm, 0.01))
    assert_valid_quadrature(wf)
    assert np.allclose(m.freq_hz, f)
    assert np.allclose(m.pulse_a_deg, 180 + dp) and np.allclose(m.pulse_b_deg, 180 + dp)
    assert m.state_error_deg == pytest.approx(abs(dp), abs=1e-6)
    assert np.allclose(m.cycle_deg, 360)


def test_guardband_example_state_in_ns():
    """The note's guard band case, 3000 rpm at 70 °C with α worst: ΔS = 28.1 e°, so the
    narrowest state of a perfect unit is 90 - 28.1 e° at 25 kHz."""
    _, m = unit_waveform(EncoderUnit(temp_c=70, alpha=2.5e-5), Profile().constant(3000, 0.01))
    assert m.min_state_ns == pytest.approx((90 - 28.125) / 360 / 25e3 * 1e9)


def test_eccentricity_position_and_phase():
    """Position error p-p = k E / R (x N e°); phase swings ±Q_e E / 2 (the TIR/2 rule)."""
    e = 0.047
    wf, m = unit_waveform(EncoderUnit(eccentricity_mm=e, eccentricity_angle_deg=30),
                          one_revolution())
    assert_valid_quadrature(wf)
    assert m.position_pp_deg == pytest.approx(note.q_p() * e * 500, rel=0.01)   # ~124 e°
    assert m.phase_error_deg == pytest.approx(note.Q_E * e / 2, rel=0.005)     # 12.9 e°
    assert np.mean(m.phase_deg) == pytest.approx(90, abs=0.1)
    assert m.cycle_error_deg < 2, "eccentricity has only a minor effect on cycle length"


@pytest.mark.parametrize("field,play,q", [("radial_play_mm", 0.006, note.Q_E),
                                          ("axial_play_mm", 0.1, note.Q_MA)])
def test_random_play_reaches_play_times_q(field, play, q):
    seed = 11
    print(f"seed {seed}")
    _, m = unit_waveform(EncoderUnit(**{field: play}, seed=seed), one_revolution())
    assert 0.97 * play * q <= m.phase_error_deg <= play * q
    assert abs(np.mean(m.phase_deg) - 90) < 0.1 * play * q
    assert np.allclose(m.pulse_a_deg, 180) and np.allclose(m.pulse_b_deg, 180)


def test_cycle_error_from_line_placement():
    seed = 5
    print(f"seed {seed}")
    wf, m = unit_waveform(EncoderUnit(cycle_error_deg=0.7, seed=seed), Profile().constant(3000, 0.5))
    assert m.cycles > 12000
    assert np.std(m.cycle_deg - 360) == pytest.approx(0.7 * math.sqrt(2), rel=0.05)
    assert np.allclose(m.pulse_a_deg, 180, atol=0.1)   # within the local-speed reference


def test_the_wheel_repeats_and_the_play_does_not():
    """Line k and line k + N are the same line: the same placement error, every revolution (and
    the eccentricity with them), so a typical unit's A edges sit exactly one revolution apart;
    the shaft's radial and axial play is drawn anew every cycle, so its B edges do not."""
    seed = 7
    print(f"seed {seed}")
    n = note.CPR
    lines = EncoderUnit(cycle_error_deg=0.7, seed=seed).edges(-3, 2 * n + 3)
    assert np.std(lines[::4] - np.arange(-3, 2 * n + 3)) > 0.5 / 360     # the errors are there
    np.testing.assert_allclose(lines[4 * n:] - lines[:-4 * n], n, rtol=0, atol=1e-9)
    u = EncoderUnit.typical(np.random.default_rng(seed))
    x = u.edges(-2, 3 * n)
    a_rise, b_rise = x[0::4], x[1::4]
    np.testing.assert_allclose(a_rise[n:] - a_rise[:-n], n, rtol=0, atol=1e-9)
    play = 360 * ((b_rise[n:] - a_rise[n:]) - (b_rise[:-n] - a_rise[:-n]))  # B phase, e°
    radial, axial = u.q_e * u.radial_play_mm, u.q_ma * u.axial_play_mm
    want = math.sqrt(2 * (radial ** 2 + axial ** 2) / 3)     # two independent uniform draws
    print(f"B phase change from one revolution to the next: {np.std(play):.2f} e° rms "
          f"(independent draws: {want:.2f}), at most {np.max(np.abs(play)):.2f} e°")
    assert np.std(play) == pytest.approx(want, rel=0.1)
    assert np.max(np.abs(play)) <= 2 * (radial + axial) + 1e-6


def test_ramp_edge_times_are_exact():
    """Constant acceleration from rest: A rises at t = sqrt(2 x / a)."""
    wf = EncoderUnit().waveform(Profile().ramp(0, 600, 0.1))
    a = F_HZ / 0.1                             # cycles / s^2
    rises = [t for t, ai, bi in wf.events[1:] if (ai, bi) == (1, 0)]
    expected = [math.sqrt(2 * (k + 45 / 360) / a) * 1e9 for k in range(len(rises))]
    assert len(rises) == 250
    assert np.max(np.abs(np.array(rises) - expected)) < 1e-3   # ns


def test_reversals_and_stops_give_valid_quadrature():
    seed = 2024
    print(f"seed {seed}")
    unit = EncoderUnit.draw(np.random.default_rng(seed))
    profile = (Profile().constant(1200, 0.01).ramp(1200, -900, 0.01).stop(2e-3)
               .constant(-300, 0.004).constant(400, 0.003).ramp(400, 0, 0.004))
    wf, index = unit.waveform(profile, index=True)
    assert_valid_quadrature(wf)
    assert len(wf.events) > 300
    assert wf.final_position == true_position(unit, profile.end_deg)
    assert index[0] == (0.0, 1)


def test_dither_about_a_transition():
    """Dithering ±20 e° across A's rise re-crosses that one edge twice per period, nothing else."""
    wf = EncoderUnit().waveform(Profile(start_deg=5).dither(20, 50, 1e-4))
    assert_valid_quadrature(wf)
    assert len(wf.events) == 1 + 100
    assert set(wf.positions) == {0, 1} and wf.final_position == 1
    seed = 3
    print(f"seed {seed}")
    unit = EncoderUnit.draw(np.random.default_rng(seed))
    profile = Profile(start_deg=0).dither(200, 40, 2e-4)
    wf = unit.waveform(profile)
    assert_valid_quadrature(wf)
    assert len(wf.events) > 40 * 8
    assert wf.final_position == true_position(unit, 0)


def test_index_once_per_revolution():
    seed = 9
    print(f"seed {seed}")
    unit = EncoderUnit.draw(np.random.default_rng(seed))
    wf, index = unit.waveform(Profile().constant(RPM, 3.2 * 0.1), index=True)
    assert index[0] == (0.0, 1)                 # the profile starts in the index state
    rises = [t for t, level in index[1:] if level]
    assert len(rises) == 3
    assert np.allclose(np.diff(rises), 0.1e9, rtol=1e-3)   # one revolution apart
    times = [e[0] for e in wf.events]
    for t, level in index[1:]:
        i = times.index(t)
        assert (wf.positions[i] % 2000 == 0) == bool(level)
        if level:
            assert wf.events[i][1:] == (0, 0)
            width_deg = (times[i + 1] - t) * 1e-9 * F_HZ * 360
            assert 45 < width_deg < 135           # one state, about 90 e°


def test_hot_and_fast_reorders_transitions_but_stays_consistent():
    """Phase +40 leaves a 50 e° state; at 3000 rpm and 125 °C the delay difference (62.5 e°)
    eats it, so A rises before B falls. The waveform then shows what a decoder sees: valid
    steps that count backwards, and a position far from the shaft's."""
    unit = EncoderUnit(phase_error_deg=40, temp_c=125, alpha=2.5e-5)
    profile = Profile().constant(3000, 0.004)
    wf = unit.waveform(profile)
    assert_valid_quadrature(wf)
    assert abs(wf.final_position) < 8
    assert true_position(unit, profile.end_deg) == 400


@pytest.mark.parametrize("rpm,excess", [(4320, 0), (-4320, 0), (-4320, 3e-8)])
def test_simultaneous_transitions_are_flagged_and_reanchored(rpm, excess):
    """At 36 kHz and 125 °C with α = 2.5e-5 the delay difference is one state (T/4), so a delayed
    edge lands on the next edge of the other channel: within one picosecond the two make one event
    with both channels changing, position None; counting then resumes at the shaft's true
    position. (``excess`` makes the delay 0.2 ps longer, so the two arrive in either order.)"""
    unit = EncoderUnit(temp_c=125, alpha=2.5e-5 * (1 + excess))
    profile = Profile(start_deg=100 * 360 + 45).constant(rpm, 0.002)
    wf = unit.waveform(profile)
    assert measure(wf).invalid_transitions > 40
    ev, pos = wf.events, wf.positions
    for i in range(1, len(ev)):
        changed = (ev[i][1] != ev[i - 1][1]) + (ev[i][2] != ev[i - 1][2])
        assert changed == (2 if pos[i] is None else 1)
        if pos[i] is not None:
            assert STATE_TO_POS[ev[i][1:]] == pos[i] % 4
    last = [p for p in pos if p is not None][-1]
    assert abs(last - true_position(unit, profile.end_deg)) <= 2


def test_pulses_shorter_than_the_delay_difference_vanish():
    """Falling edges 278 µs late (α 1e-3, 125 °C) against 100 µs low pulses at 5 kHz: every low
    pulse is swallowed, so both channels rise once and stay high until the shaft has stopped in
    state 00 (their last falls come one delay after the profile's end)."""
    wf = EncoderUnit(temp_c=125, alpha=1e-3).waveform(Profile().constant(RPM, 0.01))
    assert_valid_quadrature(wf)
    assert [e[1:] for e in wf.events] == [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]
    assert wf.events[3][0] > 0.01e9


def test_impossible_unit_is_rejected():
    with pytest.raises(ValueError, match="no quadrature"):
        EncoderUnit(phase_error_deg=95).waveform(Profile().constant(RPM, 1e-3))
    with pytest.raises(ValueError):
        Profile().constant(RPM, -1)
    with pytest.raises(ValueError):
        EncoderUnit(alpha=1)


def test_deterministic_from_seed_and_fast():
    profile = Profile().constant(3000, 0.5)
    rng_seed = 77
    print(f"seed {rng_seed}")
    unit = EncoderUnit.draw(np.random.default_rng(rng_seed), jitter_ns=50)
    start = time.perf_counter()
    wf = unit.waveform(profile)
    elapsed = time.perf_counter() - start
    assert len(wf.events) > 50000
    assert elapsed < 2.0, f"{len(wf.events)} events took {elapsed:.2f} s"
    assert unit.waveform(profile).events == wf.events
    again = EncoderUnit.draw(np.random.default_rng(rng_seed), jitter_ns=50)
    assert again == unit and again.waveform(profile).events == wf.events
    other = EncoderUnit.draw(np.random.default_rng(rng_seed + 1), jitter_ns=50)
    assert other.waveform(profile).events != wf.events


def test_typical_unit_matches_the_note_budget():
    """Every factor at its mean: the worst state error is the algebraic sum of eccentricity
    (12.9), the three random phase terms at their peaks (3 + 3.3 + 2) and internal 12, less a
    little because not every peak lines up inside one revolution."""
    seed = 4
    print(f"seed {seed}")
    _, m = unit_waveform(EncoderUnit.typical(np.random.default_rng(seed)), one_revolution())
    algebraic = 0.0471 / 2 * 550 + 3 + 0.006 * 550 + 0.1 * 20 + 12
    assert algebraic - 4 < m.state_error_deg <= algebraic + 3.5   # + line error, ~3 e° max


def test_monte_carlo_batch_is_reproducible(tmp_path):
    seed = 7
    print(f"seed {seed}")
    a = state_width_batch(60, seed)
    b = state_width_batch(60, seed)
    assert np.array_equal(a.errors_deg, b.errors_deg)
    assert 26 < a.mean_deg < 40 and 5 < a.sd_deg < 13          # README: 32.8 / 8.7 on 2000 units
    assert not np.array_equal(state_width_batch(60, seed + 1).errors_deg, a.errors_deg)
    out = tmp_path / "hist.png"
    script = Path(__file__).resolve().parents[2] / "scripts" / "monte_carlo.py"
    proc = subprocess.run([sys.executable, str(script), "--units", "60", "--seed", str(seed),
                           "--out", str(out), "--json"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result["mean_deg"] == pytest.approx(a.mean_deg)
    assert result["fraction_under_limit"] == pytest.approx(a.fraction_under(44))
    assert out.stat().st_size > 10000
