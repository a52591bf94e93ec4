# SPDX-License-Identifier: Apache-2.0
"""Minimal use of cocotbext-quadrature outside this repository's tb/: a modelled HEDS-5000 turns
forward, dithers and turns back; the user's counter must end at the monitor's 4X position.

    pip install "cocotbext-quadrature[cocotb]" pytest     # (or: pip install "./python[cocotb]")
    pytest test_quad_counter.py                          # needs Icarus Verilog (iverilog)
"""

from pathlib import Path

import cocotb
from cocotb.triggers import ClockCycles

from cocotbext.quadrature import QuadratureDriver, QuadratureMonitor, reset, start_clock
from hedsmodel import EncoderUnit, Profile

CLK_PS = 10_000  # 100 MHz


@cocotb.test()
async def counts_a_modelled_encoder(dut):
    dut.a_in.value = 0
    dut.b_in.value = 0
    await start_clock(dut.clk, CLK_PS)
    await reset(dut.rst, dut.clk)
    unit = EncoderUnit(phase_error_deg=20, pulse_error_deg=15)  # EncoderUnit() is ideal
    profile = (Profile(start_deg=-45).constant(3000, 0.0005).dither(0.5, 4, 2e-4)
               .ramp(3000, -1500, 0.0005))
    wf = unit.waveform(profile)
    mon = QuadratureMonitor(dut.a_in, dut.b_in)
    await QuadratureDriver(dut.a_in, dut.b_in, clock_period_ps=CLK_PS).play(wf)
    await ClockCycles(dut.clk, 4)
    assert mon.errors == 0
    assert mon.position == wf.final_position - wf.positions[0], (mon.position, wf.final_position)
    assert dut.count.value.to_signed() == mon.position, (dut.count.value.to_signed(), mon.position)
    dut._log.info("%d transitions, final position %d", len(wf.events) - 1, mon.position)


def test_quad_counter(tmp_path):
    from cocotb_tools.runner import get_runner

    here = Path(__file__).resolve().parent
    runner = get_runner("icarus")
    build = tmp_path / "sim_build"
    runner.build(sources=[here / "quad_counter.v"], hdl_toplevel="quad_counter", build_dir=build,
                 timescale=("1ns", "1ps"), always=True)
    runner.test(hdl_toplevel="quad_counter", test_module="test_quad_counter", test_dir=build,
                extra_env={"PYTHONPATH": str(here)})
