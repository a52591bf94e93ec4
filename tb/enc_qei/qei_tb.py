# SPDX-License-Identifier: Apache-2.0
"""Shared pieces of the enc_qei tests: the register map read from the compiled RDL, one bus
object over the ecosystem's masters (cocotbext-wishbone WishboneMaster or cocotbext-axi
AxiLiteMaster with random back-pressure on every channel), the test start, and the pytest-side
source list."""

from __future__ import annotations

import logging
import random
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

TOP = Path(__file__).resolve().parents[2]
RDL = TOP / "rtl" / "enc_qei.rdl"
QEI_RTL = ("enc_conditioner_rt.v", "enc_qei_core.v", "enc_qei_timing.v", "enc_qei_regs.v",
           "enc_qei.v", "enc_qei_wb.v", "enc_qei_axil.v")
PERIOD_PS = 10_000  # 100 MHz
T_NS = PERIOD_PS / 1000


def extra_sources() -> tuple[Path, ...]:
    """The enc_qei RTL files the harness does not already take from enc_ip.core."""
    from harness import rtl_sources

    have = {p.name for p in rtl_sources()}
    return tuple(TOP / "rtl" / f for f in QEI_RTL if f not in have)


# ---- register map from the RDL ----------------------------------------------------------------------
@dataclass
class Field:
    name: str
    lsb: int
    width: int
    sw: str
    hw: str
    reset: int | None
    sized_by: str | None
    enum: dict | None
    kind: str

    @property
    def mask(self) -> int:
        return ((1 << self.width) - 1) << self.lsb


@dataclass
class Reg:
    name: str
    offset: int
    external: bool
    fields: dict


@lru_cache(maxsize=None)
def regmap() -> dict:
    sys.path.insert(0, str(TOP / "scripts"))
    from gen_regs import compile_rdl, field_kind

    regs = {}
    for r in compile_rdl(RDL).registers():
        fields = {}
        for f in r.fields():
            enc = f.get_property("encode")
            fields[f.inst_name] = Field(
                f.inst_name, f.lsb, f.width, f.get_property("sw").name, f.get_property("hw").name,
                f.get_property("reset"), f.get_property("sized_by"),
                {m.name: m.value for m in enc} if enc is not None else None, field_kind(f))
        regs[r.inst_name] = Reg(r.inst_name, r.address_offset, r.external, fields)
    return regs


def addr(reg: str) -> int:
    return regmap()[reg].offset


def field_val(reg: str, field: str, value) -> int:
    """The register bits of ``field`` = value (an int or an enum member name)."""
    f = regmap()[reg].fields[field]
    if isinstance(value, str):
        value = f.enum[value]
    assert 0 <= value < (1 << f.width), (reg, field, value)
    return value << f.lsb


def get_field(reg: str, field: str, word: int) -> int:
    f = regmap()[reg].fields[field]
    return (word >> f.lsb) & ((1 << f.width) - 1)


def pack(reg: str, **fields) -> int:
    return sum(field_val(reg, k, v) for k, v in fields.items())


def event_names(word: int) -> set[str]:
    return {n for n, f in regmap()["EVENTS"].fields.items() if word & f.mask}


def event_bits(*names: str) -> int:
    return sum(regmap()["EVENTS"].fields[n].mask for n in names)


def size_mask(sized_by: str | None, count_w: int, ts_w: int) -> int:
    if sized_by == "COUNT_W:0":
        return (1 << min(32, count_w)) - 1
    if sized_by == "COUNT_W:1":
        return (1 << max(0, count_w - 32)) - 1
    if sized_by == "TS_W":
        return (1 << ts_w) - 1
    return 0xFFFFFFFF


