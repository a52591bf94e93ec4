# SPDX-License-Identifier: Apache-2.0
"""``make soc-sim``: build the simulated LiteX SoCs with enc_qei (simsoc.MAIN, simsoc.EFIFO
with an edge FIFO per channel, simsoc.ENGINE and simsoc.ENGINE_FULL with lean and full channels
sharing one engine, simsoc.ENGINE_EFIFO with edge FIFOs beside the engine), run their firmware
(on MAIN twice: with the fixed-point and with the double velocity estimator), print the UART tables, check them against the motion model, run the
deliberately wrong firmware and check that the checks fail, and write doc/results/soc_sim.md
(the handler's cycles of every build). The pytest module tb/soc/test_soc_sim.py asserts the
same on the same (cached) runs."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from ..paths import RESULTS, rel
from . import check, simsoc

RESULT_FILE = RESULTS / "soc_sim.md"
FAULTS = {"page": "channel k's SNAP_COUNT read from the page of channel k + 1",
          "efifo": "an edge-FIFO entry's direction read from its A bit instead of DIR"}


def run_firmware(cfg: simsoc.SocConfig, fault: str | None = None, vel: str = "fixed"):
    """Build the firmware (``fault``: the deliberately wrong one; ``vel``: its velocity
    estimator), run it, check it: (console, seconds, parsed run, check result, edge-FIFO check
    result or None, the soft-float routines it links)."""
    fw = simsoc.build_firmware(cfg, fault, vel)
    out, dt = simsoc.run(cfg, fw)
    run = check.parse(out)
    res, fifo = check.check_run(cfg.motions(), run)
    return out, dt, run, res, fifo, simsoc.soft_float_symbols(fw)


def verdict(res: check.Result, fifo: check.EfifoResult | None) -> tuple[bool, list]:
    """(every check passed, the failures) of one run."""
    fails = res.failures + (fifo.failures if fifo else [])
    return not fails, fails


def result_line(ok: bool, fails: list) -> str:
    """The "- result:" line of a run: pass, or FAIL with its first three failures."""
    return f"- result: {'pass' if ok else 'FAIL'}" + ("" if ok else
                                                      ": " + "; ".join(m for _, m in fails[:3]))


def cycles_table(run: check.Run) -> list[str]:
    period = run.build["period"]
    rows = ["| channels read | cycles min | mean | max | the channel's own: min | mean | max | "
            "max / period |", "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for k in sorted(run.cycles):
        lo, mean, hi = run.cycles[k]
        olo, omean, ohi = run.own.get(k, (0, 0, 0))
        rows.append(f"| {k} | {lo} | {mean} | {hi} | {olo} | {omean} | {ohi} | "
                    f"{100 * hi / period:.1f} % |")
    return rows


@dataclass
class PerChannel:
    """Handler cycles per channel of one run (snapshot read, velocity, record)."""
    mean: float        # (cycles to the last channel - the fixed part) / channels, means
    worst: float       # the same for the slowest snapshot (its total, the fixed part's minimum)
    fixed_max: int     # the handler's fixed part (TIMEBASE, IRQ_SUMMARY, EVENTS), at most

    @classmethod
    def of(cls, run: check.Run) -> PerChannel:
        n = max(run.cycles)
        return cls((run.cycles[n][1] - run.fixed_part[1]) / n,
                   (run.cycles[n][2] - run.fixed_part[0]) / n, run.fixed_part[2])

    def handler(self, channels: int) -> float:
        """A handler for ``channels`` channels by the worst case: its fixed part and the
        slowest per-channel cost."""
        return self.fixed_max + channels * self.worst


GOAL_PER_CHANNEL = 500      # cycles a channel, snapshot read plus velocity
GOAL_CHANNELS, GOAL_SHARE = 16, 0.20   # 16 channels at 1 kHz in 20 % of the CPU


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


def handler_section(fixed: check.Run, double: check.Run, fixed_sf: list,
                    double_sf: list) -> list[str]:
    """The handler-cycles section of the results: both estimators' tables and what they mean.
    ``*_sf``: the soft-float routines each firmware links."""
    clk, period = fixed.build["clk_hz"], fixed.build["period"]
    fx, db = PerChannel.of(fixed), PerChannel.of(double)
    n16 = fx.handler(GOAL_CHANNELS)
    lat = [r[2] for r in fixed.rows[1:]]
    # the slowest snapshots of the fixed point, per channel (the S lines: the handler's cycles)
    nch = max(fixed.cycles)
    slow = sorted(((r[3] - fixed.fixed_part[0]) / nch, r[0]) for r in fixed.rows[1:])[-2:]
    goal = (f"met on average ({fx.mean:.0f}) and in the slowest snapshot ({fx.worst:.0f})"
            if fx.worst <= GOAL_PER_CHANNEL else
            f"met on average ({fx.mean:.0f}); the slowest snapshot, {slow[-1][1]}, takes "
            f"{slow[-1][0]:.0f} a channel, the next slowest ({slow[0][1]}) {slow[0][0]:.0f}"
            if fx.mean <= GOAL_PER_CHANNEL else f"MISSED ({fx.mean:.0f} on average)")

    def fixed_part(run: check.Run) -> str:
        lo, _, hi = run.fixed_part
        return f"{lo} cycles" if lo == hi else f"{lo} to {hi} cycles"
    floats = ("none of compiler-rt's soft-float routines" if not fixed_sf
              else "soft-float routines: " + ", ".join(fixed_sf))
    return [
        "## Handler cycles per snapshot versus channels read",
        "",
        "CPU cycles (mcycle) from the handler's first instructions until channel k − 1 is done "
        "(its snapshot read through the driver: wait for its SNAP_READY, clear it and see it "
        "clear, five snapshot registers; its position and velocity; its record), over the "
        "snapshots after the first (which only initialises the estimators); *the channel's own* "
        "counts from the end of the channel before (for the first, from the end of the "
        "handler's fixed part: TIMEBASE, IRQ_SUMMARY, EVENTS). The trap entry and LiteX's "
        "interrupt dispatch before the handler are the latency below. Two builds of the same "
        "firmware that differ only in the velocity estimator, measured the same way:",
        "",
        f"**Fixed point** (the default): `qei_velfx_update_mt()` (`sw/enc_qei_velocity_fx.c`), "
        f"the timestamp method in integers, readings in 2^-{fixed.build['vel'][2:]} count/s. "
        f"The handler's fixed part takes {fixed_part(fixed)}.",
        "",
        *cycles_table(fixed),
        "",
        f"**Double** (`FW_VEL=double`): `qei_vel_update()` (`sw/enc_qei_velocity.c`), all three "
        f"methods in double precision, which this CPU (no FPU) runs in compiler-rt's software "
        f"floating point. The handler's fixed part takes {fixed_part(double)}.",
        "",
        *cycles_table(double),
        "",
        f"- Per channel (snapshot read, position, velocity, record): fixed point {fx.mean:.0f} "
        f"cycles on average and {fx.worst:.0f} in the slowest snapshot; double {db.mean:.0f} and "
        f"{db.worst:.0f}: {db.mean / fx.mean:.1f} times as many on average.",
        f"- Goal at most {GOAL_PER_CHANNEL} cycles a channel, by the fixed point: {goal}.",
        f"- {GOAL_CHANNELS} channels at 1 kHz by the worst case (the fixed part at its longest, "
        f"every channel at its slowest): fixed point {n16:,.0f} cycles of the {period:,} in a "
        f"period at {clk / 1e6:g} MHz, {100 * n16 / period:.1f} % (goal "
        f"{100 * GOAL_SHARE:.0f} %; the trap entry and dispatch add about the latency below); "
        f"double {db.handler(GOAL_CHANNELS):,.0f} cycles, "
        f"{100 * db.handler(GOAL_CHANNELS) / period:.0f} %: it fits "
        f"{int((period - db.fixed_max) // db.worst)} channels in the whole period.",
        f"- Interrupt latency, from the snapshot to the handler's first instructions (TIMEBASE "
        f"there minus GSNAP_TIME: the trap entry and LiteX's dispatch): {min(lat)} to {max(lat)} "
        f"clocks.",
        f"- Floating point: the fixed-point firmware links {floats} (`nm firmware.elf`); the "
        f"double one links {len(double_sf)} ({', '.join(double_sf)}).",
    ]


PROFILE_NAMES = {1: "counting", 2: "full", 3: "lean"}   # CAPS.PROFILE


def builds_table(results: dict) -> list[str]:
    """The handler's cycles in every run of the good firmware, side by side (one row per run)."""
    rows = ["| build | CAPS.ENGINE | channels, profile | estimator | fixed part (max) | "
            "a channel: mean | slowest snapshot | whole handler (max) | interrupt latency |",
            "|---|---|---|---|---:|---:|---:|---:|---:|"]
    for name, (cfg, run, *_rest) in results.items():
        b, pc = run.build, PerChannel.of(run)
        lat = [r[2] for r in run.rows[1:]]
        vel = "fixed point" if b["vel"].startswith("fx") else b["vel"]
        rows.append(f"| `{cfg.tag}` | {'shared' if b['engine'] else 'per_channel'} | "
                    f"{b['channels']}, {PROFILE_NAMES[b['profile']]} | {vel} | "
                    f"{run.fixed_part[2]} | {pc.mean:.0f} | {pc.worst:.0f} | "
                    f"{run.cycles[max(run.cycles)][2]} | {min(lat)} to {max(lat)} |")
    return rows


