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
    the table in use."""

    reads: int
    entries: int
    worst: float
    worst_at: tuple
    zero_bad: int
    mismatch: tuple | None
    mismatch_figures: tuple | None
    figures: tuple
    calibrated_reads: int


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
    rows = []
    k = 0
    while k < len(out):
        ln = out[k]
        if ln.startswith("M "):
            p = ln.split()
            mismatch = (int(p[1]), p[2], int(p[3]), int(p[4]))
            mfig = _figs(out[k + 1])
            k += 2
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
    return Comparison(limit, entries, worst, worst_at, zero_bad, mismatch, mfig, figures, cal)


# ----------------------------------------------------------------------------- the bench's runs

def constant_streams(tb, units, rpms, stall_s: float, meas_s: float, t0: float):
    """(name, cfg, ops): each unit at each constant speed as :func:`.calib.run_constant` feeds
    the estimator (learn_revs as the bench, its random play)."""
    import numpy as np

    from hedsmodel.calibration import stream_ops
    from hedsmodel.velocity import edge_entries_with_ticks

    from . import calib
    from .config import DETUNE, READ_HZ

    for rpm in rpms:
        rev = 60.0 / rpm
        t_meas = max(2 * rev, meas_s)
        dur = (calib.LEARN_REVS + 3.2) * rev + t_meas
        prof = calib._profile([("constant", rpm * DETUNE, dur)])
        for name, unit in units:
            ents, ticks = edge_entries_with_ticks(unit.waveform(prof, index=True), tb)
            tr = np.arange(t0, dur, 1.0 / READ_HZ)
            ops = list(stream_ops(ents, ticks, tb.ticks(tb.clock_of(tr)), (1 << tb.ts_w) - 1))
            yield f"{name} {rpm:g} rpm", calib._cfg(tb, stall_s), ops


def disturbed_streams(tb, units, cases, stall_s: float, t0: float, seed: int):
    """(name, cfg, ops): the disturbed runs of :mod:`.calib_disturb` as its ``run_case`` feeds
    the estimator."""
    import numpy as np

    from hedsmodel.calibration import stream_ops
    from hedsmodel.velocity import edge_entries_with_ticks

    from . import calib
    from .calib_disturb import CASES
    from .config import READ_HZ

    for case in cases:
        for name, unit in units:
            rng = np.random.default_rng(seed)
            run = CASES[case](unit, rng)
            ents, ticks = edge_entries_with_ticks(run.wf, tb)
            if run.fault is not None:
                ents, ticks = run.fault(ents, ticks, tb, rng)
            tr = np.arange(t0, run.truth.duration_s, 1.0 / READ_HZ)
            ops = list(stream_ops(ents, ticks, tb.ticks(tb.clock_of(tr)), (1 << tb.ts_w) - 1))
            yield f"{name} {case}", calib._cfg(tb, stall_s), ops


def summary(results) -> dict:
    """Totals over [(name, Comparison)]: runs, reads, entries, the worst difference and where,
    decision differences."""
    worst = max(results, key=lambda r: r[1].worst, default=None)
    return {"runs": len(results), "reads": sum(c.reads for _, c in results),
            "entries": sum(c.entries for _, c in results),
            "worst": worst[1].worst if worst else math.nan,
            "worst_run": worst[0] if worst else None,
            "mismatches": [(n, c.mismatch, c.mismatch_figures) for n, c in results if c.mismatch],
            "zero_bad": sum(c.zero_bad for _, c in results)}


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
