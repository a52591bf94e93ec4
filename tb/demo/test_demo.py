# SPDX-License-Identifier: Apache-2.0
"""`make demo` (scripts/demo.py): its options are checked before anything is built, and a short
run of the whole demo (every circuit from one modeled HEDS-5000) passes and leaves a VCD that
enctools.vcd_png reads.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from enctools import toolenv
from enctools import vcd_png
from enctools.demo import config, options
from enctools.paths import TOP


@pytest.mark.parametrize("kwargs, fragment", [
    ({"rpm": "fast"}, "is not a number"),
    ({"rpm": "-600"}, "must be positive"),
    ({"rpm": "0"}, "must be positive"),
    ({"rpm": "nan"}, "must be finite"),
    ({"rpm": "1e6"}, "above what the 4X decoder can count"),
    ({"rpm": "58500"}, "above what the 4X decoder can count"),        # limit at 12 MHz: 58,412
    ({"rpm": "6000", "temp_c": "125"}, "above what the 4X decoder can count"),  # 5,042 at 125 C
    ({"rpm": "3000", "clk_hz": "3e5"}, "above what the 4X decoder can count"),
    ({"rpm": "1"}, "runtime budget"),
    ({"temp_c": "126"}, "outside"),
    ({"temp_c": "-41"}, "outside"),
    ({"temp_c": "warm"}, "is not a number"),
    ({"clk_hz": "0"}, "must be positive"),
    ({"clk_hz": "-12e6"}, "must be positive"),
    ({"clk_hz": "1e12"}, "outside"),
    ({"seed": "-1"}, "non-negative integer"),
    ({"seed": "1.5"}, "non-negative integer"),
    ({"seed": "x"}, "is not a number"),
])
def test_bad_option_rejected(kwargs, fragment):
    with pytest.raises(options.OptionError, match=fragment) as exc:
        options.validate(**kwargs)
    assert "\n" not in str(exc.value)


def test_defaults_and_good_values():
    assert options.validate() == options.Options(3000.0, 25.0, 12e6, 1)
    assert options.validate("", "", "", "") == options.Options(3000.0, 25.0, 12e6, 1)
    o = options.validate(rpm="8000", temp_c="-40", clk_hz="48e6", seed="7")
    assert (o.rpm, o.temp_c, o.clk_hz, o.seed) == (8000.0, -40.0, 48e6, 7)
    assert options.validate(rpm="600").rpm == 600.0      # the note's 600 rpm example
    # the decoder limit follows the clock: the same speed that fails at 300 kHz passes at 12 MHz
    assert options.validate(rpm="3000", clk_hz="12e6").rpm == 3000.0
    assert 58_000 < options.rpm_of(options.f_max_hz(12e6, 25.0)) < 58_500


def test_bad_option_fails_before_building():
    """One line on stderr, exit status 2, nothing built."""
    r = subprocess.run([sys.executable, str(TOP / "scripts" / "demo.py"), "--rpm", "-5",
                        "--name", "demo_badopt"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "RPM=-5" in r.stderr, r.stderr
    assert not (TOP / "sim" / "build" / "icarus" / "demo_badopt").exists()


def test_short_demo_run(tmp_path):
    """The whole demo at 20000 rpm (few clocks, Icarus): every verdict passes, the VCD parses."""
    env = dict(os.environ, PATH=toolenv.tool_path())
    png = tmp_path / "waves.png"
    r = subprocess.run([sys.executable, str(TOP / "scripts" / "demo.py"), "--rpm", "20000",
                        "--sim", "icarus", "--name", "demo_test", "--png", str(png)],
                       capture_output=True, text=True, timeout=600, env=env, cwd=TOP)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "all circuits PASS" in r.stdout
    assert r.stdout.count("  PASS  ") == 8
    # the velocity table: enc_qei_wb read over Wishbone, M/T against the model's true speed
    out = r.stdout
    assert "velocity: enc_qei_wb read over Wishbone" in out and "  PASS  enc_qei_wb" in out
    vel = out[out.index("velocity: enc_qei_wb"):out.index("  PASS  enc_conditioner")]
    rows = [ln.split() for ln in vel.splitlines() if ln[:8].strip().replace(".", "").isdigit()]
    assert len(rows) >= 15, vel
    segs = {row[1] for row in rows}
    assert {"ramp", "hold", "reverse", "back", "stop", "dither"} <= segs, segs
    hold = [row for row in rows if row[1] == "hold" and row[-1] == "%)"]   # checked: "ok (<= 1.2 %)"
    assert hold and all(row[-4] == "ok" for row in hold), vel
    for row in hold:   # at 20000 rpm, M/T A-rise within the tolerance of the true speed
        true, mt = float(row[2]), float(row[3])
        assert true == 20000.0 and abs(mt - true) <= config.VEL_TOL_PCT / 100 * true, row
    assert "FAIL" not in vel and "REGISTERS != MODEL" not in vel
    vcd = TOP / "sim" / "waves" / "demo_test.vcd"
    assert vcd.stat().st_size < 50e6
    found, _ = vcd_png.read_vcd(vcd, ["a_in", "b_in", "x4_count", "bcd_count"])
    assert set(found) == {"a_in", "b_in", "x4_count", "bcd_count"}
    assert len(found["a_in"].changes) > 100
    assert png.stat().st_size > 10_000
    # every signal the GTKWave save file shows exists in the dump
    shown = [line.split()[-1].split("[")[0] for line in (TOP / "sim" / "demo.gtkw").read_text().splitlines()
             if line.startswith("+") or (line[:1].isalpha() and "." in line)]
    assert len(shown) > 20
    found, _ = vcd_png.read_vcd(vcd, shown, t_end_ps=0)
    assert sorted(set(shown) - set(found)) == [], "sim/demo.gtkw names signals the dump lacks"
