# SPDX-License-Identifier: Apache-2.0
"""The integer calibrating estimator (sw/enc_qei_calib_fx.c) against the double one
(sw/enc_qei_calib.c) on the same entry streams: the bench's constant-speed and disturbed runs
(the streams of :mod:`.calib` and :mod:`.calib_disturb`) and any stream of
``hedsmodel.calibration.stream_ops``.

Both run in one process, ``tb/velocity/calibfx_driver.c``: after every entry it compares every
counter and flag and stops comparing at the first difference (a decision the two took
differently); every read gives both versions' readings. :func:`compare` turns that into the
largest difference in units of 2^-F count/s (the double reading * 2^F clipped to the integer
range, against the integer reading), over the reads before any decision difference.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
import subprocess
from pathlib import Path

from ..paths import TOP

SW = TOP / "sw"
DRIVER_C = TOP / "tb" / "velocity" / "calibfx_driver.c"
FX_MAX = 2**31 - 1
FIGURES = ("shape", "line", "edge", "motion", "frac fine", "frac coarse")
CFLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2"]


def build_driver(out: Path) -> Path:
    """gcc the driver (both estimators) into ``out``; returns its path."""
    gcc = shutil.which("gcc")
    if gcc is None:
        raise RuntimeError("gcc not found: the C estimators cannot be compiled")
    cmd = [gcc, *CFLAGS, f"-I{SW}", str(SW / "enc_qei_calib.c"), str(SW / "enc_qei_calib_fx.c"),
           str(DRIVER_C), "-lm", "-o", str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"gcc failed:\n{' '.join(cmd)}\n{res.stderr}")
    return out


def tick_hz_of(tick_s: float) -> int:
    hz = round(1.0 / tick_s)
    if not (hz > 0 and abs(hz * tick_s - 1.0) < 1e-12):
        raise ValueError(f"tick {tick_s} s is not a whole number of Hz")
    return hz


def millionths(x: float) -> int:
    m = round(x * 1e6)
    if abs(m - x * 1e6) > 1e-6 * max(1.0, abs(m)):
        raise ValueError(f"{x} is not a whole number of millionths")
    return m


def config_line(cfg, frac_bits: int) -> str:
    """The driver's first line for a ``hedsmodel.calibration.CalibConfig``."""
    return (f"{cfg.tick_s!r} {cfg.ts_w} {cfg.cycles} {int(cfg.use_index)} {cfg.learn_revs} "
            f"{cfg.stall_ticks} {cfg.motion_tol!r} {cfg.shape_tol!r} {cfg.line_tol!r} "
            f"{cfg.edge_tol!r} {tick_hz_of(cfg.tick_s)} {frac_bits} "
            f"{millionths(cfg.motion_tol)} {millionths(cfg.shape_tol)} "
            f"{millionths(cfg.line_tol)} {millionths(cfg.edge_tol)}")


@dataclasses.dataclass
class Comparison:
    """One stream through both versions. ``reads``: reads compared (those before any decision
    difference); ``entries``; ``worst``: the largest |integer - double * 2^F| in units and
    ``worst_at`` (read index, method); ``zero_bad``: reads where the double is exactly 0 and
    the integer is not; ``mismatch``: None, or (entry index, field, double, integer) of the
    first decision difference with ``mismatch_figures`` (double's, integer's, by FIGURES);
    ``figures``: both versions' figures at the end; ``calibrated_reads``: compared reads with
    the table in use; ``ties``: [(entry, field, margin)] votes the double version decided
    within 1e-7 of a threshold and the integer one the other way (the driver resyncs the vote
    fraction and goes on)."""

    reads: int
    entries: int
    worst: float
    worst_at: tuple
    zero_bad: int
    mismatch: tuple | None
    mismatch_figures: tuple | None
    figures: tuple
    calibrated_reads: int
    ties: list


def _figs(line: str):
    v = [float(x) for x in line.split()[1:]]
    return dict(zip(FIGURES, v[:6])), dict(zip(FIGURES, v[6:]))


