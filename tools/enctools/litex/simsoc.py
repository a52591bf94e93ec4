# SPDX-License-Identifier: Apache-2.0
"""The simulated LiteX SoC with enc_qei: build it, build its firmware, run it.

The SoC: VexRiscv (the ``full`` variant, which has the mcycle counter), integrated ROM and SRAM,
the UART on the simulator's console, LiteX's sim platform (Verilator), and ``EncQEI`` whose
encoder inputs come from ``motion.MotionGen``: a deterministic motion per channel.

Three steps, each cached:

- ``build_gateware(cfg)``: LiteX generates the Verilog, the sim's C++ and the software headers,
  compiles its libraries (picolibc, compiler-rt, libbase; not the BIOS) and Verilator builds the
  simulator. The ROM is built with a placeholder of zeros: Verilator reads the ROM's contents
  from ``sim_rom.init`` when the simulation starts, so a new firmware needs no new simulator.
  Skipped when the inputs (the IP's Verilog, this package, the configuration, the tool versions)
  are those of the last build.
- ``build_firmware(cfg, fault, vel)``: ``make`` of sw/soc against that build (``vel``: the
  fixed-point or the double velocity estimator).
- ``run(cfg, firmware)``: a folder per firmware with the simulator's files and the firmware as
  ``sim_rom.init``; the simulator runs until the firmware ends it. The console output is kept,
  and reused while the simulator and the firmware are unchanged.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from .. import core, toolenv
from ..paths import BUILD, SW, TOP
from . import motion, verilog_files

SOC_BUILD = BUILD / "soc_sim"
FIRMWARE_SRC = SW / "soc"
ROM_SIZE = 0x10000
SRAM_SIZE = 0x10000


@dataclass(frozen=True)
class SocConfig:
    channels: int = 4
    profile: str = "full"
    clk_hz: int = 50_000_000     # the declared sys clock: 1 timebase tick = 20 ns
    snapshots: int = 100         # global snapshots the firmware records (one per ms)
    opt_level: str = "O3"        # C++ optimisation of the Verilated model
    efifo_log2: int = 0          # the edge FIFO of every channel: 2^efifo_log2 entries, 0 none
    engine: int = 0              # 1: the channels share one engine (CAPS.ENGINE = shared)
    motion_names: tuple = ()     # the channels' motions by name (motion.profiles); () all four

    @property
    def tag(self) -> str:
        return (f"ch{self.channels}_{self.profile}"
                + (f"_efifo{self.efifo_log2}" if self.efifo_log2 else "")
                + ("_engine" if self.engine else ""))

    @property
    def out(self) -> Path:
        return SOC_BUILD / self.tag

    def motions(self) -> list[motion.Motion]:
        base = motion.profiles(self.clk_hz)
        if self.motion_names:
            by_name = {m.name: m for m in base}
            base = [by_name[n] for n in self.motion_names]
        return [base[k % len(base)] for k in range(self.channels)]


# the builds `make soc-sim` runs: the 4 motions without an edge FIFO; an edge-FIFO build whose
# firmware drains every channel's FIFO (without the steady channel's 3.1 million steps per
# second, which no firmware on this CPU could drain: doc/litex.md); the 4 motions on lean and on
# full channels that share one engine; the edge-FIFO build's channels and motions on the engine
# (its FIFOs beside the engine)
MAIN = SocConfig()
EFIFO = SocConfig(channels=3, efifo_log2=8, motion_names=("ramp", "reversal", "slow"))
ENGINE = SocConfig(profile="lean", engine=1)
ENGINE_FULL = SocConfig(profile="full", engine=1)
ENGINE_EFIFO = replace(EFIFO, engine=1)


def _log(msg: str) -> None:
    print(f"soc-sim: {msg}", flush=True)


# --- the SoC --------------------------------------------------------------------------------------

def make_soc(cfg: SocConfig):
    """The LiteX SoC object (imports LiteX only here: the rest of enctools does not need it)."""
    from litex.build.generic_platform import Pins, Subsignal
    from litex.build.io import CRG
    from litex.build.sim import SimPlatform
    from litex.build.sim.platform import SimFinish
    from litex.soc.integration.soc_core import SoCCore

    from . import add_enc_qei

    io = [
        ("sys_clk", 0, Pins(1)),
        ("sys_rst", 0, Pins(1)),
        ("serial", 0,
            Subsignal("source_valid", Pins(1)), Subsignal("source_ready", Pins(1)),
            Subsignal("source_data", Pins(8)),
            Subsignal("sink_valid", Pins(1)), Subsignal("sink_ready", Pins(1)),
            Subsignal("sink_data", Pins(8))),
    ]

    class EncSimSoC(SoCCore):
        def __init__(self):
            platform = SimPlatform("SIM", io)
            self.crg = CRG(platform.request("sys_clk"))
            SoCCore.__init__(
                self, platform, clk_freq=cfg.clk_hz, ident="enc_qei LiteX simulation",
                cpu_type="vexriscv", cpu_variant="full",
                integrated_rom_size=ROM_SIZE, integrated_rom_init=[0] * (ROM_SIZE // 4),
                integrated_sram_size=SRAM_SIZE, uart_name="sim")
            self.motion = motion.MotionGen(cfg.motions()).module()
            add_enc_qei(self, name="enc_qei", pads=self.motion, channels=cfg.channels,
                        profile=cfg.profile, efifo_log2=cfg.efifo_log2, engine=cfg.engine)
            self.sim_finish = SimFinish()

    return EncSimSoC()


def _versions() -> dict:
    from importlib.metadata import version

    out = {p: version(p) for p in ("litex", "migen", "pythondata-cpu-vexriscv")}
    out["verilator"] = subprocess.run(["verilator", "--version"], capture_output=True, text=True,
                                      env={**os.environ, **toolenv.simulator_env()}).stdout.strip()
    return out


def gateware_key(cfg: SocConfig) -> str:
    h = hashlib.sha256()
    here = Path(__file__).parent
    # what the simulator is made of: the IP's Verilog, the SoC and the motion (not the checks)
    files = [TOP / f for f in verilog_files()]
    files += [here / n for n in ("__init__.py", "motion.py", "simsoc.py")]
    files += [TOP / f for f in core.include_files()]
    for f in files:
        h.update(f.name.encode() + f.read_bytes())
    build_cfg = {k: v for k, v in asdict(cfg).items() if k != "snapshots"}
    h.update(json.dumps([build_cfg, _versions()], sort_keys=True).encode())
    return h.hexdigest()


@contextlib.contextmanager
def output_to(fh):
    """Send this process's stdout and stderr (file descriptors 1 and 2, so also the output of its
    child processes) to the open file ``fh``."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    os.dup2(fh.fileno(), 1)
    os.dup2(fh.fileno(), 2)
    try:
        yield
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])


