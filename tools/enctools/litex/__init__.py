# SPDX-License-Identifier: Apache-2.0
"""enc_qei in a LiteX SoC.

``EncQEI`` wraps the Verilog peripheral ``enc_qei_wb`` as a LiteX module: a 32-bit Wishbone slave
(LiteX's word address turned into the peripheral's byte address), the encoder inputs, ``snap_in``,
``cmp_out`` and the interrupt through a LiteX EventManager. The Verilog sources and include folders
come from enc_ip.core (``enctools.core``). ``add_enc_qei`` maps one into a SoC::

    from enctools.litex import add_enc_qei
    pads = platform.request("encoders")   # subsignals a, b (and z, probe, snap, cmp), CHANNELS wide
    add_enc_qei(soc, name="enc_qei", pads=pads, channels=4, profile="full", efifo_log2=8)

Every parameter of ``enc_qei_wb`` is a keyword argument, its Verilog name in lower case
(``channels``, ``addr_w``, ``count_w``, ``ts_w``, ``profile``, ``func_mask``, ``efifo_log2``, and
any the module declares besides); a value outside enc_ip.core's range, a name the module does not
have, or a combination the peripheral cannot build raises ``ValueError`` before any tool runs.

Firmware then finds ``ENC_QEI_BASE`` in generated/mem.h and ``ENC_QEI_INTERRUPT`` in
generated/soc.h, enables the event with ``enc_qei_ev_enable_write(1)`` and uses
sw/enc_qei_regs.h: doc/litex.md.
"""

from __future__ import annotations

import re
from functools import lru_cache

from migen import Cat, ClockSignal, Constant, Instance, ResetSignal, Signal

from litex.gen import LiteXModule
from litex.soc.integration.soc import SoCRegion
from litex.soc.interconnect import wishbone
from litex.soc.interconnect.csr_eventmanager import EventManager, EventSourceLevel

from .. import core
from ..paths import TOP

PROFILES = {"counting": 1, "full": 2, "lean": 3}   # CAPS.PROFILE values (rtl/enc_qei.rdl)
TOP_MODULE = "enc_qei_wb"


def addr_width(channels: int) -> int:
    """The least byte-address width that holds every page: 8 + ceil(log2(CHANNELS))."""
    return 8 + max(0, (channels - 1).bit_length())


@lru_cache(maxsize=None)
def verilog_files(top: str = "enc_qei_wb") -> tuple[str, ...]:
    """The files of enc_ip.core's rtl fileset that ``top`` needs: its own and those of every module
    it instantiates, down the hierarchy (one module per file, named after it)."""
    by_module = {f.rsplit("/", 1)[-1][:-2]: f for f in core.rtl_files()}
    if top not in by_module:
        raise KeyError(f"enc_ip.core: no module {top} in the rtl fileset")
    need, todo = [], [top]
    while todo:
        mod = todo.pop()
        if by_module[mod] in need:
            continue
        need.append(by_module[mod])
        text = re.sub(r"//[^\n]*", "", (TOP / by_module[mod]).read_text())
        for name in re.findall(r"^\s*(\w+)\s*(?:#\s*\(|\w+\s*\()", text, re.M):
            if name in by_module and name != mod:
                todo.append(name)
    return tuple(sorted(need))


@lru_cache(maxsize=None)
def module_params(top: str = TOP_MODULE) -> tuple[str, ...]:
    """The parameters the Verilog module ``top`` declares (CHANNELS, ADDR_W, ...)."""
    return tuple(core.module_params(TOP / f"rtl/{top}.v"))


def check_params(params: dict) -> dict[str, int]:
    """``params`` (Verilog names, upper case; PROFILE may be a name of PROFILES) checked against
    the module's parameters, enc_ip.core's ranges and the combinations the peripheral refuses;
    returns them as integers. Raises ValueError naming the parameter and its range."""
    out = {}
    for name, value in params.items():
        if name not in module_params():
            raise ValueError(f"EncQEI: {TOP_MODULE} has no parameter {name} (it has "
                             f"{', '.join(module_params())})")
        if name == "PROFILE" and isinstance(value, str):
            if value not in PROFILES:
                raise ValueError(f"EncQEI: profile {value!r} is not one of {', '.join(PROFILES)}")
            value = PROFILES[value]
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"EncQEI: {name} = {value!r} is not an integer")
        if name in core.ranges() and not core.param_range(name).ok(value):
            raise ValueError(f"EncQEI: {name} = {value} is outside "
                             f"{core.param_range(name).text()} (enc_ip.core)")
        out[name] = value
    channels = out.get("CHANNELS", 1)
    if out.get("ADDR_W", addr_width(channels)) < addr_width(channels):
        raise ValueError(f"EncQEI: ADDR_W = {out['ADDR_W']} is too small for CHANNELS = {channels} "
                         f"(at least {addr_width(channels)})")
    profile = out.get("PROFILE", PROFILES["full"])
    if profile == PROFILES["lean"] and out.get("COUNT_W", 32) < 32:
        raise ValueError(f"EncQEI: PROFILE lean needs COUNT_W >= 32 (COUNT_W = {out['COUNT_W']})")
    if out.get("EFIFO_LOG2", 0) > 0 and profile == PROFILES["counting"]:
        raise ValueError(f"EncQEI: EFIFO_LOG2 = {out['EFIFO_LOG2']} needs the timing unit, "
                         "PROFILE full or lean (PROFILE is counting)")
    return out


