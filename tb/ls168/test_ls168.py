# SPDX-License-Identifier: Apache-2.0
"""74LS168 / 74LS169 counter stage (ls168) against an independent Python model.

Covers the whole function table: every state 0..15 (decade states 10..15 by load) crossed with every
combination of LOAD_n, ENP_n, ENT_n and U/D, checking RCO_n before the clock and Q after it; the
recovery of illegal decade states within two counting clocks; and a three-stage cascade counting
through its wrap in both directions plus a random walk, for MODULUS 10 and 16.
"""

import itertools
import random

import cocotb
import pytest
from cocotb.triggers import FallingEdge, RisingEdge, Timer

from enctools.tb import cocotb_test

from enctools import tb as tbutil
from enctools.harness import run


# ----------------------------------------------------------------------------------------------
# Reference model (written from the data-sheet function table, not from the RTL)
# ----------------------------------------------------------------------------------------------
class Ls168Model:
    def __init__(self, modulus: int):
        self.modulus = modulus
        self.top = modulus - 1
        self.q = 0

    def rco_n(self, ent_n: int, up: int) -> int:
        terminal = self.q == (self.top if up else 0)
        return 0 if (ent_n == 0 and terminal) else 1

    def clock(self, load_n: int, enp_n: int, ent_n: int, up: int, d: int) -> None:
        if load_n == 0:
            self.q = d
        elif enp_n == 0 and ent_n == 0:
            if self.q > self.top:  # illegal decade state: rejoin at once
                self.q = 0 if up else self.top
            else:
                self.q = (self.q + (1 if up else -1)) % self.modulus


def cascade_value(digits, modulus):
    return sum(dg * modulus**k for k, dg in enumerate(digits))


async def start(dut):
    await tbutil.start(dut, 10_000, has_rst=False)  # the part has no reset pin


# ----------------------------------------------------------------------------------------------
# Single stage
# ----------------------------------------------------------------------------------------------
async def drive_and_check(dut, model, load_n, enp_n, ent_n, up, d, what):
    dut.load_n.value = load_n
    dut.enp_n.value = enp_n
    dut.ent_n.value = ent_n
    dut.up.value = up
    dut.d.value = d
    await Timer(1, unit="ns")
    exp_rco = model.rco_n(ent_n, up)
    assert int(dut.rco_n.value) == exp_rco, f"{what}: rco_n={int(dut.rco_n.value)} expected {exp_rco}"
    await RisingEdge(dut.clk)
    model.clock(load_n, enp_n, ent_n, up, d)
    await FallingEdge(dut.clk)
    assert int(dut.q.value) == model.q, f"{what}: q={int(dut.q.value)} expected {model.q}"


@cocotb_test()
async def function_table(dut):
    """Every state x every control combination: load priority, ENP/ENT, U/D, wrap, RCO_n."""
    modulus = int(dut.MODULUS.value)
    model = Ls168Model(modulus)
    await start(dut)
    for state in range(16):
        for load_n, enp_n, ent_n, up in itertools.product((0, 1), repeat=4):
            # put the counter in `state` with a load, then apply the combination under test
            await drive_and_check(dut, model, 0, 1, 1, 0, state, f"load {state}")
            d = random.randrange(16)
            what = (f"state={state} load_n={load_n} enp_n={enp_n} ent_n={ent_n} up={up} d={d}"
                    f" (MODULUS {modulus})")
            await drive_and_check(dut, model, load_n, enp_n, ent_n, up, d, what)


@cocotb_test()
async def illegal_states_recover(dut):
    """A state above MAX rejoins 0..MAX within two counting clocks, in either direction."""
    modulus = int(dut.MODULUS.value)
    model = Ls168Model(modulus)
    await start(dut)
    for state in range(modulus, 16):
        for up in (0, 1):
            await drive_and_check(dut, model, 0, 1, 1, up, state, f"load {state}")
            for step in range(2):
                await drive_and_check(dut, model, 1, 0, 0, up, 0, f"from {state} up={up}")
            assert int(dut.q.value) < modulus, f"state {state} did not rejoin 0..{modulus - 1}"