def engine_section(results: dict) -> list[str]:
    """The shared-engine builds (ENGINE_RUNS): their checks and handler cycles against MAIN's."""
    main = PerChannel.of(results["main"][1])
    lines = [
        "## The shared-engine builds",
        "",
        "The same SoC and firmware (fixed point) with the channels sharing one engine "
        "(`engine=1`: CAPS.ENGINE = 1), on lean and on full channels, the four motions. The "
        "engine may show a count step, an event and a snapshot some clocks later and lets a "
        "write act later (the bounds: CAPS.ENGINE in doc/enc_qei_regs.md); the driver waits for "
        "each channel's SNAP_READY, and a read of a channel waits until that channel's earlier "
        "writes are stored in the engine's memory, so the driver's clear of SNAP_READY followed "
        "by its read of SNAP_COUNT_LO stalls the CPU until the clear is stored.",
        "",
    ]
    for name in ENGINE_RUNS:
        cfg, run, res, _, _, _ = results[name]
        b, pc = run.build, PerChannel.of(run)
        lines += [
            f"**`{cfg.tag}`**: CAPS.PROFILE = {b['profile']} ({PROFILE_NAMES[b['profile']]}), "
            f"CAPS.ENGINE = {b['engine']}, {b['channels']} channels "
            f"(P = {24 * max(b['channels'], 2)} clocks).",
            "",
            *[f"- {s}" for s in res.summary],
            f"- handler: {pc.mean:.0f} cycles a channel on average, {pc.worst:.0f} in the slowest "
            f"snapshot ({pc.mean - main.mean:+.0f} and {pc.worst - main.worst:+.0f} against the "
            f"per_channel build `{results['main'][0].tag}`), the fixed part {run.fixed_part[0]} "
            f"to {run.fixed_part[2]}",
            result_line(res.ok, res.failures),
            "",
            *cycles_table(run),
            "",
        ]
    runs = [results[name][1] for name in ENGINE_RUNS]
    if all(r.cycles == runs[0].cycles and r.rows == runs[0].rows for r in runs[1:]):
        lines += ["The engine builds' handler cycles and interrupt latencies are the same to the "
                  "cycle: the firmware makes the same accesses on both profiles, and the engine's "
                  "timing (P, the waits) depends on CHANNELS alone.", ""]
    cfg, run, res, fifo, _, _ = results["engine_efifo"]
    b = run.build
    ok, fails = verdict(res, fifo)
    lines += [
        f"**`{cfg.tag}`**: the edge-FIFO build's channels and motions on the engine (CAPS.ENGINE = "
        f"{b['engine']}, CAPS.EFIFO_LOG2 = {b['efifo_log2']}, {b['channels']} channels; the FIFOs "
        "sit beside the engine, rtl/enc_qei_efifo_bank.v), the same firmware draining them:",
        "",
        *[f"- {s}" for s in res.summary + (fifo.summary if fifo else [])],
        result_line(ok, fails),
        "",
    ]
    return lines


