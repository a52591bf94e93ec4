# SPDX-License-Identifier: Apache-2.0
"""The count-rate rule through the peripheral: enc_qei read over its bus (FUNC x4; every function
at the bound in every_function_at_bound, and past it in never_silent).

With CTRL.FILTER_LEN = F (set at run time, one build for every F), random walks whose states last
uniform [S, 2S] clocks must count exactly at S = 1.05 x max(1, F/2) (the contract's bound, see
test_count_rate.py), with QERR never set (GLITCH may fire there: a reversal after a short state is a
level of one channel shorter than the filter, rejected without a loss); below the bound every walk is exact or
has QERR/GLITCH set: never a silent loss. COUNT is read as COUNT_LO then COUNT_HI over
Wishbone (enc_qei_wb) or AXI4-Lite with random back-pressure (enc_qei_axil), through the bus
models of enctools.qei. A build of several channels (the shared engine's 16, say) plays an
independent walk on every channel at once and judges each channel alone; the counts are read
after the engine's latency. The `sweep` test is the benchmark driver of scripts/count_rate.py.
"""

from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.triggers import ClockCycles

from cocotbext.quadrature import QuadratureDriver, SharedVector
from hedsmodel.waveform import random_walk
from enctools.qei.bus import PERIOD_PS, T_NS, QeiBus
from enctools.qei.env import engine_lag
from enctools.qei.model import EDGE_FUNCS, QUAD, QUAD_FUNCS, QeiModel
from enctools.regmap import pack
from enctools.tb import cocotb_test, reset_dut, start


class Qei:
    def __init__(self, dut, rng):
        self.dut = dut
        self.channels = int(dut.CHANNELS.value)
        self.bus = QeiBus(dut, rng)
        self.mask = (1 << int(dut.COUNT_W.value)) - 1
        a, b = SharedVector(dut.a_in), SharedVector(dut.b_in)
        self.drvs = [QuadratureDriver(a.bit(k), b.bit(k), clock_period_ps=PERIOD_PS)
                     for k in range(self.channels)]
        self.pos = [0] * self.channels  # 4X position of each stimulus now (state 00 at reset)
        self.lag = engine_lag(self.channels) if int(dut.ENGINE.value) else 0

    async def walk(self, f: int, s_clocks: float, n: int, rng: random.Random,
                   p_reverse: float = 0.3, func: str = "x4") -> list[dict]:
        """Set FILTER_LEN = f and CTRL.FUNC = func, zero the counts, play n transitions on every
        channel at once (each its own walk, channel 0's first from rng); return each channel's
        verdict (the count wanted: the walk's x4 steps, or QeiModel's count for another func)."""
        clk, views = self.dut.clk, [self.bus.at(k) for k in range(self.channels)]
        for bus in views:
            await bus.wr("CTRL", pack("CTRL", EN=1, FUNC=func, RANGE="free", FILTER_LEN=f))
        await ClockCycles(clk, f + 6 + self.lag)
        for bus in views:
            await bus.set_count(0)
            await bus.events()  # clear
        await ClockCycles(clk, self.lag)  # (the shared engine: the clears act before the walks)
        wfs = [random_walk(rng, n, s_clocks * T_NS, 2 * s_clocks * T_NS, p_reverse=p_reverse,
                           start_pos=pos) for pos in self.pos]
        for task in [drv.start(wf) for drv, wf in zip(self.drvs, wfs)]:
            await task
        await ClockCycles(clk, f + 8 + self.lag)
        out = []
        for k, (bus, wf) in enumerate(zip(views, wfs)):
            count = await bus.count()
            events = await bus.events()
            if func == "x4":
                want = (wf.final_position - self.pos[k]) & self.mask
            else:
                model = QeiModel(self.mask.bit_length())
                model.set_func(func, QUAD[self.pos[k] % 4])
                for _, a, b in wf.events:
                    model.sample((a, b))
                want = model.count & self.mask
            self.pos[k] = wf.final_position
            r = {"func": func, "f": f, "s": s_clocks, "n": n, "channel": k, "count": count, "want": want,
                 "exact": count == want, "qerr": "QERR" in events, "glitch": "GLITCH" in events,
                 "min_state_clocks": wf.min_state_ns() / T_NS}
            r["flagged"] = r["qerr"] or r["glitch"]
            out.append(r)
        return out


async def begin(dut) -> tuple[Qei, random.Random]:
    """Clock, seed, inputs; the bus master is created (driving the bus idle) while rst is held,
    so no undriven bus input is sampled after reset; then reset and settle."""
    rng = await start(dut, PERIOD_PS, inputs={"a_in": 0, "b_in": 0, "z_in": 0, "probe_in": 0,
                                               "snap_in": 0}, do_reset=False)
    qei = Qei(dut, rng)
    await reset_dut(dut)
    await ClockCycles(dut.clk, 30)
    await qei.bus.events()  # nothing may be pending after reset but the bus must answer
    return qei, rng


def bound_clocks(f: int) -> float:
    return max(1.0, f / 2)


