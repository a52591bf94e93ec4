# SPDX-License-Identifier: Apache-2.0
"""Build an HDL toplevel and run a cocotb test module on it: the one way every test, bench and
tool of the repository simulates.

    run("enc_qei_wb", __name__, name="enc_qei_wb_c32_t32", parameters={"COUNT_W": 32})

- The simulator is ``SIM`` (``icarus`` by default, or ``verilator``), through cocotb's runner.
- Sources: the IP's RTL in enc_ip.core order (enctools.core), the include folders of its
  Verilog includes, files of tb/hdl/ by name, and any other files (a board's).
- Builds live in ``sim/build/<sim>/<name>-<key>``, where the key hashes everything that makes the
  build (sources and their contents, parameters, arguments): tests that ask for the same build
  share it (the first builds it under a lock, the others wait and reuse it), and each run gets
  its own directory in it (``run_<test module>``).
- ``ENC_WAVES=1`` (or ``waves=True``): a waveform per run, ``sim/waves/<name>.vcd`` unless the
  caller names the file, of ``wave_depth`` levels of the hierarchy (0: all). Verilator traces VCD.
  Icarus writes FST through a dump module of ours (cocotb's runner hands vvp a dump format, FST
  when waves are on, and no VCD option), which fst2vcd from GTKWave converts; without fst2vcd the
  .fst is kept and a line says so.
- ``SEED``: the regression seed of every cocotb test (default: cocotb picks one and each test
  logs it).
- ``ENC_SKIP_FIXED_SIM=1``: a run that names its own simulator (``sim=``, whatever SIM says) is
  skipped. CI runs `make test` on both simulators: those runs are the same in both, so the
  Verilator pass leaves them to the Icarus one (.ci/run).

Hooks: ``add_hook(hook)`` lets a tool change how a run is made without the harness knowing about
it (mutation testing swaps sources and the test module). A hook is an object with
``configure(spec)`` (change the RunSpec before the build) and ``judge(spec, tests, failed)``
(return True when the hook takes over the verdict: run() then does not raise for failures).
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

from . import core, toolenv
from .paths import RTL, SIM, TB_HDL, TOP

SUPPORTED_SIMS = ("icarus", "verilator")


@dataclass
class RunSpec:
    """Everything one run is made of; hooks may change any of it before the build."""

    toplevel: str
    test_module: str  # cocotb module, importable in the simulator's Python
    name: str  # the build's name; runs with the same name and key share the build
    sim: str
    parameters: dict = field(default_factory=dict)
    sources: list = field(default_factory=list)  # Path
    includes: list = field(default_factory=list)  # Path
    build_args: list = field(default_factory=list)
    plusargs: list = field(default_factory=list)
    testcase: str | None = None
    env: dict = field(default_factory=dict)  # extra environment of the simulator
    seed: str | None = None
    waves: bool = False
    wave_depth: int = 0  # levels of the hierarchy in the waveform, 0 = all
    vcd: Path | None = None  # where the waveform goes (default sim/waves/<name>.vcd)
    quiet: bool = False  # simulator output to build.log / test.log instead of the terminal
    build_root: Path = SIM / "build"
    run_tag: str = ""  # the run directory's name inside the build (default: the test module's)

    def key(self) -> str:
        """A hash of what the build is made of (not of the test run)."""
        h = hashlib.sha256()
        h.update(json.dumps([self.sim, self.toplevel, sorted(self.parameters.items()),
                             [str(s) for s in self.sources], [str(i) for i in self.includes],
                             self.build_args, self.waves, self.wave_depth], default=str).encode())
        for src in self.sources:
            h.update(Path(src).read_bytes())
        for inc in self.includes:
            for f in sorted(Path(inc).glob("*.vh")):
                h.update(f.name.encode() + f.read_bytes())
        return h.hexdigest()[:10]

    build_dir: Path | None = None  # set by place(), after the hooks

    def place(self) -> None:
        """Fix the build directory (name and key) once the spec is complete."""
        self.build_dir = Path(self.build_root) / self.sim / f"{self.name}-{self.key()}"

    @property
    def test_dir(self) -> Path:
        return self.build_dir / f"run_{self.run_tag or self.test_module.rsplit('.', 1)[-1]}"


@dataclass
class Outcome:
    """What a run gives back: cocotb's counts, the times of its two steps, where it ran."""

    tests: int
    failed: int
    build_s: float  # 0 when an identical build was reused
    run_s: float
    test_dir: Path