# ---- bus ------------------------------------------------------------------------------------------
class QeiBus:
    """read(offset) -> (data, err); write(offset, data, strb) -> err, on either adapter."""

    def __init__(self, dut, rng: random.Random):
        self.dut = dut
        self.kind = "axil" if hasattr(dut, "s_axil_awaddr") else "wb"
        if self.kind == "wb":
            from cocotbext.wishbone.driver import WishboneMaster

            self.m = WishboneMaster(dut, "wb", dut.clk, width=32, timeout=200, signals_dict={
                "cyc": "cyc_i", "stb": "stb_i", "we": "we_i", "adr": "adr_i", "datwr": "dat_i",
                "datrd": "dat_o", "ack": "ack_o", "err": "err_o", "sel": "sel_i"})
            self.m.log.setLevel(logging.WARNING)
        else:
            from cocotbext.axi import AxiLiteBus, AxiLiteMaster

            self.m = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
            for ch in (self.m.write_if.aw_channel, self.m.write_if.w_channel,
                       self.m.write_if.b_channel, self.m.read_if.ar_channel,
                       self.m.read_if.r_channel):
                ch.set_pause_generator(self._pauses(random.Random(rng.getrandbits(32))))
            for lg in (self.m.write_if.log, self.m.read_if.log):
                lg.setLevel(logging.WARNING)

    @staticmethod
    def _pauses(rng):
        while True:
            yield rng.random() < 0.4

    async def read(self, offset: int) -> tuple[int, bool]:
        if self.kind == "wb":
            from cocotbext.wishbone.driver import WBOp

            (res,) = await self.m.send_cycle([WBOp(adr=offset, dat=None, sel=0xF)])
            return int(res.datrd), res.ack == 2
        resp = await self.m.read(offset, 4)
        return int.from_bytes(resp.data, "little"), int(resp.resp) != 0

    async def write(self, offset: int, data: int, strb: int = 0xF) -> bool:
        if self.kind == "wb":
            from cocotbext.wishbone.driver import WBOp

            (res,) = await self.m.send_cycle([WBOp(adr=offset, dat=data & 0xFFFFFFFF, sel=strb)])
            return res.ack == 2
        lanes = [i for i in range(4) if strb >> i & 1]
        assert lanes and lanes == list(range(lanes[0], lanes[-1] + 1)), \
            "AXI4-Lite master writes contiguous byte lanes only"
        data_bytes = (data & 0xFFFFFFFF).to_bytes(4, "little")[lanes[0]:lanes[-1] + 1]
        resp = await self.m.write(offset + lanes[0], data_bytes)
        return int(resp.resp) != 0

    # convenience, by register name
    async def rd(self, reg: str) -> int:
        value, err = await self.read(addr(reg))
        assert not err, f"read of {reg} answered an error"
        return value

    async def wr(self, reg: str, value: int, strb: int = 0xF) -> None:
        err = await self.write(addr(reg), value, strb)
        assert not err, f"write of {reg} answered an error"

    async def count(self) -> int:
        lo = await self.rd("COUNT_LO")
        hi = await self.rd("COUNT_HI")
        return hi << 32 | lo

    async def set_count(self, value: int) -> None:
        await self.wr("COUNT_HI", value >> 32 & 0xFFFFFFFF)
        await self.wr("COUNT_LO", value & 0xFFFFFFFF)

    async def set64(self, base: str, value: int) -> None:
        await self.wr(f"{base}_LO", value & 0xFFFFFFFF)
        await self.wr(f"{base}_HI", value >> 32 & 0xFFFFFFFF)

    async def events(self, clear: bool = True) -> set[str]:
        word = await self.rd("EVENTS")
        if clear and word:
            await self.wr("EVENTS", word)
        return event_names(word)


# ---- clock-exact stimulus ---------------------------------------------------------------------------
async def play_clocks(env, model, clocks) -> None:
    """Drive (A, B) and Z clock by clock: ``clocks`` lists (4X position, Z level) per clock, set at
    the falling edge before that clock's rising edge, so that with FILTER_LEN 1 (a level of one
    clock is kept) each change is sampled in exactly that clock: steps in consecutive clocks, an
    index edge in the clock of a step or right before one. Every change of (A, B) or Z is one
    sample of the model (qei_model.QeiModel.sample), in order. ``env`` is test_enc_qei.Env (its
    ``pos`` is kept; ``z`` is the Z level now)."""
    from cocotb.triggers import FallingEdge
    from qei_model import QUAD

    dut = env.dut
    prev = (env.pos % 4, getattr(env, "z", 0))
    for pos, z in clocks:
        await FallingEdge(dut.clk)
        dut.a_in.value, dut.b_in.value = QUAD[pos % 4]
        dut.z_in.value = z
        if (pos % 4, z) != prev and model is not None:
            model.sample(QUAD[pos % 4], z)
        prev = (pos % 4, z)
        env.pos, env.z = pos, z


def step_clocks(pos: int, steps, z=None) -> list:
    """(position, Z) per clock for ``steps`` (+1, -1 or 0 per clock) from 4X position ``pos``;
    ``z``: the Z level per clock (default 0)."""
    out = []
    for i, s in enumerate(steps):
        pos += s
        out.append((pos, z[i] if z is not None else 0))
    return out
