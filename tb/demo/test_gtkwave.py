# SPDX-License-Identifier: Apache-2.0
"""Waveform review: the demo's GTKWave save file opens on three encoder cycles of moving signals.

scripts/demo.py writes, with every dump, a save file for it (sim/demo.gtkw's signals with that
run's view: three cycles at the peak speed, markers A-D on the rising edges of A that bound them).

- The checked-in sim/demo.gtkw is exactly what demo.py writes for the default ``make demo``, so
  ``gtkwave sim/waves/demo.vcd sim/demo.gtkw`` opens on the default run's three cycles.
- GTKWave itself, headless under Xvfb, opens a short demo run's dump with the save file written
  for it; a Tcl script prints the visible time range and the traces, then quits. The range covers
  the three cycles and not much more, every main channel moves inside it (checked in the VCD),
  and GTKWave shows every signal of the save file. Skipped when gtkwave or xvfb-run is missing
  (the structural check in test_demo.py, every save-file signal is in the dump, still runs).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from enctools import toolenv
from enctools import vcd_png
from enctools.demo import config, options, plan as demo_plan
from enctools.demo.gtkw import gtkw_text, gtkw_view, gtkw_view_lines
from enctools.paths import TOP

RPM = 20000                      # a short run: ~35k clocks, a few seconds on Icarus
NAME = f"demo_gtkw_{os.getpid()}"
GTKWAVE_TIMEOUT_S = 60
# (signal, least number of value changes in the three cycles): both channels, before and after
# the conditioner, and what each decoder makes of them
MAIN = [("demo_top.a_in", 6), ("demo_top.b_in", 6), ("demo_top.a", 6), ("demo_top.b", 6),
        ("demo_top.x4_count[31:0]", 12), ("demo_top.x2_count[31:0]", 6),
        ("demo_top.x1_count[31:0]", 2), ("demo_top.bcd_count[15:0]", 6)]

TCL = r"""
if {[catch {
    puts "GTKW_RANGE [gtkwave::getWindowStartTime] [gtkwave::getWindowEndTime]"
    puts "GTKW_TRACES [gtkwave::getTotalNumTraces]"
    puts "GTKW_SIGNALS [gtkwave::getDisplayedSignals]"
} err]} {
    puts "GTKW_ERROR $err"
}
gtkwave::/File/Quit
"""


def _run_bounded(cmd, timeout_s, **kw):
    """subprocess.run with the whole process group (xvfb-run, Xvfb, gtkwave) killed on timeout."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         start_new_session=True, **kw)
    try:
        out, _ = p.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        pytest.fail(f"{cmd[0]} did not finish within {timeout_s} s:\n{out[-3000:]}")
    return p.returncode, out


def _saved_signals(text: str) -> list:
    return [ln.split()[-1] for ln in text.splitlines() if ln.startswith("+")]


@pytest.fixture(scope="module")
def short_run():
    """A short demo run (Icarus) with its own name: its dump, the save file demo.py wrote for it,
    and the bench's result (its start time t0)."""
    vcd = TOP / "sim" / "waves" / f"{NAME}.vcd"
    gtkw = vcd.with_suffix(".gtkw")
    build = TOP / "sim" / "build" / "icarus" / f"{NAME}-io"  # the demo's plan and result files
    try:
        env = dict(os.environ, PATH=toolenv.tool_path())
        t = time.monotonic()
        r = subprocess.run([sys.executable, str(TOP / "scripts" / "demo.py"), "--rpm", str(RPM),
                            "--sim", "icarus", "--name", NAME, "--png", ""],
                           capture_output=True, text=True, timeout=300, env=env, cwd=TOP)
        # exit status 1 is a failed verdict (test_demo.py's business); the dump and save file are
        # written all the same
        assert r.returncode in (0, 1) and vcd.exists() and gtkw.exists(), \
            r.stdout[-3000:] + r.stderr[-3000:]
        print(f"short demo run: {time.monotonic() - t:.1f} s")
        res = json.loads((build / "result.json").read_text())
        yield {"vcd": vcd, "gtkw": gtkw, "res": res}
    finally:
        vcd.unlink(missing_ok=True)
        gtkw.unlink(missing_ok=True)
        shutil.rmtree(build, ignore_errors=True)


