# SPDX-License-Identifier: Apache-2.0
"""``make soc-sim``: build the simulated LiteX SoCs with enc_qei (simsoc.MAIN, and simsoc.EFIFO
with an edge FIFO per channel), run their firmware, print the UART tables, check them against the
motion model, run the deliberately wrong firmware and check that the checks fail, and write
doc/results/soc_sim.md. The pytest module tb/soc/test_soc_sim.py asserts the same on the same
(cached) runs."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from ..paths import RESULTS, rel
from . import check, simsoc

RESULT_FILE = RESULTS / "soc_sim.md"
FAULTS = {"page": "channel k's SNAP_COUNT read from the page of channel k + 1",
          "efifo": "an edge-FIFO entry's direction read from its A bit instead of DIR"}
# the builds, each with the deliberately wrong firmware its checks must catch
BUILDS = {"main": (simsoc.MAIN, "page"), "efifo": (simsoc.EFIFO, "efifo")}


def run_firmware(cfg: simsoc.SocConfig, fault: str | None = None):
    """Build the firmware (``fault``: the deliberately wrong one), run it, check it:
    (console, seconds, parsed run, check result, edge-FIFO check result or None)."""
    fw = simsoc.build_firmware(cfg, fault)
    out, dt = simsoc.run(cfg, fw)
    run = check.parse(out)
    res, fifo = check.check_run(cfg.motions(), run)
    return out, dt, run, res, fifo


def verdict(res: check.Result, fifo: check.EfifoResult | None) -> tuple[bool, list]:
    """(every check passed, the failures) of one run."""
    fails = res.failures + (fifo.failures if fifo else [])
    return not fails, fails


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


def fault_row(fault: str, fails: list) -> str:
    what = sorted({w for w, _ in fails})
    return (f"| `FW_FAULT={fault}` | {FAULTS[fault]} | "
            f"{'fails (' + ', '.join(what) + '): ' + fails[0][1] if fails else 'PASSES'} |")


def unmapped_line(run: check.Run) -> str:
    u = run.unmapped
    if not u:
        return "- (no U line)"
    return (f"- a read of offset 0x{u['offset']:02X} of page 0 (no register there) returned "
            f"0x{u['value']:08X} after {u['cycles']:,} CPU cycles "
            f"({u['cycles'] / run.build['clk_hz'] * 1e3:.1f} ms), and LiteX counted "
            f"{u['bus_errors']} bus error")


def write_results(results: dict) -> None:
    """results: build name (BUILDS) -> (config, run, check result, edge-FIFO result or None,
    fault -> its failures)."""
    _, run, res, _, fault_fails = results["main"]
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
    ]
    ecfg, erun, eres, efifo, efault_fails = results["efifo"]
    ok, fails = verdict(eres, efifo)
    eb = erun.build
    lines += [
        "## The edge-FIFO build",
        "",
        f"The same SoC with CAPS.CHANNELS = {eb['channels']}, an edge FIFO of "
        f"{1 << eb['efifo_log2']} entries per channel (EFIFO_LOG2 {eb['efifo_log2']}) and the "
        f"motions {', '.join(m.name for m in ecfg.motions())} (the steady channel's 3.1 million "
        "steps per second is left out: see the cost per entry below). The same firmware finds "
        "the FIFO in CAPS, clears and enables it, and drains every channel's FIFO in its main "
        "loop between the snapshot interrupts; at the end it turns the FIFOs off "
        "(EFIFO_CTRL.EN = 0), drains what is left and prints, per channel, the statistics of "
        "every entry it popped.",
        "",
        *[f"- {s}" for s in eres.summary + (efifo.summary if efifo else [])],
        f"- draining: {efifo.cycles_per_entry:.0f} cycles per entry, so this CPU at "
        f"{eb['clk_hz'] / 1e6:g} MHz, doing nothing else, keeps up with at most "
        f"{eb['clk_hz'] / efifo.cycles_per_entry:,.0f} steps per second over all channels "
        f"(less the snapshot handler's share); a FIFO of {1 << eb['efifo_log2']} entries drained "
        f"once per 1 kHz period holds {(1 << eb['efifo_log2']) * 1000:,} steps per second per "
        "channel" if efifo and efifo.cycles_per_entry
        else "- draining: no entries",
        f"- result: {'pass' if ok else 'FAIL'}" + ("" if ok else ": " + "; ".join(m for _, m in fails[:3])),
        "",
        "## Deliberately wrong firmware",
        "",
        "| build flag | fault | the check |",
        "|---|---|---|",
        *[fault_row(f, fl) for f, fl in fault_fails.items()],
        *[fault_row(f, fl) for f, fl in efault_fails.items()],
        "",
        "## An unmapped offset",
        "",
        "What the firmware got from one read of an offset no register uses (the peripheral answers "
        "`wb_err_o`; doc/litex.md says what VexRiscv and LiteX make of it):",
        "",
        unmapped_line(run),
    ]
    RESULT_FILE.write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="soc_sim.py", description=__doc__)
    ap.add_argument("--snapshots", type=int, default=simsoc.SocConfig.snapshots)
    ap.add_argument("--rebuild", action="store_true", help="rebuild the simulators even if current")
    ap.add_argument("--no-results", action="store_true", help=f"do not write {rel(RESULT_FILE)}")
    args = ap.parse_args(argv)
    if args.snapshots < 3:
        ap.error(f"--snapshots {args.snapshots}: give at least 3 (the first only initialises)")
    builds = {name: (dataclasses.replace(cfg, snapshots=args.snapshots), fault)
              for name, (cfg, fault) in BUILDS.items()}
    t0 = time.monotonic()
    for cfg, _ in builds.values():
        simsoc.build_gateware(cfg, force=args.rebuild)
    # the good firmware and the wrong ones of both builds, two at a time (a simulator each)
    with ThreadPoolExecutor(max_workers=2) as pool:
        jobs = {(cfg, f): pool.submit(run_firmware, cfg, f)
                for cfg, fault in builds.values() for f in (None, fault)}
    ok_all, results = True, {}
    for name, (cfg, fault) in builds.items():
        out, dt, run, res, fifo = jobs[(cfg, None)].result()
        print("\n".join(line for line in out.replace("\r", "").splitlines()
                        if line.strip() and not line.startswith(("[", "-", "%"))))
        print(f"soc-sim: {cfg.tag}: firmware run {dt:.1f} s" if dt else
              f"soc-sim: {cfg.tag}: firmware run reused (cached)")
        for s in res.summary + (fifo.summary if fifo else []):
            print(f"soc-sim: {cfg.tag}: {s}")
        ok, fails = verdict(res, fifo)
        for _, m in fails:
            print(f"soc-sim: {cfg.tag}: FAIL: {m}")
        fres = jobs[(cfg, fault)].result()
        fok, ffails = verdict(fres[3], fres[4])
        print(f"soc-sim: {cfg.tag}: FW_FAULT={fault} ({FAULTS[fault]}): the check "
              + ("PASSES: it missed the fault" if fok else f"fails as it must: {ffails[0][1]}"))
        ok_all &= ok and not fok and run.done
        results[name] = (cfg, run, res, fifo, {fault: ffails})
    if not args.no_results and all(r[1].done for r in results.values()):
        write_results(results)
        print(f"soc-sim: wrote {rel(RESULT_FILE)}")
    print(f"soc-sim: {time.monotonic() - t0:.0f} s in all")
    return 0 if ok_all else 1


if __name__ == "__main__":
    sys.exit(main())
