# SPDX-License-Identifier: Apache-2.0
"""A self-calibrating velocity estimator fed by enc_qei's edge-capture FIFO, that uses what it
has learnt only while the edges confirm it.

The same algorithm exists in C99 in ``sw/enc_qei_calib.{h,c}``, operation for operation (a test,
tb/velocity/test_velocity_calibration.py, runs both on the same entry streams). doc/velocity.md
has the user's summary; this docstring is the specification.

What it learns
--------------
An encoder's edges are not where they should be: the code wheel's line placement, its
eccentricity and the pulse-width and phase errors move every edge by a fixed amount, the same
every revolution. Boundary ``j`` of a revolution (the edge between position ``ref + j - 1`` and
``ref + j``, ``j = 0 .. S - 1``, ``S = 4N``) sits at angle ``table[j]`` counts from boundary 0
(nominally ``j``; ``table[0] = 0``; one revolution = S counts). The time of S consecutive edges
is exactly one revolution, whatever the wheel's errors, so each revolution's mean speed is known
exactly.

**A revolution** starts and ends at boundary 0 and counts only when all its S edges came in
order, in one direction, with no LOST entry, no missed entry (below) and no re-index; the first
two after a start, a reversal or a gap only give periods. For revolution ``r`` (period ``T3``,
boundary ``j`` crossed ``tau_j`` ticks after its start) and the two before it (periods ``T1``,
``T2``, same direction, contiguous):

- *fit*: the distance travelled is a quadratic through the revolution boundaries of ``r - 1``
  and ``r`` (constant acceleration: exact on a ramp)::

      acc = 2 S (T2 - T3) / (T3 T2 (T3 + T2))
      u_j = S tau_j / T3 + acc tau_j (tau_j - T3) / 2        (up;  S - u_j down), u_0 = 0

- *motion check*: the revolution is **clean** when the three periods fit one constant
  acceleration: with ``g1 = (1/T2 - 1/T1) / (T1 + T2)`` and ``g2 = (1/T3 - 1/T2) / (T2 + T3)``
  (mean speed changes per unit time; the mean speed over a period is the speed at its middle
  under constant acceleration), ``|g2 - g1| (T2 + T3) T2 <= motion_tol`` (the third period's
  mean speed against the one the first two predict, relative). A revolution with a stop, a dip,
  a step or the end of a ramp in it or in the one before it is not clean: it is neither learnt
  nor used to judge the table.

**Agreement** of a clean revolution ``u`` with a reference ``v`` (the table, or the running mean
of a learning pass), on ``dev_j = u_j - v_j``, three figures, each within its tolerance:

- *shape* (smooth damage: a speed change learnt as wheel error, a slipped hub): the cycle means
  ``m_c = (dev_4c + .. + dev_4c+3) / 4``, ``c = 0 .. N - 1``, less their least-squares straight
  line in ``c`` (timing noise on boundary 0 tilts a revolution), rms over the cycles,
  ``<= shape_tol``;
- *line* (cycle-to-cycle damage where M/T on A-rising edges reads: a noise burst, a fast
  ripple): at the A boundaries (``j`` of the parity where A changes, two per cycle),
  ``h_j = dev_j - dev_(j-4)``, ``j >= 4``, rms about their mean, ``<= line_tol``;
- *edge* (damage between the edges of a cycle, where any-edge reads): ``dev_j - m_c``, rms over
  all S boundaries, ``<= edge_tol``.

**Learning pass** (the candidate): clean revolutions that the table does not explain (all of
them before there is a table) are offered to it. The first starts it; each later one must agree
with the pass's running mean (sum / n), or the pass restarts from it (a *rejected* pass). When
``learn_revs`` revolutions agree, the pass's mean becomes the table: the first table is *learnt*,
a later one replaces a table its revolutions disagree with (*changed*: a slipped hub, another
wheel). A clean revolution that agrees with the table empties the pass.

Trust (``calibrated``): readings use the table only while all of these hold, and are exactly the
uncalibrated ones otherwise:

- there is a table, its phase is known and no IDX disagreement is pending (below);
- **revolution check**: the latest clean revolution agreed with the table (set when a table is
  installed or re-indexed; a clean revolution that disagrees clears it until one agrees);
- **edge check**: the table makes the A-rising edges' timing no rougher than the raw count does,
  at two spacings: every A-rising edge (*fine*) and every ``max(1, N // 8)``-th (*coarse*, an
  eighth of a revolution). Per spacing, the latest four samples (times ``t0 .. t3``, boundaries
  ``b0 .. b3``): with ``tau_i = t_i - t0`` and the quadratic through the first three points
  evaluated at ``tau_3`` (constant acceleration)::

      l1 = tau3 (tau3 - tau2) / (tau1 (tau1 - tau2))
      l2 = tau3 (tau3 - tau1) / (tau2 (tau2 - tau1))
      e  = x3 - (x1 l1 + x2 l2)          x_i = angle(b_i) - angle(b0)

  once with raw angles (``e_raw``), once with the table's (``e_cal``); ``eff = |e_raw -
  e_cal|``, what the table does there. If ``eff`` is below ``EDGE_MIN_TICKS`` (4) ticks' worth
  of motion (``4 |b3 - b0| / tau3`` counts) the table cannot matter: ``frac -= frac / W``;
  else if ``min(|e_raw|, |e_cal|) <= EDGE_SEEN eff`` (3: the motion does not hide it) the
  sample votes ``v = (e_cal^2 > e_raw^2)`` and ``frac += (v - frac) / W`` (``W`` = 32 fine, 4
  coarse); otherwise no vote. The check holds while both ``frac < EDGE_LIMIT`` (0.35). With
  the table in place a vote is worse only by chance; one cycle off (a slipped count) about two
  votes in three are at the fine spacing, and a slipped hub's eccentricity votes worse at the
  coarse one once it makes the table worse than none (beyond about 60°).
  **Jolt**: a fine sample with ``|e_cal| > JOLT_COUNTS`` (0.5 counts: a step in speed beyond
  about 12 % within a cycle, a stop, the wheel jumping on its shaft) sets both fractions to 1
  and empties both histories: the table must earn trust again at both spacings (about seven
  eighths of a revolution of steady motion). The histories also empty at a reversal, a LOST or
  a missed entry; both fractions restart at 0 when a table is installed or its frame is set.

Reference (phase of the table)
------------------------------
The estimator follows the A/B state: an entry whose state is not one step (in its direction) from
the previous entry's is a **missed** entry (steps were lost without a LOST mark): handled as a
LOST entry. Boundary 0 (at position ``ref``) is always an A edge, so that the revolutions are
timed free of the random phase that the shaft's play puts on the B edges: of the boundary at an
anchor position ``r`` and the next one, the one where A changes (``_a_edge``).
``use_index=True``: nothing is learnt before the first entry with IDX; boundary 0 is anchored at
its step's position. The offset ``(pos - ref) mod S`` at which an IDX step lands is known per
direction: for the direction of the first IDX from it; for the other, once two IDX steps in that
direction land at the same offset (an unconfirmed direction's IDX steps are ignored).
An IDX step of a known direction implies a frame ``f = pos - offset``:

- phase unknown (after a LOST or missed entry): the phase is restored, ``ref = f``;
- ``f = ref`` (mod S): confirms the frame, clears a pending disagreement;
- otherwise it is **pending** (readings uncalibrated) until the next IDX step of a known
  direction: one that confirms ``ref`` clears it (a glitch); one that implies the same ``f``
  again is a **re-index** (the count slipped against the wheel): ``ref = f``, the table kept
  (it belongs to the wheel, and the index says where the wheel is), the revolution check set,
  the other direction's offset relearnt, the learning pass emptied; any other starts a new
  pending frame. (Should the first IDX have been false, the re-index moves the frame and the
  edge and revolution checks reject the table until a pass relearns it.)

``use_index=False``: boundary 0 is anchored at the boundary the first entry crosses; a LOST or
missed entry drops the table and starts again, anchored at the entry that says so.

Readings (count steps per second, signed; at each host read, :meth:`read`)
--------------------------------------------------------------------------
Angle of boundary ``B`` (unwrapped count): ``B`` uncalibrated; calibrated ``ref + q S + table[j]``
with ``B - ref = q S + j``. Two methods, each with its selected edges:

- **A↑** (calibrated M/T on A-rising edges): selected edges are steps where A goes 0 -> 1;
- **any** (calibrated any-edge): every step.

At a read with new selected edges since the previous read, the reading is (angle(latest) -
angle(reference)) / (time(latest) - time(reference)), the reference being the latest selected
edge at the previous read: one state at low speed (a fresh reading after each edge), many at
high speed. Angles use the table if it is trusted at the read (uncalibrated otherwise).
**Reversal**: a step against the direction of the previous step, or a LOST or missed entry,
reads 0 at once and leaves no reference; the next selected edge is a reference only (reads 0),
the one after it reads again. **Standstill**: with no new selected edge, the magnitude is
``min(last, ext / since)``: ``ext`` the angle from the latest selected edge to the next one in
the direction of motion (calibrated; uncalibrated 1 count for any, 4 for A↑), ``since`` the
ticks since the latest selected edge; 0 once ``since >= stall_ticks`` (``stall_ticks`` > 0).
Before an edge: 0.

Times are TS_W-bit ticks; entries and reads must come in time order (drain the FIFO, then read
the TIMEBASE), less than 2^TS_W ticks apart; they are unwrapped by adding the modular
differences. Memory: three arrays of S doubles (table, learning pass, one revolution's work)
plus O(1) state; the work per entry is O(1), per revolution O(S).

Limits: a speed ripple locked to the shaft angle (a load that varies with the angle) repeats
every revolution like the wheel's errors and is learnt as one; the calibrated readings then show
the mean speed over the ripple instead of the ripple. Damage that builds up smoothly within a
revolution and without a jolt is seen by the coarse edge check after a few eighths of a
revolution and by the revolution check after a clean revolution; until then it is read.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

QUAD = ((0, 0), (1, 0), (1, 1), (0, 1))
EDGE_W = (32, 4)          # edge check: votes averaged (weight 1/W), fine and coarse spacing
EDGE_LIMIT = 0.35         # edge check: the table is rejected at this fraction of worse votes
EDGE_MIN_TICKS = 4.0      # edge check: a vote counts when the table moves e by this many ticks
EDGE_SEEN = 3.0           # edge check: a vote is cast when a residual is within this many
                          # times the table's effect (else the motion hides it: no vote)
JOLT_COUNTS = 0.5         # a jolt: e_cal at the fine spacing beyond this, counts


@dataclass(frozen=True)
class CalibConfig:
    """``tick_s``: seconds per tick; ``ts_w``: timebase width; ``cycles``: N, cycles per
    revolution (4N states); ``use_index``: phase the table on IDX entries; ``learn_revs``:
    agreeing clean revolutions averaged into a table; ``stall_ticks``: stall timeout (0: off);
    ``motion_tol``: relative speed mismatch of a clean revolution; ``shape_tol``, ``line_tol``,
    ``edge_tol``: agreement tolerances, counts rms (see the module docstring)."""

    tick_s: float
    ts_w: int = 32
    cycles: int = 500
    use_index: bool = True
    learn_revs: int = 8
    stall_ticks: int = 0
    motion_tol: float = 1e-3
    shape_tol: float = 0.05
    line_tol: float = 0.005
    edge_tol: float = 0.15

    def __post_init__(self):
        if not (self.tick_s > 0 and math.isfinite(self.tick_s)):
            raise ValueError(f"tick_s must be > 0, not {self.tick_s!r}")
        if not 1 <= self.ts_w <= 32:
            raise ValueError(f"ts_w must be 1 .. 32, not {self.ts_w!r}")
        if not 2 <= self.cycles <= 1 << 20:
            raise ValueError(f"cycles must be 2 .. 2^20, not {self.cycles!r}")
        if self.learn_revs < 1 or self.stall_ticks < 0:
            raise ValueError("learn_revs must be >= 1, stall_ticks >= 0")
        for name in ("motion_tol", "shape_tol", "line_tol", "edge_tol"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0")


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


COUNTERS = ("learned", "changes", "rejected", "disagree", "unclean", "reindex", "suspect", "lost",
            "missed", "edge_alarms", "jolts")


class CalibratingEstimator:
    """Feed :class:`hedsmodel.velocity.EdgeEntry` s with :meth:`push` (in FIFO order) and call
    :meth:`read` once per host read; see the module docstring."""

    def __init__(self, cfg: CalibConfig):
        self.cfg = cfg
        S = self.S = 4 * cfg.cycles
        self.table = [0.0] * S
        self.acc = [0.0] * S
        self.work = [0.0] * S
        self.mask = (1 << cfg.ts_w) - 1
        self.t_raw = 0
        self.t = 0
        self.started = False
        self.pos = 0
        self.dir = 0
        self.ab = -1                     # QUAD index after the latest entry (-1: none yet)
        self.framed = False              # an IDX has set the frame
        self.phase_ok = False
        self.ref = 0
        self.a_par = 0                   # boundaries j with j % 2 == a_par are A edges
        self.idx_off = [-1, -1]          # offset of an IDX step per direction [down, up]
        self.idx_cand = [-1, -1]         # an unconfirmed direction's first offset
        self.pending = False
        self.alt_ref = 0
        self.valid = False               # there is a table
        self.rev_ok = False
        self.edge_ok = True
        self.cand_n = 0
        self.rev_dir = 0
        self.rev_t0 = 0
        self.rev_next = 0
        self.t_prev = 0
        self.t_prev2 = 0
        self.coarse = max(1, cfg.cycles // 8)   # the coarse spacing, A-rising edges
        self.ea_n = [0, 0]               # edge check, per spacing: edges in the history (0 .. 3)
        self.ea_b = [[0, 0, 0], [0, 0, 0]]
        self.ea_t = [[0, 0, 0], [0, 0, 0]]
        self.ea_k = 0                    # A-rising edges since the last coarse sample
        self.frac = [0.0, 0.0]
        self.last_shape = self.last_line = self.last_edge = self.last_motion = 0.0
        self.n = {k: 0 for k in COUNTERS}
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
        return (self.valid and self.phase_ok and not self.pending and self.rev_ok
                and self.edge_ok)

    def _cal_diff(self, b2: int, b1: int) -> float:
        """angle(b2) - angle(b1) with the table, counts."""
        S = self.S
        j2 = (b2 - self.ref) % S
        j1 = (b1 - self.ref) % S
        q = ((b2 - self.ref - j2) - (b1 - self.ref - j1)) // S
        return float(q * S) + (self.table[j2] - self.table[j1])

    def _angle_diff(self, b2: int, b1: int) -> float:
        """angle(b2) - angle(b1) as the readings use it, counts."""
        return self._cal_diff(b2, b1) if self.calibrated else float(b2 - b1)

    def _a_edge(self, r: int) -> int:
        """``r``, or ``r + 1`` when the boundary at ``r`` is a B edge (boundary 0 is always an
        A edge: the random phase of the shaft's play moves the B edges)."""
        return r + (self.ab + r - self.pos + 1) % 2

    def _set_ref(self, r: int) -> None:
        """Boundary 0 at position ``r``; the A edges' parity from the state there."""
        self.ref = r
        self.a_par = (self.ab + r - self.pos + 1) % 2
        self._edge_reset(0.0)

    def _edge_reset(self, frac: float) -> None:
        """Empty the edge check's histories; both vote fractions to ``frac``."""
        self.ea_n[0] = self.ea_n[1] = 0
        self.ea_k = 0
        self.frac[0] = self.frac[1] = frac
        self.edge_ok = frac < EDGE_LIMIT

    def _drop_table(self) -> None:
        for j in range(self.S):
            self.table[j] = 0.0
        self.valid = False
        self.cand_n = 0

    def _abort_rev(self) -> None:
        self.rev_dir = 0
        self.t_prev = 0
        self.t_prev2 = 0

    # ------------------------------------------------------------------ learning
    def _revolution(self, T: int, d: int) -> None:
        """Revolution of period T complete (work[j]: ticks from its start to boundary j)."""
        S, Sd = self.S, float(self.S)
        T1, T2, T3 = float(self.t_prev2), float(self.t_prev), float(T)
        acc = 2.0 * Sd * (T2 - T3) / (T3 * T2 * (T3 + T2))
        w = self.work
        for j in range(1, S):
            tau = w[j]
            u = Sd * tau / T3 + 0.5 * acc * tau * (tau - T3)
            w[j] = u if d > 0 else Sd - u
        w[0] = 0.0
        g1 = (1.0 / T2 - 1.0 / T1) / (T1 + T2)
        g2 = (1.0 / T3 - 1.0 / T2) / (T2 + T3)
        self.last_motion = abs(g2 - g1) * (T2 + T3) * T2
        if not self.last_motion <= self.cfg.motion_tol:
            self.n["unclean"] += 1
            return
        if self.valid:
            if self._agrees(self.table, 1.0):
                self.rev_ok = True
                self.cand_n = 0
                return
            self.rev_ok = False
            self.n["disagree"] += 1
        if self.cand_n > 0 and not self._agrees(self.acc, float(self.cand_n)):
            self.n["rejected"] += 1
            self.cand_n = 0
        if self.cand_n == 0:
            for j in range(S):
                self.acc[j] = w[j]
        else:
            for j in range(S):
                self.acc[j] += w[j]
        self.cand_n += 1
        if self.cand_n >= self.cfg.learn_revs:
            k = float(self.cand_n)
            for j in range(S):
                self.table[j] = self.acc[j] / k
            self.n["changes" if self.valid else "learned"] += 1
            self.valid = True
            self.rev_ok = True
            self.cand_n = 0
            self._edge_reset(0.0)

    def _agrees(self, ref, scale: float) -> bool:
        """Does the revolution in work agree with ref / scale (the three figures)?"""
        S, N, w = self.S, self.S // 4, self.work
        xm = 0.5 * float(N - 1)
        sm = smm = sxm = sxx = e2 = 0.0
        for c in range(N):
            j = 4 * c
            d0 = w[j] - ref[j] / scale
            d1 = w[j + 1] - ref[j + 1] / scale
            d2 = w[j + 2] - ref[j + 2] / scale
            d3 = w[j + 3] - ref[j + 3] / scale
            m = (d0 + d1 + d2 + d3) / 4.0
            e2 += (d0 - m) * (d0 - m) + (d1 - m) * (d1 - m) + (d2 - m) * (d2 - m) \
                + (d3 - m) * (d3 - m)
            x = float(c) - xm
            sm += m
            smm += m * m
            sxm += x * m
            sxx += x * x
        r2 = smm - sm * sm / float(N) - sxm * sxm / sxx
        self.last_shape = math.sqrt(max(r2, 0.0) / float(N))
        self.last_edge = math.sqrt(e2 / float(S))
        sh = shh = 0.0
        n = 0
        for j in range(4 + self.a_par, S, 2):
            h = (w[j] - ref[j] / scale) - (w[j - 4] - ref[j - 4] / scale)
            sh += h
            shh += h * h
            n += 1
        self.last_line = math.sqrt(max(shh - sh * sh / float(n), 0.0) / float(n))
        return (self.last_shape <= self.cfg.shape_tol and self.last_line <= self.cfg.line_tol
                and self.last_edge <= self.cfg.edge_tol)

    def _learn(self, b: int, d: int, t: int) -> None:
        S = self.S
        slot = (b - self.ref) % S
        if self.rev_dir != 0:
            if d != self.rev_dir or slot != self.rev_next:
                self._abort_rev()
            elif slot == 0:
                T = t - self.rev_t0
                if self.t_prev > 0 and self.t_prev2 > 0 and T > 0:
                    self._revolution(T, d)
                self.t_prev2 = self.t_prev
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

    # ------------------------------------------------------------------ edge check
    def _edge_check(self, b: int, t: int) -> None:
        """One A-rising edge (boundary b, time t) while there is a table and a phase: a sample
        of the fine spacing, and of the coarse one every ``coarse`` edges."""
        self.ea_k += 1
        for k in (0, 1):
            if k == 1:
                if self.ea_k < self.coarse:
                    break
                self.ea_k = 0
            n, hb, ht = self.ea_n[k], self.ea_b[k], self.ea_t[k]
            if n < 3:
                hb[n], ht[n] = b, t
                self.ea_n[k] = n + 1
                continue
            e_raw, e_cal, ok = self._residuals(hb, ht, b, t)
            if ok and k == 0 and abs(e_cal) > JOLT_COUNTS:
                self.n["jolts"] += 1                     # re-earn trust at both spacings
                if self.edge_ok:
                    self.n["edge_alarms"] += 1
                self._edge_reset(1.0)
                self.ea_b[0][0], self.ea_t[0][0], self.ea_n[0] = b, t, 1
                return
            if ok:
                eff = abs(e_raw - e_cal)                 # what the table does here
                if eff < EDGE_MIN_TICKS * abs(float(b - hb[0])) / float(t - ht[0]):
                    self.frac[k] -= self.frac[k] / float(EDGE_W[k])     # nothing: no objection
                elif min(abs(e_raw), abs(e_cal)) <= EDGE_SEEN * eff:
                    vote = 1.0 if e_cal * e_cal > e_raw * e_raw else 0.0
                    self.frac[k] += (vote - self.frac[k]) / float(EDGE_W[k])
            hb[0], hb[1], hb[2] = hb[1], hb[2], b
            ht[0], ht[1], ht[2] = ht[1], ht[2], t
        ok = self.frac[0] < EDGE_LIMIT and self.frac[1] < EDGE_LIMIT
        if self.edge_ok and not ok:
            self.n["edge_alarms"] += 1
        self.edge_ok = ok

    def _residuals(self, hb, ht, b: int, t: int):
        """(e_raw, e_cal, ok): the position of edge (b, t) less the constant-acceleration
        extrapolation through the three edges of the history, raw and with the table, counts;
        ok: the four times strictly increase."""
        tau1, tau2, tau3 = float(ht[1] - ht[0]), float(ht[2] - ht[0]), float(t - ht[0])
        if not (0.0 < tau1 < tau2 < tau3):
            return 0.0, 0.0, False
        l1 = tau3 * (tau3 - tau2) / (tau1 * (tau1 - tau2))
        l2 = tau3 * (tau3 - tau1) / (tau2 * (tau2 - tau1))
        e_raw = float(b - hb[0]) - (float(hb[1] - hb[0]) * l1 + float(hb[2] - hb[0]) * l2)
        e_cal = self._cal_diff(b, hb[0]) - (self._cal_diff(hb[1], hb[0]) * l1
                                            + self._cal_diff(hb[2], hb[0]) * l2)
        return e_raw, e_cal, True

    # ------------------------------------------------------------------ input
    def _lose(self, b: int) -> None:
        """A LOST or missed entry at boundary b: the count no longer knows the wheel."""
        self._abort_rev()
        self.cand_n = 0
        self.ea_n[0] = self.ea_n[1] = 0
        self.pending = False
        if self.cfg.use_index:
            self.phase_ok = False
        else:
            self._drop_table()
            self._set_ref(self._a_edge(b))
            self.phase_ok = True

    def push(self, e) -> None:
        """One FIFO entry (``time``, ``a``, ``b``, ``up``, ``lost``, ``idx``)."""
        t = self._time(e.time)
        d = 1 if e.up else -1
        self.pos += d
        b = self.pos if d > 0 else self.pos + 1          # boundary crossed
        s = QUAD.index((e.a, e.b))
        a_before = QUAD[(s - d) % 4][0]
        missed = self.ab >= 0 and not e.lost and s != (self.ab + d) % 4
        self.ab = s
        reversal = self.dir != 0 and d != self.dir
        self.dir = d
        broken = bool(e.lost) or missed
        if broken:
            self.n["lost" if e.lost else "missed"] += 1
            self._lose(b)
        elif reversal:
            self._abort_rev()
            self.ea_n[0] = self.ea_n[1] = 0
        if not self.cfg.use_index and not self.phase_ok:
            self._set_ref(self._a_edge(b))               # the first entry: boundary 0
            self.phase_ok = True
        if self.cfg.use_index and e.idx:
            self._index(d)
        if self.phase_ok:
            self._learn(b, d, t)
        a_rise = a_before == 0 and e.a == 1
        if a_rise and self.valid and self.phase_ok:
            self._edge_check(b, t)
        for m, sel in zip(self.m, (a_rise, True)):
            if broken or reversal:
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
        if not self.framed:                              # the first IDX: boundary 0
            self.framed = True
            self._set_ref(self._a_edge(self.pos))
            self.idx_off[k] = (self.pos - self.ref) % S
            self.phase_ok = True
            self._abort_rev()
            return
        if self.idx_off[k] < 0:                          # this direction's offset: twice alike
            if self.phase_ok and not self.pending:
                j = (self.pos - self.ref) % S
                if self.idx_cand[k] == j:
                    self.idx_off[k] = j
                else:
                    self.idx_cand[k] = j
            return
        f = self.pos - self.idx_off[k]
        if not self.phase_ok:                            # after LOST: restore the phase
            self._set_ref(f)
            self.phase_ok = True
            self.pending = False
            return
        if (f - self.ref) % S == 0:
            self.pending = False
            return
        if self.pending and (f - self.alt_ref) % S == 0:
            self.n["reindex"] += 1                       # re-index: the count slipped
            self._set_ref(f)
            self.pending = False
            self.rev_ok = True
            self.cand_n = 0
            self.idx_off[1 - k] = -1
            self.idx_cand[0] = self.idx_cand[1] = -1
            self._abort_rev()
            return
        self.n["suspect"] += 1
        self.pending = True
        self.alt_ref = f

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
                "pending": self.pending, "rev_ok": self.rev_ok, "edge_ok": self.edge_ok,
                "cand_n": self.cand_n, **self.n, "shape": self.last_shape,
                "line": self.last_line, "edge": self.last_edge, "motion": self.last_motion,
                "frac": list(self.frac)}


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
