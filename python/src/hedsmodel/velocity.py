# SPDX-License-Identifier: Apache-2.0
"""Host-side velocity estimators for enc_qei snapshots, and ideal snapshots from model waveforms.

No cocotb here. The same estimators exist in C99 in ``sw/enc_qei_velocity.{h,c}``; a test
(tb/velocity/) runs both on the same vectors and checks that they agree.

Snapshots
---------
A :class:`Snapshot` is what one read of enc_qei's snapshot registers gives (rtl/enc_qei.rdl):
``count`` (SNAP_COUNT, COUNT_W bits as read), ``time`` (SNAP_TIME, timebase ticks, TS_W bits),
``edge_time`` (SNAP_EDGE_TIME: the timebase at the last edge of the selected type, any edge or A
rising only), ``delta`` (SNAP_DELTA: signed count steps since the previous snapshot),
``edge_delta`` (SNAP_EDGE_DELTA: signed count steps between the last selected edges before the
previous snapshot and before this one), and for the period method ``period`` (PERIOD, ticks
spanned by the last ``period_n`` selected edges), ``period_ovf`` / ``period_dir_change``
(PERIOD_CTRL flags), and ``stalled`` (STATUS.STALLED). Times are integers that wrap at TS_W bits;
with ``ts_w=None`` (model only) they may be floats and never wrap.

Estimators (all in count steps per second, signed; :func:`to_rpm` converts)
--------------------------------------------------------------------------
Let ``cpe`` be the count steps per selected edge (1 for any edge with x4 counting, 4 for A-rising
edges with x4 counting), ``since`` = time - edge_time (ticks since the last selected edge, modulo
2^TS_W) and "new edge" = ``edge_delta != 0`` or ``edge_time`` changed since the previous snapshot.

- **M (unit time)**: ``delta / (time - prev.time)``. Nothing else: the eQEP unit-timer reading,
  which quantises to one count per read period (1 kHz reads: 1000 counts/s = 30 rpm) and so
  reads 0 at low speed. (``delta_from_count``: use the wrapped count difference instead of
  SNAP_DELTA, hostmot2 style; wraps at COUNT_W bits.)
- **T (period)**: ``period_n * cpe / period`` in the direction of the last non-zero ``delta``.
  0 when there is no measurement yet (``period == 0``), on period overflow, when the
  measurement spans a direction change (``period_dir_change``), and from a snapshot whose
  ``delta`` reverses the direction until the next new edge in a later snapshot.
- **M/T (timestamp, hostmot2)**: on a new edge, ``edge_delta / (edge_time - prev.edge_time)``.
  **Reversal rule**: a new edge whose ``edge_delta`` has the sign opposite to the last one reads
  0 and becomes the new reference (hostmot2's one-edge-reversal rule); so does a new edge with
  ``edge_delta == 0`` (there and back). When ``delta`` goes against the last direction before a
  selected edge confirms it (A rising at low speed), the reading is 0 at once, the direction
  follows the counts, and the next new edge is a reference only (its interval spans the
  reversal). The first new edge after initialisation is a reference only too.

**Standstill rule** (T and M/T): with no new edge since the previous snapshot, the magnitude is
``min(last magnitude, cpe / since)`` -- at most one selected edge's worth of counts over the time
since the last edge, in the last direction of motion -- so a slowly turning shaft never reads 0
between its edges and a stopped one decays towards 0. **Stall**: the reading is 0 when ``since
>= stall_ticks`` (``stall_ticks`` > 0) or when the snapshot says ``stalled``. The first
snapshot only initialises (all readings 0).

Ideal snapshots from the model
------------------------------
:func:`ideal_snapshots` turns a :class:`hedsmodel.waveform.Waveform` (exact edge times) into the
snapshot stream an ideal peripheral would latch at ``read_hz``: with ``timebase=None`` the times
are the exact edge times in ns (the encoder's own error floor), with a :class:`Timebase` they are
quantised as enc_qei does it (edges seen at the first clock after the pin changes plus a fixed
pipeline latency, timebase = clocks / (PRESCALE + 1) modulo 2^TS_W). :func:`snapshot_trace`
does the same and also says which model edges each snapshot refers to (a :class:`SnapTrace`);
:func:`exact_twin` then rebuilds those snapshots with exact times (same edges, same counts), so
``estimate(twin) - estimate(latched)`` is exactly what the timebase adds. :func:`true_rpm` gives
a profile's speed at given times, :func:`estimate` runs all three estimators and returns rpm.

Example (the error floor of M/T on A-rising edges for a typical unit at 30 rpm)::

    unit = EncoderUnit.typical(np.random.default_rng(1))
    et = edge_table(unit.waveform(Profile().constant(30, 2.0)))
    snaps, t = ideal_snapshots(et, read_hz=1000, edge="a_rising")
    rpm = estimate(snaps, EstimatorConfig(tick_s=1e-9, ts_w=None, counts_per_edge=4))["MT"]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

EDGE_TYPES = ("any", "a_rising")
METHODS = ("M", "T", "MT")


@dataclass
class Snapshot:
    """One read of the snapshot registers (see the module docstring)."""

    count: int
    time: int | float
    edge_time: int | float
    delta: int
    edge_delta: int
    period: int | float = 0
    period_n: int = 1
    period_ovf: int = 0
    period_dir_change: int = 0
    stalled: int = 0


@dataclass(frozen=True)
class EstimatorConfig:
    """``tick_s``: seconds per timebase tick; ``ts_w``: timebase width (None: no wrap, model
    only); ``count_w``: counter width; ``counts_per_edge``: count steps per selected edge (x4:
    any edge 1, A rising 4); ``stall_ticks``: stall timeout in ticks since the last selected
    edge (0: off); ``delta_from_count``: M uses the wrapped count difference, not ``delta``."""

    tick_s: float
    ts_w: int | None = 32
    count_w: int = 32
    counts_per_edge: int = 1
    stall_ticks: int | float = 0
    delta_from_count: bool = False

    def __post_init__(self):
        if not (self.tick_s > 0 and math.isfinite(self.tick_s)):
            raise ValueError(f"tick_s must be > 0, not {self.tick_s!r}")
        if self.ts_w is not None and not 1 <= self.ts_w <= 64:
            raise ValueError(f"ts_w must be 1 .. 64 or None, not {self.ts_w!r}")
        if not 1 <= self.count_w <= 64:
            raise ValueError(f"count_w must be 1 .. 64, not {self.count_w!r}")
        if self.counts_per_edge < 1:
            raise ValueError(f"counts_per_edge must be >= 1, not {self.counts_per_edge!r}")
        if self.stall_ticks < 0:
            raise ValueError(f"stall_ticks must be >= 0, not {self.stall_ticks!r}")


@dataclass
class Reading:
    """Velocities in count steps per second from one snapshot."""

    m: float
    t: float
    mt: float

    def get(self, method: str) -> float:
        return {"M": self.m, "T": self.t, "MT": self.mt}[method]


def _sign(x) -> int:
    return (x > 0) - (x < 0)


class VelocityEstimator:
    """Feed :class:`Snapshot` s in order to :meth:`update`; each returns a :class:`Reading`.
    The C version (sw/enc_qei_velocity.c) performs the same operations in the same order in
    double precision, so the two agree to the last bit or so."""

    def __init__(self, cfg: EstimatorConfig):
        self.cfg = cfg
        self.prev: Snapshot | None = None
        self.mt_dir = 0       # direction of motion for M/T (edge_delta, or delta on a reversal)
        self.mt_mag = 0.0     # magnitude of the last M/T measurement (counts/s)
        self.mt_ref = True    # the next new edge is a reference only (start, after a reversal)
        self.t_dir = 0        # direction of the last non-zero delta
        self.t_hold = False   # T reads 0: delta reversed, no new edge since

    def _dt(self, a, b):
        """a - b in ticks, modulo 2^TS_W."""
        d = a - b
        return d if self.cfg.ts_w is None else d % (1 << self.cfg.ts_w)

    def _count_delta(self, s: Snapshot, p: Snapshot) -> int:
        w = self.cfg.count_w
        d = (s.count - p.count) % (1 << w)
        return d - (1 << w) if d >= 1 << (w - 1) else d

    def _bounded(self, mag: float, new_edge: bool, since, stalled: bool) -> float:
        """Standstill rule and stall timeout applied to a magnitude."""
        if stalled:
            return 0.0
        if not new_edge and since > 0:
            bound = self.cfg.counts_per_edge / (since * self.cfg.tick_s)
            if bound < mag:
                return bound
        return mag

    def update(self, s: Snapshot) -> Reading:
        cfg, p = self.cfg, self.prev
        self.prev = s
        if p is None:
            return Reading(0.0, 0.0, 0.0)
        tick = cfg.tick_s
        # M: unit time
        dt = self._dt(s.time, p.time)
        delta = self._count_delta(s, p) if cfg.delta_from_count else s.delta
        m = delta / (dt * tick) if dt > 0 else 0.0
        since = self._dt(s.time, s.edge_time)
        stalled = bool(s.stalled) or (cfg.stall_ticks > 0 and since >= cfg.stall_ticks)
        new_edge = s.edge_delta != 0 or s.edge_time != p.edge_time
        cdir = _sign(delta)
        # M/T: timestamp
        if cdir != 0 and self.mt_dir != 0 and cdir != self.mt_dir:
            self.mt_dir = cdir                    # the counts reversed: 0 until re-referenced
            self.mt_mag = 0.0
            self.mt_ref = True
        if new_edge:
            d = _sign(s.edge_delta)
            if self.mt_ref or d == 0 or (self.mt_dir != 0 and d != self.mt_dir):
                if d != 0 and not self.mt_ref:
                    self.mt_dir = d               # reversal rule: reads 0, new reference
                elif self.mt_dir == 0:
                    self.mt_dir = d
                self.mt_mag = 0.0
                self.mt_ref = False
            else:
                dte = self._dt(s.edge_time, p.edge_time)
                if dte > 0:
                    self.mt_mag = abs(s.edge_delta) / (dte * tick)
                self.mt_dir = d
        mt = self.mt_dir * self._bounded(self.mt_mag, new_edge, since, stalled)
        # T: period
        if cdir != 0 and self.t_dir != 0 and cdir != self.t_dir:
            self.t_hold = True
        elif new_edge:
            self.t_hold = False
        if cdir != 0:
            self.t_dir = cdir
        if self.t_hold or s.period == 0 or s.period_ovf or s.period_dir_change:
            t_mag = 0.0
        else:
            t_mag = max(s.period_n, 1) * cfg.counts_per_edge / (s.period * tick)
        t = self.t_dir * self._bounded(t_mag, new_edge, since, stalled)
        return Reading(float(m), float(t), float(mt))

    def run(self, snaps) -> list[Reading]:
        return [self.update(s) for s in snaps]


def to_rpm(counts_per_s: float, cpr: int = 500, counts_per_cycle: int = 4) -> float:
    """Count steps per second -> shaft rpm (x4 counting: 4 steps per cycle, ``cpr`` cycles/rev)."""
    return counts_per_s * 60.0 / (cpr * counts_per_cycle)


def counts_per_edge(edge: str, counts_per_cycle: int = 4) -> int:
    """Count steps per selected edge: every edge is one x4 step; A rising is one per cycle."""
    if edge not in EDGE_TYPES:
        raise ValueError(f"edge type must be one of {EDGE_TYPES}, not {edge!r}")
    return 1 if edge == "any" else counts_per_cycle


# ---------------------------------------------------------------------------- ideal peripheral

@dataclass(frozen=True)
class Timebase:
    """How enc_qei sees time: a ``clk_hz`` clock, TIMEBASE += 1 every ``prescale + 1`` clocks,
    ``ts_w`` bits. An edge at the pins is seen at the first rising clock edge at or after it
    (clock edges at ``(k + phase) / clk_hz``) plus ``latency_clocks`` (synchroniser and filter:
    FILTER_LEN + 3 in enc_qei); a snapshot read at time t latches in the clock seen the same way
    (without the latency). ``tb_offset`` is the prescaler's count at clock 0."""

    clk_hz: float = 100e6
    prescale: int = 0
    ts_w: int = 32
    latency_clocks: int = 6
    phase: float = 0.0
    tb_offset: int = 0

    @property
    def tick_s(self) -> float:
        return (self.prescale + 1) / self.clk_hz

    def clock_of(self, t_s: np.ndarray) -> np.ndarray:
        """Index of the first clock edge at or after each time."""
        return np.ceil(np.asarray(t_s) * self.clk_hz - self.phase - 1e-9).astype(np.int64)

    def ticks(self, clocks: np.ndarray) -> np.ndarray:
        """TIMEBASE at each clock index (unwrapped)."""
        return (np.asarray(clocks, dtype=np.int64) + self.tb_offset) // (self.prescale + 1)


