# SPDX-License-Identifier: Apache-2.0
"""What the mutation flow works on: test groups, corners, mutants, and their stable ids.

- ``Group``: pytest ids that share one simulator build, found by discovery (enctools.mutation.
  discover): one simulation runs the cocotb tests of all of them.
- ``Corner``: one module at one set of parameter values (every parameter, as the builds of its
  tests instantiate it), with the groups of tests that build it so.
- ``Mutant``: one mutation of a corner, its verdict and the id scripts/mutate_reviewed.txt uses.
"""

from __future__ import annotations

import hashlib
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

from ..paths import TOP


@dataclass(frozen=True)
class Suite:
    """How the tests of a module run against its mutants.

    ``lazy``: a test runs on the unmutated design only when it first kills a mutant (only a kill
    needs that proof); otherwise the unmutated design runs every test first. ``limit_ns``: the
    simulated-time limit of a test that has no timeout of its own (lazy suites; the others use 10
    x the unmutated run's time + 1 ms). ``cap``: a mutant still alive after this share of the
    first group's tests is checked for equivalence at once (0: never)."""

    lazy: bool = False
    limit_ns: int = 0
    cap: float = 0.0


@dataclass(frozen=True)
class Module:
    """A module to mutate: its file, the tests that cover it (pytest paths or ids, in priority
    order: survivors of one group go on to the next; ``exclude`` leaves paths under them out),
    and optionally which builds give its corners (patterns on pytest ids, `*` the only wildcard;
    default: every build of its tests)."""

    file: str
    tests: tuple[str, ...]
    corners: tuple[str, ...] = ()
    exclude: tuple[str, ...] = ()  # test paths or ids under ``tests`` that do not cover it
    n: int = 25
    suite: Suite = Suite()
    priority: tuple[str, ...] = ()  # cocotb test names to run first (order only)


@dataclass
class Group:
    """pytest ids that share one build (same toplevel, parameters and sources): one simulation
    runs the cocotb tests of all their modules."""

    nodeids: list[str]
    members: list[list]  # [cocotb module, testcase or None] per pytest id
    key: str  # the harness's build key (before the mutation hook)
    toplevel: str
    parameters: dict
    sources: list[str]  # relative to TOP where inside it
    includes: list[str]
    name: str

    @property
    def label(self) -> str:
        files = sorted({n.split("::")[0].rsplit("/", 1)[-1] for n in self.nodeids})
        ids = sorted({n.split("[", 1)[1].rstrip("]") for n in self.nodeids if "[" in n})
        head = files[0] if len(files) == 1 else f"{len(files)} files ({', '.join(files)})"
        return head + (f" [{', '.join(ids)}]" if ids else "")


def tag_of(params: dict, defaults: dict) -> str:
    diff = {k: v for k, v in params.items() if defaults.get(k) != v}
    return "_".join(f"{k}{v}" for k, v in diff.items()) or "default"


@dataclass
class Corner:
    module: str
    file: str
    params: dict  # every parameter of the module at this corner
    defaults: dict  # the module's defaults (the label names the parameters that differ)
    groups: list[Group]
    index: int
    spec: Module
    baseline_s: float = 0.0  # CPU seconds of the unmutated runs
    error: str = ""

    @property
    def tag(self) -> str:
        return tag_of(self.params, self.defaults)

    @property
    def label(self) -> str:
        """The parameters that differ from the module's defaults (all of them when there are
        only one or two), or "defaults"."""
        diff = {k: v for k, v in self.params.items() if self.defaults.get(k) != v}
        if not diff and len(self.params) <= 2:
            diff = self.params
        return " ".join(f"{k}={v}" for k, v in diff.items()) or "defaults"

    @property
    def suite(self) -> Suite:
        return self.spec.suite


RESULTS = ("killed", "timeout", "loop", "equivalent", "survived", "unresolved")
KILLS = ("killed", "timeout", "loop")