def compare(exe: Path, cfg, ops, frac_bits: int = 8) -> Comparison:
    """Run ``ops`` (``stream_ops`` output) through both versions; see :class:`Comparison`."""
    lines = [config_line(cfg, frac_bits)]
    read_entries = []                    # entries pushed before each read
    n_ent = 0
    for kind, x in ops:
        if kind == "E":
            lines.append(f"E {x.time} {x.a} {x.b} {int(x.up)} {int(x.lost)} {int(x.idx)}")
            n_ent += 1
        else:
            lines.append(f"R {x}")
            read_entries.append(n_ent)
    res = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True,
                         text=True)
    if res.returncode != 0:
        raise RuntimeError(f"calibfx_driver failed ({res.returncode}): {res.stderr}")
    out = res.stdout.splitlines()
    mismatch = mfig = None
    rows, ties = [], []
    k = 0
    while k < len(out):
        ln = out[k]
        if ln.startswith("M "):
            p = ln.split()
            mismatch = (int(p[1]), p[2], int(p[3]), int(p[4]))
            mfig = _figs(out[k + 1])
            k += 2
            continue
        if ln.startswith("T "):
            p = ln.split()
            ties.append((int(p[1]), p[2], float(p[3])))
            k += 1
            continue
        if ln.startswith("S "):
            entries = int(ln.split()[1])
            figures = _figs(out[k + 1])
            break
        rows.append(ln.split())
        k += 1
    if len(rows) != len(read_entries):
        raise RuntimeError(f"{len(rows)} readings for {len(read_entries)} reads")
    scale = 2.0 ** frac_bits
    limit = len(rows) if mismatch is None else sum(1 for e in read_entries if e <= mismatch[0])
    worst, worst_at, zero_bad, cal = 0.0, (None, None), 0, 0
    for i in range(limit):
        r = rows[i]
        for j, name in ((0, "mt_a"), (1, "any")):
            d, f = float(r[j]), int(r[3 + j])
            ref = min(max(d * scale, -FX_MAX), FX_MAX)
            err = abs(f - ref)
            if err > worst:
                worst, worst_at = err, (i, name)
            if d == 0.0 and f != 0:
                zero_bad += 1
        cal += int(r[2])
        if r[2] != r[5] and mismatch is None:
            raise RuntimeError(f"read {i}: calibrated {r[2]} / {r[5]} without a flag difference")
    return Comparison(limit, entries, worst, worst_at, zero_bad, mismatch, mfig, figures, cal,
                      ties)


# ----------------------------------------------------------------------------- the bench's runs

def _ops(wf, tb, t0: float, t_end: float, fault=None, rng=None):
    import numpy as np

    from hedsmodel.calibration import stream_ops
    from hedsmodel.velocity import edge_entries_with_ticks

    from .config import READ_HZ

    ents, ticks = edge_entries_with_ticks(wf, tb)
    if fault is not None:
        ents, ticks = fault(ents, ticks, tb, rng)
    tr = np.arange(t0, t_end, 1.0 / READ_HZ)
    return list(stream_ops(ents, ticks, tb.ticks(tb.clock_of(tr)), (1 << tb.ts_w) - 1))


def disturbed_streams(tb, units, cases, stall_s: float, t0: float, seed: int):
    """(name, cfg, ops): the disturbed runs of :mod:`.calib_disturb` as its ``run_case`` feeds
    the estimator."""
    import numpy as np

    from . import calib
    from .calib_disturb import CASES

    for case in cases:
        for name, unit in units:
            rng = np.random.default_rng(seed)
            run = CASES[case](unit, rng)
            yield (f"{name}, {case}", calib._cfg(tb, stall_s),
                   _ops(run.wf, tb, t0, run.truth.duration_s, run.fault, rng))


