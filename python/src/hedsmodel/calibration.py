# SPDX-License-Identifier: Apache-2.0
"""A self-calibrating velocity estimator fed by enc_qei's edge-capture FIFO.

The same algorithm exists in C99 in ``sw/enc_qei_calib.{h,c}``, operation for operation (a test,
tb/velocity/test_velocity_calibration.py, runs both on the same entry streams).

What it learns
--------------
An encoder's edges are not where they should be: the code wheel's line placement, its
eccentricity and the pulse-width and phase errors move every edge by a fixed amount, the same
every revolution. Boundary ``j`` of a revolution (the edge between state ``j - 1`` and state
``j``, ``j = 0 .. 4N - 1``, counted from the reference) sits at angle ``cum[j]`` counts
(nominally ``j``; ``cum[0] = 0``; one revolution = 4N counts). The table ``cum`` is learnt from
the edges themselves: the time of 4N consecutive edges is exactly one revolution, whatever the
wheel's errors, so the mean speed of each revolution is known exactly. For revolution ``r``
(period ``T``, boundaries crossed at times ``tau_j`` after its start) and the revolution just
before it (period ``Tp``, same direction, contiguous), the distance travelled is fitted as a
quadratic through the three revolution boundaries (constant acceleration, exact on a ramp)::

    acc = 2 S (Tp - T) / (T Tp (T + Tp))          S = 4N
    u(tau) = S tau / T + acc tau (tau - T) / 2
    cum[j] = u(tau_j)  (up)      S - u(tau_j)  (down)

and the table is the mean of ``learn_revs`` such revolutions. A revolution starts and ends at
boundary 0 and counts only when all its 4N edges came in order, in one direction, with no LOST
entry; the first one after a start, a reversal or a gap only gives ``Tp``. So learning takes
``learn_revs + 1`` whole revolutions after boundary 0 is first crossed, at any speed at which
the FIFO keeps up, ramps included.

Reference (phase of the table)
------------------------------
``use_index=True``: nothing is learnt before the first entry with IDX; the state entered by
that step is state 0 (its boundary slot 0 going up, 1 going down). The state an IDX step enters
is remembered per direction (the first IDX of each direction); a later IDX step in the same
direction entering another state (mod 4N) is a **re-index**: counted, the table is dropped and
learnt again in the new frame. A **LOST** entry makes the phase unknown: readings are
uncalibrated until the next IDX step of a direction already seen restores it; the table is kept
(it belongs to the wheel, not to the count) and the change check below still watches it.
``use_index=False``: boundary 0 is the one crossed by the first entry; a LOST entry drops the
table and starts again from the entry that says so (nothing can restore the phase).

Changed wheel: every complete revolution after the table is learnt is fitted the same way and
compared with it: per state, measured extent minus table extent, less the mean of its cycle's
four (a high-pass: a speed change within the revolution moves the four states of a cycle alike);
the rms over the revolution is ``last_check`` (counts). ``change_revs`` consecutive revolutions
above ``change_threshold`` mean a different wheel: counted, the table is dropped and relearnt.

Readings (count steps per second, signed; at each host read, :meth:`read`)
--------------------------------------------------------------------------
Angle of boundary ``B`` (unwrapped count): ``B`` uncalibrated; calibrated ``ref + q S + cum[j]``
with ``B - ref = q S + j``. Two methods, each with its selected edges:

- **A↑** (calibrated M/T on A-rising edges): selected edges are steps where A goes 0 -> 1;
- **any** (calibrated any-edge): every step.

At a read with new selected edges since the previous read, the reading is (angle(latest) -
angle(reference)) / (time(latest) - time(reference)), the reference being the latest selected
edge at the previous read: one state at low speed (a fresh reading after each edge), many at
high speed. Angles use the table in force at the read (uncalibrated until it is learnt and
phased). **Reversal**: a step against the direction of the previous step, or a LOST entry,
reads 0 at once and leaves no reference; the next selected edge is a reference only (reads 0),
the one after it reads again. **Standstill**: with no new selected edge, the magnitude is
``min(last, ext / since)``: ``ext`` the angle from the latest selected edge to the next one in
the direction of motion (calibrated; uncalibrated 1 count for any, 4 for A↑), ``since`` the
ticks since the latest selected edge; 0 once ``since >= stall_ticks`` (``stall_ticks`` > 0). Before an edge: 0.

Times are TS_W-bit ticks; entries and reads must come in time order (drain the FIFO, then read
the TIMEBASE), less than 2^TS_W ticks apart; they are unwrapped by adding the modular
differences. Memory: two arrays of 4N doubles (table, one revolution's work) plus O(1) state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

QUAD = ((0, 0), (1, 0), (1, 1), (0, 1))


@dataclass(frozen=True)
class CalibConfig:
    """``tick_s``: seconds per tick; ``ts_w``: timebase width; ``cycles``: N, cycles per
    revolution (4N states); ``use_index``: phase the table on IDX entries; ``learn_revs``:
    revolutions averaged; ``stall_ticks``: stall timeout (0: off); ``change_threshold``: rms of
    the high-passed extent difference, counts, above which a revolution disagrees with the
    table; ``change_revs``: consecutive disagreeing revolutions that mean a changed wheel."""

    tick_s: float
    ts_w: int = 32
    cycles: int = 500
    use_index: bool = True
    learn_revs: int = 8
    stall_ticks: int = 0
    change_threshold: float = 0.06
    change_revs: int = 2

    def __post_init__(self):
        if not (self.tick_s > 0 and math.isfinite(self.tick_s)):
            raise ValueError(f"tick_s must be > 0, not {self.tick_s!r}")
        if not 1 <= self.ts_w <= 32:
            raise ValueError(f"ts_w must be 1 .. 32, not {self.ts_w!r}")
        if not 1 <= self.cycles <= 1 << 20:
            raise ValueError(f"cycles must be 1 .. 2^20, not {self.cycles!r}")
        if self.learn_revs < 1 or self.change_revs < 1 or self.stall_ticks < 0:
            raise ValueError("learn_revs and change_revs must be >= 1, stall_ticks >= 0")
        if not self.change_threshold > 0:
            raise ValueError("change_threshold must be > 0")


@dataclass
class CalReading:
    """Readings of one host read, count steps per second; ``calibrated``: the table was in use."""

    mt_a: float
    any: float
    calibrated: bool


class _Method:
    """Per-method state: latest selected edge, reference, direction and magnitude."""

    def __init__(self, cpe: int):
        self.cpe = cpe
        self.has_last = False
        self.last_b = 0
        self.last_t = 0
        self.has_ref = False
        self.ref_b = 0
        self.ref_t = 0
        self.new = False
        self.dir = 0
        self.mag = 0.0


class CalibratingEstimator:
    """Feed :class:`hedsmodel.velocity.EdgeEntry` s with :meth:`push` (in FIFO order) and call
    :meth:`read` once per host read; see the module docstring."""

    def __init__(self, cfg: CalibConfig):
        self.cfg = cfg
        self.S = 4 * cfg.cycles
        self.table = [0.0] * self.S
        self.work = [0.0] * self.S
        self.mask = (1 << cfg.ts_w) - 1
        self.t_raw = 0
        self.t = 0
        self.started = False
        self.pos = 0
        self.dir = 0
        self.phase_ok = False
        self.ref = 0
        self.idx_state = [-1, -1]        # state entered by an IDX step, [down, up]
        self.valid = False               # the table is learnt
        self.acc_revs = 0
        self.rev_dir = 0
        self.rev_t0 = 0
        self.rev_next = 0
        self.t_prev = 0
        self.bad = 0
        self.last_check = 0.0
        self.n_learned = self.n_changes = self.n_reindex = self.n_lost = 0
        self.m = (_Method(4), _Method(1))

    # ------------------------------------------------------------------ time, table
    def _time(self, raw: int) -> int:
        raw &= self.mask
        if not self.started:
            self.started = True
            self.t = raw
        else:
            self.t += (raw - self.t_raw) & self.mask
        self.t_raw = raw
        return self.t

    @property
    def calibrated(self) -> bool:
        return self.valid and self.phase_ok

    def _angle_diff(self, b2: int, b1: int) -> float:
        """angle(b2) - angle(b1), counts."""
        if not self.calibrated:
            return float(b2 - b1)
        S = self.S
        j2 = (b2 - self.ref) % S
        j1 = (b1 - self.ref) % S
        q = ((b2 - self.ref - j2) - (b1 - self.ref - j1)) // S
        return float(q * S) + (self.table[j2] - self.table[j1])

    def _drop_table(self) -> None:
        for j in range(self.S):
            self.table[j] = 0.0
        self.valid = False
        self.acc_revs = 0
        self.bad = 0

    def _abort_rev(self) -> None:
        self.rev_dir = 0
        self.t_prev = 0

    # ------------------------------------------------------------------ learning
    def _fit(self, T: int, d: int) -> None:
        """Revolution of period T complete (work[j]: times of boundaries j); fit and use it."""
        S, Sd = self.S, float(self.S)
        Tr, Tp = float(T), float(self.t_prev)
        acc = 2.0 * Sd * (Tp - Tr) / (Tr * Tp * (Tr + Tp))
        w = self.work
        for j in range(1, S):
            tau = w[j]
            u = Sd * tau / Tr + 0.5 * acc * tau * (tau - Tr)
            w[j] = u if d > 0 else Sd - u
        w[0] = 0.0
        if not self.valid:
            tb = self.table
            for j in range(1, S):
                tb[j] += w[j]
            self.acc_revs += 1
            if self.acc_revs >= self.cfg.learn_revs:
                k = float(self.acc_revs)
                for j in range(1, S):
                    tb[j] = tb[j] / k
                tb[0] = 0.0
                self.valid = True
                self.n_learned += 1
            return
        self.last_check = self._check()
        self.bad = self.bad + 1 if self.last_check > self.cfg.change_threshold else 0
        if self.bad >= self.cfg.change_revs:
            self.n_changes += 1
            self._drop_table()

    def _check(self) -> float:
        """rms over the states of (measured - table extent) less its cycle's mean, counts."""
        S, w, tb = self.S, self.work, self.table
        total = 0.0
        for c in range(0, S, 4):
            diff = [0.0, 0.0, 0.0, 0.0]
            for k in range(4):
                j = c + k
                hi_w = w[j + 1] if j + 1 < S else float(S)
                hi_t = tb[j + 1] if j + 1 < S else float(S)
                diff[k] = (hi_w - w[j]) - (hi_t - tb[j])
            mean = (diff[0] + diff[1] + diff[2] + diff[3]) / 4.0
            for k in range(4):
                e = diff[k] - mean
                total += e * e
        return math.sqrt(total / float(S))

    def _learn(self, b: int, d: int, t: int) -> None:
        S = self.S
        slot = (b - self.ref) % S
        if self.rev_dir != 0:
            if d != self.rev_dir or slot != self.rev_next:
                self._abort_rev()
            elif slot == 0:
                T = t - self.rev_t0
                if self.t_prev > 0 and T > 0:
                    self._fit(T, d)
                self.t_prev = T
                self.rev_t0 = t
                self.rev_next = 1 if d > 0 else S - 1
                return
            else:
                self.work[slot] = float(t - self.rev_t0)
                self.rev_next = (slot + d) % S
                return
        if slot == 0:
            self.rev_dir = d
            self.rev_t0 = t
            self.rev_next = 1 if d > 0 else S - 1

    # ------------------------------------------------------------------ input
    def push(self, e) -> None:
        """One FIFO entry (``time``, ``a``, ``b``, ``up``, ``lost``, ``idx``)."""
        t = self._time(e.time)
        d = 1 if e.up else -1
        self.pos += d
        b = self.pos if d > 0 else self.pos + 1          # boundary crossed
        s = QUAD.index((e.a, e.b))
        a_before = QUAD[(s - d) % 4][0]
        reversal = self.dir != 0 and d != self.dir
        self.dir = d
        if e.lost:
            self.n_lost += 1
            self._abort_rev()
            if self.cfg.use_index:
                self.phase_ok = False
            else:
                self._drop_table()
                self.ref = b
                self.phase_ok = True
        elif reversal:
            self._abort_rev()
        if not self.cfg.use_index and not self.phase_ok and not e.lost:
            self.ref = b                                 # the first entry: boundary 0
            self.phase_ok = True
        if self.cfg.use_index and e.idx:
            self._index(d)
        if self.phase_ok:
            self._learn(b, d, t)
        for m, sel in zip(self.m, (a_before == 0 and e.a == 1, True)):
            if e.lost or reversal:
                m.has_ref = False
                m.mag = 0.0
                m.dir = d
            if sel:
                m.has_last = True
                m.last_b = b
                m.last_t = t
                m.new = True
                if not m.has_ref:
                    m.has_ref = True
                    m.ref_b = b
                    m.ref_t = t
                    m.dir = d

    def _index(self, d: int) -> None:
        S, k = self.S, (1 if d > 0 else 0)
        if self.idx_state[0] < 0 and self.idx_state[1] < 0:
            self.ref = self.pos                          # the first IDX: state 0
            self.idx_state[k] = 0
            self.phase_ok = True
            self._abort_rev()
            return
        if self.idx_state[k] < 0:
            if self.phase_ok:
                self.idx_state[k] = (self.pos - self.ref) % S
            return
        if not self.phase_ok:                            # after LOST: restore the phase
            self.ref = self.pos - self.idx_state[k]
            self.phase_ok = True
            return
        if (self.pos - self.ref) % S != self.idx_state[k]:
            self.n_reindex += 1                          # re-index: new frame, relearn
            self.ref = self.pos - self.idx_state[k]
            self._drop_table()
            self._abort_rev()

    def read(self, time: int) -> CalReading:
        """A host read at TIMEBASE ``time``: the two readings (count steps per second)."""
        t = self._time(time)
        tick = self.cfg.tick_s
        out = [0.0, 0.0]
        for i, m in enumerate(self.m):
            if not m.has_last:
                continue
            if m.new and m.has_ref and m.last_t != m.ref_t:
                dang = self._angle_diff(m.last_b, m.ref_b)
                m.mag = abs(dang) / (float(m.last_t - m.ref_t) * tick)
            since = t - m.last_t
            mag = m.mag
            if self.cfg.stall_ticks > 0 and since >= self.cfg.stall_ticks:
                mag = 0.0
            elif not m.new and since > 0:
                ext = abs(self._angle_diff(m.last_b + m.cpe * m.dir, m.last_b))
                bound = ext / (float(since) * tick)
                if bound < mag:
                    mag = bound
            out[i] = float(m.dir) * mag
            if m.new:
                m.ref_b, m.ref_t = m.last_b, m.last_t
                m.has_ref = True
                m.new = False
        return CalReading(out[0], out[1], self.calibrated)

    def state(self) -> dict:
        """Counters and flags (for logs and tests)."""
        return {"calibrated": self.calibrated, "valid": self.valid, "phase_ok": self.phase_ok,
                "acc_revs": self.acc_revs, "learned": self.n_learned, "changes": self.n_changes,
                "reindex": self.n_reindex, "lost": self.n_lost, "last_check": self.last_check}



