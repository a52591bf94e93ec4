# SPDX-License-Identifier: Apache-2.0
"""``make soc-bitstream BOARD=...``: the LiteX SoC with enc_qei on an FPGA board, through Yosys and
nextpnr (the YoWASP builds of requirements.txt, under their plain names by scripts/bin), and its
row in doc/results/soc_bitstream.md.

- ``icebreaker``: iCE40 UP5K. VexRiscv ``minimal`` (RV32I, no caches), one lean channel with a
  16-bit timebase on PMOD1A (A, B, Z), 64 KiB of SRAM in the SPRAM, an 8 KiB ROM of block RAM at
  12 MHz (two lean channels need 5,980 logic cells of the 5,280). The ROM holds no program:
  sw/soc (about 12.5 KiB with printf, and it reads mcycle, which ``minimal`` lacks) does not fit
  the UP5K's 15 KiB of block RAM; the row is the SoC's size and speed.
- ``icebreaker_engine``: the same SoC with 8 lean channels that share one engine (ENGINE 1; A on
  PMOD1A, B on PMOD1B, no index), TS_W 32, and sw/soc in the SPI flash instead of a ROM (the
  engine's state memory takes most of the block RAM): the CPU runs it in place from the flash
  (LiteSPI, memory-mapped, 1x), as LiteX's own iCEBreaker target runs its BIOS; the firmware is
  programmed at FLASH_OFFSET beside the bitstream (``iceprog -o 0x40000 firmware.bin``).
- ``colorlight_i5``: ECP5 LFE5U-25F. VexRiscv ``full``, 8 lean channels (A and B on the two PMODs
  of the extension board, no index), 16 KiB of ROM holding sw/soc, 64 KiB of SRAM, at 60 MHz
  from the PLL (the 1 kHz handler needs about 500 cycles per channel with the fixed-point
  estimator, doc/results/soc_sim.md).
- ``colorlight_i5_engine``: VexRiscv ``lite``, 16 full channels that share one engine (A and B
  on the extension board's P3A, P3B, P2A and P4B), 16 KiB of ROM holding sw/soc (built with 20
  snapshot records), 16 KiB of SRAM, at 50 MHz (placed and routed at 60 MHz it reached 51.7; the
  SoC simulation of `make soc-sim` declares 50 MHz too): the engine's state memory takes 32 of the
  56 DP16KD, and ``full`` or 32 KiB of SRAM need more than the rest.

``--ts-w``, ``--channels``, ``--cpu-variant`` and ``--sram-kib`` change a board's build for a try
(its row says what was built). A build that does not fit its part is a row too: what it needed,
from nextpnr's report of the failed placement.

The pins are the boards' (their published pinouts; the Colorlight i5's extension board v1.2);
no board is at hand here, so the bitstreams are built and measured, not run.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, replace

from .. import core, toolenv
from ..paths import BUILD, RESULTS, TOP, rel
from . import add_enc_qei, simsoc

RESULT_FILE = RESULTS / "soc_bitstream.md"


FLASH_OFFSET = 0x40000  # the firmware's place in the SPI flash, past the bitstream (as LiteX's BIOS)
FLASH_SIZE = 0x10000    # the part of the flash the firmware is linked for (the "rom" region)

# the boards' pins
ICEBREAKER_CLK, ICEBREAKER_SERIAL = ("clk12", "35", 12_000_000), ("9", "6")
ICEBREAKER_FLASH = ("16", "15", "14", "17")  # cs_n, clk, mosi, miso (W25Q128JV)
ICEBREAKER_PMOD1A = "4 2 47 45 3 48 46 44".split()
ICEBREAKER_PMOD1B = "43 38 34 31 42 36 32 28".split()
COLORLIGHT_CLK, COLORLIGHT_SERIAL = ("clk25", "P3", 25_000_000), ("J17", "H18")
# (A, B) per channel: neighbouring pins of P3B, P3A (the first 8), P2A and P4B
COLORLIGHT_AB = tuple(zip("C17 B20 A18 B19 D1 C2 E2 B1 J20 M18 G20 L20 H4 F1 H3 E4".split(),
                          "B18 F20 A19 D20 C1 E3 D2 A3 L18 N17 K20 N18 G3 F2 F3 E1".split()))


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
    rom_size: int         # the integrated ROM of block RAM (0: none)
    sram: str             # "spram" (UP5K) or "bram"
    firmware: str         # sw/soc: "rom" (in the ROM, in the bitstream), "flash" (run from the
                          # SPI flash at FLASH_OFFSET) or "" (none)
    engine: int = 0       # enc_qei's ENGINE
    sram_size: int = 0x10000
    fw_snapshots: int = 0  # sw/soc's ENC_FW_SNAPSHOTS (its records take SRAM), 0: its default
    spiflash: tuple = ()  # (cs_n, clk, mosi, miso) pins, for firmware "flash"


BOARDS = {
    "icebreaker": Board(
        "icebreaker", "ice40-up5k-sg48", "icestorm", ICEBREAKER_CLK, ICEBREAKER_SERIAL,
        (("4", "2", "47"),), "minimal", "lean", 16, 12_000_000, 0x2000, "spram", ""),
    "icebreaker_engine": Board(
        "icebreaker_engine", "ice40-up5k-sg48", "icestorm", ICEBREAKER_CLK, ICEBREAKER_SERIAL,
        tuple(zip(ICEBREAKER_PMOD1A, ICEBREAKER_PMOD1B)), "minimal", "lean", 32, 12_000_000, 0,
        "spram", "flash", engine=1, spiflash=ICEBREAKER_FLASH),
    "colorlight_i5": Board(
        "colorlight_i5", "LFE5U-25F-6BG381C", "trellis", COLORLIGHT_CLK, COLORLIGHT_SERIAL,
        COLORLIGHT_AB[:8], "full", "lean", 32, 60_000_000, 0x4000, "bram", "rom"),
    "colorlight_i5_engine": Board(
        "colorlight_i5_engine", "LFE5U-25F-6BG381C", "trellis", COLORLIGHT_CLK, COLORLIGHT_SERIAL,
        COLORLIGHT_AB, "lite", "full", 32, 50_000_000, 0x4000, "bram", "rom", engine=1,
        sram_size=0x4000, fw_snapshots=20),
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
    if board.spiflash:
        io.append(("spiflash", 0, *(Subsignal(k, Pins(p)) for k, p in
                                    zip(("cs_n", "clk", "mosi", "miso"), board.spiflash)),
                   IOStandard("LVCMOS33")))
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
            rom = dict(integrated_rom_size=board.rom_size,
                       integrated_rom_init=[0] * (board.rom_size // 4)) if board.rom_size else {}
            SoCCore.__init__(
                self, platform, clk_freq=board.sys_hz, ident=f"enc_qei on {board.name}",
                cpu_type="vexriscv", cpu_variant=board.cpu_variant, **rom,
                integrated_sram_size=0 if board.sram == "spram" else board.sram_size)
            if board.sram == "spram":
                from litex.soc.cores.ram.lattice_ice40 import Up5kSPRAM
                self.spram = Up5kSPRAM(size=board.sram_size)
                self.bus.add_slave("sram", self.spram.bus, SoCRegion(size=board.sram_size))
            if board.firmware == "flash":
                # the firmware runs in place from the SPI flash: its "rom" region is there
                from litespi.modules import W25Q128JV
                from litespi.opcodes import SpiNorFlashOpCodes
                self.add_spi_flash(mode="1x", module=W25Q128JV(SpiNorFlashOpCodes.READ_1_1_1),
                                   with_master=False)
                self.bus.add_region("rom", SoCRegion(
                    origin=self.bus.regions["spiflash"].origin + FLASH_OFFSET, size=FLASH_SIZE,
                    linker=True))
                self.cpu.set_reset_address(self.bus.regions["rom"].origin)
                self.integrated_rom_initialized = True  # (LiteX's BIOS is not built: sw/soc is)
            pads = platform.request("encoders")
            add_enc_qei(self, name="enc_qei", pads=pads, channels=n, profile=board.profile,
                        ts_w=board.ts_w, **({"engine": board.engine} if board.engine else {}))

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
    """LiteX, the firmware, Yosys and nextpnr: the result (cells used of the part's, Fmax, build
    time, bitstream; ``fits`` False when nextpnr could not place the design)."""
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
                          compile_software=bool(board.firmware))
        keep = ("libc", "libcompiler_rt", "libbase")
        builder.software_packages = [p for p in builder.software_packages if p[0] in keep]
        builder.software_libraries = [x for x in builder.software_libraries if x in keep]
        builder.build(run=False)
    gw = out / "gateware"
    for old in list(gw.glob("*.bin")) + list(gw.glob("*.bit")):
        old.unlink()  # a bitstream of an earlier build is not this one's
    fw_bytes = None
    if board.firmware:
        fw = _firmware(out, board.fw_snapshots)
        fw_bytes = fw.stat().st_size
        if board.firmware == "rom":
            rom = next(gw.glob("*_rom.init"))
            rom.write_text("".join(f"{w:08x}\n" for w in _words(fw, board.rom_size)))
        elif fw_bytes > FLASH_SIZE:
            raise SystemExit(f"soc-bitstream: {fw} is {fw_bytes} bytes; its flash region holds {FLASH_SIZE}")
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
    res = _parse(text, "ice40" if board.toolchain == "icestorm" else "ecp5")
    res.update(board=board.name, seconds=round(dt), bitstream=rel(bit) if bit else None,
               firmware_bytes=fw_bytes, fits=True)
    if r.returncode != 0 or bit is None:
        # a design larger than the part: nextpnr has reported what it needs, then stopped
        over = [k for k, (used, avail) in res["cells"].items() if used > avail]
        if not over:
            raise SystemExit(f"soc-bitstream: {board.name}: the build failed; see {log}")
        res["fits"] = False
        res["fmax"] = None
    (out / "result.json").write_text(json.dumps(res, indent=1))
    return res


def _firmware(out, snapshots: int):
    fw_dir = out / "firmware"
    fw_dir.mkdir(exist_ok=True)
    r = subprocess.run(["make", "-s", "-B", "-C", str(fw_dir), "-f",
                        str(simsoc.FIRMWARE_SRC / "Makefile"), f"BUILD_DIR={out}",
                        *([f"FW_SNAPSHOTS={snapshots}"] if snapshots else [])],
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


COLUMNS = ["board", "device", "CPU", "channels", "logic", "FF", "block RAM", "sys MHz", "Fmax MHz",
           "program", "build"]
KEY_COLUMNS = (0, 2, 3, 9)  # a row is replaced by a build of the same board, CPU, channels, program


def _row(board: Board, res: dict) -> str:
    c = res["cells"]

    def use(k):
        return f"{c[k][0]:,} / {c[k][1]:,} ({100 * c[k][0] / c[k][1]:.0f} %)" if k in c else "—"

    if board.toolchain == "icestorm":
        logic, ff, ram = use("ICESTORM_LC"), "(in LC)", \
            f"{use('ICESTORM_RAM')} EBR, {use('ICESTORM_SPRAM')} SPRAM"
    else:
        logic, ff, ram = use("TRELLIS_COMB"), use("TRELLIS_FF"), f"{use('DP16KD')} DP16KD"
    if not res.get("fits", True):
        logic = f"**does not fit**: {logic}"
    kb = f"{res['firmware_bytes'] / 1024:.1f} KiB" if res.get("firmware_bytes") else ""
    if board.fw_snapshots:
        kb += f", {board.fw_snapshots} snapshots"
    fw = {"rom": f"sw/soc in ROM ({kb})",
          "flash": f"sw/soc in SPI flash at {FLASH_OFFSET:#x} ({kb}), run in place",
          "": "none"}[board.firmware]
    fw += f"; {board.sram_size // 1024} KiB SRAM"
    fmax = f"{res['fmax']:.1f}" if res["fmax"] else "—"
    arch = ", shared engine" if board.engine else ""
    return (f"| {board.name} | {board.device} | VexRiscv {board.cpu_variant} | "
            f"{len(board.encoders)} × {board.profile}{arch}, TS_W {board.ts_w} | {logic} | {ff} | "
            f"{ram} | {board.sys_hz / 1e6:g} | {fmax} | {fw} | {res['seconds']} s |")


def _key(line: str) -> tuple | None:
    """(board, CPU, channels, program, SRAM) of a row; the program by its first word (sw/soc or
    none), the SRAM as the row states it (None: a row that does not)."""
    cells = [x.strip() for x in line.strip().strip("|").split("|")]
    if len(cells) != len(COLUMNS) or cells[0] not in BOARDS:
        return None
    sram = re.search(r"(\d+) KiB SRAM", cells[9])
    return (*(cells[i].split(" (")[0] if i != 9 else cells[i].split()[0] for i in KEY_COLUMNS),
            sram and sram.group(1))


def write_results(board: Board, res: dict) -> None:
    head = ["<!-- written by scripts/soc_bitstream.py (make soc-bitstream); do not edit by "
            "hand -->", "", "# enc_qei in a LiteX SoC on FPGA boards: size and speed", "",
            "Yosys and nextpnr (YoWASP, seed 1) on the SoCs of `tools/enctools/litex/boards.py` "
            "(doc/litex.md), one row per build (a board's defaults, or a try with other "
            "`--ts-w`, `--channels`, `--cpu-variant` or `--sram-kib`). Logic: LUT4 cells used of "
            "the part's "
            "(iCE40 logic cells hold one LUT4 and its flip-flop; ECP5 TRELLIS_COMB); a build that "
            "does not fit shows what nextpnr found it needs before it stopped. Fmax: nextpnr's "
            "estimate for the sys clock after routing; time: the whole build on the project's "
            "2-core machine.", "",
            "| " + " | ".join(COLUMNS) + " |", "|---|---|---|---|---:|---:|---|---:|---:|---|---:|"]
    new = _row(board, res)
    rows = []
    if RESULT_FILE.exists():
        rows = [line for line in RESULT_FILE.read_text().splitlines()
                if _key(line) is not None and _key(line) != _key(new)]
    rows.append(new)
    order = list(BOARDS)
    rows.sort(key=lambda line: order.index(_key(line)[0]))  # stable: a board's rows as written
    RESULT_FILE.write_text("\n".join(head + rows) + "\n")


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog="soc_bitstream.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--board", required=True, choices=list(BOARDS))
    ap.add_argument("--ts-w", type=int, metavar="N", help="enc_qei's TS_W instead of the board's")
    ap.add_argument("--channels", type=int, metavar="N",
                    help="the first N of the board's channels (its pins) instead of all")
    ap.add_argument("--cpu-variant", metavar="NAME", help="VexRiscv variant instead of the board's")
    ap.add_argument("--sram-kib", type=int, metavar="N", help="KiB of SRAM instead of the board's")
    args = ap.parse_args(argv)
    board = BOARDS[args.board]
    if args.channels is not None and not 1 <= args.channels <= len(board.encoders):
        ap.error(f"--channels {args.channels}: {board.name} has pins for 1 to {len(board.encoders)}")
    if args.ts_w is not None and not core.param_range("TS_W").ok(args.ts_w):
        ap.error(f"--ts-w {args.ts_w} is outside {core.param_range('TS_W').text()} (enc_ip.core)")
    if args.cpu_variant is not None:
        from litex.soc.cores.cpu.vexriscv.core import CPU_VARIANTS
        if args.cpu_variant not in CPU_VARIANTS:
            ap.error(f"--cpu-variant {args.cpu_variant}: not one of {', '.join(CPU_VARIANTS)}")
    if args.sram_kib is not None and (args.sram_kib < 1 or args.sram_kib & (args.sram_kib - 1) or
                                      (board.sram == "spram" and args.sram_kib not in (64, 128))):
        ap.error(f"--sram-kib {args.sram_kib}: "
                 f"{'64 or 128 (the UP5K SPRAM)' if board.sram == 'spram' else 'a power of two'}")
    board = replace(board, ts_w=args.ts_w or board.ts_w,
                    sram_size=(args.sram_kib or board.sram_size // 1024) * 1024,
                    encoders=board.encoders[:args.channels or len(board.encoders)],
                    cpu_variant=args.cpu_variant or board.cpu_variant)
    res = build(board)
    fit = "" if res["fits"] else " DOES NOT FIT"
    print(f"soc-bitstream: {board.name}:{fit} {res['bitstream'] or 'no bitstream'} in {res['seconds']} s; "
          f"{res['cells']}; Fmax {res['fmax']} MHz (target {res['target']} MHz)")
    write_results(board, res)
    print(f"soc-bitstream: wrote {rel(RESULT_FILE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
