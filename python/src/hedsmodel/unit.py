# SPDX-License-Identifier: Apache-2.0
"""One HEDS-5000 unit on its shaft: error sources -> A/B (and index) edge times.

The model works in two steps.

1. **Space.** Every transition of the unit sits at a fixed shaft position. Edge ``m = 4k + j`` of
   cycle ``k`` is A rise (j=0), B rise (1), A fall (2), B fall (3), nominally at ``k + j/4`` cycles
   (cycle = 360 e°). Errors move them (all in e°):

   - eccentricity, TIR ``E`` at angle ``ψ`` (Table 2 factors combined vectorially): the wheel
     centre is off by ``d = E/2``. Its tangential part shifts every edge by the position error
     ``N d / (2π R)`` cycles · sin(θ + ψ) (peak-to-peak k E / R angular degrees, the note's
     formula); its radial part adds ``Q_e d cos(θ + ψ)`` to the phase: the note's TIR/2 rule.
   - radial play ``P_r`` and axial play ``P_a``: per cycle the shaft sits at ``u P`` with ``u``
     uniform in [-1, 1], drawn once per cycle, adding ``Q_e u P_r + Q_ma u' P_a`` to the phase;
     so the largest excursion is P Q, the amount the note budgets. Play is random: it is drawn
     for the absolute cycle number ``k``, so it never repeats from one revolution to the next.
     (It is tied to the cycle, not to time, so re-crossing an edge in a dither finds it in the
     same place. Its position effect is ignored: Table 1 says play leaves cycle uniformity
     alone.)
   - assembly adjustment: a constant phase offset ``phase_error_deg`` (B moves, A stays).
   - pulse width: A's high pulse is ``180 + p_A``, B's ``180 + p_B``, centred. This is where the
     internal error ΔS3 lives: static pulse errors with zero net phase give a state-width error
     of exactly (|p_A| + |p_B|) / 2.
   - cycle error: each cycle's four edges move together by a line-placement error ~ N(0,
     ``cycle_error_deg``) (code-wheel artwork). It belongs to the wheel's line ``k mod N``
     (N = ``cpr``): cycle ``k`` and cycle ``k + N`` are the same line and sit the same distance
     off, so the wheel's line errors repeat every revolution, as a real wheel's do.

2. **Time.** The profile is split into monotone pieces; each edge it passes is crossed at a time
   found in closed form. Then the comparators' unequal propagation delays (``α ΔT / 360`` s on the
   falling edges, or the rising ones below 25 °C; the note's ΔP = α ΔT f at frequency f) and
   optional timing jitter (``jitter_ns`` rms) are applied per channel. A pulse that they shrink to
   nothing disappears with both its edges.

The output is a :class:`hedsmodel.waveform.Waveform`. Its positions follow the states the waveform shows
(``None`` on an event where both channels changed in the same picosecond; the count is then
re-anchored to the shaft's true position), so a decoder that counts the waveform exactly matches
them even when speed and delays reorder transitions. The index channel is gated: high exactly
while the 4X position is a multiple of 4N (state 00 before cycle 0 of each revolution), 90 e° wide.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .waveform import QUAD, STATE_TO_POS, Waveform

from . import note
from .profile import Profile

BLOCK = 1024               # cycles per block of per-cycle random numbers
CYCLE_ERROR_RMS = 0.7      # e°, line placement: max cycle error ~3 e° per revolution (data sheets)


def _folded(rng: np.random.Generator, mean: float, sd: float) -> float:
    """A magnitude drawn as |N(mean, sd)|: the note's Gaussian factors, mean of absolute values."""
    return abs(rng.normal(mean, sd))


def _sign(rng: np.random.Generator) -> float:
    return 1.0 if rng.random() < 0.5 else -1.0