def _gateware(cfg: SocConfig) -> Path:
    return cfg.out / "gateware"


def simulator(cfg: SocConfig) -> Path:
    return _gateware(cfg) / "obj_dir" / "Vsim"


def build_gateware(cfg: SocConfig, force: bool = False) -> float:
    """Build (or reuse) the SoC and its simulator; returns the seconds spent."""
    key = gateware_key(cfg)
    stamp = cfg.out / "gateware.key"
    if not force and simulator(cfg).exists() and stamp.exists() and stamp.read_text() == key:
        _log(f"simulator of {cfg.tag} is up to date ({simulator(cfg).relative_to(TOP)})")
        return 0.0
    t0 = time.monotonic()
    stamp.unlink(missing_ok=True)
    # a new gateware folder; the software folder stays (LiteX rebuilds it when its settings change)
    for old in [_gateware(cfg), *cfg.out.glob("firmware*")]:
        shutil.rmtree(old, ignore_errors=True)
    from litex.build.sim.config import SimConfig
    from litex.soc.integration.builder import Builder

    env = toolenv.simulator_env()
    os.environ.update(env)
    cfg.out.mkdir(parents=True, exist_ok=True)
    log = cfg.out / "build.log"
    _log(f"building the SoC {cfg.tag} (LiteX: Verilog, libraries) in {cfg.out.relative_to(TOP)}")
    with open(log, "w") as fh, output_to(fh):   # LiteX's messages and its make runs
        soc = make_soc(cfg)
        builder = Builder(soc, output_dir=str(cfg.out), compile_gateware=False)
        keep = ("libc", "libcompiler_rt", "libbase")
        builder.software_packages = [p for p in builder.software_packages if p[0] in keep]
        builder.software_libraries = [n for n in builder.software_libraries if n in keep]
        sim_config = SimConfig()
        sim_config.add_clocker("sys_clk", freq_hz=cfg.clk_hz)
        sim_config.add_module("serial2console", "serial")
        try:
            builder.build(sim_config=sim_config, run=False, jobs=os.cpu_count() or 2,
                          opt_level=cfg.opt_level, interactive=False)
        except (Exception, SystemExit) as e:
            failed = e
        else:
            failed = None
    if failed is not None:
        raise SystemExit(f"soc-sim: the LiteX build failed ({failed!r}); see {log}")
    t1 = time.monotonic()
    _log(f"LiteX: {t1 - t0:.0f} s; now Verilator and the C++ build of the simulator (log: "
         f"{log.relative_to(TOP)})")
    with open(log, "a") as fh:
        r = subprocess.run(["bash", "build_sim.sh"], cwd=_gateware(cfg), stdout=fh,
                           stderr=subprocess.STDOUT, env={**os.environ, **env})
    if r.returncode != 0 or not simulator(cfg).exists():
        raise SystemExit(f"soc-sim: the simulator build failed; see {log}")
    stamp.write_text(key)
    _prune(cfg)
    dt = time.monotonic() - t0
    _log(f"simulator built in {dt:.0f} s (LiteX {t1 - t0:.0f} s, Verilator and C++ "
         f"{dt - (t1 - t0):.0f} s)")
    return dt


