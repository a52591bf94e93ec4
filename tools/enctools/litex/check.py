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
  sw/enc_qei_velocity.c -- and the firmware's reading must equal that: to the printed 0.001
  count/s for the double estimator, to one unit of its resolution (2^-F count/s, printed exactly)
  for the fixed-point one (sw/enc_qei_velocity_fx.c, BUILD's ``fx<F>``). So the firmware read the
  right registers, and where the estimator's documented rules read 0 (the first edge is a
  reference, a reversal, the stall timeout), it reads 0 (exactly, in fixed point).
- **Velocity, the physics.** Every reading that is not such a 0 must be within the bound
      |v_read - v(t)| <= |v_read| * tick / (dT - tick) + a_max * (t - t_mid) + 0.0005
  of the true speed v(t) at the snapshot: the reading is the counts between two A-rising edges
  over their timestamps dT apart, each edge time quantised to one tick (so dT is off by less than
  one tick); it is the mean speed over that interval, which is the speed at its midpoint t_mid
  when the acceleration is constant, and the speed moves by at most a_max (the largest
  |acceleration| from the first edge to the snapshot) per second after that; 0.0005 count/s is
  the printing (2^-F count/s, the resolution, for the fixed point). In a constant-speed stretch
  the bound is the timebase term alone, the benchmark's "one tick over the time between the two
  timestamps" (doc/velocity.md).
- **No missed snapshot**: consecutive GSNAP_TIMEs are one GSNAP_PERIOD apart, and the firmware
  counted no miss, no torn read, no skewed SNAP_TIME and no failed driver call.
- **The command snapshot** (G line: enc_qei_drv_gsnap_take after the timer stopped): the driver
  returned 0 and every position is the model's at its GSNAP_TIME, with the same D.
- **Index and errors**: each INDEX_LATCH (read at the end, while the motion goes on) is a count
  at an index position of the model, and the QERR and GLITCH counters are 0.

``check_efifo(motions, run)`` compares a build's edge-FIFO statistics (the E lines: every entry
the firmware drained, from the FIFO's start to its last entry) with the model's steps: the entries
are exactly the model's steps up to the last entry's time (their number, the sum of their
directions, the direction changes, the steps onto an index position marked IDX, the sum of their
times), each timestamped at the step's clock + one offset for every channel; times increase,
every (A, B) follows the previous one, nothing LOST. ``check_run(motions, run)`` runs both: the
FIFO's offset must be a D that fits every position (one time axis with the snapshots), and it is
the D of the velocity check.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import motion


EFIFO_FIELDS = ("k", "entries", "net", "dir_changes", "idx", "lost", "nonmono", "ab_bad",
                "t_first", "t_last", "sum_t", "efifo_lost", "cycles")


@dataclass
class Run:
    build: dict = field(default_factory=dict)
    rows: list = field(default_factory=list)      # (n, T, latency, cycles, [pos], [vel])
    cycles: dict = field(default_factory=dict)    # k -> (min, mean, max) up to channel k - 1 done
    own: dict = field(default_factory=dict)       # k -> (min, mean, max) of channel k - 1 alone
    fixed_part: tuple = ()                        # (min, mean, max) before the first channel
    ends: dict = field(default_factory=dict)      # k -> (count, index_latch, qerr, glitch)
    misses: tuple = (None, None, None, None)      # missed, torn, skewed, driver errors
    gsnap: tuple = ()                             # the G line: (err, time, [pos])
    efifo: dict = field(default_factory=dict)     # k -> {name: value} of its E line
    unmapped: dict = field(default_factory=dict)  # the U line: offset, value, cycles, bus_errors
    done: bool = False
    table: list = field(default_factory=list)     # the console's table lines, as printed