@cocotb_test()
async def exact_at_bound(dut):
    """F = 1..4 at run time: 8,000 transitions each at S = 1.05 x max(1, F/2), exact, no QERR (every
    channel)."""
    qei, rng = await begin(dut)
    for f in (1, 2, 3, 4):
        for r in await qei.walk(f, 1.05 * bound_clocks(f), 8000, rng):
            dut._log.info("F=%d S=%.3f: %s", f, r["s"], r)
            assert r["exact"], f"miscount through the bus at the contract's bound: {r}"
            assert not r["qerr"], f"QERR at the contract's bound: {r}"


@cocotb_test()
async def every_function_at_bound(dut):
    """Every count function at its bound (x4: exact_at_bound), FILTER_LEN 1 and 4 at run time,
    2,000 transitions each, COUNT = the function's count of the walk (QeiModel), no QERR. The
    quadrature functions at S = 1.05 x max(1, F/2); x1_hyst at F = 1 only (after a reversal's
    dither that the filter rejects, its hysteresis may keep a count one off its count of the
    unfiltered inputs; FILTER_LEN's text). The A-edge functions (pulse_dir, increase, decrease)
    count A's rising edges, so every A level is a pulse the filter must take: at S = 1.05 x
    max(1, F) (every level of A at least 1.05 FILTER_LEN clocks) exact; at the quadrature bound
    with reversals (A levels shorter than the filter) exact or GLITCH, never silent."""
    qei, rng = await begin(dut)
    for func in QUAD_FUNCS + EDGE_FUNCS:
        for f in ((1,) if func == "x1_hyst" else (1, 4)):
            bound = max(1.0, f) if func in EDGE_FUNCS else bound_clocks(f)
            for r in await qei.walk(f, 1.05 * bound, 2000, rng, func=func):
                dut._log.info("%s F=%d S=%.3f: %s", func, f, r["s"], r)
                assert r["exact"], f"{func}: miscount through the bus at the contract's bound: {r}"
                assert not r["qerr"], f"{func}: QERR at the contract's bound: {r}"
            if func in EDGE_FUNCS and f > 1:
                for r in await qei.walk(f, 1.05 * bound_clocks(f), 2000, rng, func=func):
                    dut._log.info("%s F=%d S=%.3f: %s", func, f, r["s"], r)
                    assert r["exact"] or r["glitch"], f"{func}: silent miscount with A pulses under FILTER_LEN: {r}"


@cocotb_test()
async def never_silent(dut):
    """Past the bound (F = 3: levels shorter than the filter; states under one clock), with every
    count function (x4 2,000 transitions a walk, the others 1,000): every walk exact or flagged,
    and states under one clock always flagged. The A-edge functions only with states of 1.05
    clocks or more (F = 3 and 2): an A pulse shorter than a clock may fall between two samples,
    and one no clock samples is neither counted nor flagged (CTRL.FILTER_LEN's text;
    test_counting's sub_clock_a_pulse_unseen)."""
    qei, rng = await begin(dut)
    inexact = {}
    for func in QUAD_FUNCS + EDGE_FUNCS:
        points = ((3, 1.05), (1, 0.7), (2, 0.4)) if func in QUAD_FUNCS else ((3, 1.05), (2, 1.05))
        for f, s in points:
            for r in await qei.walk(f, s, 2000 if func == "x4" else 1000, rng, func=func):
                dut._log.info("%s F=%d S=%.2f: %s", func, f, s, r)
                assert r["exact"] or r["flagged"], f"{func}: silent miscount through the bus: {r}"
                if s < 1:
                    assert r["flagged"], f"{func}: states under one clock but neither QERR nor GLITCH: {r}"
                inexact[func] = inexact.get(func, 0) + (not r["exact"])
    dut._log.info("inexact (flagged) walks by function: %s", inexact)
    assert all(inexact.values()), f"a function never miscounted past the bound: {inexact}"


@cocotb_test()
async def flagged_below_bound(dut):
    """F = 1..4 at S = 0.8 x max(1, F/2): every channel's walk exact or flagged (QERR / GLITCH),
    and some walk inexact (the stimulus broke the rule)."""
    qei, rng = await begin(dut)
    inexact = 0
    for f in (1, 2, 3, 4):
        for r in await qei.walk(f, 0.8 * bound_clocks(f), 2000, rng):
            dut._log.info("F=%d S=%.2f: %s", f, r["s"], r)
            assert r["exact"] or r["flagged"], f"silent miscount below the bound: {r}"
            inexact += not r["exact"]
    assert inexact, "every walk at 0.8 x the bound counted exactly: the test tested nothing"


@cocotb_test()
async def sweep(dut):
    """Benchmark driver (scripts/count_rate.py --dut qei): points from ENC_POINTS."""
    qei, _ = await begin(dut)
    results = []
    for pt in json.loads(os.environ["ENC_POINTS"]):
        for r in await qei.walk(pt["f"], pt["s"], pt["n"], random.Random(pt["seed"])):
            r["seed"] = pt["seed"]
            results.append(r)
        with open(os.environ["ENC_RESULTS"], "w") as fh:
            json.dump(results, fh)
