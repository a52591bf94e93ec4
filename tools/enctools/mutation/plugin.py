# SPDX-License-Identifier: Apache-2.0
"""The mutation flow's side of the test runs: a pytest plugin that installs a harness hook.

The flow runs pytest as ``python -m pytest -p enctools.mutation.plugin <pytest ids>``; loading
the plugin adds one hook to enctools.harness (``harness.add_hook``), chosen by the environment
(both simulate every run on Icarus, ``on_icarus``, also one that names Verilator):

- ``MUT_PLAN=<file>`` (discovery): every ``harness.run()`` is written down instead of built (the
  pytest id, toplevel, parameters, sources, cocotb module, testcase and build key, one JSON line
  each; the build key as if rtl/ were the run's copy of it, ``ENC_RTL_SNAPSHOT``) and its pytest
  test is skipped.
- ``MUT_LOOP_IDS=1,2,...`` (mutant runs): the first ``harness.run()`` of the pytest process runs
  the mutants. The hook puts the run's RTL copy in place of rtl/ (``ENC_RTL_SNAPSHOT``), the
  design that holds every mutant of the module in place of its file (``ENC_RTL_OVERRIDE``, "rtl/
  x.v=/abs/mut.v"), builds under ``ENC_BUILD_ROOT``, adds the root module ``mut_ctl`` (the
  register ``mut_ctl.sel`` selects the mutant), and runs the cocotb module
  enctools.mutation.loop instead of the test's own: it runs the cocotb tests of every module of
  the group (``MUT_LOOP_SUITE``) against the mutants and writes the verdicts to
  ``MUT_LOOP_DIR``. The build must be the one discovery planned (``MUT_GROUP_KEY``). Later
  ``harness.run()`` calls of the same process (the group's other pytest ids) are skipped: their
  tests ran in that simulation. The hook judges the run (failing tests are the point).

Without either variable the plugin does nothing.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path

import pytest

from .. import harness
from ..paths import RTL, TOP

LOOP_MODULE = "enctools.mutation.loop"


def _rel(p) -> str:
    p = Path(p)
    try:
        return str(p.resolve().relative_to(TOP))
    except ValueError:
        return str(p)


def current_nodeid() -> str:
    """The running pytest id (pytest sets PYTEST_CURRENT_TEST to "<id> (call)")."""
    return os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" (", 1)[0]


def to_snapshot(path, snapshot: Path) -> Path:
    """A file or folder of rtl/ in the run's copy of it; any other path as it is."""
    p = Path(path).resolve()
    return snapshot / p.relative_to(TOP) if p == RTL or RTL in p.parents else p


def on_icarus(spec) -> None:
    """Simulate the run on Icarus whatever simulator it names: the mutant selector (``mut_ctl.sel``,
    a register of a second root module the mutants read by hierarchical name) is an Icarus
    construct. The runs that name Verilator do so for speed (the shared engine's feature-file and
    16-channel builds): on Icarus they take about five times longer and test the same."""
    spec.sim = "icarus"


def snapshot_key(spec, snapshot: Path) -> str:
    """The build key of ``spec`` with its RTL read from the snapshot (what discovery groups by,
    and what the mutant run checks against: rtl/ may change during a run, the snapshot not)."""
    s = copy.copy(spec)
    s.sources = [to_snapshot(p, snapshot) for p in spec.sources]
    s.includes = [to_snapshot(p, snapshot) for p in spec.includes]
    return s.key()


class PlanHook:
    """Write down each run (see the module docstring) and skip its test."""

    def __init__(self, path: str, snapshot: str):
        self.path = Path(path)
        self.snapshot = Path(snapshot)

    def configure(self, spec) -> None:
        on_icarus(spec)
        entry = {"nodeid": current_nodeid(), "toplevel": spec.toplevel,
                 "test_module": spec.test_module, "testcase": spec.testcase, "name": spec.name,
                 "parameters": spec.parameters, "sources": [_rel(s) for s in spec.sources],
                 "includes": [_rel(i) for i in spec.includes], "sim": spec.sim,
                 "key": snapshot_key(spec, self.snapshot)}
        with open(self.path, "a") as f:
            f.write(json.dumps(entry, default=str) + "\n")
        pytest.skip("mutation flow: build planned, not run")

    def judge(self, spec, tests, failed) -> bool:
        return False


class MutationHook:
    """Run the mutants in the first harness.run() of the process (see the module docstring)."""

    def __init__(self, env):
        self.env = env
        self.snapshot = Path(env["ENC_RTL_SNAPSHOT"])  # the copy of the repository's rtl/ parent
        self.override = {}
        for item in env.get("ENC_RTL_OVERRIDE", "").split(","):
            if item:
                rel, path = item.split("=", 1)
                self.override[(TOP / rel).resolve()] = Path(path)
        self.build_root = Path(env["ENC_BUILD_ROOT"])
        self.suite = env.get("MUT_LOOP_SUITE", "")
        self.key = env.get("MUT_GROUP_KEY", "")
        self.ran = False

    def _map(self, path: Path) -> Path:
        p = Path(path).resolve()
        return self.override.get(p) or to_snapshot(p, self.snapshot)

    def configure(self, spec) -> None:
        if self.ran:
            pytest.skip("mutation flow: this test ran in its group's simulation")
        on_icarus(spec)
        key = snapshot_key(spec, self.snapshot)
        if self.key and key != self.key:
            raise RuntimeError(f"{spec.name}: the build differs from the one discovery planned "
                               f"(key {key}, planned {self.key})")
        self.ran = True
        spec.sources = [self._map(s) for s in spec.sources]
        spec.includes = [self._map(i) for i in spec.includes]
        self.build_root.mkdir(parents=True, exist_ok=True)
        ctl = self.build_root / "mut_ctl.v"
        # no initial value: an `initial` runs at time 0 after the first test has set sel, and
        # would undo it (the loop sets sel before every test)
        text = "module mut_ctl;\n  reg [15:0] sel;\nendmodule\n"
        if not ctl.exists() or ctl.read_text() != text:  # (processes of one corner share it)
            ctl.write_text(text)
        spec.sources.append(ctl)
        spec.build_args = list(spec.build_args) + ["-s", "mut_ctl"]
        spec.build_root = self.build_root
        spec.quiet = True
        spec.waves = False
        suite = self.suite or json.dumps([[spec.test_module, spec.testcase]])
        results = Path(self.env["MUT_LOOP_DIR"]) / f"{spec.name}.json"
        results.parent.mkdir(parents=True, exist_ok=True)
        spec.env = dict(spec.env, MUT_LOOP_SUITE=suite, MUT_LOOP_RESULTS=str(results))
        # processes that run at once share the build: each runs in a directory of its own
        tag = self.env.get("MUT_RUN_TAG", "")
        spec.test_module, spec.testcase = LOOP_MODULE, None
        spec.run_tag = "mutants" + (f"_{tag}" if tag else "")

    def judge(self, spec, tests, failed) -> bool:
        return spec.test_module == LOOP_MODULE


def _install() -> None:
    env = os.environ
    if env.get("MUT_PLAN"):
        harness.add_hook(PlanHook(env["MUT_PLAN"], env["ENC_RTL_SNAPSHOT"]))
    elif env.get("MUT_LOOP_IDS") is not None and env.get("ENC_BUILD_ROOT"):
        harness.add_hook(MutationHook(env))


def pytest_configure(config) -> None:
    _install()
