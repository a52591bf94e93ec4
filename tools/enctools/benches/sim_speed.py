# SPDX-License-Identifier: Apache-2.0
"""cocotb side of scripts/sim_speed.py (not collected by pytest): play a fixed random walk into
enc_quad_probe at 12 MHz and time it. Parameters from ENC_SPEED (JSON), results to ENC_RESULTS."""

import json
import os
import random
import time

import cocotb
from cocotb.triggers import FallingEdge, Timer
from cocotb.utils import get_sim_time

from cocotbext.quadrature import play, start_clock
from hedsmodel.waveform import random_walk
from enctools.tb import cocotb_test, reset_dut

PERIOD_PS = 83_333  # 12 MHz


@cocotb_test()
async def speed(dut):
    cfg = json.loads(os.environ["ENC_SPEED"])
    await start_clock(dut.clk, PERIOD_PS)
    dut.a_in.value = 0
    dut.b_in.value = 0
    await reset_dut(dut)
    await Timer(10 * PERIOD_PS, unit="ps")
    period_ns = PERIOD_PS / 1000
    wf = random_walk(random.Random(cfg["seed"]), cfg["transitions"],
                     cfg["state_clocks"] * period_ns, 2 * cfg["state_clocks"] * period_ns)
    t0_sim = get_sim_time("ps")
    t0 = time.perf_counter()
    await play(dut, wf, clock_period_ps=PERIOD_PS)
    await Timer(20 * PERIOD_PS, unit="ps")
    await FallingEdge(dut.clk)
    wall = time.perf_counter() - t0
    clocks = (get_sim_time("ps") - t0_sim) / PERIOD_PS
    assert dut.pos4.value.to_signed() == wf.final_position, "the speed run miscounted"
    with open(os.environ["ENC_RESULTS"], "w") as fh:
        json.dump({"wall_s": wall, "clocks": clocks, "transitions": cfg["transitions"]}, fh)