def job_streams(kind: str, job: dict):
    """[(name, cfg, ops)]: the streams one job of :func:`.calib.plan` feeds the estimator, with
    the configurations it uses (learning, never learning, without the index)."""
    from . import calib
    from .config import DETUNE

    tb, stall = job["tb"], job["stall_s"]
    out = []
    if kind in ("constant", "learning"):
        rpm = job["rpm"]
        rev = 60.0 / rpm
        t_meas = max(2 * rev, job["meas_s"])
        for k in (job["ks"] if kind == "learning" else (calib.LEARN_REVS,)):
            learn = max(k, 1)
            dur = (learn + 3.2) * rev + t_meas
            prof = calib._profile([("constant", rpm * DETUNE, dur)])
            cfgs = [calib._cfg(tb, stall, learn_revs=learn)]
            if kind == "constant":
                cfgs += [calib._cfg(tb, stall, learn_revs=10**9),
                         calib._cfg(tb, stall, use_index=False)]
            for play in job["plays"]:
                ops = _ops(calib._played(job["unit"], play).waveform(prof, index=True), tb,
                           job["t0"], dur)
                for cfg in cfgs:
                    out.append((f"{job['unit_name']}, {rpm:g} rpm, play {play}, learn_revs "
                                f"{cfg.learn_revs}{'' if cfg.use_index else ', no index'}",
                                cfg, ops))
    elif kind == "latency":
        v0, v1 = calib.LATENCY_RPM, calib.LATENCY_RPM * calib.LATENCY_STEP
        spec = [("constant", 60.0 * DETUNE, (calib.LEARN_REVS + 4.2) * 1.0),
                ("ramp", 60.0 * DETUNE, v0 * DETUNE, 1.0), ("constant", v0 * DETUNE, 1.0)]
        for i in range(job["steps"]):
            spec.append(("constant", (v1 if i % 2 == 0 else v0) * DETUNE, job["hold_s"]))
        prof = calib._profile(spec)
        for play in job["plays"]:
            ops = _ops(calib._played(job["unit"], play).waveform(prof, index=True), tb,
                       job["t0"], prof.duration_s)
            out.append((f"{job['unit_name']}, 6 rpm steps, play {play}", calib._cfg(tb, stall),
                        ops))
    else:
        out += list(disturbed_streams(tb, [(job["unit_name"], job["unit"])], [job["case"]],
                                      stall, job["t0"], job["seed"]))
    return out


def _compare_job(item):
    """One job's streams through the driver at each F: [(kind, name, F, Comparison)]."""
    exe, kind, job, fracs = item
    res = []
    for name, cfg, ops in job_streams(kind, job):
        for f in fracs:
            res.append((kind, name, f, compare(exe, cfg, ops, f)))
    return res


# ----------------------------------------------------------------------------- cost on RV32IM

COST_C = TOP / "tb" / "velocity" / "calibfx_cost.c"
RV_GCC = "riscv64-unknown-elf-gcc"
RV_FLAGS = ["-march=rv32im", "-mabi=ilp32", "-O2", "-ffreestanding", "-nostdlib",
            "-nostartfiles", "-Wl,-Ttext=0", "-Wl,-e,_start"]
SHIMS = {"string.h": "#include <stddef.h>\nvoid *memset(void *d, int c, size_t n);\n",
         "math.h": "double sqrt(double x);\n#define fabs __builtin_fabs\n"}


def build_cost(out_dir: Path, double: bool = False) -> Path:
    """The bare-metal cost program (tb/velocity/calibfx_cost.c) for RV32IM, with the integer
    estimator or (``double``) the double one in software floating point."""
    gcc = shutil.which(RV_GCC)
    if gcc is None:
        raise RuntimeError(f"{RV_GCC} not found (Debian: gcc-riscv64-unknown-elf)")
    inc = out_dir / "shim"
    inc.mkdir(parents=True, exist_ok=True)
    for name, text in SHIMS.items():
        (inc / name).write_text(text)
    src = SW / ("enc_qei_calib.c" if double else "enc_qei_calib_fx.c")
    out = out_dir / ("calib_cost_double.elf" if double else "calib_cost_fx.elf")
    cmd = [gcc, *RV_FLAGS, f"-I{inc}", f"-I{SW}", *(["-DCOST_DOUBLE"] if double else []),
           str(COST_C), str(src), "-lgcc", "-o", str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"{RV_GCC} failed:\n{' '.join(cmd)}\n{res.stderr}")
    return out


def soft_float_calls(elf: Path) -> list[str]:
    """libgcc's soft-float routines the program links (riscv64-unknown-elf-nm)."""
    nm = shutil.which("riscv64-unknown-elf-nm")
    res = subprocess.run([nm, str(elf)], capture_output=True, text=True, check=True)
    pat = re.compile(r"^__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord|extend|trunc|fix|float)"
                     r"\w*[sdt]f\w*$")
    return sorted({ln.split()[-1] for ln in res.stdout.splitlines()
                   if pat.match(ln.split()[-1])})


