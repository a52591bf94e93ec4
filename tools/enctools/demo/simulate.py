# SPDX-License-Identifier: Apache-2.0
"""Run the plan on tb/hdl/demo_top.v through enctools.harness (the same path as every test), with
a progress line while it simulates."""

from __future__ import annotations

import json
import logging
import os
import sys
import threading
from pathlib import Path

from ..paths import TOP
from .config import CHAR_CNT_W, CHAR_CYCLES, FILTER_LEN, NAME, TEST_LIMIT_DEG, VCD
from .plan import Plan, write_plan


def _progress(progress_file: Path, stop: threading.Event, tty: bool) -> None:
    """Print the bench's progress (it rewrites ``progress_file``): one line rewritten in place on a
    terminal, a line every 25 % otherwise."""
    last_pct = -1
    shown = -25
    while not stop.wait(0.2):
        try:
            text = progress_file.read_text().split()
            now, total, label = float(text[0]), float(text[1]), " ".join(text[2:])
        except (OSError, ValueError, IndexError):
            continue
        pct = int(100 * now / total) if total else 0
        if pct == last_pct:
            continue
        last_pct = pct
        line = (f"demo: simulating {now / 1e6:6.2f} of {total / 1e6:.2f} ms  "
                f"[{'#' * (pct // 5):<20}] {pct:3d}%  {label}")
        if tty:
            print("\r" + line.ljust(88), end="", flush=True)
        elif pct >= shown + 25:
            shown = pct - pct % 25
            print(line, flush=True)
    if tty:
        print("\r" + " " * 88 + "\r", end="", flush=True)


def parameters(plan: Plan) -> dict:
    """demo_top's parameters for this plan."""
    return {"FILTER_LEN": FILTER_LEN, "WINDOW_LOG2": plan.window_log2, "CNT_W": CHAR_CNT_W,
            "WINDOW_CYCLES": CHAR_CYCLES, "MIN_STATE": int(round(TEST_LIMIT_DEG * 256))}


def _run_with_progress(plan: Plan, sim: str, name: str, vcd: Path, env: dict, progress_file: Path):
    from .. import harness

    print(f"demo: building and running demo_top with {sim}", flush=True)
    stop = threading.Event()
    th = threading.Thread(target=_progress, args=(progress_file, stop, sys.stdout.isatty()),
                          daemon=True)
    th.start()
    try:
        # demo_top's own signals only (wave_depth 1): every signal the review needs is one of them
        return harness.run("demo_top", "enctools.benches.demo_bench", name=name,
                           parameters=parameters(plan), tb_sources=("demo_top.v",), extra_env=env,
                           quiet=True, waves=True, wave_depth=1, vcd=vcd, seed=str(plan.opts.seed))
    except RuntimeError as exc:
        raise SystemExit(f"demo: simulation failed ({exc})")
    finally:
        stop.set()
        th.join()


def simulate(plan: Plan, sim: str, name: str = NAME) -> dict:
    """Run the plan on demo_top: the bench enctools.benches.demo_bench reads the plan and writes
    its result (returned, with the build and run times); the VCD (demo_top's own signals) goes to
    sim/waves/<name>.vcd."""
    logging.getLogger("cocotb").setLevel(logging.WARNING)
    os.environ["SIM"] = sim
    io_dir = TOP / "sim" / "build" / sim / f"{name}-io"
    vcd = VCD.with_name(f"{name}.vcd")
    io_dir.mkdir(parents=True, exist_ok=True)
    plan_file, result_file, progress_file = (io_dir / n for n in
                                             ("plan.json", "result.json", "progress.txt"))
    for fpath in (result_file, progress_file):
        fpath.unlink(missing_ok=True)
    write_plan(plan, plan_file)
    vcd.parent.mkdir(parents=True, exist_ok=True)
    vcd.unlink(missing_ok=True)
    env = {"ENC_DEMO_PLAN": str(plan_file), "ENC_DEMO_RESULT": str(result_file),
           "ENC_DEMO_PROGRESS": str(progress_file)}
    if sim == "icarus":
        env["COCOTB_RESOLVE_X"] = "ZEROS"
    out = _run_with_progress(plan, sim, name, vcd, env, progress_file)
    if not result_file.exists():
        log = out.test_dir / "test.log"
        tail = "".join(log.read_text(errors="replace").splitlines(True)[-20:])
        raise SystemExit(f"demo: the bench wrote no result; last lines of {log}:\n{tail}")
    res = json.loads(result_file.read_text())
    res["t_build"], res["t_sim"] = out.build_s, out.run_s
    return res
