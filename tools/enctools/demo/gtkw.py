# SPDX-License-Identifier: Apache-2.0
"""The GTKWave save file written with every dump: sim/demo.gtkw's signals, groups and layout with
that run's dump file and view (three cycles at the peak speed, markers on the rising edges of A
that bound them)."""

from __future__ import annotations

import math
import os
from pathlib import Path

from .config import GTKW, GTKW_CYCLES, GTKW_VIEW_CYCLES, GTKW_WAVE_PX
from .plan import Plan, a_rises, tau_ps


def gtkw_view(plan: Plan) -> dict:
    """The save file's view of this run, in simulation ps (``plan.t0_ps`` set from the bench):
    ``rises`` the GTKW_CYCLES + 1 rising edges of A (the encoder's output) that bound the cycles,
    ``start``/``end`` the span meant to be visible, ``zoom`` GTKWave's zoom for it."""
    tau = tau_ps(plan)
    h0, h1 = plan.seg["hold"]
    mid = plan.t0_ps + (h0 + h1) / 2 * 1000.0
    rises = [int(round(t)) for t, _ in a_rises(plan.wf, plan.t0_ps) if t >= mid][:GTKW_CYCLES + 1]
    start = int(rises[0] - (GTKW_VIEW_CYCLES - GTKW_CYCLES) / 2 * tau)
    end = int(start + GTKW_VIEW_CYCLES * tau)
    # GTKWave 3.3: time per pixel = 2 ** -zoom / 200 (its 200 pixels per zoom frame)
    zoom = -math.log2((end - start) * 200.0 / GTKW_WAVE_PX)
    return {"rises": rises, "start": start, "end": end, "zoom": zoom, "tau_ps": tau}


def gtkw_text(plan: Plan, vcd: Path, gtkw: Path) -> str:
    """sim/demo.gtkw (signals, groups, layout) with this run's dump file and view: timestart and
    zoom from gtkw_view, named markers A.. on the rising edges of A that bound the cycles."""
    v = gtkw_view(plan)
    o = plan.opts
    named = v["rises"] + [-1] * (26 - len(v["rises"]))
    out = []
    for line in GTKW.read_text().splitlines():
        if line.startswith("[*] Opens on"):
            line = (f"[*] Opens on {GTKW_CYCLES} encoder cycles at {o.rpm:g} rpm ({o.temp_c:g} degC, "
                    f"{o.clk_hz / 1e6:g} MHz clock, seed {o.seed}), markers A-"
                    f"{chr(ord('A') + GTKW_CYCLES)} on A's rising edges; Zoom Full: the whole run.")
        elif line.startswith("[dumpfile]"):
            line = f'[dumpfile] "{os.path.relpath(vcd, gtkw.parent)}"'
        elif line.startswith("[savefile]"):
            line = f'[savefile] "{gtkw.name}"'
        elif line.startswith("[timestart]"):
            line = f"[timestart] {v['start']}"
        elif line.startswith("*"):
            # zoom, primary marker (none), then the named markers A..Z
            line = f"*{v['zoom']:.6f} -1 " + " ".join(str(t) for t in named)
        out.append(line)
    return "\n".join(out) + "\n"


def write_gtkw(plan: Plan, vcd: Path, gtkw: Path) -> None:
    text = gtkw_text(plan, vcd, gtkw)
    gtkw.parent.mkdir(parents=True, exist_ok=True)
    gtkw.write_text(text)


def gtkw_view_lines(text: str) -> list:
    """A save file's lines less its own and its dump's name: equal for two files with one view."""
    return [ln for ln in text.splitlines() if not ln.startswith(("[dumpfile]", "[savefile]"))]
