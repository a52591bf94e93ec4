#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Render a short window of a VCD to a PNG, without GTKWave: a small VCD reader plus matplotlib.

    python scripts/vcd_to_png.py sim/waves/demo.vcd out.png --start-us 5000 --span-us 120 \
        [--signal a_in --signal b_in ...]

Signals are named by their last path component (or any suffix of the dotted path, e.g.
``demo_top.a_in``). One-bit signals are drawn as logic traces, wider ones as buses with their
values written in (decimal; ``--hex NAME`` for BCD or hex). The demo (enctools.demo.view) renders
its README picture from its own dump with :func:`render`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .qei.bus import signed

TIMESCALE_UNITS = {"s": 1e12, "ms": 1e9, "us": 1e6, "ns": 1e3, "ps": 1.0, "fs": 1e-3}


class Var:
    def __init__(self, path: str, width: int):
        self.path = path
        self.width = width
        self.changes: list[tuple[float, str]] = []   # (time ps, value as a bit string)


def _timescale_ps(spec: str) -> float:
    num = "".join(c for c in spec if c.isdigit()) or "1"
    unit = spec[len(num):] if spec.startswith(num) else spec.lstrip("0123456789")
    return float(num) * TIMESCALE_UNITS.get(unit, 1.0)


def _read_header(f, wanted):
    """The definitions up to $enddefinitions: ({wanted name: Var}, {id code: [Var]}, timescale
    in ps)."""
    buf = []
    for line in f:
        buf.append(line)
        if "$enddefinitions" in line:
            break
    header = " ".join(buf).split()
    scope: list[str] = []
    by_code: dict[str, list[Var]] = {}
    found: dict[str, Var] = {}
    ts_ps = 1.0
    i = 0
    while i < len(header):
        tok = header[i]
        if tok == "$timescale":
            j = header.index("$end", i)
            ts_ps = _timescale_ps("".join(header[i + 1:j]))
            i = j
        elif tok == "$scope":
            scope.append(header[i + 2])
            i += 3
        elif tok == "$upscope":
            scope.pop()
        elif tok == "$var":
            j = header.index("$end", i)
            width, code, name = int(header[i + 2]), header[i + 3], header[i + 4]
            full = ".".join(scope + [name])
            for w in wanted:
                if w not in found and (full == w or full.endswith("." + w)):
                    var = Var(full, width)
                    found[w] = var
                    by_code.setdefault(code, []).append(var)
            i = j
        i += 1
    return found, by_code, ts_ps


def _read_changes(f, by_code, ts_ps: float, t_end_ps: float | None) -> None:
    """The value changes of the signals in ``by_code``, up to ``t_end_ps``."""
    t = 0.0
    for line in f:
        if not line or line[0] == "$":
            continue
        c = line[0]
        if c == "#":
            t = float(line[1:]) * ts_ps
            if t_end_ps is not None and t > t_end_ps:
                break
        elif c in "01xzXZ":
            for v in by_code.get(line[1:].strip(), ()):
                v.changes.append((t, c.lower()))
        elif c in "bBrR":
            val, _, code = line[1:].strip().partition(" ")
            for v in by_code.get(code, ()):
                v.changes.append((t, val.lower()))


def read_vcd(path, wanted, t_end_ps: float | None = None):
    """Read the signals named in ``wanted`` (suffixes of their dotted paths) from a VCD, up to
    ``t_end_ps``. Returns ({wanted name: Var}, timescale in ps). Value strings are bits
    ('0', '1', 'x', 'z', or a vector without the 'b')."""
    with open(path, "r", errors="replace") as f:
        found, by_code, ts_ps = _read_header(f, wanted)
        _read_changes(f, by_code, ts_ps, t_end_ps)
    return found, ts_ps


def _value_at(var: Var, t: float) -> str:
    val = "x"
    for tc, v in var.changes:
        if tc > t:
            break
        val = v
    return val


def _fmt(bits: str, width: int, style: str) -> str:
    if any(c in "xz" for c in bits):
        return "x"
    n = int(bits, 2)
    if style == "hex":
        return f"{n:0{(width + 3) // 4}x}"
    return str(signed(n, width) if style == "signed" else n)


