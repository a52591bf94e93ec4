# SPDX-License-Identifier: Apache-2.0
"""``make soc-sim``: build the simulated LiteX SoC with enc_qei, run its firmware, print the UART
table, check it against the motion model, run the deliberately wrong firmware and check that the
check fails, and write doc/results/soc_sim.md. The pytest module tb/soc/test_soc_sim.py asserts
the same on the same (cached) runs."""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from ..paths import RESULTS, rel
from . import check, simsoc

RESULT_FILE = RESULTS / "soc_sim.md"
FAULTS = {"page": "channel k's SNAP_COUNT read from the page of channel k + 1"}


def run_firmware(cfg: simsoc.SocConfig, fault: str | None = None):
    """Build the firmware (``fault``: the deliberately wrong one), run it, check it:
    (console, seconds, parsed run, check result)."""
    fw = simsoc.build_firmware(cfg, fault)
    out, dt = simsoc.run(cfg, fw)
    run = check.parse(out)
    return out, dt, run, check.check(cfg.motions(), run)


def cycles_table(run: check.Run) -> list[str]:
    clk, period = run.build["clk_hz"], run.build["period"]
    rows = ["| channels read | cycles min | mean | max | mean added by the channel | "
            "max / period |", "|---:|---:|---:|---:|---:|---:|"]
    prev = 0
    for k in sorted(run.cycles):
        lo, mean, hi = run.cycles[k]
        rows.append(f"| {k} | {lo} | {mean} | {hi} | {mean - prev} | {100 * hi / period:.1f} % |")
        prev = mean
    k = max(run.cycles)
    per_mean, per_max = run.cycles[k][1] / k, run.cycles[k][2] / k
    lat = [r[2] for r in run.rows[1:]]
    return rows + [
        "",
        f"Per channel about {per_mean:.0f} cycles on average and {per_max:.0f} at most (the "
        f"handler's fixed part, IRQ_SUMMARY, EVENTS and GSNAP_TIME, is in the first row). At "
        f"{clk / 1e6:g} MHz and 1 kHz the period is {period} cycles: by the worst case "
        f"{int(period // per_max)} channels fit in it this way. Interrupt latency, from the "
        f"snapshot to the handler's first instructions (TIMEBASE there minus GSNAP_TIME: the "
        f"trap entry and LiteX's dispatch): {min(lat)} to {max(lat)} clocks.",
    ]


def write_results(cfg: simsoc.SocConfig, run: check.Run, res: check.Result,
                  fault_res: dict[str, check.Result]) -> None:
    b = run.build
    lines = [
        "<!-- written by scripts/soc_sim.py (make soc-sim); do not edit by hand -->",
        "",
        "# enc_qei in a simulated LiteX SoC: the firmware's figures",
        "",
        f"LiteX SoC in Verilator: VexRiscv (`full` variant, RV32IM, no FPU) at a declared "
        f"{b['clk_hz'] / 1e6:g} MHz, integrated ROM (the firmware) and SRAM, `enc_qei_wb` with "
        f"CAPS.CHANNELS = {b['channels']}, CAPS.PROFILE = {b['profile']} (full), COUNT_W "
        f"{b['count_w']}, TS_W {b['ts_w']}, TB_PRESCALE 0 (one tick per clock). The global unit "
        f"timer takes a snapshot of every channel each {b['period']} ticks (1 kHz); the interrupt "
        f"handler of `sw/soc/main.c` reads each channel's snapshot registers and runs "
        f"`qei_vel_update()` (`sw/enc_qei_velocity.c`, double precision in software). "
        f"{len(run.rows)} snapshots; the encoder inputs are the motions of "
        f"`tools/enctools/litex/motion.py` (doc/litex.md).",
        "",
        "## Handler cycles per snapshot versus channels read",
        "",
        "CPU cycles (mcycle) from the handler's first instructions until channel k − 1 is done "
        "(its registers read, `qei_vel_update()` run, the record stored), over the snapshots "
        "after the first (which only initialises the estimators); the trap entry and LiteX's "
        "interrupt dispatch before the handler are the latency below.",
        "",
        *cycles_table(run),
        "",
        "## Checks against the motion model",
        "",
        *[f"- {s}" for s in res.summary],
        f"- result: {'pass' if res.ok else 'FAIL'}"
        + ("" if res.ok else ": " + "; ".join(m for _, m in res.failures[:3])),
        "",
        "## Deliberately wrong firmware",
        "",
        "| build flag | fault | the check |",
        "|---|---|---|",
    ]
    for fault, fr in fault_res.items():
        what = sorted({w for w, _ in fr.failures})
        first = fr.failures[0][1] if fr.failures else ""
        lines.append(f"| `FW_FAULT={fault}` | {FAULTS[fault]} | "
                     f"{'fails (' + ', '.join(what) + '): ' + first if not fr.ok else 'PASSES'} |")
    RESULT_FILE.write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="soc_sim.py", description=__doc__)
    ap.add_argument("--channels", type=int, default=simsoc.SocConfig.channels)
    ap.add_argument("--snapshots", type=int, default=simsoc.SocConfig.snapshots)
    ap.add_argument("--rebuild", action="store_true", help="rebuild the simulator even if current")
    ap.add_argument("--no-results", action="store_true", help=f"do not write {rel(RESULT_FILE)}")
    args = ap.parse_args(argv)
    cfg = simsoc.SocConfig(channels=args.channels, snapshots=args.snapshots)
    t0 = time.monotonic()
    simsoc.build_gateware(cfg, force=args.rebuild)
    # the good firmware and the wrong ones run side by side (one simulator process each)
    with ThreadPoolExecutor(max_workers=2) as pool:
        jobs = {f: pool.submit(run_firmware, cfg, f) for f in (None, *FAULTS)}
    out, dt, run, res = jobs[None].result()
    print("\n".join(line for line in out.replace("\r", "").splitlines()
                    if line.strip() and not line.startswith(("[", "-", "%"))))
    print(f"soc-sim: firmware run {dt:.1f} s" if dt else "soc-sim: firmware run reused (cached)")
    for s in res.summary:
        print(f"soc-sim: {s}")
    for _, m in res.failures:
        print(f"soc-sim: FAIL: {m}")
    fault_res = {}
    for fault in FAULTS:
        fres = fault_res[fault] = jobs[fault].result()[3]
        verdict = "fails as it must" if not fres.ok else "PASSES: the check missed the fault"
        print(f"soc-sim: FW_FAULT={fault} ({FAULTS[fault]}): the check {verdict}"
              + (f": {fres.failures[0][1]}" if fres.failures else ""))
    if not args.no_results and run.done:
        write_results(cfg, run, res, fault_res)
        print(f"soc-sim: wrote {rel(RESULT_FILE)}")
    print(f"soc-sim: {time.monotonic() - t0:.0f} s in all")
    ok = res.ok and not any(r.ok for r in fault_res.values())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