@dataclass
class EdgeTable:
    """The steps of a waveform: time (s), signed step, 4X position after it (relative to the
    start), whether it is an A-rising edge. ``pos0``: the position before the first step."""

    t_s: np.ndarray
    step: np.ndarray
    pos: np.ndarray
    a_rise: np.ndarray
    pos0: int = 0


def edge_table(wf) -> EdgeTable:
    """The count steps of ``wf`` (events where the 4X position changes). An event whose position
    is unknown (both channels changed at once) is merged into the next known one."""
    ev, positions = wf.events, wf.positions
    start = positions[0] if positions[0] is not None else 0
    t, step, pos, arise = [], [], [], []
    last, last_a = start, ev[0][1]
    for (tn, a, _b), p in zip(ev[1:], positions[1:]):
        rose = last_a == 0 and a == 1
        last_a = a
        if p is None or p == last:
            continue
        t.append(tn * 1e-9)
        step.append(p - last)
        pos.append(p - start)
        arise.append(rose)
        last = p
    return EdgeTable(np.array(t, float), np.array(step, np.int64), np.array(pos, np.int64),
                     np.array(arise, bool), 0)


@dataclass
class SnapTrace:
    """Snapshots plus what they refer to in the model: per read, the read time ``t_read_s``, the
    time of the clock that latched it ``t_latch_s``, the edge-table index of the last selected
    edge seen (``last_edge``, -1: none yet) and of the edges bounding the measurement in PERIOD
    (``period_from``, ``period_to``, -1: none)."""

    snaps: list
    t_read_s: np.ndarray
    t_latch_s: np.ndarray
    last_edge: np.ndarray
    period_from: np.ndarray
    period_to: np.ndarray


