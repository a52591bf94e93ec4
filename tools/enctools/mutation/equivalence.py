# SPDX-License-Identifier: Apache-2.0
"""Is a surviving mutant equivalent to the original? Two Yosys stages, each with a CPU-time limit
(a busy machine gives the same answer as an idle one), after a check that needs none.

0. The mutant written alone (mNN.v) is the text of the unmutated design written the same way
   (m00.v): the mutation set a bit to the constant it is already, and changed no cell. Equivalent
   whatever the design; stage 1 cannot show it where ``equiv_make`` fails on the design (the
   engine's memories).
1. ``equiv_make`` (signals matched by name, both sides flattened), ``equiv_simple -seq 5``,
   ``equiv_induct -seq 5``, ``equiv_status -assert``: a proof holds from any state in which the
   matched signals agree, reset or not.
2. For a survivor that is not yet reviewed (or with --full-equiv): a miter of the ports only, from
   the all-zero state (the simulation's start: registers without a reset start at 0), every
   input free in every clock, ``sat -tempinduct`` up to MITER_STEPS clocks. A proof by induction
   makes the mutant equivalent; a base-case model is a trace on which the outputs differ (the
   tests miss a real difference); otherwise no output difference within the clocks it reached.
"""

from __future__ import annotations

import re
from pathlib import Path

from . import generate as gen
from .data import Mutant

EQUIV_CPU_S = 300  # CPU seconds of stage 1
MITER_STEPS = 24  # clocks of the bounded output check (stage 2)
MITER_CPU_S = 60  # CPU seconds of stage 2 (the large modules stop early: a note, not a verdict)


def _side(c, rel: str, name: str, mutate: str) -> str:
    # the other modules after the original (deferred), elaborated before the mutation: `mutate`
    # needs the directions of the instances' ports
    return (f"read_rtlil {rel}/orig.il\n" + gen.read_cmd(gen.others(c), defer=True)
            + f"hierarchy -top {c.module}\n{mutate}proc\nflatten\nmemory_map\nopt_clean\n"
            f"rename {c.module} {name}\n")


STAGE0_NOTE = "proven equivalent (written alone it is the unmutated netlist, m00.v)"


def same_as_m00(path: Path) -> bool:
    """A mutant written alone (mNN.v) has the text of its corner's unmutated design (m00.v, in the
    same directory); False when either file is missing."""
    base = path.parent / "m00.v"
    return path.exists() and base.exists() and path.read_text() == base.read_text()


def unchanged(root: Path, m: Mutant) -> bool:
    """Stage 0: the mutant written alone is the unmutated design's text (m00.v)."""
    try:
        gen.write_mutant(root, m)
    except RuntimeError:
        return False
    return same_as_m00(m.path)


def equivalence(root: Path, m: Mutant, miter: bool = True) -> tuple[bool, str]:
    """(proven equivalent, what the stages found)."""
    if unchanged(root, m):
        return True, STAGE0_NOTE
    c = m.corner
    d = gen.corner_dir(root, c)
    rel = gen.rel(d)
    pair = (_side(c, rel, "gold", "") + "design -stash gold\n" + _side(c, rel, "gate", m.command + "\n")
            + "design -copy-from gold -as gold gold\n")
    if m.stage1:  # ran already (early, for a capped mutant): not proven
        first = m.stage1.split(";")[0]
    else:
        log = d / f"m{m.number:02d}_equiv.log"
        script = (pair + "equiv_make gold gate equiv\nhierarchy -top equiv\nasync2sync\n"
                  + "equiv_simple -seq 5\nequiv_induct -seq 5\nequiv_status -assert\n")
        try:
            proc = gen.run_yosys(script, log, cpu_s=EQUIV_CPU_S)
        except gen.CpuLimit:
            proc = None
        if proc is not None and proc.returncode == 0:
            return True, "proven equivalent (equiv_induct)"
        text = log.read_text() if log.exists() else ""
        um = re.search(r"Found (\d+) unproven \$equiv cells", text)
        first = (f"{um.group(1)} unproven $equiv cells" if um else
                 f"equivalence check: no result in {EQUIV_CPU_S} CPU s" if proc is None else
                 "equiv_make failed")
    if not miter:
        return False, f"{first}; port miter not run (a reviewed survivor; --full-equiv runs it)"

    log = d / f"m{m.number:02d}_miter.log"
    script = (pair + "miter -equiv -flatten -make_outputs gold gate miter\nhierarchy -top miter\n"
              + f"sat -tempinduct -prove trigger 0 -set-init-zero -seq 1 -maxsteps {MITER_STEPS} "
              + "miter\n")
    try:
        proc = gen.run_yosys(script, log, cpu_s=MITER_CPU_S)
    except gen.CpuLimit:  # the log tells how far the base case got
        text = log.read_text() if log.exists() else ""
        if re.search(r"model found for base case", text):
            return False, f"{first}; outputs differ on a trace from the zero state"
        steps = re.findall(r"Base case for induction length (\d+) proven", text)
        return False, (f"{first}; no output difference within {steps[-1]} clocks of the zero state "
                       f"(miter stopped after {MITER_CPU_S} CPU s)" if steps else
                       f"{first}; miter: no result in {MITER_CPU_S} CPU s")
    text = log.read_text() if log.exists() else proc.stdout + proc.stderr
    if proc.returncode == 0 and re.search(r"Induction step proven: SUCCESS", text):
        return True, "proven equivalent (miter, temporal induction)"
    if re.search(r"model found for base case", text):
        return False, f"{first}; outputs differ on a trace from the zero state"
    if re.search(r"Reached maximum number of time steps", text):
        return False, f"{first}; no output difference within {MITER_STEPS} clocks of the zero state"
    err = re.search(r"ERROR: (.*)", text)
    return False, f"{first}; miter: {err.group(1) if err else 'see ' + gen.rel(log)}"
