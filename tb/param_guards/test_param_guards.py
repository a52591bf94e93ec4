# SPDX-License-Identifier: Apache-2.0
"""An out-of-range parameter must stop elaboration with a message naming the parameter, on the
simulator under test (SIM=icarus: iverilog; SIM=verilator: verilator). Yosys is covered by
test_param_guards_yosys.py. The cases come from enc_ip.core (each parameter's legal range, its
corners and the values just outside), so a guard that always fires fails here too. The message must
also state the range: both ends (or every legal value) after the parameter's name."""

import subprocess

import pytest

from enctools.core import files_for, guard_cases, include_dirs, names_param, ranges
from enctools.paths import TOP
from enctools.harness import sim_name

CASES = list(guard_cases())


# limits between parameters, which a range cannot express: (module, parameters, ok, the name the
# message must contain). enc_qei's address must reach every channel's page; a lean channel's count
# is at least 32 bits (its free-running count is the one a driver extends); the edge FIFO needs the
# timing unit (its timebase), with either architecture.
RELATIONAL = [(top, params, ok, name) for top in ("enc_qei_wb", "enc_qei_axil")
              for params, ok, name in (
    ({"CHANNELS": 2, "ADDR_W": 8}, False, "ADDR_W"),
    ({"CHANNELS": 16, "ADDR_W": 11}, False, "ADDR_W"),
    ({"CHANNELS": 16, "ADDR_W": 12}, True, ""),
    ({"CHANNELS": 3}, True, ""),
    ({"PROFILE": 3, "COUNT_W": 31}, False, "COUNT_W"),
    ({"PROFILE": 3, "COUNT_W": 32}, True, ""),
    ({"PROFILE": 3, "COUNT_W": 64, "CHANNELS": 16}, True, ""),
    ({"PROFILE": 1, "EFIFO_LOG2": 4}, False, "EFIFO_LOG2"),
    ({"PROFILE": 3, "EFIFO_LOG2": 8}, True, ""),
    ({"ENGINE": 1, "EFIFO_LOG2": 4}, True, ""),
    ({"ENGINE": 1, "PROFILE": 3, "EFIFO_LOG2": 8, "CHANNELS": 2}, True, ""),
    ({"ENGINE": 1, "PROFILE": 1, "EFIFO_LOG2": 4}, False, "EFIFO_LOG2"),
    ({"ENGINE": 1, "PROFILE": 3, "CHANNELS": 16}, True, ""),
    ({"ENGINE": 1, "CHANNELS": 3}, True, ""),
    ({"ENGINE": 1, "PROFILE": 1, "CHANNELS": 2}, True, ""),
)]


def elaborate(path: str, module: str, param: str | dict, value: int | None = None
              ) -> subprocess.CompletedProcess:
    """Elaborate ``module`` with ``param`` = ``value`` (or a dict of parameters)."""
    params = param if isinstance(param, dict) else {param: value}
    sources = [str(TOP / f) for f in files_for(path)] + [f"-I{d}" for d in include_dirs()]
    if sim_name() == "icarus":
        cmd = ["iverilog", "-g2012", "-o", "/dev/null", "-s", module]
        cmd += [f"-P{module}.{k}={v}" for k, v in params.items()]
    else:
        cmd = ["verilator", "--lint-only", "--top-module", module]
        cmd += [f"-G{k}={v}" for k, v in params.items()]
    return subprocess.run(cmd + sources, capture_output=True, text=True, timeout=120)


# a submodule's own name for a parameter of the board top: its message may name that
SUBMODULE_NAME = {"PHASE_WINDOW_LOG2": ("WINDOW_LOG2",)}


@pytest.mark.parametrize("path,module,param,value,ok", CASES,
                         ids=[f"{m}-{p}={v}" for _, m, p, v, _ in CASES])
def test_parameter_guard(path, module, param, value, ok):
    result = elaborate(path, module, param, value)
    output = result.stdout + result.stderr
    if ok:
        assert result.returncode == 0, f"{module} {param}={value} should elaborate:\n{output}"
    else:
        assert result.returncode != 0, f"{module} {param}={value} elaborated; it must stop"
        alias = SUBMODULE_NAME.get(param, ())
        assert names_param(output, param, alias), f"the message does not name {param}:\n{output}"
        assert ranges()[param].stated_in(output, alias), \
            f"the message does not state {param}'s range {ranges()[param].text()}:\n{output}"


@pytest.mark.parametrize("module,params,ok,name", RELATIONAL,
                         ids=[f"{m}-" + "-".join(f"{k}={v}" for k, v in p.items())
                              for m, p, _, _ in RELATIONAL])
def test_relational_guard(module, params, ok, name):
    result = elaborate(f"rtl/{module}.v", module, params)
    output = result.stdout + result.stderr
    if ok:
        assert result.returncode == 0, f"{module} {params} should elaborate:\n{output}"
    else:
        assert result.returncode != 0, f"{module} {params} elaborated; it must stop"
        assert names_param(output, name), f"the message does not name {name}:\n{output}"