def ideal_snapshots(wf_or_table, read_hz: float = 1000.0, edge: str = "any", period_n: int = 1,
                    timebase: Timebase | None = None, t0_s: float = 0.0,
                    t_end_s: float | None = None, count_w: int = 32):
    """Snapshots an ideal enc_qei would latch when read at ``read_hz`` from ``t0_s``.

    Returns ``(snaps, t_read_s)``: the :class:`Snapshot` list and the read times (for the edge
    bookkeeping as well, use :func:`snapshot_trace`). With ``timebase=None`` times are exact, in
    ns, and never wrap (``EstimatorConfig(tick_s=1e-9, ts_w=None)``); with a :class:`Timebase`
    they are its ticks, wrapped at TS_W bits."""
    tr = snapshot_trace(wf_or_table, read_hz, edge, period_n, timebase, t0_s, t_end_s, count_w)
    return tr.snaps, tr.t_read_s


def snapshot_trace(wf_or_table, read_hz: float = 1000.0, edge: str = "any", period_n: int = 1,
                   timebase: Timebase | None = None, t0_s: float = 0.0,
                   t_end_s: float | None = None, count_w: int = 32) -> SnapTrace:
    """:func:`ideal_snapshots` with the edge bookkeeping (a :class:`SnapTrace`)."""
    if edge not in EDGE_TYPES:
        raise ValueError(f"edge type must be one of {EDGE_TYPES}, not {edge!r}")
    if read_hz <= 0:
        raise ValueError("read_hz must be > 0")
    if period_n < 1:
        raise ValueError("period_n must be >= 1")
    et = wf_or_table if isinstance(wf_or_table, EdgeTable) else edge_table(wf_or_table)
    if t_end_s is None:
        t_end_s = (et.t_s[-1] if et.t_s.size else 0.0) + 1.0 / read_hz
    n_reads = max(int(math.floor((t_end_s - t0_s) * read_hz + 1e-9)) + 1, 0)
    t_read = t0_s + np.arange(n_reads) / read_hz
    # when the peripheral sees the steps and the reads, and what its timebase says then
    if timebase is None:
        seen_e, seen_r = et.t_s, t_read
        tstamp_e, tstamp_r = et.t_s * 1e9, t_read * 1e9
        t_latch = t_read
        mask = None
    else:
        ck_e = timebase.clock_of(et.t_s) + timebase.latency_clocks
        ck_r = timebase.clock_of(t_read)
        seen_e, seen_r = ck_e, ck_r
        tstamp_e, tstamp_r = timebase.ticks(ck_e), timebase.ticks(ck_r)
        t_latch = (ck_r + timebase.phase) / timebase.clk_hz
        mask = (1 << timebase.ts_w) - 1
    sel = np.flatnonzero(et.a_rise) if edge == "a_rising" else np.arange(et.step.size)
    # steps seen at or before each read ("this clock's edge included")
    n_steps = np.searchsorted(seen_e, seen_r, side="right")
    n_sel = np.searchsorted(seen_e[sel], seen_r, side="right")   # selected edges seen
    pos_ext = np.concatenate([[et.pos0], et.pos])
    count = pos_ext[n_steps]
    pos_sel = np.concatenate([[et.pos0], et.pos[sel]])
    edge_count = pos_sel[n_sel]          # count after the last selected edge (pos0 before one)
    sel_ext = np.concatenate([[-1], sel])
    last_edge = sel_ext[n_sel]
    # period: blocks of period_n selected edges from the first one
    dirchg = np.zeros(et.step.size, np.int64)
    if et.step.size > 1:
        d = np.sign(et.step)
        dirchg[1:] = (d[1:] != d[:-1]).astype(np.int64)
    cum_chg = np.cumsum(dirchg)
    blocks = np.where(n_sel >= 1, (n_sel - 1) // period_n, -1)
    p_from = np.full(n_reads, -1, np.int64)
    p_to = np.full(n_reads, -1, np.int64)
    ok = blocks >= 1
    p_to[ok] = sel[blocks[ok] * period_n]
    p_from[ok] = sel[(blocks[ok] - 1) * period_n]
    snaps = []
    cw = (1 << count_w) - 1
    prev_count, prev_edge_count = et.pos0, et.pos0
    for i in range(n_reads):
        period, ovf, dchg = 0, 0, 0
        if p_to[i] >= 0:
            e1, e0 = p_to[i], p_from[i]
            period = tstamp_e[e1] - tstamp_e[e0]
            dchg = int(cum_chg[e1] - cum_chg[e0] > 0)
            if mask is not None:
                if period > mask:
                    period, ovf = mask, 1
                period = int(period)
        tr = tstamp_r[i]
        te = tstamp_e[last_edge[i]] if last_edge[i] >= 0 else tr * 0
        if mask is not None:
            tr, te = int(tr) & mask, int(te) & mask
        else:
            tr, te = float(tr), float(te)
        snaps.append(Snapshot(
            count=int(count[i]) & cw, time=tr, edge_time=te,
            delta=int(count[i] - prev_count), edge_delta=int(edge_count[i] - prev_edge_count),
            period=period if mask is not None else float(period), period_n=period_n,
            period_ovf=ovf, period_dir_change=dchg))
        prev_count, prev_edge_count = count[i], edge_count[i]
    return SnapTrace(snaps, t_read, np.asarray(t_latch, float), last_edge, p_from, p_to)


def exact_twin(trace: SnapTrace, et: EdgeTable, latency_s: float = 0.0) -> list:
    """The snapshots of ``trace`` with every time replaced by the exact one (ns, float, no wrap):
    SNAP_TIME by the latching clock's time, SNAP_EDGE_TIME by the pin time of the same edge plus
    ``latency_s``, PERIOD by the exact time between its two edges. Counts stay as latched. Run
    with ``EstimatorConfig(tick_s=1e-9, ts_w=None)``: the same estimator on the encoder's exact
    edge times, so the difference to the latched readings is what the timebase adds."""
    out = []
    for i, s in enumerate(trace.snaps):
        le = trace.last_edge[i]
        te = (et.t_s[le] + latency_s) * 1e9 if le >= 0 else 0.0
        period = 0.0
        if trace.period_to[i] >= 0 and not s.period_ovf:
            period = (et.t_s[trace.period_to[i]] - et.t_s[trace.period_from[i]]) * 1e9
        out.append(Snapshot(count=s.count, time=float(trace.t_latch_s[i] * 1e9), edge_time=te,
                            delta=s.delta, edge_delta=s.edge_delta, period=period,
                            period_n=s.period_n, period_ovf=s.period_ovf,
                            period_dir_change=s.period_dir_change, stalled=s.stalled))
    return out


def true_rpm(profile, t_s) -> np.ndarray:
    """The profile's shaft speed (rpm) at each time (0 where it stands still)."""
    t_s = np.atleast_1d(np.asarray(t_s, float))
    out = np.zeros(t_s.shape)
    for pc in profile.pieces():
        sel = (t_s >= pc.ta) & (t_s < pc.tb)
        if not sel.any():
            continue
        if pc.kind == "poly":
            v, a = pc.p
            out[sel] = (v + a * (t_s[sel] - pc.ta)) * 60.0 / profile.cpr
        else:
            xc, amp, w, t0, _k = pc.p
            out[sel] = amp * w * np.cos(w * (t_s[sel] - t0)) * 60.0 / profile.cpr
    return out


def estimate(snaps, cfg: EstimatorConfig, cpr: int = 500) -> dict:
    """Run the estimators on a snapshot list; readings in rpm per method, as numpy arrays."""
    est = VelocityEstimator(cfg)
    rd = est.run(snaps)
    return {meth: np.array([to_rpm(r.get(meth), cpr) for r in rd]) for meth in METHODS}


# ------------------------------------------------------------------ ideal edge-capture FIFO

@dataclass(frozen=True)
class EdgeEntry:
    """One entry of enc_qei's edge-capture FIFO: ``time`` (TIMEBASE at the step, TS_W bits,
    the same stamp as SNAP_EDGE_TIME for an any-edge), ``a``/``b`` (the A/B state after the
    step), ``up`` (True: +1 step, False: -1), ``lost`` (one or more entries were lost to a full
    FIFO between the previous entry and this one), ``idx`` (a qualified index edge came since the
    previous entry, up to this entry's step)."""

    time: int
    a: int
    b: int
    up: bool
    lost: bool = False
    idx: bool = False


def ideal_edge_entries(wf, timebase: Timebase, t0_s: float = 0.0, t_end_s: float | None = None,
                       index=None) -> list:
    """The :class:`EdgeEntry` list an ideal enc_qei edge FIFO (x4 count function, never full)
    pushes for the model waveform ``wf``.

    ``wf`` is a :class:`hedsmodel.waveform.Waveform`, or the ``(wf, index)`` pair that
    ``EncoderUnit.waveform(profile, index=True)`` returns; ``index`` (``[(t_ns, level)]``, its
    first entry the level at t = 0) may also be given on its own. Exactly:

    - the steps are those of :func:`edge_table` (a model event where both channels change in the
      same picosecond has no position of its own and is merged into the next known one); each
      step of ``n`` counts (``|n| > 1`` only after such a merge) pushes ``|n|`` entries with the
      same time, one per count, each with the A/B state after its count (``QUAD[pos % 4]`` of
      the absolute 4X position). The RTL's x4 decoder would treat a double change as an illegal
      transition instead: walks compared with the RTL should not contain one;
    - only steps at pin times ``t0_s <= t <= t_end_s`` (``t_end_s=None``: all) are pushed;
    - ``time`` = ``timebase.ticks(timebase.clock_of(t) + latency_clocks)`` modulo 2^TS_W: the
      first clock edge at or after the pin time, plus the pipeline latency, through the
      prescaler (TIMEBASE = (clock + tb_offset) // (prescale + 1)), wrapped at ``ts_w`` bits;
    - ``up`` = the step is +1; ``lost`` is always False (the ideal FIFO is never full);
    - ``idx`` is set on the first entry whose step's pin time is at or after a rising edge of the
      model's index (Z) level (a rise with no step after it sets nothing; the level at t = 0 is
      not a rise). With the model's gated index (high exactly in state 0 of each revolution)
      that is the step into a 4X position that is a multiple of 4N, in either direction; its
      state is (0, 0).
    """
    return edge_entries_with_ticks(wf, timebase, t0_s, t_end_s, index)[0]


def edge_entries_with_ticks(wf, timebase: Timebase, t0_s: float = 0.0,
                            t_end_s: float | None = None, index=None):
    """:func:`ideal_edge_entries` and, per entry, its TIMEBASE unwrapped (numpy int64), to merge
    the entries with reads in time order."""
    from .waveform import QUAD

    if isinstance(wf, tuple):
        wf, index = wf
    et = edge_table(wf)
    start = wf.positions[0] if wf.positions[0] is not None else 0
    rises = []
    if index:
        rises = [t * 1e-9 for (t, lv), (_, lv0) in zip(index[1:], index[:-1]) if lv and not lv0]
    ticks = timebase.ticks(timebase.clock_of(et.t_s) + timebase.latency_clocks)
    mask = (1 << timebase.ts_w) - 1
    out, unwrapped, ri = [], [], 0
    hi = math.inf if t_end_s is None else t_end_s
    for t, n, p, tk in zip(et.t_s.tolist(), et.step.tolist(), et.pos.tolist(), ticks.tolist()):
        flag = False
        while ri < len(rises) and rises[ri] <= t:
            ri += 1
            flag = True
        if not t0_s <= t <= hi:
            continue
        up = n > 0
        for k in range(abs(n)):
            a, b = QUAD[(start + p - (abs(n) - 1 - k) * (1 if up else -1)) % 4]
            out.append(EdgeEntry(int(tk) & mask, a, b, up, False, flag and k == 0))
            unwrapped.append(int(tk))
    return out, np.array(unwrapped, np.int64)