_hooks: list = []


def add_hook(hook) -> None:
    """Register a hook (see the module docstring); hooks run in the order added."""
    _hooks.append(hook)


def remove_hook(hook) -> None:
    _hooks.remove(hook)


def sim_name() -> str:
    sim = os.environ.get("SIM", "icarus") or "icarus"
    if sim not in SUPPORTED_SIMS:
        raise SystemExit(f"SIM={sim!r} is not supported; use one of {', '.join(SUPPORTED_SIMS)}")
    return sim


def waves_enabled() -> bool:
    return os.environ.get("ENC_WAVES", "0") not in ("", "0")


def rtl_sources() -> list[Path]:
    """The IP's RTL, in the order the FuseSoC core lists it."""
    return [TOP / f for f in core.rtl_files()]


def spec(toplevel: str, test_module: str, name: str, parameters: dict | None = None,
         tb_sources: tuple[str, ...] = (), extra_sources: tuple[Path, ...] = (),
         testcase: str | None = None, extra_env: dict | None = None, quiet: bool = False,
         run_tag: str = "", waves: bool | None = None, wave_depth: int = 0,
         vcd: Path | None = None, seed: str | None = None, sim: str | None = None) -> RunSpec:
    """The RunSpec of a run with the usual sources (see :func:`run`), before the hooks (and
    before the simulator's own build arguments, added after them)."""
    sim = sim or sim_name()
    s = RunSpec(toplevel=toplevel, test_module=test_module, name=name, sim=sim,
                parameters=dict(parameters or {}),
                sources=rtl_sources() + [TB_HDL / f for f in tb_sources] + [Path(p) for p in extra_sources],
                includes=core.include_dirs(), testcase=testcase, env=dict(extra_env or {}),
                seed=seed or os.environ.get("SEED") or None,
                waves=waves_enabled() if waves is None else waves, wave_depth=wave_depth, vcd=vcd,
                quiet=quiet, run_tag=run_tag)
    return s


def _icarus_dump(s: RunSpec) -> None:
    """Icarus: a second root module that dumps the waveform ($dumpfile name from a plusarg)."""
    d = s.build_dir
    d.mkdir(parents=True, exist_ok=True)
    path = d / "enc_wave_dump.v"
    path.write_text("module enc_wave_dump;\n"
                    "  reg [8*1024-1:0] path;\n"
                    "  initial begin\n"
                    '    if ($value$plusargs("enc_dump=%s", path)) begin\n'
                    "      $dumpfile(path);\n"
                    f"      $dumpvars({s.wave_depth}, {s.toplevel});\n"
                    "    end\n"
                    "  end\n"
                    "endmodule\n")
    s.sources.append(path)
    s.build_args += ["-s", "enc_wave_dump"]


