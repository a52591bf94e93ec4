# SPDX-License-Identifier: Apache-2.0
"""What the firmware of the simulated SoC printed, against the motion that drove the encoders.

``parse(console)`` reads the firmware's lines (sw/soc/main.c lists them); ``check(cfg, run)``
compares them with ``motion``'s exact model:

- **Positions.** The count of a snapshot at timebase T is the model's x(T - D) - x(0): the
  position D clocks before, D being the fixed delay from the pins to the count (synchronizer,
  filter, decoder) plus the offset between the timebase and the model's clock. Every position of
  every channel and snapshot must match for one D; the check finds the D that do.
- **Velocity, the estimator.** The model's own snapshot registers (count, times, deltas of the
  last A-rising edges) go through ``hedsmodel.velocity`` -- the same estimator as
  sw/enc_qei_velocity.c -- and the firmware's reading must equal that to the printed 0.001
  count/s. So the firmware read the right registers, and where the estimator's documented rules
  read 0 (the first edge is a reference, a reversal, the stall timeout), it reads 0.
- **Velocity, the physics.** Every reading that is not such a 0 must be within the bound
      |v_read - v(t)| <= |v_read| * tick / (dT - tick) + a_max * (t - t_mid) + 0.0005
  of the true speed v(t) at the snapshot: the reading is the counts between two A-rising edges
  over their timestamps dT apart, each edge time quantised to one tick (so dT is off by less than
  one tick); it is the mean speed over that interval, which is the speed at its midpoint t_mid
  when the acceleration is constant, and the speed moves by at most a_max (the largest
  |acceleration| from the first edge to the snapshot) per second after that; 0.0005 count/s is
  the printing. In a constant-speed stretch the bound is the timebase term alone, the benchmark's
  "one tick over the time between the two timestamps" (doc/velocity.md).
- **No missed snapshot**: consecutive GSNAP_TIMEs are one GSNAP_PERIOD apart, and the firmware
  counted no miss, no torn read and no skewed SNAP_TIME.
- **Index and errors**: each INDEX_LATCH (read at the end, while the motion goes on) is a count
  at an index position of the model, and the QERR and GLITCH counters are 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import motion


@dataclass
class Run:
    build: dict = field(default_factory=dict)
    rows: list = field(default_factory=list)      # (n, T, latency, cycles, [pos], [vel])
    cycles: dict = field(default_factory=dict)    # k -> (min, mean, max)
    ends: dict = field(default_factory=dict)      # k -> (count, index_latch, qerr, glitch)
    misses: tuple = (None, None, None)
    done: bool = False
    table: list = field(default_factory=list)     # the console's table lines, as printed


def parse(console: str) -> Run:
    r = Run()
    for line in console.replace("\r", "").splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "BUILD" and len(f) == 7:
            r.build = dict(zip(("channels", "profile", "count_w", "ts_w", "clk_hz", "period"),
                               map(int, f[1:])))
        elif f[0] == "S":
            v = [x for x in f[1:] if x != "|"]
            n, t, lat, cyc = (int(x) for x in v[:4])
            pos = [int(x) for x in v[4::2]]
            vel = [float(x) for x in v[5::2]]
            r.rows.append((n, t, lat, cyc, pos, vel))
            r.table.append(line)
        elif f[0] == "C" and len(f) == 5:
            r.cycles[int(f[1])] = tuple(int(x) for x in f[2:])
        elif f[0] == "X" and len(f) == 6:
            r.ends[int(f[1])] = tuple(int(x) for x in f[2:])
        elif f[0] == "M" and len(f) == 4:
            r.misses = tuple(int(x) for x in f[1:])
        elif f[0] == "DONE":
            r.done = True
        elif line.lstrip().startswith("snap "):
            r.table.append(line)
    return r


@dataclass
class Channel:
    """The model of one channel, over the clocks of a run."""
    mo: motion.Motion
    n: int

    def __post_init__(self):
        pos, vel = self.mo.trace(self.n)
        self.x = pos >> motion.FRAC
        self.vel = vel
        self.acc = self.mo.acc_at(self.n)
        a, _, z = motion.quadrature(self.x)
        self.a_rise = np.flatnonzero((a[1:] == 1) & (a[:-1] == 0)) + 1
        self.z_rise = np.flatnonzero((z[1:] == 1) & (z[:-1] == 0)) + 1

    def count(self, t):
        return self.x[t] - self.mo.x0


@dataclass
class Result:
    ok: bool
    failures: list         # (what, message)
    delays: list           # the D for which every position matches
    delay: int | None
    positions: int         # positions compared
    velocities: int        # readings compared with the estimator
    bounded: int           # readings checked against the bound
    zeros: int             # documented zeros
    worst: float           # largest |error| / bound
    worst_const: float     # the same, in constant-speed stretches (bound = timebase term)
    summary: list


def _ref_readings(ch: Channel, times: np.ndarray, d: int, clk_hz: float, edge_off: int,
                  stall_ticks: int):
    """hedsmodel.velocity's M/T readings on the model's snapshot registers, and per snapshot the
    (t1, t2) of the edge pair behind the reading (stimulus clocks)."""
    from hedsmodel.velocity import EstimatorConfig, Snapshot, VelocityEstimator

    snaps, pairs = [], []
    prev_edge, pair = None, None
    for T in times:
        t = T - d
        i = np.searchsorted(ch.a_rise, t, side="right") - 1
        e = int(ch.a_rise[i]) if i >= 0 else None
        edge_time = (e + d + edge_off) if e is not None else 0
        edge_count = ch.count(e) if e is not None else 0
        if prev_edge is not None and e is not None and e != prev_edge:
            pair = (prev_edge, e)
        edge_delta = edge_count - (ch.count(prev_edge) if prev_edge is not None else 0)
        prev_edge = e
        snaps.append(Snapshot(count=int(ch.count(t)) & 0xFFFFFFFF, time=int(T) & 0xFFFFFFFF,
                              edge_time=edge_time & 0xFFFFFFFF, delta=0,
                              edge_delta=int(edge_delta)))
        pairs.append(pair)
    for k in range(1, len(snaps)):
        snaps[k].delta = int(ch.count(times[k] - d) - ch.count(times[k - 1] - d))
    cfg = EstimatorConfig(tick_s=1.0 / clk_hz, ts_w=32, counts_per_edge=4,
                          stall_ticks=stall_ticks, count_w=32)
    return np.array([r.mt for r in VelocityEstimator(cfg).run(snaps)]), pairs


def check(motions: list[motion.Motion], run: Run, stall_ms: float = 20.0) -> Result:
    fails: list[tuple[str, str]] = []   # (what, message); what: finish, snapshots, positions,
                                        # velocity or index

    def fail(what: str, msg: str) -> None:
        fails.append((what, msg))

    b = run.build
    if not run.done or not b or not run.rows:
        return Result(False, [("finish", "the firmware did not finish (no BUILD, rows or DONE)")],
                      [], None, 0, 0, 0, 0, 0.0, 0.0, [])
    clk, period, nch = b["clk_hz"], b["period"], b["channels"]
    times = np.array([r[1] for r in run.rows], dtype=np.int64)
    pos = np.array([r[4] for r in run.rows], dtype=np.int64)
    vel = np.array([r[5] for r in run.rows], dtype=float)
    n = int(times.max()) + 10
    chans = [Channel(motions[k], n) for k in range(nch)]

    # no missed snapshot
    gaps = np.diff(times)
    if np.any(gaps != period):
        fail("snapshots", f"snapshots not one GSNAP_PERIOD ({period}) apart: gaps "
                          f"{sorted(set(gaps))}")
    if [r[0] for r in run.rows] != list(range(len(run.rows))):
        fail("snapshots", "snapshot numbers are not consecutive")
    if run.misses != (0, 0, 0):
        fail("snapshots", f"firmware counted missed/torn/skewed snapshots {run.misses}")

    # positions: one delay D for all
    delays = [d for d in range(0, 64)
              if all(np.array_equal(chans[k].count(times - d), pos[:, k]) for k in range(nch))]
    if not delays:
        for k in range(nch):
            best = max(range(64), key=lambda d: int(np.sum(chans[k].count(times - d) == pos[:, k])))
            bad = np.flatnonzero(chans[k].count(times - best) != pos[:, k])
            fail("positions", f"channel {k}: positions differ from the model at {len(bad)} of "
                         f"{len(times)} snapshots for every delay (best D = {best}; first at "
                         f"snapshot {bad[0]}: read {pos[bad[0], k]}, model "
                         f"{chans[k].count(times[bad[0]] - best)})")
    d = delays[len(delays) // 2] if delays else None

    nvel = nbound = nzero = 0
    offsets: set[int] = set()
    worst = worst_const = 0.0
    if d is not None:
        stall = int(round(clk * stall_ms / 1000))
        for k, ch in enumerate(chans):
            # the edge timestamp's offset from the count's step: the one that reproduces the
            # readings (it only enters through the standstill rule)
            cands = {}
            for off in (0, -1, 1, -2, 2):
                ref, pairs = _ref_readings(ch, times, d, clk, off, stall)
                cands[off] = (int(np.sum(np.abs(ref - vel[:, k]) > 0.0015)), ref, pairs)
            off = min(cands, key=lambda o: cands[o][0])
            offsets.add(off)
            nbad, ref, pairs = cands[off]
            nvel += len(ref)
            if nbad:
                i = int(np.flatnonzero(np.abs(ref - vel[:, k]) > 0.0015)[0])
                fail("velocity", f"channel {k}: {nbad} velocity readings differ from the estimator "
                             f"on the model's registers (first: snapshot {i}, read {vel[i, k]}, "
                             f"expected {ref[i]:.3f})")
            for i, T in enumerate(times):
                t = int(T - d)
                v_true = ch.vel[t] * clk / 2 ** motion.FRAC
                v_read = vel[i, k]
                if ref[i] == 0.0:
                    nzero += 1
                    continue
                if pairs[i] is None:
                    continue
                t1, t2 = pairs[i]
                a_max = float(np.max(np.abs(ch.acc[t1:t + 1]))) * clk * clk / 2 ** motion.VFRAC
                bound = (abs(v_read) / (t2 - t1 - 1) + a_max * (t - (t1 + t2) / 2 + 1) / clk
                         + 0.0005)
                err = abs(v_read - v_true)
                nbound += 1
                worst = max(worst, err / bound)
                if a_max == 0.0:
                    worst_const = max(worst_const, err / bound)
                if err > bound:
                    fail("velocity", f"channel {k} snapshot {i}: velocity {v_read} vs true "
                                 f"{v_true:.3f}: error {err:.4f} > bound {bound:.4f}")

    # index latches and error counters
    for k, ch in enumerate(chans):
        if k not in run.ends:
            fail("index", f"channel {k}: no end line")
            continue
        _, latch, qerr, glitch = run.ends[k]
        if qerr or glitch:
            fail("index", f"channel {k}: QERR_COUNT {qerr}, GLITCH_COUNT {glitch}")
        crossed = ch.z_rise.size > 0
        if crossed and (latch + ch.mo.x0) % (1 << motion.CPR_LOG2) != 0:
            fail("index", f"channel {k}: INDEX_LATCH {latch} is no count at an index "
                          f"(index every {1 << motion.CPR_LOG2} steps from x = {-ch.mo.x0})")
        if not crossed and latch != 0:
            fail("index", f"channel {k}: INDEX_LATCH {latch} without an index")

    summary = [
        f"{len(times)} snapshots x {nch} channels: positions exact for delay D = {d} "
        f"(D consistent with every position: {delays[0] if delays else '-'}.."
        f"{delays[-1] if delays else '-'} clocks)",
        f"velocity: {nvel} readings equal the estimator on the model's registers (edge "
        f"timestamps {sorted(offsets)} clocks from the count's step); {nzero} are its documented "
        f"0; {nbound} within the bound (worst error/bound {worst:.6f}; {worst_const:.6f} at "
        f"constant speed)",
        f"snapshots: gaps {sorted(set(int(g) for g in gaps))} ticks, missed/torn/skewed "
        f"{run.misses}",
    ]
    return Result(not fails, fails, delays, d, len(times) * nch, nvel, nbound, nzero, worst,
                  worst_const, summary)
