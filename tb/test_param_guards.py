# SPDX-License-Identifier: Apache-2.0
"""An out-of-range parameter must stop elaboration with a message naming the parameter, on the
simulator under test (SIM=icarus: iverilog; SIM=verilator: verilator). Yosys is covered by
tb/test_param_guards_yosys.py. Every module is also elaborated at its good corners, so a guard
that always fires would fail here too."""

import subprocess

import pytest

from harness import RTL, sim_name

# (module, parameter, good values, bad values)
GUARDS = [
    ("ls168", "MODULUS", (10, 16), (0, 9, 12, 17)),
    ("enc_conditioner", "FILTER_LEN", (1, 16), (0, 17, -1)),
    ("enc_updown_buffer", "DIGITS", (1, 8), (0, 9)),
    ("enc_updown_buffer", "MODULUS", (10, 16), (2, 15)),
    ("enc_updown_buffer", "FILTER_LEN", (1, 16), (0, 17)),
    ("enc_phase_meter", "WINDOW_LOG2", (8, 24), (7, 25)),
]


def elaborate(module: str, param: str, value: int) -> subprocess.CompletedProcess:
    sources = sorted(str(p) for p in RTL.glob("*.v"))
    if sim_name() == "icarus":
        cmd = ["iverilog", "-g2012", "-o", "/dev/null", "-s", module, f"-P{module}.{param}={value}"]
    else:
        cmd = ["verilator", "--lint-only", "--top-module", module, f"-G{param}={value}"]
    return subprocess.run(cmd + sources, capture_output=True, text=True, timeout=120)


CASES = [(m, p, v, ok) for m, p, good, bad in GUARDS
         for v, ok in [(g, True) for g in good] + [(b, False) for b in bad]]


@pytest.mark.parametrize("module,param,value,ok", CASES,
                         ids=[f"{m}-{p}={v}" for m, p, v, _ in CASES])
def test_parameter_guard(module, param, value, ok):
    if not (RTL / f"{module}.v").exists():
        pytest.skip(f"rtl/{module}.v not present")
    result = elaborate(module, param, value)
    output = result.stdout + result.stderr
    if ok:
        assert result.returncode == 0, f"{module} {param}={value} should elaborate:\n{output}"
    else:
        assert result.returncode != 0, f"{module} {param}={value} elaborated; it must stop"
        assert param in output, f"the message does not name {param}:\n{output}"