def build(s: RunSpec):
    """Build ``s`` unless an identical build exists (a lock serialises parallel workers); return
    the runner to test with and whether it built."""
    toolenv.apply()
    runner = get_runner(s.sim)
    built = False
    d = s.build_dir
    d.mkdir(parents=True, exist_ok=True)
    stamp = d / "built.stamp"
    with open(d / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not stamp.exists():
            runner.build(sources=s.sources, includes=s.includes, hdl_toplevel=s.toplevel,
                         parameters=s.parameters, build_args=s.build_args, build_dir=d,
                         timescale=("1ns", "1ps"), waves=s.waves and s.sim == "verilator",
                         always=True,
                         log_file=d / "build.log" if s.quiet else None)
            stamp.write_text(s.key() + "\n")
            built = True
            if s.sim == "verilator":
                # (a build directory is never built again: its name holds the key of what it is
                # made of; a `make test` makes dozens, 75 MB each unpruned)
                toolenv.prune_verilator_build(d)
    return runner, built


def run(toplevel: str, test_module: str, name: str, parameters: dict | None = None,
        tb_sources: tuple[str, ...] = (), extra_sources: tuple[Path, ...] = (),
        testcase: str | None = None, extra_env: dict | None = None, quiet: bool = False,
        run_tag: str = "", waves: bool | None = None, wave_depth: int = 0,
        vcd: Path | None = None, seed: str | None = None, sim: str | None = None) -> Outcome:
    """Build ``toplevel`` (or reuse its build) and run the cocotb tests of ``test_module`` (a
    module name the simulator's Python can import: a test file's ``__name__`` under pytest, or a
    module of enctools). ``tb_sources`` are file names in tb/hdl/, ``extra_sources`` any other HDL
    files. With ``quiet`` the simulator's output goes to build.log / test.log. ``waves`` (default:
    ENC_WAVES), ``wave_depth`` and ``vcd``: see the module docstring; ``seed``: the regression seed
    (default: SEED); ``sim``: the simulator, whatever SIM says (a run too slow on the other).
    Raises when a test failed (unless a hook judges the run), else returns the Outcome."""
    if sim is not None and os.environ.get("ENC_SKIP_FIXED_SIM") == "1":
        import pytest
        pytest.skip(f"{name}: on {sim} whatever SIM says; ENC_SKIP_FIXED_SIM=1 leaves it to the "
                    "other make test run")
    s = spec(toplevel, test_module, name, parameters, tb_sources, extra_sources, testcase,
             extra_env, quiet, run_tag, waves, wave_depth, vcd, seed, sim)
    for h in _hooks:
        h.configure(s)  # (a hook may change the simulator: its build arguments come after)
    if s.sim == "verilator":
        # the project's one waiver file (reasons inside): the same one `make lint` uses
        s.build_args += ["-j", "2", str(RTL / "lint_waivers.vlt")]
    if s.waves and s.sim == "verilator" and s.wave_depth:
        s.build_args += ["--trace-depth", str(s.wave_depth)]
    s.place()
    if s.waves and s.sim == "icarus":
        _icarus_dump(s)  # (after place(): the key holds the depth, the module is in the build)
    t0 = time.monotonic()
    runner, built = build(s)
    t1 = time.monotonic()
    test_dir = s.test_dir
    shutil.rmtree(test_dir, ignore_errors=True)
    test_dir.mkdir(parents=True)
    plusargs = list(s.plusargs)
    fst = test_dir / "wave.fst"
    if s.waves and s.sim == "icarus":
        plusargs.append(f"+enc_dump={fst}")
    results = runner.test(hdl_toplevel=s.toplevel, hdl_toplevel_lang="verilog",
                          test_module=s.test_module, testcase=s.testcase,
                          plusargs=plusargs, extra_env=s.env, seed=s.seed, waves=s.waves,
                          build_dir=s.build_dir, test_dir=test_dir,
                          log_file=test_dir / "test.log" if s.quiet else None)
    tests, failed = get_results(results)
    out = Outcome(tests, failed, t1 - t0 if built else 0.0, time.monotonic() - t1, test_dir)
    if s.waves:
        save_waves(s, test_dir, fst)
    if any(h.judge(s, tests, failed) for h in _hooks):
        return out
    if failed or not tests:
        log = f" (log: {test_dir / 'test.log'})" if s.quiet else ""
        raise RuntimeError(f"{s.name}: {failed} of {tests} cocotb tests failed{log}")
    return out


def save_waves(s: RunSpec, test_dir: Path, fst: Path) -> None:
    """The run's waveform as sim/waves/<name>.vcd (see the module docstring)."""
    out = Path(s.vcd) if s.vcd else SIM / "waves" / f"{s.name}.vcd"
    out.parent.mkdir(parents=True, exist_ok=True)
    if s.sim == "verilator":
        produced = test_dir / "dump.vcd"
        if produced.exists():
            shutil.move(produced, out)
        return
    if not fst.exists():
        return
    conv = shutil.which("fst2vcd")
    if conv is None:
        kept = out.with_suffix(".fst")
        shutil.move(fst, kept)
        print(f"harness: fst2vcd (GTKWave) not found: the Icarus waveform stays FST, {kept}")
        return
    subprocess.run([conv, "-f", str(fst), "-o", str(out)], check=True, capture_output=True)