def draw(ax_rows, found, rows, t0_ps: float, t1_ps: float, unit_ps: float = 1e6):
    """Draw ``rows`` [(wanted name, label, style)] of the window [t0, t1] on the axes column."""
    for ax, (name, label, style) in zip(ax_rows, rows):
        var = found.get(name)
        ax.set_yticks([])
        ax.set_ylim(-0.25, 1.25)
        ax.set_xlim(t0_ps / unit_ps, t1_ps / unit_ps)
        for s in ("top", "right", "left"):
            ax.spines[s].set_visible(False)
        if var is None:
            ax.text(0.5, 0.5, f"({name} not in dump)", transform=ax.transAxes, ha="center")
            continue
        pts = [(t0_ps, _value_at(var, t0_ps))] + [(t, v) for t, v in var.changes if t0_ps < t < t1_ps]
        pts.append((t1_ps, pts[-1][1]))
        if var.width == 1 and style != "bus":
            xs, ys = [], []
            for (t, v), (tn, _) in zip(pts, pts[1:]):
                y = 1.0 if v == "1" else 0.0 if v == "0" else 0.5
                xs += [t / unit_ps, tn / unit_ps]
                ys += [y, y]
            ax.plot(xs, ys, color="tab:blue", lw=1.3, solid_joinstyle="miter")
        else:
            span = (t1_ps - t0_ps) / unit_ps
            for (t, v), (tn, _) in zip(pts, pts[1:]):
                a, b = t / unit_ps, tn / unit_ps
                e = min(span * 0.004, (b - a) / 3)
                ax.plot([a, a + e, b - e, b, b - e, a + e, a], [0.5, 1, 1, 0.5, 0, 0, 0.5],
                        color="tab:green", lw=1.0)
                text = _fmt(v, var.width, style)
                if (b - a) / span * 110 > len(text) * 0.9:
                    ax.text((a + b) / 2, 0.5, text, ha="center", va="center", fontsize=7)
        ax.set_ylabel(label, rotation=0, ha="right", va="center", fontsize=8)


DEMO_ROWS = [
    ("a_in", "A  (encoder)", "bit"),
    ("b_in", "B  (encoder)", "bit"),
    ("x1_up", "1X up  (Fig. 14 Q1)", "bit"),
    ("x1_dn", "1X down  (Q2)", "bit"),
    ("x2_pulse", "2X pulse  (Fig. 15)", "bit"),
    ("x4_pulse", "4X pulse", "bit"),
    ("x1_count", "1X count", "signed"),
    ("x2_count", "2X count", "signed"),
    ("x4_count", "4X count", "signed"),
    ("bcd_count", "BCD buffer (Fig. 17)", "hex"),
]


def render(vcd, png, windows, rows=DEMO_ROWS, title=None):
    """``windows``: [(t0_ps, t1_ps, caption)], one column each."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t_end = max(w[1] for w in windows)
    found, _ = read_vcd(vcd, [r[0] for r in rows], t_end_ps=t_end)
    fig, axes = plt.subplots(len(rows), len(windows), figsize=(6.2 * len(windows) + 1.6, 0.42 * len(rows) + 1.2),
                             sharex="col", squeeze=False)
    for col, (t0, t1, caption) in enumerate(windows):
        column = [axes[r][col] for r in range(len(rows))]
        draw(column, found, rows, t0, t1)
        column[0].set_title(caption, fontsize=9)
        column[-1].set_xlabel("time (us)", fontsize=8)
        for ax in column:
            ax.tick_params(axis="x", labelsize=7)
            if col:
                ax.set_ylabel("")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    Path(png).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("vcd")
    ap.add_argument("png")
    ap.add_argument("--start-us", type=float, required=True)
    ap.add_argument("--span-us", type=float, required=True)
    ap.add_argument("--signal", action="append", help="signal to draw (repeat); default: the demo's")
    ap.add_argument("--hex", action="append", default=[], help="show this bus in hex")
    args = ap.parse_args(argv)
    rows = DEMO_ROWS if not args.signal else \
        [(s, s, "hex" if s in args.hex else "signed") for s in args.signal]
    t0 = args.start_us * 1e6
    render(args.vcd, args.png, [(t0, t0 + args.span_us * 1e6, f"{args.start_us:g} us +")], rows)
    print(f"wrote {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