@cocotb_test()
async def random_controls(dut):
    """Long random sequence of controls against the model."""
    model = Ls168Model(int(dut.MODULUS.value))
    await start(dut)
    await drive_and_check(dut, model, 0, 1, 1, 1, 0, "clear")
    for i in range(3000):
        await drive_and_check(dut, model, int(random.random() > 0.05), random.randrange(2),
                              random.randrange(2), random.randrange(2), random.randrange(16),
                              f"step {i}")


# ----------------------------------------------------------------------------------------------
# Three-stage cascade
# ----------------------------------------------------------------------------------------------
async def cascade_step(dut, expect, load_n, en_n, up, d_value, modulus, what):
    digits = [(d_value // modulus**k) % modulus for k in range(3)]
    dut.load_n.value = load_n
    dut.en_n.value = en_n
    dut.up.value = up
    dut.d.value = sum(dg << (4 * k) for k, dg in enumerate(digits))
    await Timer(1, unit="ns")
    span = modulus**3
    exp_rco = 0 if (en_n == 0 and expect == (span - 1 if up else 0)) else 1
    assert int(dut.rco_n.value) == exp_rco, f"{what}: cascade rco_n at {expect}"
    await RisingEdge(dut.clk)
    if load_n == 0:
        expect = d_value
    elif en_n == 0:
        expect = (expect + (1 if up else -1)) % span
    await FallingEdge(dut.clk)
    q = int(dut.q.value)
    got = cascade_value([(q >> (4 * k)) & 0xF for k in range(3)], modulus)
    assert all(((q >> (4 * k)) & 0xF) < modulus for k in range(3)), f"{what}: digit out of range {q:03x}"
    assert got == expect, f"{what}: cascade reads {got}, expected {expect}"
    return expect


@cocotb_test()
async def cascade_wraps_both_ways(dut):
    """Three stages count up through MAX..0 and down through 0..MAX, then a random walk."""
    modulus = int(dut.MODULUS.value)
    span = modulus**3
    await start(dut)
    value = await cascade_step(dut, 0, 0, 1, 1, span - 3, modulus, "load near top")
    for i in range(6):  # ..., top-1, top, 0, 1, 2
        value = await cascade_step(dut, value, 1, 0, 1, 0, modulus, f"up {i}")
    assert value == 3 % span
    for i in range(6):  # 2, 1, 0, top, top-1, top-2
        value = await cascade_step(dut, value, 1, 0, 0, 0, modulus, f"down {i}")
    assert value == span - 3
    # carries out of the middle digit: load x(M-1)(M-1) and cross it both ways
    value = await cascade_step(dut, value, 0, 1, 1, modulus**2 - 2, modulus, "load middle")
    for i in range(4):
        value = await cascade_step(dut, value, 1, 0, 1, 0, modulus, f"up mid {i}")
    for i in range(4):
        value = await cascade_step(dut, value, 1, 0, 0, 0, modulus, f"down mid {i}")
    for i in range(3000):
        value = await cascade_step(dut, value, int(random.random() > 0.01), random.randrange(2),
                                   int(random.random() < 0.5), random.randrange(span), modulus,
                                   f"walk {i}")


# ----------------------------------------------------------------------------------------------
# pytest entry points
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("modulus", [10, 16])
def test_ls168(modulus):
    run("ls168", __name__, name=f"ls168_m{modulus}", parameters={"MODULUS": modulus},
        testcase="function_table,illegal_states_recover,random_controls")


@pytest.mark.parametrize("modulus", [10, 16])
def test_ls168_cascade(modulus):
    run("ls168_cascade3", __name__, name=f"ls168_cascade3_m{modulus}",
        parameters={"MODULUS": modulus}, tb_sources=("ls168_cascade3.v",),
        testcase="cascade_wraps_both_ways")
