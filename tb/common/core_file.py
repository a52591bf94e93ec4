# SPDX-License-Identifier: Apache-2.0
"""Read enc_ip.core, the FuseSoC CAPI2 core file: the one list of RTL sources and of parameter
ranges. Used by the cocotb harness, the parameter-guard tests, scripts/synth.py and (through the
command line) scripts/lint.sh:

    python tb/common/core_file.py files [FILESET ...]   one path per line (default: rtl)
    python tb/common/core_file.py corners               "<module> -GNAME=value" lint corners
"""

from __future__ import annotations

import re
import sys
from functools import lru_cache
from pathlib import Path

import yaml

TOP = Path(__file__).resolve().parents[2]
CORE = TOP / "enc_ip.core"


@lru_cache(maxsize=None)
def core() -> dict:
    return yaml.safe_load(CORE.read_text())


def fileset(name: str) -> list[str]:
    """Paths (relative to the repository top) of one fileset, in core order."""
    out = []
    for entry in core()["filesets"][name]["files"]:
        out.append(next(iter(entry)) if isinstance(entry, dict) else entry)
    return out


def rtl_files() -> list[str]:
    return [f for f in fileset("rtl") if f.endswith(".v")]


def board_files(board: str = "icebreaker") -> list[str]:
    return fileset(f"board_{board}")


def param_values(name: str) -> tuple[list[int], list[int]]:
    """(legal corner values, illegal values just outside) of a core parameter, from the
    "(range LO..HI)" or "(values A, B)" at the end of its description."""
    desc = core()["parameters"][name]["description"]
    m = re.search(r"\(range (-?\d+)\.\.(-?\d+)\)\s*$", desc)
    if m:
        lo, hi = int(m.group(1)), int(m.group(2))
        return [lo, hi], [lo - 1, hi + 1]
    m = re.search(r"\(values ([\d, ]+)\)\s*$", desc)
    if m:
        good = [int(v) for v in m.group(1).split(",")]
        bad = sorted({v + d for v in good for d in (-1, 1)} - set(good))
        return good, bad
    raise ValueError(f"enc_ip.core: parameter {name} has no '(range ..)' or '(values ..)'")


def module_params(path: Path, guarded_only: bool = False) -> list[str]:
    """The parameters a Verilog file declares (``parameter integer NAME``). With
    ``guarded_only``, leave out those whose declaration says "(checked by <parent>)": internal
    submodules whose range the instantiating module guards."""
    decls = re.findall(r"parameter\s+integer\s+(\w+)([^\n]*)", Path(path).read_text())
    return [name for name, rest in decls if not (guarded_only and "checked by" in rest)]


def ranged_params() -> list[str]:
    return list(core()["parameters"])


def corners(files: list[str] | None = None):
    """(module, {param: value}) for every module and every legal corner of each of its ranged
    parameters, the others at their defaults."""
    for f in files or (rtl_files() + board_files()):
        module = Path(f).stem
        for p in module_params(TOP / f):
            if p in core()["parameters"]:
                for v in param_values(p)[0]:
                    yield module, {p: v}


def guard_cases(files: list[str] | None = None):
    """(file, module, param, value, ok) for every ranged parameter each module declares: its legal
    corners (ok) and the values just outside (not ok), for the parameter-guard tests."""
    for f in files or (rtl_files() + board_files()):
        module = Path(f).stem
        for p in module_params(TOP / f, guarded_only=True):
            if p in core()["parameters"]:
                good, bad = param_values(p)
                for v in good:
                    yield f, module, p, v, True
                for v in bad:
                    yield f, module, p, v, False


def files_for(path: str) -> list[str]:
    """The sources needed to elaborate the module in ``path``: the IP, plus the board's own files
    for a board module."""
    return rtl_files() + (board_files() if path in board_files() else [])


if __name__ == "__main__":
    cmd, *args = sys.argv[1:] or ["files"]
    if cmd == "files":
        for name in args or ["rtl"]:
            print("\n".join(fileset(name)))
    elif cmd == "corners":
        for module, params in corners():
            print(module, " ".join(f"-G{k}={v}" for k, v in params.items()))
    else:
        sys.exit(f"core_file.py: unknown command {cmd!r}; use 'files [FILESET ...]' or 'corners'")