def parse(console: str) -> Run:
    r = Run()
    for line in console.replace("\r", "").splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "BUILD" and len(f) == 10:
            r.build = dict(zip(("channels", "profile", "count_w", "ts_w", "clk_hz", "period",
                                "efifo_log2", "engine"), map(int, f[1:9])))
            r.build["vel"] = f[9]                 # "double" or "fx<F>"
        elif f[0] == "S":
            v = [x for x in f[1:] if x != "|"]
            n, t, lat, cyc = (int(x) for x in v[:4])
            pos = [int(x) for x in v[4::2]]
            vel = [float(x) for x in v[5::2]]
            r.rows.append((n, t, lat, cyc, pos, vel))
            r.table.append(line)
        elif f[0] == "C" and len(f) == 5:
            r.cycles[int(f[1])] = tuple(int(x) for x in f[2:])
        elif f[0] == "D" and len(f) == 5:
            r.own[int(f[1])] = tuple(int(x) for x in f[2:])
        elif f[0] == "F" and len(f) == 4:
            r.fixed_part = tuple(int(x) for x in f[1:])
        elif f[0] == "G" and len(f) >= 3:
            r.gsnap = (int(f[1]), int(f[2]), [int(x) for x in f[3:]])
        elif f[0] == "X" and len(f) == 6:
            r.ends[int(f[1])] = tuple(int(x) for x in f[2:])
        elif f[0] == "M" and len(f) == 5:
            r.misses = tuple(int(x) for x in f[1:])
        elif f[0] == "E" and len(f) == 1 + len(EFIFO_FIELDS):
            r.efifo[int(f[1])] = dict(zip(EFIFO_FIELDS[1:], map(int, f[2:])))
        elif f[0] == "U" and len(f) == 5:
            r.unmapped = dict(zip(("offset", "value", "cycles", "bus_errors"),
                                  (int(x, 0) for x in f[1:])))
        elif f[0] == "DONE":
            r.done = True
        elif line.lstrip().startswith("snap "):
            r.table.append(line)
    return r


def resolution(run: Run) -> float | None:
    """The fixed-point firmware's unit, 2^-F count/s (None: the double estimator)."""
    vel = run.build.get("vel", "double")
    return 2.0 ** -int(vel[2:]) if vel.startswith("fx") else None


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


def check(motions: list[motion.Motion], run: Run, stall_ms: float = 20.0,
          delay: int | None = None) -> Result:
    """The checks of the module docstring. ``delay``: the D to use when several fit every
    position (the edge FIFO's, which its entries' times pin to the clock); without it, or when
    it does not fit, the middle one of those that fit."""
    fails: list[tuple[str, str]] = []   # (what, message); what: finish, snapshots, positions,
                                        # gsnap, velocity or index

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
    if run.misses != (0, 0, 0, 0):
        fail("snapshots", f"firmware counted missed/torn/skewed snapshots and driver errors "
                          f"{run.misses}")

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
    d = delay if delay in delays else delays[len(delays) // 2] if delays else None

    # the command snapshot at the end
    if not run.gsnap:
        fail("gsnap", "no G line (the command snapshot)")
    else:
        err, tg, gpos = run.gsnap
        if err != 0 or len(gpos) != nch:
            fail("gsnap", f"enc_qei_drv_gsnap_take returned {err} with {len(gpos)} positions")
        elif d is not None:
            n = max(n, tg + 10)
            chans = [Channel(motions[k], n) for k in range(nch)]
            want = [int(chans[k].count(tg - d)) for k in range(nch)]
            if gpos != want:
                fail("gsnap", f"the command snapshot at {tg}: positions {gpos}, the model's "
                              f"{want} (D = {d})")

    nvel = nbound = nzero = 0
    offsets: set[int] = set()
    worst = worst_const = 0.0
    unit = resolution(run)
    tol = unit + 1e-9 if unit else 0.0015      # one unit of the fixed point; the printing
    slack = unit if unit else 0.0005           # the same, in the error bound
    dev = 0.0                                  # the largest |reading - estimator|
    if d is not None:
        stall = int(round(clk * stall_ms / 1000))
        for k, ch in enumerate(chans):
            # the edge timestamp's offset from the count's step: the one that reproduces the
            # readings (it only enters through the standstill rule)
            cands = {}
            for off in (0, -1, 1, -2, 2):
                ref, pairs = _ref_readings(ch, times, d, clk, off, stall)
                off_by = (np.abs(ref - vel[:, k]) > tol) | ((ref == 0.0) & (vel[:, k] != 0.0))
                cands[off] = (int(np.sum(off_by)), ref, pairs, off_by)
            off = min(cands, key=lambda o: cands[o][0])
            offsets.add(off)
            nbad, ref, pairs, off_by = cands[off]
            nvel += len(ref)
            dev = max(dev, float(np.max(np.abs(ref - vel[:, k]))))
            if nbad:
                i = int(np.flatnonzero(off_by)[0])
                fail("velocity", f"channel {k}: {nbad} velocity readings differ from the estimator "
                             f"on the model's registers by more than {tol:g} count/s (first: "
                             f"snapshot {i}, read {vel[i, k]}, expected {ref[i]:.8f})")
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
                         + slack)
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

    if unit:
        kind = f"fixed point, 2^-{run.build['vel'][2:]} count/s"
        equal = f"within one unit (largest difference {dev / unit:.3f} unit)"
    else:
        kind, equal = "double", "to the printed 0.001 count/s"
    gsnap_ok = run.gsnap and not [m for w, m in fails if w == "gsnap"]
    summary = [
        f"{len(times)} snapshots x {nch} channels: positions exact for delay D = {d} "
        f"(D consistent with every position: {delays[0] if delays else '-'}.."
        f"{delays[-1] if delays else '-'} clocks)",
        f"velocity ({kind}): {nvel} readings equal the estimator on the model's registers "
        f"{equal} (edge timestamps {sorted(offsets)} clocks from the count's step); {nzero} are "
        f"its documented 0; {nbound} within the bound (worst error/bound {worst:.6f}; "
        f"{worst_const:.6f} at constant speed)",
        f"snapshots: gaps {sorted(set(int(g) for g in gaps))} ticks, missed/torn/skewed/driver "
        f"errors {run.misses}; the command snapshot (enc_qei_drv_gsnap_take) "
        f"{'equals the model' if gsnap_ok else 'FAILS'}",
    ]
    return Result(not fails, fails, delays, d, len(times) * nch, nvel, nbound, nzero, worst,
                  worst_const, summary)


