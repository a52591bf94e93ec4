# SPDX-License-Identifier: Apache-2.0
"""scripts/error_budget.py and hedsmodel.budget against every worked example of the application note.

Plain pytest, no simulator. Each example is checked twice: through the functions and through the
command line with --json (a subprocess, as a user runs it). The note rounds its intermediate
values (Q_p = 5.3, E_T = 4.7e-2 mm), so results are compared at the precision the note prints.
Invalid input must exit non-zero with exactly one line on stderr.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from hedsmodel import budget

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "error_budget.py"


def cli(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          timeout=60)


def cli_json(*args):
    proc = cli(*args, "--json")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


# (subcommand args, function, function kwargs, {key: (note's value, tolerance)})
EXAMPLES = {
    "position": ((), budget.position_error, {},
                 {"mean_arcmin": (15, 0.5), "sd_arcmin": (6, 0.5), "max_arcmin": (27, 0.5),
                  "max_elec_deg": (225, 5)}),
    "state-width": ((), budget.state_width_error, {},
                    {"mean_deg": (30, 0.5), "sd_deg": (8.7, 0.05), "p95_deg": (44, 0.5)}),
    "guardband": ((), budget.guardband, {},
                  {"f_hz": (25000, 1e-6), "s_min_deg": (18, 1e-9), "ds_max_deg": (72, 1e-9),
                   "ds_temp_deg": (28, 0.2), "room_limit_deg": (44, 0.2)}),
    "sampling": ((), budget.sampling_period, {},
                 {"f_hz": (5000, 1e-9), "ts_s": (50e-6, 1e-15), "tp_max_s": (25e-6, 1e-15)}),
    "sampling-speed": (("--tp-s", "25e-6"), budget.sampling_speed, {"tp_s": 25e-6},
                       {"f_max_hz": (5000, 1e-6), "rpm_max": (600, 1e-9),
                        "omega_max_rad_s": (2 * math.pi * 10, 1e-9)}),
}


@pytest.mark.parametrize("via", ["function", "cli"])
@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_worked_example(example, via):
    args, func, kwargs, expected = EXAMPLES[example]
    command = example.removesuffix("-speed")
    result = func(**kwargs) if via == "function" else cli_json(command, *args)
    if via == "cli":
        assert set(result) == set(expected), f"JSON keys of {command}"
    for key, (value, tol) in expected.items():
        assert result[key] == pytest.approx(value, abs=tol), f"{example} {key}"


def test_guardband_uses_the_temperature_given():
    """The note's text says 60 °C but its numbers are for 70 °C: the flag decides."""
    r = cli_json("guardband", "--temp-c", "60")
    assert r["ds_temp_deg"] == pytest.approx(2.5e-5 * 35 * 25000)
    assert r["room_limit_deg"] == pytest.approx(72 - 2.5e-5 * 35 * 25000)
    assert cli_json("guardband", "--alpha", "1e-5")["ds_temp_deg"] == pytest.approx(11.25)


def test_overrides_change_the_result():
    r = cli_json("position", "--factor", "0.1", "0", "--radius-mm", "20")
    assert r["mean_arcmin"] == pytest.approx(0.1 * 360 / (2 * math.pi * 20) * 60)
    assert r["sd_arcmin"] == 0
    r = cli_json("state-width", "--ecc-mean-mm", "0", "--ecc-sd-mm", "0", "--random", "3", "1", "1",
                 "--internal", "10", "0")
    assert (r["mean_deg"], r["sd_deg"]) == pytest.approx((13, 1))
    assert cli_json("sampling", "--rpm", "1200", "--state-error-deg", "30")["tp_max_s"] == \
        pytest.approx(1 / (4 * 10000) * (1 - 30 / 90))


def test_count_limit():
    """Defaults: 12 MHz, FILTER_LEN 3, ΔS 45 -> ΔP 90 by default; the filtered pulse binds."""
    r = cli_json("count-limit")
    assert set(r) == {"f_max_hz", "rpm_max"}
    expected = min(45 / 360 * 12e6 / 1.05, 90 / 360 * 12e6 / (1.05 * 3))
    assert r["f_max_hz"] == pytest.approx(expected)
    assert r["rpm_max"] == pytest.approx(expected * 60 / 500)
    full = budget.count_limit(pulse_error_deg=0, filter_len=3)
    assert full["binding"] == "state" and full["f_max_hz"] == pytest.approx(45 / 360 * 12e6 / 1.05)
    assert budget.count_limit(filter_len=16)["f_max_hz"] == pytest.approx(90 / 360 * 12e6 / 16.8)
    table = cli("count-limit", "--pulse-error-deg", "0")
    assert table.returncode == 0 and "binding constraint" in table.stdout
    assert "state" in table.stdout.split("binding constraint")[1].splitlines()[0]


def test_tables_print_the_examples():
    out = cli("position").stdout
    assert "26.7 arcmin" in out and "222 e°" in out
    assert "44.2 e°" in cli("state-width").stdout
    assert "43.9 e°" in cli("guardband").stdout
    assert "25.00 µs" in cli("sampling").stdout


BAD = [
    ("guardband", "--rpm", "-3000"),
    ("sampling", "--rpm", "0"),
    ("guardband", "--alpha", "2e-3"),
    ("guardband", "--alpha", "-1e-5"),
    ("guardband", "--rpm", "fast"),
    ("guardband", "--min-state-us", "20"),
    ("sampling", "--state-error-deg", "90"),
    ("sampling", "--rpm", "600", "--tp-s", "1e-5"),
    ("count-limit", "--filter-len", "17"),
    ("count-limit", "--pulse-error-deg", "180"),
    ("count-limit", "--clk-hz", "nan"),
    ("position", "--factor", "0.1"),
    ("position", "--radius-mm", "-1"),
    ("position", "--unknown-flag"),
    ("teleport",),
    (),
]


@pytest.mark.parametrize("args", BAD, ids=lambda a: " ".join(a) or "no-command")
def test_bad_input_exits_with_one_line(args):
    proc = cli(*args)
    assert proc.returncode != 0
    assert proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr


def test_bad_input_raises_in_the_functions():
    with pytest.raises(ValueError):
        budget.guardband(alpha=1.0)
    with pytest.raises(ValueError):
        budget.sampling_speed(tp_s=0)
    with pytest.raises(ValueError):
        budget.count_limit(state_error_deg=95)