@dataclass
class EncoderUnit:
    """One assembled encoder. All angles in electrical degrees, lengths in mm TIR/play."""

    phase_error_deg: float = 0.0          # static phase error (assembly adjustment)
    pulse_error_deg: float | tuple[float, float] = 0.0  # pulse width error, both or (A, B)
    eccentricity_mm: float = 0.0          # total cyclic eccentricity, TIR
    eccentricity_angle_deg: float = 0.0   # mechanical angle where the wheel centre is offset
    radial_play_mm: float = 0.0
    axial_play_mm: float = 0.0
    cycle_error_deg: float = 0.0          # rms line-placement error per cycle
    jitter_ns: float = 0.0                # rms timing jitter per transition
    temp_c: float = note.T_REF_C
    alpha: float = note.ALPHA_TYPICAL     # e°/(°C·Hz)
    seed: int = 0                         # per-cycle play and line errors, jitter
    cpr: int = note.CPR
    radius_mm: float = note.RADIUS_MM
    q_e: float = note.Q_E
    q_ma: float = note.Q_MA

    def __post_init__(self):
        p = self.pulse_error_deg
        self.pulse_error_deg = (float(p), float(p)) if np.isscalar(p) else tuple(map(float, p))
        if not (note.ALPHA_RANGE[0] <= self.alpha <= note.ALPHA_RANGE[1]):
            raise ValueError(f"alpha {self.alpha:g} outside {note.ALPHA_RANGE}")
        if min(self.eccentricity_mm, self.radial_play_mm, self.axial_play_mm,
               self.cycle_error_deg, self.jitter_ns) < 0:
            raise ValueError("eccentricity, play, cycle error and jitter must be >= 0")

    # ------------------------------------------------------------------ construction
    @classmethod
    def draw(cls, rng: np.random.Generator, **conditions) -> "EncoderUnit":
        """A random unit from the note's batch: Table 2 eccentricities (random directions, summed
        as vectors), Table 3 plays and assembly error, internal error 12 ± 6 e° split at random
        between the two channels' pulse widths. ``conditions``: any other field (temp_c, alpha,
        jitter_ns, ...)."""
        ecc = sum(_folded(rng, m, s) * np.exp(2j * np.pi * rng.random()) for _, m, s in note.TABLE2)
        (_, ax_m, ax_s, _), (_, rad_m, rad_s, _), (_, asm_m, asm_s, _) = note.TABLE3
        internal = _folded(rng, *note.INTERNAL)
        share = rng.random()
        fields = dict(
            eccentricity_mm=float(abs(ecc)), eccentricity_angle_deg=math.degrees(np.angle(ecc)),
            axial_play_mm=_folded(rng, ax_m, ax_s), radial_play_mm=_folded(rng, rad_m, rad_s),
            phase_error_deg=_sign(rng) * _folded(rng, asm_m, asm_s),
            pulse_error_deg=(_sign(rng) * 2 * internal * share,
                             _sign(rng) * 2 * internal * (1 - share)),
            cycle_error_deg=CYCLE_ERROR_RMS, seed=int(rng.integers(2**63)))
        return cls(**(fields | conditions))

    @classmethod
    def typical(cls, rng: np.random.Generator, **conditions) -> "EncoderUnit":
        """A unit with every factor at its table mean (directions and signs still random)."""
        ecc_mean = math.sqrt(sum(m * m for _, m, _ in note.TABLE2))
        (_, ax_m, _, _), (_, rad_m, _, _), (_, asm_m, _, _) = note.TABLE3
        internal = note.INTERNAL[0]
        fields = dict(
            eccentricity_mm=ecc_mean, eccentricity_angle_deg=360 * rng.random(),
            axial_play_mm=ax_m, radial_play_mm=rad_m, phase_error_deg=_sign(rng) * asm_m,
            pulse_error_deg=(_sign(rng) * internal, _sign(rng) * internal),
            cycle_error_deg=CYCLE_ERROR_RMS, seed=int(rng.integers(2**63)))
        return cls(**(fields | conditions))

    # ------------------------------------------------------------------ space
    def _cycle_noise(self, k: np.ndarray) -> np.ndarray:
        """Per-cycle uniform radial and axial displacements in [-1, 1] and a standard normal line
        error, shape (len(k), 3). The play (columns 0, 1) is drawn for the absolute cycle ``k``:
        the same cycle always gets the same numbers, the next revolution new ones. The line error
        (column 2) is that of the wheel's line ``k mod cpr``: the same every revolution."""
        k = np.asarray(k, dtype=np.int64)
        out = self._draws(k)
        out[:, 2] = self._draws(np.mod(k, self.cpr))[:, 2]
        return out

    def _draws(self, k: np.ndarray) -> np.ndarray:
        """The random numbers of cycle number ``k``: three per cycle, in blocks of BLOCK cycles,
        each block from its own generator seeded with (seed, 2, block)."""
        out = np.empty((len(k), 3))
        block = k // BLOCK
        for b in np.unique(block):
            g = np.random.default_rng([self.seed, 2, int(b) % 2**32])
            table = np.column_stack([g.uniform(-1, 1, (BLOCK, 2)), g.standard_normal(BLOCK)])
            sel = block == b
            out[sel] = table[k[sel] % BLOCK]
        return out

    def position_amplitude_cycles(self) -> float:
        """Amplitude of the once-per-revolution position error, in cycles."""
        return self.cpr * self.eccentricity_mm / 2 / (2 * math.pi * self.radius_mm)

    def edges(self, k0: int, k1: int) -> np.ndarray:
        """Positions (cycles) of the edges of cycles k0 .. k1-1, index m - 4 k0 for edge m."""
        k = np.repeat(np.arange(k0, k1), 4)
        j = np.tile(np.arange(4), k1 - k0)
        noise = self._cycle_noise(np.arange(k0, k1))
        radial, axial, line = (np.repeat(noise[:, i], 4) for i in range(3))
        d = self.eccentricity_mm / 2
        psi = math.radians(self.eccentricity_angle_deg)
        pa, pb = self.pulse_error_deg
        is_b = j % 2 == 1
        half_pulse = np.where(is_b, pb, pa) / 2 * np.where(j < 2, -1.0, 1.0)
        fixed_deg = (half_pulse + self.cycle_error_deg * line + is_b * (
            self.phase_error_deg + self.q_e * self.radial_play_mm * radial
            + self.q_ma * self.axial_play_mm * axial))
        nominal = k + j / 4 + fixed_deg / 360
        amp = self.position_amplitude_cycles()
        x = nominal.copy()
        for _ in range(4):  # x = nominal + offset(x); |d offset / dx| ~ d / R << 1
            rev_angle = 2 * math.pi * x / self.cpr + psi
            x = nominal + amp * np.sin(rev_angle) + is_b * (self.q_e * d * np.cos(rev_angle)) / 360
        return x

    # ------------------------------------------------------------------ time
    def _crossings(self, profile: Profile):
        """Edges crossed by ``profile``: times (s), edge indices m, directions (+1/-1), and the
        4X position at the start."""
        lo, hi = profile.extent()
        margin = math.ceil(self.position_amplitude_cycles()) + 2
        k0, k1 = math.floor(lo) - margin, math.ceil(hi) + margin
        xe = self.edges(k0, k1)
        if np.any(np.diff(xe) <= 0):
            raise ValueError("this unit's errors leave a state of zero or negative width "
                             "(state width error >= 90 e°): no quadrature to model")
        m0 = 4 * k0
        times, ms, dirs = [], [], []
        for pc in profile.pieces():
            ia, ib = np.searchsorted(xe, (pc.xa, pc.xb), "right")
            idx = np.arange(ia, ib) if pc.xb > pc.xa else np.arange(ia - 1, ib - 1, -1)
            if idx.size:
                times.append(pc.times(xe[idx]))
                ms.append(idx + m0)
                dirs.append(np.full(idx.size, 1 if pc.xb > pc.xa else -1))
        start_pos = m0 + int(np.searchsorted(xe, profile.start_x, "right"))
        if not times:
            return np.zeros(0), np.zeros(0, int), np.zeros(0, int), start_pos
        return np.concatenate(times), np.concatenate(ms), np.concatenate(dirs), start_pos

    def waveform(self, profile: Profile, index: bool = False):
        """The unit's A/B waveform for ``profile`` (a :class:`hedsmodel.waveform.Waveform`, times in ns from the
        profile's start); with ``index=True`` also the index channel as ``[(t_ns, level)]``, its
        first entry the level at t = 0. Delayed edges may land after ``profile.duration_s``."""
        if profile.cpr != self.cpr:
            raise ValueError(f"profile is for {profile.cpr} cycles/rev, unit has {self.cpr}")
        t, m, d, pos = self._crossings(profile)
        kind = m % 4
        level = ((kind < 2) == (d > 0)).astype(int)
        label = np.where(d > 0, m + 1, m)            # true 4X position after the crossing
        delay = self.alpha * (self.temp_c - note.T_REF_C) / 360.0
        t = t + np.where(level == 0, max(delay, 0.0), max(-delay, 0.0))
        if self.jitter_ns:
            t = t + np.random.default_rng([self.seed, 1]).normal(0, self.jitter_ns * 1e-9, t.size)
        keep = np.concatenate([_drop_collapsed(np.flatnonzero(kind % 2 == ch), t) for ch in (0, 1)])
        keep = keep[np.argsort(t[keep], kind="stable")]
        wf, idx = _assemble(t[keep] * 1e9, kind[keep] % 2, level[keep], label[keep], pos,
                            4 * self.cpr)
        return (wf, idx) if index else wf