@dataclass
class EfifoResult:
    ok: bool
    failures: list         # (what, message): what is "efifo"
    entries: int           # entries drained, all channels
    offset: int | None     # entry time - model step clock (None: not one for every channel)
    cycles_per_entry: float
    summary: list


def check_efifo(motions: list[motion.Motion], run: Run) -> EfifoResult:
    """The E lines against the model's steps (the module docstring)."""
    fails = []
    nch = run.build.get("channels", 0)
    if not run.build.get("efifo_log2"):
        return EfifoResult(False, [("efifo", "the build has no edge FIFO (BUILD efifo_log2 0)")],
                           0, None, 0.0, [])
    total = cycles = 0
    offsets = set()
    for k in range(nch):
        e = run.efifo.get(k)
        if e is None:
            fails.append(("efifo", f"channel {k}: no E line"))
            continue
        total += e["entries"]
        cycles += e["cycles"]
        x = Channel(motions[k], e["t_last"] + 10).x
        steps = np.flatnonzero(x[1:] != x[:-1]) + 1         # clocks at which x changed
        if np.any(np.abs(np.diff(x)) > 1):
            fails.append(("efifo", f"channel {k}: the model moves more than one step per clock"))
            continue
        if steps.size == 0 or e["entries"] == 0:
            if steps.size or e["entries"]:
                fails.append(("efifo", f"channel {k}: {e['entries']} entries, model steps {steps.size}"))
            continue
        off = e["t_first"] - int(steps[0])
        offsets.add(off)
        steps = steps[steps + off <= e["t_last"]]
        up = x[steps] > x[steps - 1]
        expect = {
            "entries": int(steps.size),
            "net": int(x[steps[-1]] - x[0]),
            "dir_changes": int(np.sum(up[1:] != up[:-1])),
            "idx": int(np.sum((x[steps] & ((1 << motion.CPR_LOG2) - 1)) == 0)),
            "lost": 0, "nonmono": 0, "ab_bad": 0, "efifo_lost": 0,
            "t_last": int(steps[-1]) + off,
            "sum_t": int(np.sum(steps + off)) & 0xFFFFFFFF,
        }
        for name, want in expect.items():
            if e[name] != want:
                fails.append(("efifo", f"channel {k}: {name} {e[name]}, the model's steps give {want}"))
    if len(offsets) > 1:
        fails.append(("efifo", f"entry times are the step's clock + {sorted(offsets)}: not one "
                               "offset for every channel"))
    per = cycles / total if total else 0.0
    summary = [
        f"edge FIFO: {total} entries drained from {nch} channels "
        f"{'equal' if not fails else 'compared with'} the model's steps (number, directions, "
        f"direction changes, IDX marks, times = the step's clock + "
        f"{','.join(map(str, sorted(offsets))) or '-'}), times increasing, every (A, B) the "
        f"successor of the previous, no LOST{'' if not fails else ': ' + str(len(fails)) + ' differ'}"
        f"; {per:.0f} CPU cycles per entry (two reads and the firmware's bookkeeping)",
    ]
    return EfifoResult(not fails, fails, total, offsets.pop() if len(offsets) == 1 else None, per,
                       summary)


def check_run(motions: list[motion.Motion], run: Run) -> tuple[Result, EfifoResult | None]:
    """check(), and with an edge FIFO check_efifo() first: its offset is the D of check(), and
    must fit every position."""
    if not run.build.get("efifo_log2"):
        return check(motions, run), None
    fifo = check_efifo(motions, run)
    res = check(motions, run, delay=fifo.offset)
    if fifo.offset is not None and fifo.offset not in res.delays:
        fifo.failures.append(("efifo", f"entry times are the step's clock + {fifo.offset}, which "
                                       f"fits no position (D fitting them: {res.delays})"))
        fifo.ok = False
    return res, fifo