def stream_ops(entries, entry_ticks, read_ticks, mask: int):
    """Entries (with their unwrapped TIMEBASE ``entry_ticks``) and reads at the unwrapped
    TIMEBASE values ``read_ticks`` merged in time order: before each read, every entry at or
    before it (the FIFO drained). Yields ``("E", entry)`` and ``("R", time & mask)``."""
    i, n = 0, len(entries)
    for rt in read_ticks:
        while i < n and entry_ticks[i] <= rt:
            yield "E", entries[i]
            i += 1
        yield "R", int(rt) & mask


def run_stream(est: CalibratingEstimator, ops):
    """Run :func:`stream_ops`' output through ``est``: (mt_a, any, calibrated) lists, one per
    read."""
    mt_a, any_, cal = [], [], []
    for kind, x in ops:
        if kind == "E":
            est.push(x)
        else:
            r = est.read(x)
            mt_a.append(r.mt_a)
            any_.append(r.any)
            cal.append(r.calibrated)
    return mt_a, any_, cal


def repeating_wheel(unit, play: str = "random"):
    """A copy of the :class:`hedsmodel.unit.EncoderUnit` ``unit`` whose code-wheel line errors
    repeat every revolution (the model draws them per cycle number, so cycle k + N differs from
    cycle k; a real wheel's artwork does not). ``play``: the per-cycle radial and axial play as
    the model draws it ("random": never repeating, the note's random phase error), "repeating"
    (drawn for k mod N, a fixed pattern) or "none" (zero play)."""
    import dataclasses

    import numpy as np

    if play not in ("random", "repeating", "none"):
        raise ValueError(f"play must be random, repeating or none, not {play!r}")
    fields = {f.name: getattr(unit, f.name) for f in dataclasses.fields(unit)}
    if play == "none":
        fields.update(radial_play_mm=0.0, axial_play_mm=0.0)
    base = type(unit)

    class RepeatingWheel(base):
        def _cycle_noise(self, k):
            out = base._cycle_noise(self, k)
            per = base._cycle_noise(self, np.mod(k, self.cpr))
            out[:, 2] = per[:, 2]
            if play == "repeating":
                out[:, :2] = per[:, :2]
            return out

    return RepeatingWheel(**fields)