def test_checked_in_save_file_is_the_default_runs(short_run):
    """sim/demo.gtkw = what `make demo` writes for the default options (regenerate it with
    ``scripts/demo.py --gtkw sim/demo.gtkw``), and its view is three cycles of that run."""
    plan = demo_plan.make_plan(options.validate())
    # the bench starts the waveform a fixed number of clocks after time 0: the short run has the
    # default clock too, so its start is the default run's
    assert short_run["res"]["clk_ps"] == plan.clk_ps
    plan.t0_ps = short_run["res"]["t0_ps"]
    assert config.GTKW.read_text() == gtkw_text(plan, config.VCD, config.GTKW), (
        "sim/demo.gtkw is not the save file `make demo` writes for the default options; "
        "regenerate it: .venv/bin/python scripts/demo.py --gtkw sim/demo.gtkw")
    v = gtkw_view(plan)
    h0, h1 = plan.seg["hold"]
    assert len(v["rises"]) == 4
    assert plan.t0_ps + h0 * 1e3 < v["start"] < v["rises"][0] < v["rises"][3] < v["end"] \
        < plan.t0_ps + h1 * 1e3, "the view is not inside the constant-speed hold"
    assert 2.9 * v["tau_ps"] < v["rises"][3] - v["rises"][0] < 3.1 * v["tau_ps"]
    # the file `make waves` opens after a short run is the one written for it (other view)
    assert gtkw_view_lines(short_run["gtkw"].read_text()) != gtkw_view_lines(config.GTKW.read_text())


@pytest.mark.skipif(not (shutil.which("gtkwave") and shutil.which("xvfb-run")),
                    reason="gtkwave or xvfb-run is not installed (scripts/bootstrap.sh installs "
                           "them with apt-get as root: gtkwave, xvfb)")
def test_gtkwave_opens_on_moving_signals(short_run, tmp_path):
    vcd, gtkw = short_run["vcd"], short_run["gtkw"]
    text = gtkw.read_text()
    script = tmp_path / "probe.tcl"
    script.write_text(TCL)
    # a screen larger than the save file's [size], so the window gets the size the zoom assumes
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1000x24", "gtkwave", "-S", str(script),
           str(vcd), str(gtkw)]
    rc, out = _run_bounded(cmd, GTKWAVE_TIMEOUT_S, cwd=TOP)
    got = {ln.split(" ", 1)[0]: ln.split(" ", 1)[1] if " " in ln else ""
           for ln in out.splitlines() if ln.startswith("GTKW_")}
    assert "GTKW_ERROR" not in got and "GTKW_RANGE" in got, out[-3000:]
    start, end = (int(x) for x in got["GTKW_RANGE"].split())
    traces = int(got["GTKW_TRACES"])
    shown = got["GTKW_SIGNALS"].split()
    print(f"GTKWave 3.3 under Xvfb: visible {start / 1e6:.3f} .. {end / 1e6:.3f} us "
          f"({end - start} ps), {traces} traces, {len(shown)} signals")

    # the three cycles: the save file's named markers A-D, on the rising edges of A
    markers = [int(x) for x in next(ln for ln in text.splitlines() if ln.startswith("*")).split()[2:]]
    rises = [m for m in markers if m >= 0]
    tau_ps = 1e12 / (RPM / 60.0 * config.CPR)
    assert len(rises) == 4 and 2.9 * tau_ps < rises[3] - rises[0] < 3.1 * tau_ps, rises
    assert start <= rises[0] and rises[3] <= end, \
        f"visible {start}..{end} ps does not cover the three cycles {rises[0]}..{rises[3]} ps"
    assert end - start <= 6 * tau_ps, f"visible {end - start} ps: more than 6 cycles of {tau_ps:g} ps"

    # signals move inside the visible window
    found, _ = vcd_png.read_vcd(vcd, [name.split("[")[0] for name, _ in MAIN], t_end_ps=end)
    for name, least in MAIN:
        n = sum(start <= t <= end for t, _ in found[name.split("[")[0]].changes)
        assert n >= least, f"{name}: {n} changes in the visible window, expected >= {least}"

    # GTKWave shows every signal of the save file, and nothing else: the signals plus the group
    # begin/end comment traces
    saved = _saved_signals(text)
    assert shown == saved
    assert traces == sum(ln[:1] in "+-" for ln in text.splitlines() if ln)
