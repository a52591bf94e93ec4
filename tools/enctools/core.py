# SPDX-License-Identifier: Apache-2.0
"""enc_ip.core, the FuseSoC CAPI2 core file: the one list of sources and the one home of the
parameter ranges.

The ranges are data in the core's `generate: enc_params: parameters:` section (a map from
parameter name to ``{range: [LO, HI]}`` or ``{values: [A, B, ...]}``); the generator of the
Verilog guards (rtl/enc_params.vh), the lint corners and the parameter-guard tests all read them
from here.

    python -m enctools.core files [FILESET ...]   one path per line (default: rtl)
    python -m enctools.core corners               "<module> -GNAME=value" lint corners
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import yaml

from .paths import CORE_FILE, TOP


@lru_cache(maxsize=None)
def core() -> dict:
    return yaml.safe_load(CORE_FILE.read_text())


def fileset(name: str) -> list[str]:
    """Paths (relative to the repository top) of one fileset, in core order."""
    out = []
    for entry in core()["filesets"][name]["files"]:
        out.append(next(iter(entry)) if isinstance(entry, dict) else entry)
    return out


def rtl_files() -> list[str]:
    """The IP's Verilog modules (the rtl fileset without its include files)."""
    return [f for f in fileset("rtl") if f.endswith(".v")]


def include_files() -> list[str]:
    """The IP's Verilog include files (rtl/*.vh): their folder goes on every tool's include path."""
    return [f for f in fileset("rtl") if f.endswith(".vh")]


def include_dirs() -> list[Path]:
    return sorted({(TOP / f).parent for f in include_files()})


def yosys_read(files: list[str], defer: bool = True) -> str:
    """A Yosys `read_verilog` of repository files with the include folders (paths relative to
    the repository top, as YoWASP's Yosys needs)."""
    incs = " ".join(f"-I{d.relative_to(TOP)}" for d in include_dirs())
    return f"read_verilog {'-defer ' if defer else ''}{incs} {' '.join(files)}"


def board_files(board: str = "icebreaker") -> list[str]:
    return fileset(f"board_{board}")


@dataclass(frozen=True)
class ParamRange:
    name: str
    lo: int | None = None   # a range LO .. HI
    hi: int | None = None
    values: tuple[int, ...] = ()  # or a list of values

    def ok(self, v: int) -> bool:
        return v in self.values if self.values else self.lo <= v <= self.hi

    @property
    def corners(self) -> list[int]:
        """The legal values the lint and the guard tests use: both ends, or every value."""
        return list(self.values) if self.values else [self.lo, self.hi]

    @property
    def outside(self) -> list[int]:
        """Values just outside: below and above the range, or next to each listed value."""
        if self.values:
            return sorted({v + d for v in self.values for d in (-1, 1)} - set(self.values))
        return [self.lo - 1, self.hi + 1]

    def text(self) -> str:
        return ", ".join(map(str, self.values)) if self.values else f"{self.lo} .. {self.hi}"

    def stated_in(self, output: str, names: tuple[str, ...] = ()) -> bool:
        """A guard's message states this range: some line of ``output`` names the parameter (or
        one of ``names``, a submodule's own name for it; see ``names_param``) and, after the name,
        both ends of the range (every value of a list) as numbers of their own. Verilator's echo
        of the source line (`` 40 |     if (X < 1 || X > 16) ...``) is not a message and does
        not count."""
        for line in output.splitlines():
            if re.match(r"\s*[0-9]*\s*\|", line):
                continue
            for name in (self.name, *names):
                for m in _name_re(name).finditer(line):
                    numbers = set(re.findall(r"(?<![0-9])-?[0-9]+(?![0-9])", line[m.end():]))
                    if {str(v) for v in self.corners} <= numbers:
                        return True
        return False


def _name_re(name: str) -> re.Pattern:
    # the name as a word of its own: not the tail of another name (MAX_FILTER_LEN is not
    # FILTER_LEN), except after "parameter_", and followed by anything but a letter or digit (an
    # underscore too: Icarus's message is the module name enc__parameter_FILTER_LEN_must_be_1_to_16)
    return re.compile(rf"(?:(?<![A-Za-z0-9_])|(?<=parameter_)){re.escape(name)}(?![A-Za-z0-9])")