def _prune(cfg: SocConfig) -> None:
    """Delete what a built SoC no longer needs, about 0.55 of its 0.68 GB (0.13 GB stay): the
    simulator's object files, archives and precompiled headers in obj_dir/ (Vsim, the generated
    C++ and the makefiles stay) and picolibc's objects and intermediate archives (the firmware
    links libc.a and includes picolibc.h). A rebuild (a new gateware key) makes them again: meson
    keeps its configuration and compiles afresh."""
    toolenv.prune_verilator_build(_gateware(cfg) / "obj_dir")
    libc = cfg.out / "software" / "libc"
    shutil.rmtree(libc / "newlib", ignore_errors=True)
    for name in ("_libc.a", "__libc.a"):
        (libc / name).unlink(missing_ok=True)


VELOCITY = ("fixed", "double")   # the firmware's estimator (sw/soc/Makefile's FW_VEL)


def build_firmware(cfg: SocConfig, fault: str | None = None, vel: str = "fixed") -> Path:
    """make sw/soc against the build; returns firmware.bin (in firmware/, firmware_<fault>/,
    firmware_double/ ...). ``vel``: the velocity estimator, "fixed" (the default) or "double"."""
    if vel not in VELOCITY:
        raise ValueError(f"vel={vel!r}: give one of {VELOCITY}")
    name = "firmware" + (f"_{fault}" if fault else "") + ("" if vel == "fixed" else f"_{vel}")
    fw_dir = cfg.out / name
    fw_dir.mkdir(parents=True, exist_ok=True)
    args = ["make", "-s", "-C", str(fw_dir), "-f", str(FIRMWARE_SRC / "Makefile"),
            f"BUILD_DIR={cfg.out}", f"FW_SNAPSHOTS={cfg.snapshots}", f"FW_VEL={vel}"]
    if fault:
        args.append(f"FW_FAULT={fault}")
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"soc-sim: firmware build failed:\n{r.stdout}{r.stderr}")
    return fw_dir / "firmware.bin"


SOFT_FLOAT = ("__adddf3", "__subdf3", "__muldf3", "__divdf3", "__floatsidf", "__floatunsidf",
              "__floatdidf", "__fixdfsi", "__fixdfdi", "__fixunsdfsi", "__fixunsdfdi", "__cmpdf2",
              "__ledf2", "__gedf2", "__addsf3", "__mulsf3", "__divsf3")


def soft_float_symbols(firmware: Path) -> list[str]:
    """The soft-float routines (compiler-rt's double and single precision) linked into the
    firmware next to ``firmware`` (its firmware.elf), by the toolchain's nm."""
    nm = subprocess.run(["riscv64-unknown-elf-nm", str(firmware.with_suffix(".elf"))],
                        capture_output=True, text=True)
    if nm.returncode != 0:
        raise SystemExit(f"soc-sim: nm failed on {firmware.with_suffix('.elf')}: {nm.stderr}")
    names = {line.split()[-1] for line in nm.stdout.splitlines() if line.strip()}
    return sorted(names.intersection(SOFT_FLOAT))


def rom_words(firmware: Path) -> list[int]:
    """The firmware as little-endian 32-bit words, padded to the ROM (VexRiscv is little-endian)."""
    data = firmware.read_bytes()
    if len(data) > ROM_SIZE:
        raise SystemExit(f"soc-sim: {firmware} is {len(data)} bytes; the ROM holds {ROM_SIZE}")
    data += bytes(-len(data) % 4)
    words = [int.from_bytes(data[i:i + 4], "little") for i in range(0, len(data), 4)]
    return words + [0] * (ROM_SIZE // 4 - len(words))


def run(cfg: SocConfig, firmware: Path, timeout: float = 900.0) -> tuple[str, float]:
    """Run the simulator with ``firmware`` in ROM; returns (console output, seconds). A run of the
    same simulator and firmware is read back from its folder instead of run again."""
    gw = _gateware(cfg)
    run_dir = firmware.parent / "run"
    key = hashlib.sha256((cfg.out / "gateware.key").read_bytes() + firmware.read_bytes()
                         + str(cfg.snapshots).encode()).hexdigest()
    out_file, key_file = run_dir / "console.log", run_dir / "run.key"
    if out_file.exists() and key_file.exists() and key_file.read_text() == key:
        return out_file.read_text(), 0.0
    if run_dir.exists():
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    for f in gw.glob("*.init"):
        shutil.copy(f, run_dir)
    roms = [f for f in gw.glob("*.init") if f.name.endswith("rom.init")]
    if len(roms) != 1:
        raise SystemExit(f"soc-sim: expected one ROM init file in {gw}, found {roms}")
    (run_dir / roms[0].name).write_text("".join(f"{w:08x}\n" for w in rom_words(firmware)))
    shutil.copy(gw / "sim_config.js", run_dir)
    (run_dir / "modules").symlink_to(gw / "modules")
    t0 = time.monotonic()
    try:
        r = subprocess.run([str(simulator(cfg))], cwd=run_dir, capture_output=True, text=True,
                           timeout=timeout, stdin=subprocess.DEVNULL)
        out = r.stdout + r.stderr
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace") + "\nsoc-sim: TIMEOUT\n"
    dt = time.monotonic() - t0
    out_file.write_text(out)
    if "DONE" in out:
        key_file.write_text(key)
    return out, dt
