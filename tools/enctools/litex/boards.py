# SPDX-License-Identifier: Apache-2.0
"""``make soc-bitstream BOARD=...``: the LiteX SoC with enc_qei on an FPGA board, through Yosys and
nextpnr (the YoWASP builds of requirements.txt, under their plain names by scripts/bin), and its
row in doc/results/soc_bitstream.md.

- ``icebreaker``: iCE40 UP5K. VexRiscv ``minimal`` (RV32I, no caches), one lean channel with a
  16-bit timebase on PMOD1A (A, B, Z), 64 KiB of SRAM in the SPRAM, an 8 KiB ROM of block RAM at
  12 MHz (two lean channels need 5,980 logic cells of the 5,280). The ROM holds no program:
  sw/soc (about 12.5 KiB with printf, and it reads mcycle, which ``minimal`` lacks) does not fit
  the UP5K's 15 KiB of block RAM; the row is the SoC's size and speed.
- ``colorlight_i5``: ECP5 LFE5U-25F. VexRiscv ``full``, 8 lean channels (A and B on the two PMODs
  of the extension board, no index), 16 KiB of ROM holding sw/soc, 64 KiB of SRAM, at 60 MHz
  from the PLL (the 1 kHz handler needs about 500 cycles per channel with the fixed-point
  estimator, doc/results/soc_sim.md).

The pins are the boards' (their published pinouts); no board is at hand here, so the bitstreams
are built and measured, not run.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass

from .. import toolenv
from ..paths import BUILD, RESULTS, TOP, rel
from . import add_enc_qei, simsoc

RESULT_FILE = RESULTS / "soc_bitstream.md"


@dataclass(frozen=True)
class Board:
    name: str
    device: str
    toolchain: str
    clk: tuple            # (io name, pin, Hz)
    serial: tuple         # (tx, rx)
    encoders: tuple       # per channel: (a, b) or (a, b, z) pins
    cpu_variant: str
    profile: str
    ts_w: int
    sys_hz: int
    rom_size: int
    sram: str             # "spram" (UP5K) or "bram"
    firmware: bool


BOARDS = {
    "icebreaker": Board(
        "icebreaker", "ice40-up5k-sg48", "icestorm", ("clk12", "35", 12_000_000), ("9", "6"),
        (("4", "2", "47"),), "minimal", "lean", 16, 12_000_000, 0x2000,
        "spram", False),
    "colorlight_i5": Board(
        "colorlight_i5", "LFE5U-25F-6BG381C", "trellis", ("clk25", "P3", 25_000_000),
        ("J17", "H18"),
        tuple(zip("C17 B20 A18 B19 D1 C2 E2 B1".split(), "B18 F20 A19 D20 C1 E3 D2 A3".split())),
        "full", "lean", 32, 60_000_000, 0x4000, "bram", True),
}


def make_soc(board: Board):
    from migen import ClockDomain, Module

    from litex.build.generic_platform import IOStandard, Pins, Subsignal
    from litex.build.io import CRG
    from litex.build.lattice import LatticePlatform
    from litex.soc.integration.soc import SoCRegion
    from litex.soc.integration.soc_core import SoCCore

    n = len(board.encoders)
    io = [
        (board.clk[0], 0, Pins(board.clk[1]), IOStandard("LVCMOS33")),
        ("serial", 0, Subsignal("tx", Pins(board.serial[0])),
         Subsignal("rx", Pins(board.serial[1])), IOStandard("LVCMOS33")),
        ("encoders", 0,
         Subsignal("a", Pins(" ".join(e[0] for e in board.encoders))),
         Subsignal("b", Pins(" ".join(e[1] for e in board.encoders))),
         *([Subsignal("z", Pins(" ".join(e[2] for e in board.encoders)))]
           if all(len(e) > 2 for e in board.encoders) else []),
         IOStandard("LVCMOS33")),
    ]
    platform = LatticePlatform(board.device, io, toolchain=board.toolchain)

    class BoardSoC(SoCCore):
        def __init__(self):
            clk = platform.request(board.clk[0])
            if board.sys_hz == board.clk[2]:
                self.crg = CRG(clk)
            else:
                from litex.soc.cores.clock import ECP5PLL
                self.crg = Module()
                self.crg.clock_domains.cd_sys = ClockDomain()
                self.crg.submodules.pll = pll = ECP5PLL()
                pll.register_clkin(clk, board.clk[2])
                pll.create_clkout(self.crg.cd_sys, board.sys_hz)
            platform.add_period_constraint(clk, 1e9 / board.clk[2])
            SoCCore.__init__(
                self, platform, clk_freq=board.sys_hz, ident=f"enc_qei on {board.name}",
                cpu_type="vexriscv", cpu_variant=board.cpu_variant,
                integrated_rom_size=board.rom_size,
                integrated_rom_init=[0] * (board.rom_size // 4),
                integrated_sram_size=0 if board.sram == "spram" else 0x10000)
            if board.sram == "spram":
                from litex.soc.cores.ram.lattice_ice40 import Up5kSPRAM
                self.spram = Up5kSPRAM(size=0x10000)
                self.bus.add_slave("sram", self.spram.bus, SoCRegion(size=0x10000))
            pads = platform.request("encoders")
            add_enc_qei(self, name="enc_qei", pads=pads, channels=n, profile=board.profile,
                        ts_w=board.ts_w)

    return BoardSoC()


def _parse(log: str, family: str) -> dict:
    cells = {}
    for m in re.finditer(r"Info:\s+(\w+):\s+(\d+)/\s*(\d+)\s+(\d+)%", log):
        cells[m.group(1)] = (int(m.group(2)), int(m.group(3)))
    fmax = [(m.group(1), float(m.group(2)), float(m.group(3)))
            for m in re.finditer(r"Max frequency for clock\s+'([^']+)':\s+([\d.]+) MHz "
                                 r"\((?:PASS|FAIL) at ([\d.]+) MHz\)", log)]
    keys = (("ICESTORM_LC", "ICESTORM_RAM", "ICESTORM_SPRAM", "SB_IO") if family == "ice40"
            else ("TRELLIS_COMB", "TRELLIS_FF", "DP16KD", "TRELLIS_IO"))
    return {"cells": {k: cells[k] for k in keys if k in cells},
            "fmax": fmax[-1][1] if fmax else None, "target": fmax[-1][2] if fmax else None}


def build(board: Board) -> dict:
    from litex.soc.integration.builder import Builder

    out = BUILD / f"soc_{board.name}"
    env = toolenv.simulator_env()
    os.environ.update(env)
    out.mkdir(parents=True, exist_ok=True)
    log = out / "build.log"
    t0 = time.monotonic()
    print(f"soc-bitstream: {board.name}: LiteX (Verilog{', libraries' if board.firmware else ''})"
          f" in {rel(out)}", flush=True)
    with open(log, "w") as fh, simsoc.output_to(fh):
        soc = make_soc(board)
        builder = Builder(soc, output_dir=str(out), compile_gateware=False,
                          compile_software=board.firmware)
        keep = ("libc", "libcompiler_rt", "libbase")
        builder.software_packages = [p for p in builder.software_packages if p[0] in keep]
        builder.software_libraries = [x for x in builder.software_libraries if x in keep]
        builder.build(run=False)
    gw = out / "gateware"
    if board.firmware:
        fw = _firmware(out)
        rom = next(gw.glob("*_rom.init"))
        rom.write_text("".join(f"{w:08x}\n" for w in _words(fw, board.rom_size)))
    print(f"soc-bitstream: {board.name}: Yosys and nextpnr (log {rel(log)}); this takes minutes",
          flush=True)
    script = next(gw.glob("build_*.sh"))
    # YoWASP's nextpnr has no Python: the clock goes to nextpnr-ice40 as --freq instead of
    # LiteX's --pre-pack script (for the ECP5, LiteX writes it into the .lpf)
    text = script.read_text()
    script.write_text(re.sub(r"--pre-pack \S+", f"--freq {board.sys_hz / 1e6:g}", text))
    with open(log, "a") as fh:
        r = subprocess.run(["bash", script.name], cwd=gw, stdout=fh, stderr=subprocess.STDOUT,
                           env={**os.environ, **env})
    dt = time.monotonic() - t0
    text = log.read_text(errors="replace")
    bit = next(iter(sorted(gw.glob("*.bin")) + sorted(gw.glob("*.bit"))), None)
    if r.returncode != 0 or bit is None:
        raise SystemExit(f"soc-bitstream: {board.name}: the build failed; see {log}")
    res = _parse(text, "ice40" if board.toolchain == "icestorm" else "ecp5")
    res.update(board=board.name, seconds=round(dt), bitstream=rel(bit))
    (out / "result.json").write_text(json.dumps(res, indent=1))
    return res


def _firmware(out):
    fw_dir = out / "firmware"
    fw_dir.mkdir(exist_ok=True)
    r = subprocess.run(["make", "-s", "-C", str(fw_dir), "-f",
                        str(simsoc.FIRMWARE_SRC / "Makefile"), f"BUILD_DIR={out}"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"soc-bitstream: firmware build failed:\n{r.stdout}{r.stderr}")
    return fw_dir / "firmware.bin"


def _words(fw, size):
    data = fw.read_bytes()
    if len(data) > size:
        raise SystemExit(f"soc-bitstream: {fw} is {len(data)} bytes; the ROM holds {size}")
    data += bytes(-len(data) % 4)
    words = [int.from_bytes(data[i:i + 4], "little") for i in range(0, len(data), 4)]
    return words + [0] * (size // 4 - len(words))


def _row(board: Board, res: dict) -> str:
    c = res["cells"]

    def use(k):
        return f"{c[k][0]} / {c[k][1]}" if k in c else "—"

    if board.toolchain == "icestorm":
        logic, ff, ram = use("ICESTORM_LC"), "(in LC)", \
            f"{use('ICESTORM_RAM')} EBR, {use('ICESTORM_SPRAM')} SPRAM"
    else:
        logic, ff, ram = use("TRELLIS_COMB"), use("TRELLIS_FF"), f"{use('DP16KD')} DP16KD"
    fw = "sw/soc" if board.firmware else "none (does not fit)"
    fmax = f"{res['fmax']:.1f}" if res["fmax"] else "—"
    return (f"| {board.name} | {board.device} | VexRiscv {board.cpu_variant} | "
            f"{len(board.encoders)} × {board.profile}, TS_W {board.ts_w} | {logic} | {ff} | "
            f"{ram} | {board.sys_hz / 1e6:g} | {fmax} | {fw} | {res['seconds']} s |")


def write_results(board: Board, res: dict) -> None:
    head = ["<!-- written by scripts/soc_bitstream.py (make soc-bitstream); do not edit by "
            "hand -->", "", "# enc_qei in a LiteX SoC on FPGA boards: size and speed", "",
            "Yosys and nextpnr (YoWASP, seed 1) on the SoCs of `tools/enctools/litex/boards.py` "
            "(doc/litex.md). Logic: LUT4 cells (iCE40 logic cells hold one LUT4 and its "
            "flip-flop); Fmax: nextpnr's estimate for the sys clock after routing; time: the "
            "whole build on the project's 2-core machine.", "",
            "| board | device | CPU | channels | logic | FF | block RAM | sys MHz | Fmax MHz | "
            "ROM program | build |", "|---|---|---|---|---:|---:|---|---:|---:|---|---:|"]
    rows = {}
    if RESULT_FILE.exists():
        for line in RESULT_FILE.read_text().splitlines():
            cells = [x.strip() for x in line.split("|")]
            if len(cells) > 2 and cells[1] in BOARDS:
                rows[cells[1]] = line
    rows[board.name] = _row(board, res)
    RESULT_FILE.write_text("\n".join(head + [rows[b] for b in BOARDS if b in rows]) + "\n")


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog="soc_bitstream.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--board", required=True, choices=sorted(BOARDS))
    args = ap.parse_args(argv)
    board = BOARDS[args.board]
    res = build(board)
    print(f"soc-bitstream: {board.name}: {res['bitstream']} in {res['seconds']} s; "
          f"{res['cells']}; Fmax {res['fmax']} MHz (target {res['target']} MHz)")
    write_results(board, res)
    print(f"soc-bitstream: wrote {rel(RESULT_FILE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