def cost(elf: Path, cfg, ops, frac_bits: int = 8) -> dict:
    """Run ``ops`` through the cost program in :class:`.rv32.Sim`: per kind of call (``read``,
    ``entry``: a push that crosses no revolution boundary, ``boundary``: one that does, where
    a completed revolution is learnt and checked) the largest instruction count with its
    multiplications and divisions, the mean and the number of calls; ``readings``: [(mt_a,
    any, calibrated)] per read; ``total``: the whole run's counts."""
    from .rv32 import Sim

    sim = Sim(elf)
    words = [0, tick_hz_of(cfg.tick_s), frac_bits, cfg.ts_w, cfg.cycles, int(cfg.use_index),
             cfg.learn_revs, cfg.stall_ticks & 0xFFFFFFFF, cfg.stall_ticks >> 32,
             millionths(cfg.motion_tol), millionths(cfg.shape_tol), millionths(cfg.line_tol),
             millionths(cfg.edge_tol)]
    n_reads = 0
    for kind, x in ops:
        if kind == "E":
            words += [int(x.a) | int(x.b) << 1 | int(x.up) << 2 | int(x.lost) << 3
                      | int(x.idx) << 4, x.time]
        else:
            words += [1 << 31, x]
            n_reads += 1
    words[0] = len(ops)
    sim.write_words(0x400000, words)
    code = sim.run()
    if code != 0:
        raise RuntimeError(f"cost program exited {code}")
    # MARK k, the call (a push ends with MARK 0x80000000 | boundaries so far), MARK k + 1
    out = {"read": [], "entry": [], "boundary": []}
    marks = sim.marks
    i, revs = 0, 0
    for k, (kind, _) in enumerate(ops):
        if marks[i][0] != k:
            raise RuntimeError(f"cost program: mark {marks[i][0]:#x} where op {k} starts")
        nxt = marks[i + 1]
        cost_k = (nxt[1] - marks[i][1], nxt[2] - marks[i][2], nxt[3] - marks[i][3])
        if kind == "R":
            out["read"].append(cost_k)
            i += 1
        else:
            r = nxt[0] & 0x7FFFFFFF
            out["boundary" if r != revs else "entry"].append(cost_k)
            revs = r
            i += 2
    res = {}
    for key, v in out.items():
        if v:
            worst = max(v)
            res[key] = {"max": worst[0], "max_mul": worst[1], "max_div": worst[2],
                        "mean": sum(c[0] for c in v) / len(v), "count": len(v)}
    raw = sim.read_words(0x600000, 3 * n_reads)
    res["readings"] = [tuple(x - (1 << 32) if x >> 31 else x for x in raw[j:j + 3])
                       for j in range(0, len(raw), 3)]
    res["total"] = dict(sim.counts)
    return res


# ----------------------------------------------------------------------------- the report

TABLE = TOP / "doc" / "results" / "velocity_calib_fx.md"
SOURCES = ("sw/enc_qei_calib.c", "sw/enc_qei_calib_fx.c", "tb/velocity/calibfx_driver.c",
           "tb/velocity/calibfx_cost.c",
           "tools/enctools/velocity/calib_fx.py", "tools/enctools/velocity/rv32.py",
           "tools/enctools/velocity/calib.py", "tools/enctools/velocity/calib_disturb.py")
FRACS = (8, 16)
COST_CASE = "slip 90"      # learns, uses, disagrees, relearns: every path of a revolution


def source_hash() -> str:
    import hashlib

    h = hashlib.sha256()
    for s in SOURCES:
        h.update((TOP / s).read_bytes())
    return h.hexdigest()[:12]


def _bench_args(argv):
    from .cli import parse_args

    return parse_args(argv)


def run_agreement(args, exe: Path):
    """Every constant, learning, latency and disturbed run of the bench (``calib.plan``) through
    both versions at each F of FRACS: [(kind, name, F, Comparison)]."""
    import numpy as np
    from concurrent.futures import ProcessPoolExecutor

    from . import calib
    from .plan import make_units

    units = make_units(args)
    jobs = calib.plan(args, units, np.random.default_rng([args.seed, 7]))
    out = []
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        items = [(exe, kind, job, FRACS) for kind, job in jobs]
        for i, res in enumerate(ex.map(_compare_job, items)):
            out += res
            w = max((c.worst for *_, c in res), default=0.0)
            bad = sum(c.mismatch is not None for *_, c in res)
            ties = sum(len(c.ties) for *_, c in res)
            print(f"[{i + 1}/{len(items)}] {res[0][0]} {res[0][1]}: {len(res)} comparisons, "
                  f"worst {w:.4f} unit, {bad} decision differences, {ties} votes tied",
                  flush=True)
    return units, out


