# SPDX-License-Identifier: Apache-2.0
"""The bus of the enc_qei tests: one object over the ecosystem's masters (cocotbext-wishbone
WishboneMaster or cocotbext-axi AxiLiteMaster with random back-pressure on every channel), with
register access by name (the register map is enctools.regmap). Clock-exact stimulus is in
enctools.qei.stimulus."""

from __future__ import annotations

import copy
import logging
import random

from enctools.regmap import addr, event_names, regmap

PERIOD_PS = 10_000  # 100 MHz
T_NS = PERIOD_PS / 1000


async def wb_abandon_read(dut, adr: int, hold: int) -> None:
    """Wishbone, driven by hand: a read of byte address ``adr`` that the master abandons after
    ``hold`` clocks (CYC and STB high from a falling edge, then low at the falling edge ``hold``
    clocks later). Returns in that clock, CYC already low."""
    from cocotb.triggers import ClockCycles, FallingEdge

    await FallingEdge(dut.clk)
    dut.wb_adr_i.value = adr
    dut.wb_we_i.value = 0
    dut.wb_sel_i.value = 0xF
    dut.wb_cyc_i.value = 1
    dut.wb_stb_i.value = 1
    await ClockCycles(dut.clk, hold)
    await FallingEdge(dut.clk)
    dut.wb_cyc_i.value = 0
    dut.wb_stb_i.value = 0


def signed(value: int, bits: int = 32) -> int:
    """A ``bits``-wide register value read as two's complement (SNAP_DELTA, a count)."""
    value &= (1 << bits) - 1
    return value - (1 << bits) if value >> (bits - 1) else value


# ---- bus ------------------------------------------------------------------------------------------
class QeiBus:
    """read(offset) -> (data, err); write(offset, data, strb) -> err, on either adapter; by
    register name with rd / wr / read_many. ``offsets`` (name -> byte offset) replaces the
    register map's offsets (a bench simulating the RTL of another revision); ``rng`` drives the
    AXI4-Lite back-pressure (default: a fixed seed)."""

    def __init__(self, dut, rng: random.Random | None = None, offsets: dict | None = None):
        self.dut = dut
        self.offsets = offsets
        self.chan = 0  # the channel page that register names refer to (see at())
        rng = rng or random.Random(1)
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
        if not lanes or lanes != list(range(lanes[0], lanes[-1] + 1)):
            # the master writes contiguous lanes only: this one (no lane, or lanes with a gap)
            # goes straight onto its AW, W and B channels (their random back-pressure included)
            wif = self.m.write_if
            aw, w = wif.aw_channel._transaction_obj(), wif.w_channel._transaction_obj()
            aw.awaddr, aw.awprot = offset, 0
            w.wdata, w.wstrb = data & 0xFFFFFFFF, strb
            await wif.aw_channel.send(aw)
            await wif.w_channel.send(w)
            return int((await wif.b_channel.recv()).bresp) != 0
        data_bytes = (data & 0xFFFFFFFF).to_bytes(4, "little")[lanes[0]:lanes[-1] + 1]
        resp = await self.m.write(offset + lanes[0], data_bytes)
        return int(resp.resp) != 0

    def at(self, chan: int) -> "QeiBus":
        """The same bus, its register names meaning channel ``chan``'s registers (global
        registers stay on page 0). Views share the master, so their accesses queue in order."""
        view = copy.copy(self)
        view.chan = chan
        return view

    # convenience, by register name
    def offset(self, reg: str) -> int:
        if self.offsets is not None:
            return self.offsets[reg]
        return addr(reg, self.chan if regmap()[reg].group == "chan" else 0)

    async def rd(self, reg: str) -> int:
        value, err = await self.read(self.offset(reg))
        assert not err, f"read of {reg} answered an error"
        return value

    async def wr(self, reg: str, value: int, strb: int = 0xF) -> None:
        err = await self.write(self.offset(reg), value, strb)
        assert not err, f"write of {reg} answered an error"

    async def read_many(self, regs) -> list[int]:
        """Several registers in one bus transaction where the bus has one (a Wishbone block
        cycle), one after the other otherwise."""
        if self.kind != "wb":
            return [await self.rd(r) for r in regs]
        from cocotbext.wishbone.driver import WBOp

        res = await self.m.send_cycle([WBOp(adr=self.offset(r), dat=None, sel=0xF) for r in regs])
        for r, x in zip(regs, res):
            assert x.ack != 2, f"read of {r} answered an error"
        return [int(x.datrd) for x in res]

    async def count(self) -> int:
        lo = await self.rd("COUNT_LO")
        hi = await self.rd("COUNT_HI")
        return hi << 32 | lo

    async def set_count(self, value: int) -> None:
        await self.wr("COUNT_HI", value >> 32 & 0xFFFFFFFF)
        await self.wr("COUNT_LO", value & 0xFFFFFFFF)

    async def get64(self, base: str) -> int:
        """A 64-bit register pair, {base}_LO then {base}_HI."""
        lo = await self.rd(f"{base}_LO")
        return await self.rd(f"{base}_HI") << 32 | lo

    async def set64(self, base: str, value: int) -> None:
        await self.wr(f"{base}_LO", value & 0xFFFFFFFF)
        await self.wr(f"{base}_HI", value >> 32 & 0xFFFFFFFF)

    async def events(self, clear: bool = True) -> set[str]:
        word = await self.rd("EVENTS")
        if clear and word:
            await self.wr("EVENTS", word)
        return event_names(word)