def write_results(results: dict) -> None:
    """results: run name (RUNS) -> (config, run, check result, edge-FIFO result or None,
    fault -> its failures, soft-float routines)."""
    _, run, res, _, fault_fails, sf = results["main"]
    _, drun, dres, _, _, dsf = results["main_double"]
    b = run.build
    lines = [
        "<!-- written by scripts/soc_sim.py (make soc-sim); do not edit by hand -->",
        "",
        "# enc_qei in a simulated LiteX SoC: the firmware's figures",
        "",
        f"LiteX SoC in Verilator: VexRiscv (`full` variant, RV32IM, no FPU, 4 KiB instruction "
        f"and data caches) at a declared {b['clk_hz'] / 1e6:g} MHz, integrated ROM (the firmware) "
        f"and SRAM, `enc_qei_wb` with CAPS.CHANNELS = {b['channels']}, CAPS.PROFILE = "
        f"{b['profile']} (full), COUNT_W {b['count_w']}, TS_W {b['ts_w']}, TB_PRESCALE 0 (one "
        f"tick per clock). The global unit timer takes a snapshot of every channel each "
        f"{b['period']} ticks (1 kHz); the interrupt handler of `sw/soc/main.c` reads each "
        f"channel's part of it through the driver API (`sw/enc_qei_drv.c`) and computes its "
        f"velocity. {len(run.rows)} snapshots; the encoder inputs are the motions of "
        f"`tools/enctools/litex/motion.py` (doc/litex.md).",
        "",
        *handler_section(run, drun, sf, dsf),
        "",
        "## Checks against the motion model",
        "",
        "The fixed-point firmware:",
        "",
        *[f"- {s}" for s in res.summary],
        result_line(res.ok, res.failures),
        "",
        "The double firmware:",
        "",
        *[f"- {s}" for s in dres.summary],
        result_line(dres.ok, dres.failures),
        "",
    ]
    ecfg, erun, eres, efifo, efault_fails, _ = results["efifo"]
    ok, fails = verdict(eres, efifo)
    eb = erun.build
    lines += [
        "## The edge-FIFO build",
        "",
        f"The same SoC with CAPS.CHANNELS = {eb['channels']}, an edge FIFO of "
        f"{1 << eb['efifo_log2']} entries per channel (EFIFO_LOG2 {eb['efifo_log2']}) and the "
        f"motions {', '.join(m.name for m in ecfg.motions())} (the steady channel's 3.1 million "
        "steps per second is left out: see the cost per entry below). The same firmware (fixed "
        "point) finds the FIFO in CAPS, clears and enables it, and drains every channel's FIFO "
        "in its main loop between the snapshot interrupts; at the end it turns the FIFOs off "
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
        result_line(ok, fails),
        "",
        *engine_section(results),
        "## Every build",
        "",
        "The handler's CPU cycles in every run of the good firmware (the tables above: a channel "
        "is the snapshot read, the position, the velocity and the record; the interrupt latency "
        "in clocks from the snapshot to the handler's first instructions):",
        "",
        *builds_table(results),
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


# the runs: name -> (build, deliberately wrong firmware its checks must catch, estimator)
RUNS = {"main": (simsoc.MAIN, "page", "fixed"), "main_double": (simsoc.MAIN, None, "double"),
        "efifo": (simsoc.EFIFO, "efifo", "fixed"), "engine": (simsoc.ENGINE, None, "fixed"),
        "engine_full": (simsoc.ENGINE_FULL, None, "fixed"),
        "engine_efifo": (simsoc.ENGINE_EFIFO, None, "fixed")}
ENGINE_RUNS = ("engine", "engine_full")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="soc_sim.py", description=__doc__)
    ap.add_argument("--snapshots", type=int, default=simsoc.SocConfig.snapshots)
    ap.add_argument("--rebuild", action="store_true", help="rebuild the simulators even if current")
    ap.add_argument("--no-results", action="store_true", help=f"do not write {rel(RESULT_FILE)}")
    args = ap.parse_args(argv)
    if args.snapshots < 3:
        ap.error(f"--snapshots {args.snapshots}: give at least 3 (the first only initialises)")
    runs = {name: (dataclasses.replace(cfg, snapshots=args.snapshots), fault, vel)
            for name, (cfg, fault, vel) in RUNS.items()}
    t0 = time.monotonic()
    for cfg in {cfg for cfg, _, _ in runs.values()}:
        simsoc.build_gateware(cfg, force=args.rebuild)
    # the good firmware of every run and the wrong ones, two at a time (a simulator each)
    with ThreadPoolExecutor(max_workers=2) as pool:
        jobs = {(name, f): pool.submit(run_firmware, cfg, f, vel)
                for name, (cfg, fault, vel) in runs.items()
                for f in ((None, fault) if fault else (None,))}
    ok_all, results = True, {}
    for name, (cfg, fault, vel) in runs.items():
        out, dt, run, res, fifo, sf = jobs[(name, None)].result()
        tag = f"{cfg.tag} ({vel})"
        print("\n".join(line for line in out.replace("\r", "").splitlines()
                        if line.strip() and not line.startswith(("[", "-", "%"))))
        print(f"soc-sim: {tag}: firmware run {dt:.1f} s" if dt else
              f"soc-sim: {tag}: firmware run reused (cached)")
        for s in res.summary + (fifo.summary if fifo else []):
            print(f"soc-sim: {tag}: {s}")
        ok, fails = verdict(res, fifo)
        if vel == "fixed" and sf:
            ok, fails = False, fails + [("float", f"the fixed-point firmware links {sf}")]
        for _, m in fails:
            print(f"soc-sim: {tag}: FAIL: {m}")
        ffails = []
        if fault:
            fres = jobs[(name, fault)].result()
            fok, ffails = verdict(fres[3], fres[4])
            print(f"soc-sim: {tag}: FW_FAULT={fault} ({FAULTS[fault]}): the check "
                  + ("PASSES: it missed the fault" if fok else f"fails as it must: {ffails[0][1]}"))
            ok = ok and not fok
        ok_all &= ok and run.done
        results[name] = (cfg, run, res, fifo, {fault: ffails} if fault else {}, sf)
    if results["main"][1].done and results["main_double"][1].done:
        fx, db = PerChannel.of(results["main"][1]), PerChannel.of(results["main_double"][1])
        print(f"soc-sim: handler cycles per channel: fixed point {fx.mean:.0f} mean, "
              f"{fx.worst:.0f} worst; double {db.mean:.0f} mean, {db.worst:.0f} worst")
    if not args.no_results and all(r[1].done for r in results.values()):
        write_results(results)
        print(f"soc-sim: wrote {rel(RESULT_FILE)}")
    print(f"soc-sim: {time.monotonic() - t0:.0f} s in all")
    return 0 if ok_all else 1


if __name__ == "__main__":
    sys.exit(main())