def run_cost(args, units, out_dir: Path):
    """The integer and the double version on RV32IM (rv32.Sim) on the bench's COST_CASE run of
    the first non-ideal unit: {"fx": cost(...), "double": cost(...), "what": ...}."""
    real = [(n, u) for n, u in units if n != "ideal"] or units
    tb = _timebase(args)
    (name, cfg, ops), = disturbed_streams(tb, real[:1], [COST_CASE], args.stall_ms * 1e-3,
                                         3.1e-4, args.seed)
    res = {"what": f"{name}: {sum(k == 'E' for k, _ in ops)} entries, "
                   f"{sum(k == 'R' for k, _ in ops)} reads, N = {cfg.cycles}"}
    for key, double in (("fx", False), ("double", True)):
        t = __import__("time").perf_counter()
        print(f"cost: {key} version on RV32IM ({res['what']}) ...", flush=True)
        res[key] = cost(build_cost(out_dir, double), cfg, ops, 8)
        print(f"cost: {key}: {res[key]['total']['insns']} instructions in "
              f"{__import__('time').perf_counter() - t:.0f} s", flush=True)
    exe = build_driver(out_dir / "calibfx_driver")
    nat = _native_fx_readings(exe, cfg, ops, 8)
    res["iss_matches_native"] = nat == res["fx"]["readings"]
    return res


def _timebase(args):
    from .plan import timebase

    return timebase(args)


def _native_fx_readings(exe: Path, cfg, ops, frac_bits: int):
    lines = [config_line(cfg, frac_bits)]
    lines += [f"E {x.time} {x.a} {x.b} {int(x.up)} {int(x.lost)} {int(x.idx)}" if k == "E"
              else f"R {x}" for k, x in ops]
    res = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True,
                         text=True, check=True)
    return [tuple(int(v) for v in ln.split()[3:6]) for ln in res.stdout.splitlines()
            if ln and ln[0] not in "MSF"]