class WbRaw:
    """Wishbone B4 classic driven on enc_qei_wb's raw signals, for measurements to the clock: each
    access sets its request at a falling edge and returns (stamp, data, err), where stamp is the
    timebase (dut.u_qei.timebase: one tick a clock at TB_PRESCALE 0) in the clock before the
    request is sampled; it ends at the falling edge after the acknowledge, where the next one can
    begin. Do not use it while a QeiBus transaction is under way."""

    def __init__(self, dut):
        self.dut = dut
        self.tb = dut.u_qei.timebase

    async def access(self, adr: int, data: int | None = None, sel: int = 0xF) -> tuple[int, int, bool]:
        from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge

        dut = self.dut
        await FallingEdge(dut.clk)
        dut.wb_adr_i.value = adr
        dut.wb_we_i.value = int(data is not None)
        dut.wb_dat_i.value = (data or 0) & 0xFFFFFFFF
        dut.wb_sel_i.value = sel
        dut.wb_cyc_i.value = dut.wb_stb_i.value = 1
        stamp = int(self.tb.value)
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if dut.wb_ack_o.value or dut.wb_err_o.value:
                break
        value, err = int(dut.wb_dat_o.value), bool(dut.wb_err_o.value)
        await FallingEdge(dut.clk)
        dut.wb_cyc_i.value = dut.wb_stb_i.value = dut.wb_we_i.value = 0
        return stamp, value, err


# The snapshot clock of a register write (the RDL text of GSNAP_CTRL), from its *write clock*: the
# first clock of the Wishbone strobe, or the later of the AXI4-Lite AW and W handshake clocks
WB_SNAP_LAT = 3    # Wishbone: the write clock + 3 (the clock after wb_ack_o)
AXIL_SNAP_LAT = 5  # AXI4-Lite: the write clock + 5 (the clock s_axil_bvalid rises)


class BusTrace:
    """Per clock (sampled after each rising edge): the timebase, the global snapshot request, the
    Wishbone strobe / acknowledge or the AXI4-Lite handshakes."""

    def __init__(self, dut):
        import cocotb

        self.dut = dut
        self.wb = hasattr(dut, "wb_stb_i")
        self.rows = []
        self.task = cocotb.start_soon(self._run())

    def _sample(self) -> dict:
        d = self.dut
        row = {"tb": int(d.u_qei.timebase.value), "gsnap": int(d.u_qei.gsnap.value)}
        if self.wb:
            row["req"] = int(d.wb_cyc_i.value) & int(d.wb_stb_i.value)
            row["resp"] = int(d.wb_ack_o.value) | int(d.wb_err_o.value)
        else:
            row["aw"] = int(d.s_axil_awvalid.value) & int(d.s_axil_awready.value)
            row["w"] = int(d.s_axil_wvalid.value) & int(d.s_axil_wready.value)
            row["resp"] = int(d.s_axil_bvalid.value)
        return row

    async def _run(self):
        from cocotb.triggers import ReadOnly, RisingEdge

        while True:
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            self.rows.append(self._sample())

    def now(self) -> int:
        return len(self.rows)

    def first(self, key: str, after: int) -> int:
        return next(i for i in range(after, len(self.rows)) if self.rows[i][key])

    def write_clock(self, after: int) -> int:
        """The clock the bus hands the peripheral the first write after clock ``after``."""
        if self.wb:
            return self.first("req", after)
        return max(self.first("aw", after), self.first("w", after))

    def clock_of(self, tb: int, after: int) -> int:
        return next(i for i in range(after, len(self.rows)) if self.rows[i]["tb"] == tb)

    def snapshots(self, after: int, before: int | None = None) -> list[int]:
        """The clocks of the global snapshots in [after, before)."""
        return [i for i in range(after, before or len(self.rows)) if self.rows[i]["gsnap"]]


async def traced_write(bus, trace: BusTrace, reg: str, value: int) -> tuple[int, int]:
    """Write ``reg``; returns (write clock, response clock)."""
    from cocotb.triggers import ClockCycles

    n0 = trace.now()
    await bus.wr(reg, value)
    await ClockCycles(bus.dut.clk, 2)
    return trace.write_clock(n0), trace.first("resp", n0)