def names_param(output: str, name: str, names: tuple[str, ...] = ()) -> bool:
    """Some line of a guard's ``output`` names the parameter ``name`` (or one of ``names``, a
    submodule's own name for it) as a word of its own: not the tail of a longer name, and
    followed by anything but a letter or digit (see ``_name_re``)."""
    return any(_name_re(n).search(output) for n in (name, *names))


@lru_cache(maxsize=None)
def ranges() -> dict[str, ParamRange]:
    """Every ranged parameter of the IP and its legal values, from the core's enc_params data."""
    data = core()["generate"]["enc_params"]["parameters"]
    out = {}
    for name, spec in data.items():
        if "range" in spec:
            lo, hi = (_symbol(v) for v in spec["range"])
            out[name] = ParamRange(name, lo, hi)
        elif "values" in spec:
            out[name] = ParamRange(name, values=tuple(int(v) for v in spec["values"]))
        else:
            raise ValueError(f"enc_ip.core: enc_params.{name} needs 'range: [LO, HI]' or 'values: [...]'")
        if name not in core()["parameters"]:
            raise ValueError(f"enc_ip.core: enc_params.{name} is not a declared parameter")
    return out


def _symbol(value) -> int:
    """A range end: a number, or ``func_all`` (every CTRL.FUNC code of rtl/enc_qei.rdl's enum: the
    all-ones FUNC_MASK, so that a new count function widens FUNC_MASK's range by itself)."""
    if value == "func_all":
        from .regmap import enum

        return max(1 << v for v in enum("CTRL", "FUNC").values()) * 2 - 1
    return int(value)


def param_range(name: str) -> ParamRange:
    try:
        return ranges()[name]
    except KeyError:
        raise KeyError(f"enc_ip.core: parameter {name} has no range in generate.enc_params") from None


def module_params(path: Path, guarded_only: bool = False) -> list[str]:
    """The parameters a Verilog file declares (``parameter integer NAME``). With
    ``guarded_only``, leave out those whose declaration says "(checked by <parent>)": internal
    submodules whose range the instantiating module guards."""
    decls = re.findall(r"parameter\s+integer\s+(\w+)([^\n]*)", Path(path).read_text())
    return [name for name, rest in decls if not (guarded_only and "checked by" in rest)]


def corners(files: list[str] | None = None):
    """(module, {param: value}) for every module and every legal corner of each of its ranged
    parameters, the others at their defaults."""
    for f in files or (rtl_files() + board_files()):
        module = Path(f).stem
        for p in module_params(TOP / f):
            if p in ranges():
                for v in ranges()[p].corners:
                    yield module, {p: v}


def guard_cases(files: list[str] | None = None):
    """(file, module, param, value, ok) for every ranged parameter each module declares: its legal
    corners (ok) and the values just outside (not ok), for the parameter-guard tests."""
    for f in files or (rtl_files() + board_files()):
        module = Path(f).stem
        for p in module_params(TOP / f, guarded_only=True):
            if p in ranges():
                r = ranges()[p]
                for v in r.corners:
                    yield f, module, p, v, True
                for v in r.outside:
                    yield f, module, p, v, False


def files_for(path: str) -> list[str]:
    """The sources needed to elaborate the module in ``path``: the IP, plus the board's own files
    for a board module."""
    return rtl_files() + (board_files() if path in board_files() else [])


def main(argv: list[str]) -> int:
    cmd, *args = argv or ["files"]
    if cmd == "files":
        for name in args or ["rtl"]:
            print("\n".join(fileset(name)))
    elif cmd == "incdirs":
        print("\n".join(str(d.relative_to(TOP)) for d in include_dirs()))
    elif cmd == "corners":
        for module, params in corners():
            print(module, " ".join(f"-G{k}={v}" for k, v in params.items()))
    else:
        print(f"enctools.core: unknown command {cmd!r}; use 'files [FILESET ...]', 'incdirs' or "
              "'corners'", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