def write_table(args, agreement, costs, path: Path, wall_s: float) -> list[str]:
    """The results table; returns its summary lines."""
    kinds = ("constant", "learning", "latency", "disturbed")
    lines = [f"<!-- source {source_hash()} -->",
             "# The integer calibrating estimator against the double one",
             "",
             "Generated by `scripts/calib_fx_check.py` (the bench's seed "
             f"{args.seed}, {args.units} non-ideal units{', --quick' if args.quick else ''}; "
             f"{wall_s / 60:.1f} min). [`sw/enc_qei_calib_fx.c`](../../sw/enc_qei_calib_fx.c) "
             "and [`sw/enc_qei_calib.c`](../../sw/enc_qei_calib.c) on the same entry streams: "
             "every run of the calibrated part of `make velocity` (constant speeds with the "
             "index, without it and never learning; the learning curves; the 6 rpm steps; the "
             "disturbed runs), each at F = 8 and F = 16. A difference is |integer reading − "
             "double reading × 2^F| in units of 2^-F count/s (the double clipped to ±(2^31 − 1) "
             "units); a decision difference is an entry after which any counter or flag differs.",
             "",
             "## Readings and decisions",
             "",
             "| runs | F | streams | entries | reads | of them calibrated | largest difference, "
             "units | where | decision differences | votes tied | 0 read as non-zero |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    summary = []
    for f in FRACS:
        for kind in kinds + ("all",):
            rows = [c for k, n, ff, c in agreement if ff == f and (kind == "all" or k == kind)]
            names = [n for k, n, ff, c in agreement if ff == f and (kind == "all" or k == kind)]
            if not rows:
                continue
            i = max(range(len(rows)), key=lambda j: rows[j].worst)
            bad = sum(c.mismatch is not None for c in rows)
            lines.append(f"| {kind} | {f} | {len(rows)} | {sum(c.entries for c in rows):,} | "
                         f"{sum(c.reads for c in rows):,} | "
                         f"{sum(c.calibrated_reads for c in rows):,} | {rows[i].worst:.4f} | "
                         f"{names[i]}, read {rows[i].worst_at[0]}, {rows[i].worst_at[1]} | "
                         f"{bad} | {sum(len(c.ties) for c in rows)} | "
                         f"{sum(c.zero_bad for c in rows)} |")
            if kind == "all":
                summary.append(f"F = {f}: {len(rows)} streams, {sum(c.reads for c in rows):,} "
                               f"reads: largest difference {rows[i].worst:.4f} unit, {bad} "
                               f"decision differences, {sum(len(c.ties) for c in rows)} votes "
                               "tied")
    mism = [(n, f, c) for k, n, f, c in agreement if c.mismatch is not None]
    if mism:
        lines += ["", "Decision differences (entry, field, double, integer; the figures then):",
                  ""]
        for n, f, c in mism:
            lines.append(f"- {n}, F = {f}: {c.mismatch}; double {c.mismatch_figures[0]}, "
                         f"integer {c.mismatch_figures[1]}")
    if costs:
        lines += ["", "## Cost on RV32IM", "",
                  f"Instructions per call, counted by `enctools.velocity.rv32` (an RV32IM "
                  "instruction-set simulator) running `tb/velocity/calibfx_cost.c` built with "
                  "`riscv64-unknown-elf-gcc -march=rv32im -mabi=ilp32 -O2`, on the bench's "
                  f"'{COST_CASE}' run ({costs['what']}). The double version is the same source "
                  "in libgcc's software floating point (and a Newton square root). "
                  "*entry*: a push that completes no revolution; *revolution*: the push that "
                  "completes one (the fit, the checks, a table learnt); *read*: "
                  "`qei_calfx_read()`, both methods. Largest (with its multiplications and "
                  "divisions) and mean. The integer version's readings on the simulator "
                  f"{'equal' if costs['iss_matches_native'] else 'DIFFER FROM'} its native "
                  "build's.", "",
                  "| call | version | largest, instructions | of them mul | of them div | "
                  "mean | calls |", "|---|---|---|---|---|---|---|"]
        for key, label in (("entry", "entry"), ("boundary", "revolution"), ("read", "read")):
            for v in ("fx", "double"):
                c = costs[v].get(key)
                if c:
                    lines.append(f"| {label} | {'integer' if v == 'fx' else 'double'} | "
                                 f"{c['max']:,} | {c['max_mul']:,} | {c['max_div']:,} | "
                                 f"{c['mean']:,.0f} | {c['count']:,} |")
        fx = costs["fx"]
        summary.append(f"cost (RV32IM instructions, largest): entry {fx['entry']['max']:,}, "
                       f"revolution {fx['boundary']['max']:,}, read {fx['read']['max']:,}")
    path.write_text("\n".join(lines) + "\n")
    return summary


def main(argv=None) -> int:
    import argparse
    import time

    p = argparse.ArgumentParser(description="The integer calibrating estimator "
                                "(sw/enc_qei_calib_fx.c) against the double one on every run "
                                "of the bench's calibrated part, and its cost on RV32IM; "
                                "writes doc/results/velocity_calib_fx.md.")
    p.add_argument("--quick", action="store_true", help="the bench's --quick runs, one unit")
    p.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--seed", type=int, default=2026, help="the bench's seed (default 2026)")
    p.add_argument("--no-cost", action="store_true", help="skip the RV32IM cost (no table "
                   "written)")
    a = p.parse_args(argv)
    if a.jobs < 1:
        p.error("--jobs must be >= 1")
    bench = ["--seed", str(a.seed), "--jobs", str(a.jobs)] + (["--quick", "--units", "1"]
                                                                if a.quick else [])
    args = _bench_args(bench)
    t0 = time.perf_counter()
    out_dir = TOP / "build" / "calib_fx"
    out_dir.mkdir(parents=True, exist_ok=True)
    exe = build_driver(out_dir / "calibfx_driver")
    units, agreement = run_agreement(args, exe)
    costs = None if a.no_cost else run_cost(args, units, out_dir)
    path = TABLE if not (a.quick or a.no_cost) else out_dir / "velocity_calib_fx.md"
    summary = write_table(args, agreement, costs, path, time.perf_counter() - t0)
    print(f"wrote {path.relative_to(TOP)}")
    for s in summary:
        print("  " + s)
    bad = sum(c.mismatch is not None or bool(c.ties) for *_, c in agreement)
    return 1 if bad or any(c.worst > 1.0 for *_, c in agreement) else 0