def _drop_collapsed(idx: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Remove pulses of one channel (index array ``idx`` in crossing order) whose edges the delays
    or jitter put out of order: both edges of such a pulse go."""
    while True:
        bad = np.flatnonzero(np.diff(t[idx]) <= 0)
        if bad.size == 0:
            return idx
        keep = np.ones(idx.size, bool)
        last = -2
        for i in bad:
            if i > last + 1:
                keep[i] = keep[i + 1] = False
                last = i + 1
        idx = idx[keep]


def _assemble(t_ns, channel, level, label, pos, index_period):
    """Merge the channel events into a Waveform (events in the same picosecond become one) and
    derive the gated index channel."""
    state = list(QUAD[pos % 4])
    wf = Waveform(events=[(0.0, *state)], positions=[pos])
    index = [(0.0, int(pos % index_period == 0))]
    ps = np.round(t_ns * 1000.0).astype(np.int64)
    t_l, ch_l, lv_l, lb_l, ps_l = (a.tolist() for a in (t_ns, channel, level, label, ps))
    n, i = len(t_l), 0
    while i < n:
        j = i
        old = tuple(state)
        while j < n and ps_l[j] == ps_l[i]:
            state[ch_l[j]] = lv_l[j]
            j += 1
        new = tuple(state)
        if new != old:
            step = (STATE_TO_POS[new] - STATE_TO_POS[old]) % 4
            if step == 2:   # both channels changed: re-anchor on the true position
                true = lb_l[j - 1]
                pos = true + (STATE_TO_POS[new] - true) % 4
                pos -= 4 if pos - true > 2 else 0
                shown = None
            else:
                pos += 1 if step == 1 else -1
                shown = pos
            ind = int(pos % index_period == 0)
            if t_l[i] <= 0:   # jitter moved it before the start: part of the initial state
                wf.events[0], wf.positions[0] = (0.0, *new), pos
                index[0] = (0.0, ind)
            else:
                wf.events.append((t_l[i], *new))
                wf.positions.append(shown)
                if ind != index[-1][1]:
                    index.append((t_l[i], ind))
        i = j
    return wf, index
