# SPDX-License-Identifier: Apache-2.0
"""Which tests cover which module at which parameter values: found, not listed.

1. **Plan.** pytest runs every test path the modules name (enctools.mutation.modules), with the
   plugin in plan mode: each ``harness.run()`` is written down (pytest id, toplevel, parameters,
   sources, cocotb module, testcase, build key) instead of built. Tests that do not simulate run
   as usual and are not part of the flow.
2. **Groups.** pytest ids whose runs share one build (the same key: toplevel, parameters,
   sources) form a group: one simulation runs the cocotb tests of all their modules. The feature
   files of tb/enc_qei/, for instance, share the build of each configuration, so each
   configuration is one group of all their tests; a test added to a feature file (or a feature
   file added) is in it without any list to edit.
3. **Corners.** Yosys elaborates every group's build and reads the parameters each module is
   instantiated with. A module's corners are the distinct parameter sets of the builds its
   patterns pick (all its builds by default); the tests of a corner are every group that builds
   the module with exactly those values, in the order of the module's test paths. A build that
   instantiates the module with several parameter sets (the lean profile's two snapshot
   triggers) cannot hold one mutant design for all of them and is left out for that module.
   Runs that choose Verilator themselves (the shared engine's feature-file and 16-channel
   builds, for speed) are planned and run on Icarus: the mutant selector is an Icarus construct
   (enctools.mutation.plugin.on_icarus).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

from ..paths import TOP
from . import generate as gen
from .data import Corner, Group, Module


def run_plan(root: Path, paths: list[str], seed: int) -> tuple[list[dict], str]:
    """Run pytest over ``paths`` in plan mode; return the planned runs (first per pytest id) and
    pytest's output."""
    plan = root / "plan.jsonl"
    plan.unlink(missing_ok=True)
    env = dict(os.environ, MUT_PLAN=str(plan), ENC_RTL_SNAPSHOT=str(gen.snapshot_root()),
               SIM="icarus", SEED=str(seed), ENC_WAVES="0", PYTHONDONTWRITEBYTECODE="1")
    for k in ("MUT_LOOP_IDS", "ENC_BUILD_ROOT", "WAVES"):
        env.pop(k, None)
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
           "-p", "enctools.mutation.plugin", "-rfE", *paths]
    proc = subprocess.run(cmd, cwd=TOP, env=env, capture_output=True, text=True)
    entries, seen = [], set()
    if plan.exists():
        for ln in plan.read_text().splitlines():
            e = json.loads(ln)
            if e["nodeid"] not in seen:
                seen.add(e["nodeid"])
                entries.append(e)
    return entries, proc.stdout + proc.stderr


def selects(selector: str, nodeid: str) -> bool:
    if "::" in selector:
        return nodeid == selector
    s = selector.rstrip("/")
    return nodeid.startswith(s + "::") or nodeid.startswith(s + "/")


def matches(pattern: str, nodeid: str) -> bool:
    """A pattern with `*` as its only wildcard (pytest ids hold brackets) against a pytest id."""
    return re.fullmatch(".*".join(map(re.escape, pattern.split("*"))), nodeid) is not None


def groups_of(entries: list[dict], selectors: tuple[str, ...],
              exclude: tuple[str, ...] = ()) -> list[Group]:
    """The groups of the pytest ids ``selectors`` pick (less those ``exclude`` picks), in
    selector order."""
    ordered: list[dict] = []
    for s in selectors:
        ordered += [e for e in entries if selects(s, e["nodeid"]) and e not in ordered
                    and not any(selects(x, e["nodeid"]) for x in exclude)]
    groups: dict[str, Group] = {}
    for e in ordered:
        g = groups.get(e["key"])
        if g is None:
            g = groups[e["key"]] = Group([], [], e["key"], e["toplevel"], e["parameters"],
                                         e["sources"], e["includes"], e["name"])
        g.nodeids.append(e["nodeid"])
        member = [e["test_module"], e["testcase"]]
        if member not in g.members:
            g.members.append(member)
    return list(groups.values())


def corners_of(root: Path, name: str, spec: Module, entries: list[dict], defaults: dict,
               instances) -> tuple[list[Corner], list[str]]:
    """The corners of one module and notes on the builds left out."""
    notes = []
    found: list[dict] = []  # {"params", "groups", "picked"}, in the order of the test paths
    for g in groups_of(entries, spec.tests, spec.exclude):
        sets = instances(g).get(name, [])
        if not sets:
            continue
        if len(sets) > 1:
            notes.append(f"{name}: {g.label} instantiates it with {len(sets)} parameter sets: "
                         "left out")
            continue
        entry = next((f for f in found if f["params"] == sets[0]), None)
        if entry is None:
            entry = {"params": sets[0], "groups": [], "picked": False}
            found.append(entry)
        entry["groups"].append(g)
        entry["picked"] |= (not spec.corners) or any(
            matches(p, n) for n in g.nodeids for p in spec.corners)
    corners = [Corner(name, spec.file, f["params"], defaults, f["groups"], i, spec)
               for i, f in enumerate(f for f in found if f["picked"])]
    return corners, notes


def discover(root: Path, modules: dict[str, Module], seed: int, say=print) -> tuple[list[Corner], list[str]]:
    """Every corner of ``modules`` with its groups of tests (see the module docstring)."""
    paths: list[str] = []
    for spec in modules.values():
        for s in spec.tests:
            base = s.split("::")[0]
            if base not in paths:
                paths.append(base)
    entries, output = run_plan(root, paths, seed)
    notes = []
    tail = [ln for ln in output.splitlines() if ln.startswith(("FAILED", "ERROR"))]
    if tail:
        notes += [f"discovery: pytest reported {ln}" for ln in tail]
    if not entries:
        raise RuntimeError("discovery found no test runs; pytest said:\n" + output[-3000:])
    say(f"discovery: {len(entries)} pytest ids build a design ({len({e['key'] for e in entries})} "
        f"builds)")
    defaults = gen.module_defaults(root, {m: s.file for m, s in modules.items()})
    cache: dict[str, dict] = {}

    def instances(g: Group) -> dict:
        if g.key not in cache:
            cache[g.key] = gen.build_instances(root, g)
        return cache[g.key]

    corners: list[Corner] = []
    for name, spec in modules.items():
        cs, ns = corners_of(root, name, spec, entries, defaults[name], instances)
        if not cs:
            notes.append(f"{name}: no test of {', '.join(spec.tests)} builds it")
        corners += cs
        notes += ns
    return corners, notes
