# SPDX-License-Identifier: Apache-2.0
"""cocotb side of scripts/velocity_bench.py's simulated layer (not collected by pytest).

Plays modelled HEDS-5000 waveforms into enc_qei_wb and reads the snapshot registers over
Wishbone (cocotbext-wishbone WishboneMaster) at the planned times, as a host would at 1 kHz:
write SNAP_CTRL (CMD = 1, EDGE), then read SNAP_COUNT_LO, SNAP_TIME, SNAP_EDGE_TIME, SNAP_DELTA,
SNAP_EDGE_DELTA, PERIOD, PERIOD_CTRL and STATUS. No verdicts here: the host script turns the
raw words into readings and compares them with the model.

Environment (set by scripts/velocity_bench.py):
  ENC_VEL_PLAN  JSON: clk_ps, regs {name: byte offset}, bits {"REG.FIELD": lsb}, cases [{id,
            events [[t_ns, a, b]...] (relative to the case start), reads_ns [...], edge (0 any,
            1 a_rising), prescale, period_n, stall_ticks}]
  ENC_VEL_OUT   JSON written at the end: per case the calibration (sim time and TIMEBASE of one read
            before the waveform starts), the case start time, and per read the sim time of the
            SNAP_CTRL write's acknowledge and the raw register words.
"""

from __future__ import annotations

import json
import logging
import os

import cocotb
from cocotb.triggers import ClockCycles, Timer
from cocotb.utils import get_sim_time

from cocotbext.quadrature import QuadratureDriver, start_clock
from hedsmodel.waveform import Waveform
from enctools.tb import cocotb_test, reset_dut

READ_REGS = ("SNAP_COUNT_LO", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA", "SNAP_EDGE_DELTA",
             "PERIOD", "PERIOD_CTRL", "STATUS")


class Bus:
    def __init__(self, dut, regs: dict):
        from cocotbext.wishbone.driver import WishboneMaster

        self.regs = regs
        self.m = WishboneMaster(dut, "wb", dut.clk, width=32, timeout=200, signals_dict={
            "cyc": "cyc_i", "stb": "stb_i", "we": "we_i", "adr": "adr_i", "datwr": "dat_i",
            "datrd": "dat_o", "ack": "ack_o", "err": "err_o", "sel": "sel_i"})
        self.m.log.setLevel(logging.WARNING)

    async def write(self, name: str, value: int) -> None:
        from cocotbext.wishbone.driver import WBOp

        (res,) = await self.m.send_cycle([WBOp(adr=self.regs[name], dat=value & 0xFFFFFFFF,
                                               sel=0xF)])
        if res.ack == 2:
            raise RuntimeError(f"write of {name} answered a bus error")

    async def read_many(self, names) -> list[int]:
        from cocotbext.wishbone.driver import WBOp

        res = await self.m.send_cycle([WBOp(adr=self.regs[n], dat=None, sel=0xF) for n in names])
        for n, r in zip(names, res):
            if r.ack == 2:
                raise RuntimeError(f"read of {n} answered a bus error")
        return [int(r.datrd) for r in res]


async def _until(t_ps: float) -> None:
    now = get_sim_time("ps")
    if t_ps > now:
        await Timer(int(round(t_ps - now)), unit="ps")


@cocotb_test()
async def velocity_reads(dut):
    plan = json.loads(open(os.environ["ENC_VEL_PLAN"]).read())
    clk_ps = int(plan["clk_ps"])
    bits = plan["bits"]
    for name in ("a_in", "b_in", "z_in", "probe_in", "snap_in", "wb_cyc_i", "wb_stb_i",
                 "wb_we_i"):
        getattr(dut, name).value = 0
    dut.wb_adr_i.value = 0
    dut.wb_dat_i.value = 0
    dut.wb_sel_i.value = 0
    await start_clock(dut.clk, clk_ps)
    await reset_dut(dut)
    bus = Bus(dut, plan["regs"])
    drv = QuadratureDriver(dut.a_in, dut.b_in, clock_period_ps=clk_ps)
    out = []
    progress = os.environ.get("ENC_VEL_PROGRESS")
    for ci, case in enumerate(plan["cases"]):
        events = [tuple(e) for e in case["events"]]
        wf = Waveform(events=events, positions=[None] * len(events))
        drv.set_state(events[0][1], events[0][2])
        edge = int(case["edge"])
        await bus.write("TB_PRESCALE", int(case["prescale"]))
        await bus.write("PERIOD_CTRL", (1 << bits["PERIOD_CTRL.EN"])
                        | (edge << bits["PERIOD_CTRL.EDGE"])
                        | (int(case["period_n"]) << bits["PERIOD_CTRL.N"]))
        await bus.write("STALL_TIMEOUT", int(case["stall_ticks"]))
        await bus.write("SNAP_CTRL", edge << bits["SNAP_CTRL.EDGE"])
        await ClockCycles(dut.clk, 40)    # the initial state through the filter
        t_cal0 = get_sim_time("ps")
        (tb_cal,) = await bus.read_many(["TIMEBASE"])
        t_cal1 = get_sim_time("ps")
        # start the waveform on a clock edge plus a fixed offset (the driver keeps 1 ps off edges)
        await ClockCycles(dut.clk, 5)
        t_start = get_sim_time("ps")
        task = drv.start(wf)
        reads = []
        for r_ns in case["reads_ns"]:
            await _until(t_start + r_ns * 1000.0)
            await bus.write("SNAP_CTRL", (1 << bits["SNAP_CTRL.CMD"]) | (edge << bits["SNAP_CTRL.EDGE"]))
            t_ack = get_sim_time("ps")
            words = await bus.read_many(list(READ_REGS))
            reads.append({"t_ack_ps": t_ack, **dict(zip(READ_REGS, words))})
        await task
        out.append({"id": case["id"], "t_cal0_ps": t_cal0, "t_cal1_ps": t_cal1, "tb_cal": tb_cal,
                    "t_start_ps": t_start, "reads": reads})
        if progress:
            with open(progress, "a") as fh:
                fh.write(f"{case['id']}\n")
    with open(os.environ["ENC_VEL_OUT"], "w") as fh:
        json.dump(out, fh)