@dataclass
class Mutant:
    corner: Corner
    number: int
    command: str  # the `mutate -mode ...` line
    path: Path | None = None  # the mutant alone as Verilog (written for survivors and hangs)
    result: str = "-"  # one of RESULTS; "-" while undecided
    seconds: float = 0.0  # CPU seconds of its simulations
    failed_test: str = ""
    eq_note: str = ""
    opts: dict = field(default_factory=dict)
    stage1: str = ""  # the first equivalence stage's finding, if it ran early (capped)

    @property
    def name(self) -> str:
        return f"{self.corner.module}:{self.corner.tag}:m{self.number:02d}"

    def mutant_id(self) -> str:
        """A stable id for the reviewed-survivors file: module, corner, mode, cell type, port/bit,
        wire/bit and the source text the mutation points at (not line numbers, Yosys's cell
        counters or the run's work directory, which move when unrelated lines are added or the
        run is elsewhere: see wire_key)."""
        o = self.opts
        cell_type = o.get("cell", "").lstrip("$").split("$")[0]
        texts = [src_text(s) for s in o.get("src", [])]
        sig = "|".join([self.corner.module, self.corner.tag, o.get("mode", ""), cell_type,
                        o.get("port", ""), o.get("portbit", ""), o.get("ctrlbit", ""),
                        wire_key(o.get("wire", "")), o.get("wirebit", ""), *texts])
        return hashlib.sha1(sig.encode()).hexdigest()[:10]

    def describe(self) -> str:
        o = self.opts
        cell = unsnap(o.get("cell", ""))
        what = f"{o.get('mode')} {cell}.{o.get('port')}[{o.get('portbit')}]"
        if "ctrlbit" in o:
            what += f" ctrl[{o['ctrlbit']}]"
        if "wire" in o:
            what += f" ({unsnap(o['wire'])}[{o.get('wirebit')}])"
        srcs = sorted(o.get("src", []), key=lambda x: len(src_text(x)))  # innermost first
        if srcs:
            loc = unsnap(srcs[0].split("-")[0].rsplit(".", 1)[0])
            what += f" at {loc} `{src_text(srcs[0])[:60]}`"
        return what


def unsnap(text: str) -> str:
    """A path into any run's RTL copy (build/mutate/<work>/src/rtl/x.v) as rtl/x.v."""
    return re.sub(r"build/mutate/[^/\s]+/src/", "", text)


# the call site in a function result's wire name: tstamp$func$<file>:<line>$<counter>.$result
_CALL_SITE = re.compile(r"([^$\s]+?\.s?vh?):(\d+)\$\d+")


def wire_key(wire: str) -> str:
    """A wire's name as the id hashes it. A function result's wire names its call site by file,
    line and Yosys's counter (tstamp$func$build/mutate/<work>/src/rtl/x.v:927$2232.$result); the
    key names it by the file as in the repository and the text of that line instead, so that the
    id does not change with the work directory, nor when unrelated lines are added."""
    def site(m: re.Match) -> str:
        f, line = m.group(1), int(m.group(2))
        lines = source_lines(f)
        if len(lines) < line:  # (the run's copy is gone)
            return f"{unsnap(f)}:{line}"
        return f"{unsnap(f)}:`{' '.join(lines[line - 1].split())}`"
    return _CALL_SITE.sub(site, wire)


def parse_mutate(command: str) -> dict:
    args = shlex.split(command)[1:]
    out: dict = {"src": []}
    i = 0
    while i < len(args):
        key = args[i].lstrip("-")
        val = args[i + 1] if i + 1 < len(args) else ""
        if key == "src":
            out["src"].append(val)
        else:
            out[key] = val
        i += 2
    return out


_SRC_CACHE: dict[str, list[str]] = {}


def source_lines(f: str) -> list[str]:
    """The lines of a source file named relative to TOP (read once; none when it is gone)."""
    if f not in _SRC_CACHE:
        try:
            _SRC_CACHE[f] = (TOP / f).read_text().splitlines()
        except OSError:
            _SRC_CACHE[f] = []
    return _SRC_CACHE[f]


def src_text(src: str) -> str:
    """The source text of a Yosys src attribute "file:l1.c1-l2.c2", whitespace collapsed."""
    m = re.fullmatch(r"(.+):(\d+)\.(\d+)-(\d+)\.(\d+)", src)
    if not m:
        return src
    f, l1, c1, l2, c2 = m.group(1), *map(int, m.groups()[1:])
    lines = source_lines(f)[l1 - 1:l2]
    if not lines:
        return src
    if len(lines) == 1:
        text = lines[0][c1 - 1:c2 - 1]
    else:
        text = "\n".join([lines[0][c1 - 1:]] + lines[1:-1] + [lines[-1][:c2 - 1]])
    return " ".join(text.split())


REVIEWED = TOP / "scripts" / "mutate_reviewed.txt"


def load_reviewed() -> dict[str, str]:
    """id -> reason, from scripts/mutate_reviewed.txt: `<id> <module> <corner>: <mutation> --
    <reason>` (the reason is what follows the last " -- "; lines starting with # are comments)."""
    out = {}
    if REVIEWED.exists():
        for ln in REVIEWED.read_text().splitlines():
            ln = ln.strip()
            if ln and not ln.startswith("#"):
                out[ln.split()[0]] = ln.rsplit(" -- ", 1)[1].strip() if " -- " in ln else ""
    return out