def add_sources(platform, top: str = TOP_MODULE) -> None:
    """Add the Verilog of ``top`` and the IP's include folders to a LiteX platform."""
    for f in verilog_files(top):
        platform.add_source(str(TOP / f))
    for d in core.include_dirs():
        platform.add_verilog_include_path(str(d))


class EncQEI(LiteXModule):
    """``enc_qei_wb`` with CHANNELS encoder channels on a LiteX Wishbone bus.

    The parameters: ``channels``, ``profile`` ("full", "counting", "lean" or the PROFILE number),
    ``count_w``, ``ts_w``, ``func_mask`` and ``addr_w`` (None: the module's default),
    ``efifo_log2`` (0: no edge FIFO), and any other parameter of ``enc_qei_wb`` by its name in
    lower case (``**params``); ``check_params`` refuses bad ones with a ValueError.

    Attributes: ``bus`` (wishbone.Interface, 32-bit data, word addressed, the SoC's side), the
    inputs ``a``, ``b``, ``z``, ``probe`` (CHANNELS bits each, asynchronous), ``snap`` (one bit,
    synchronous to sys), the output ``cmp`` (CHANNELS bits), ``irq`` (the peripheral's level
    interrupt) and ``ev`` (an EventManager with the one level source ``qei``, whose ``irq`` a
    LiteX SoC connects to its CPU). ``pads``, when given, is any object with attributes ``a`` and
    ``b`` and optionally ``z``, ``probe``, ``snap`` and ``cmp``; absent inputs are tied to 0.
    """

    def __init__(self, platform, pads=None, channels: int = 1, profile: str | int = "full",
                 count_w: int = 32, ts_w: int = 32, func_mask: int | None = None,
                 addr_w: int | None = None, efifo_log2: int = 0, **params):
        given = dict(CHANNELS=channels, PROFILE=profile, COUNT_W=count_w, TS_W=ts_w,
                     FUNC_MASK=func_mask, ADDR_W=addr_w, EFIFO_LOG2=efifo_log2)
        for key, value in params.items():
            if key != key.lower() or key.upper() in given:
                raise ValueError(f"EncQEI: parameter {key!r}: give a parameter once, by its "
                                 "Verilog name in lower case")
            given[key.upper()] = value
        self.params = check_params({k: v for k, v in given.items() if v is not None})
        self.channels = channels
        self.profile = {v: k for k, v in PROFILES.items()}[self.params["PROFILE"]]
        self.count_w = count_w
        self.ts_w = ts_w
        self.efifo_log2 = efifo_log2
        self.addr_w = self.params.get("ADDR_W", addr_width(channels))
        self.size = 1 << self.addr_w   # bytes of the bus window

        self.bus = wishbone.Interface(data_width=32, address_width=32, addressing="word")
        self.a = Signal(channels)
        self.b = Signal(channels)
        self.z = Signal(channels)
        self.probe = Signal(channels)
        self.snap = Signal()
        self.cmp = Signal(channels)
        self.irq = Signal()

        self.ev = EventManager()
        self.ev.qei = EventSourceLevel(description="enc_qei interrupt: read IRQ_SUMMARY")
        self.ev.finalize()
        self.comb += self.ev.qei.trigger.eq(self.irq)

        if pads is not None:
            for name in ("a", "b", "z", "probe", "snap"):
                if hasattr(pads, name):
                    self.comb += getattr(self, name).eq(getattr(pads, name))
            if hasattr(pads, "cmp"):
                self.comb += pads.cmp.eq(self.cmp)

        verilog_params = {f"p_{k}": v for k, v in self.params.items()}
        verilog_params["p_ADDR_W"] = self.addr_w
        # LiteX's Wishbone address counts 32-bit words; enc_qei_wb takes the byte address.
        byte_adr = Cat(Constant(0, 2), self.bus.adr[:self.addr_w - 2])
        self.specials += Instance(
            TOP_MODULE, **verilog_params,
            i_clk=ClockSignal("sys"), i_rst=ResetSignal("sys"),
            i_wb_adr_i=byte_adr, i_wb_dat_i=self.bus.dat_w, o_wb_dat_o=self.bus.dat_r,
            i_wb_sel_i=self.bus.sel, i_wb_we_i=self.bus.we, i_wb_stb_i=self.bus.stb,
            i_wb_cyc_i=self.bus.cyc, o_wb_ack_o=self.bus.ack, o_wb_err_o=self.bus.err,
            i_a_in=self.a, i_b_in=self.b, i_z_in=self.z, i_probe_in=self.probe,
            i_snap_in=self.snap, o_irq=self.irq, o_cmp_out=self.cmp,
        )
        add_sources(platform)


def add_enc_qei(soc, name: str = "enc_qei", pads=None, channels: int = 1, profile: str = "full",
                count_w: int = 32, ts_w: int = 32, origin: int | None = None, **kwargs) -> EncQEI:
    """Instantiate an EncQEI in ``soc``: its registers in an uncached bus region of 2^ADDR_W bytes
    (at ``origin``, or wherever the SoC allocates it), its event on the interrupt controller.
    ``kwargs``: EncQEI's other parameters (``func_mask``, ``addr_w``, ``efifo_log2``, ...).
    Returns the module."""
    qei = EncQEI(soc.platform, pads=pads, channels=channels, profile=profile, count_w=count_w,
                 ts_w=ts_w, **kwargs)
    soc.add_module(name=name, module=qei)
    soc.bus.add_slave(name=name, slave=qei.bus,
                      region=SoCRegion(origin=origin, size=qei.size, cached=False))
    if soc.irq.enabled:
        soc.irq.add(name, use_loc_if_exists=True)
    return qei
