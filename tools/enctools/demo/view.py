# SPDX-License-Identifier: Apache-2.0
"""The demo's pictures of its dump: the README picture (rendered by enctools.vcd_png) and
``make waves`` (GTKWave on the dump with its save file, or where the files are)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from ..paths import TOP
from .config import DEFAULT_PNG, GTKW, README_PNG, VCD
from .gtkw import gtkw_view_lines
from .plan import Plan, tau_ps


def demo_figure(vcd: Path, png: Path, plan: Plan) -> None:
    """The README picture: three cycles at constant peak speed, and two periods of the dither."""
    from .. import vcd_png

    tau = tau_ps(plan)
    base = plan.t0_ps  # simulation time (ps) at which the model waveform starts
    h0, h1 = plan.seg["hold"]
    a = base + (h0 + h1) / 2 * 1000
    d0, _ = plan.seg["dither"]
    b = base + d0 * 1000
    windows = [(a, a + 3 * tau, f"{plan.opts.rpm:g} rpm forward, 3 cycles: 1X pulses once per cycle,\n"
                                "2X twice (each edge of A), 4X four times"),
               (b, b + 2.2 * 5 * tau, "shaft dithering about one edge of A: 4X and 2X count every "
                                      "crossing,\nup and down (net 0); the 1X hysteresis counter "
                                      "counts once")]
    vcd_png.render(vcd, png, windows,
                   title=f"make demo: modeled HEDS-5000 ({plan.opts.rpm:g} rpm, {plan.opts.temp_c:g} degC), "
                         f"clock {plan.clk_hz / 1e6:.4g} MHz - from sim/waves/demo.vcd")


def open_waves() -> int:
    """``make waves``: GTKWave on sim/waves/demo.vcd when there is a display and gtkwave is
    installed, else where the files are and the command."""
    # sim/demo.gtkw, whose view is the default run's; after a run with other options, the save file
    # written with its dump (same signals, the view of that run)
    gtkw, run_gtkw = GTKW, VCD.with_suffix(".gtkw")
    if run_gtkw.exists() and gtkw_view_lines(run_gtkw.read_text()) != gtkw_view_lines(GTKW.read_text()):
        gtkw = run_gtkw
    rel_vcd, rel_gtkw = VCD.relative_to(TOP), gtkw.relative_to(TOP)
    cmd = ["gtkwave", str(rel_vcd), str(rel_gtkw)]
    if not VCD.exists():
        print(f"waves: {rel_vcd} does not exist yet; run 'make demo' first, then: {' '.join(cmd)}")
        return 1
    size = VCD.stat().st_size / 1e6
    if shutil.which("gtkwave") and (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        print(f"waves: {' '.join(cmd)}")
        return subprocess.call(cmd, cwd=TOP)
    why = "gtkwave is not installed" if not shutil.which("gtkwave") else "no display ($DISPLAY)"
    print(f"waves: {why}. The files:\n"
          f"  dump:       {rel_vcd} ({size:.1f} MB)\n"
          f"  save file:  {rel_gtkw} (signals grouped and named after the note)\n"
          f"  picture:    {DEFAULT_PNG.relative_to(TOP)} (README copy: {README_PNG.relative_to(TOP)})\n"
          f"Open them with: {' '.join(cmd)}   (gtkwave: e.g. 'apt-get install gtkwave')")
    return 0
