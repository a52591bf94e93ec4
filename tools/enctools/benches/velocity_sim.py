# SPDX-License-Identifier: Apache-2.0
"""cocotb side of `make velocity`'s simulated layer (enctools.velocity.simulate; not collected by
pytest).

Plays modelled HEDS-5000 waveforms into enc_qei_wb and reads the snapshot registers over
Wishbone (enctools.qei.bus's QeiBus) at the planned times, as a host would at 1 kHz: write the
snapshot command to SNAP_CTRL, then read the planned registers (SNAP_COUNT_LO, SNAP_TIME,
SNAP_EDGE_TIME, SNAP_DELTA, SNAP_EDGE_DELTA, PERIOD, PERIOD_CTRL, STATUS) in one block cycle. No
verdicts here: the host turns the raw words into readings and compares them with the model.

Environment (set by enctools.velocity.simulate):
  ENC_VEL_PLAN      JSON: clk_ps, regs {name: byte offset} (the simulated revision's), reads [names],
                cases [{id, events [[t_ns, a, b]...] (relative to the case start), reads_ns [...],
                setup [[name, word]...] written before the waveform starts, snap_cmd (the
                SNAP_CTRL word that commands a snapshot)}]
  ENC_VEL_OUT       JSON written at the end: per case the calibration (sim time and TIMEBASE of one
                read before the waveform starts), the case start time, and per read the sim time
                of the SNAP_CTRL write's acknowledge and the raw register words.
  ENC_VEL_PROGRESS  a file the id of each finished case is appended to
"""

from __future__ import annotations

import json
import os

from cocotb.triggers import ClockCycles
from cocotb.utils import get_sim_time

from cocotbext.quadrature import QuadratureDriver, start_clock
from enctools.qei.bus import QeiBus
from enctools.tb import cocotb_test, reset_dut, until
from hedsmodel.waveform import Waveform


async def _case(dut, bus: QeiBus, drv: QuadratureDriver, case: dict, reads: list) -> dict:
    """One case: setup, the calibration read of TIMEBASE, the waveform, the planned reads."""
    events = [tuple(e) for e in case["events"]]
    wf = Waveform(events=events, positions=[None] * len(events))
    drv.set_state(events[0][1], events[0][2])
    for name, word in case["setup"]:
        await bus.wr(name, int(word))
    await ClockCycles(dut.clk, 40)    # the initial state through the filter
    t_cal0 = get_sim_time("ps")
    (tb_cal,) = await bus.read_many(["TIMEBASE"])
    t_cal1 = get_sim_time("ps")
    # start the waveform on a clock edge plus a fixed offset (the driver keeps 1 ps off edges)
    await ClockCycles(dut.clk, 5)
    t_start = get_sim_time("ps")
    task = drv.start(wf)
    out = []
    for r_ns in case["reads_ns"]:
        await until(t_start + r_ns * 1000.0)
        await bus.wr("SNAP_CTRL", int(case["snap_cmd"]))
        t_ack = get_sim_time("ps")
        out.append({"t_ack_ps": t_ack, **dict(zip(reads, await bus.read_many(reads)))})
    await task
    return {"id": case["id"], "t_cal0_ps": t_cal0, "t_cal1_ps": t_cal1, "tb_cal": tb_cal,
            "t_start_ps": t_start, "reads": out}


@cocotb_test()
async def velocity_reads(dut):
    plan = json.loads(open(os.environ["ENC_VEL_PLAN"]).read())
    clk_ps = int(plan["clk_ps"])
    for name in ("a_in", "b_in", "z_in", "probe_in", "snap_in", "wb_cyc_i", "wb_stb_i",
                 "wb_we_i"):
        getattr(dut, name).value = 0
    dut.wb_adr_i.value = 0
    dut.wb_dat_i.value = 0
    dut.wb_sel_i.value = 0
    await start_clock(dut.clk, clk_ps)
    await reset_dut(dut)
    bus = QeiBus(dut, offsets=plan["regs"])
    drv = QuadratureDriver(dut.a_in, dut.b_in, clock_period_ps=clk_ps)
    out = []
    progress = os.environ.get("ENC_VEL_PROGRESS")
    for case in plan["cases"]:
        out.append(await _case(dut, bus, drv, case, plan["reads"]))
        if progress:
            with open(progress, "a") as fh:
                fh.write(f"{case['id']}\n")
    with open(os.environ["ENC_VEL_OUT"], "w") as fh:
        json.dump(out, fh)
