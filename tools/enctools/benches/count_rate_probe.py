# SPDX-License-Identifier: Apache-2.0
"""Count-rate limit at the physical bound (contract of enc_conditioner + decoders).

With FILTER_LEN = F and clock period T, counting must be exact whenever every state lasts at
least 1.05 T and every level of A or B that spans a change of the other channel lasts at least
1.05 F T. For random walks whose states last uniform[S, 2S], a level spanning a change is at
least two states, so the bound is S = max(1, F/2) clocks. Below it the count may be wrong, but
never silently: error or glitch must have fired.

The DUT is tb/hdl/enc_quad_probe.v (conditioner -> x4, x2, x1 with accumulators). The cocotb test
`sweep` is driven by scripts/count_rate.py, which measures the limit; the others run in make test
(tb/count_rate/test_count_rate.py).
"""

import json
import os
import random

import cocotb
from cocotb.triggers import FallingEdge, Timer

from enctools import tb as tbutil
from enctools.tb.models import two_x_count
from cocotbext.quadrature import play
from hedsmodel.waveform import random_walk
from enctools.tb import cocotb_test, log_seed, reset_dut

PERIOD_PS = 10_000
T_NS = PERIOD_PS / 1000


async def start(dut):
    await tbutil.start(dut, PERIOD_PS, {"a_in": 0, "b_in": 0})


async def run_walk(dut, rng, n, s_clocks, p_reverse=0.3) -> dict:
    """Reset, settle, play n transitions with states uniform[S, 2S] clocks; return what the
    decoders counted and what the shaft did."""
    f = int(dut.FILTER_LEN.value)
    dut.a_in.value = 0  # the walk starts in state 00: be there before the decoders take their
    dut.b_in.value = 0  # reference state (FILTER_LEN + 2 clocks after rst)
    await reset_dut(dut)
    await Timer((f + 4) * PERIOD_PS, unit="ps")
    wf = random_walk(rng, n, s_clocks * T_NS, 2 * s_clocks * T_NS, p_reverse=p_reverse)
    await play(dut, wf, clock_period_ps=PERIOD_PS)
    await Timer((f + 8) * PERIOD_PS, unit="ps")
    await FallingEdge(dut.clk)
    p = wf.final_position
    r = {name: getattr(dut, name).value.to_signed()
         for name in ("pos4", "pos2", "pos1", "n_err4", "n_err2", "n_err1", "n_glitch")}
    r.update(true4=p, true2=two_x_count(p) - two_x_count(0), s=s_clocks, n=n,
             min_state_clocks=wf.min_state_ns() / T_NS)
    r["exact4"] = r["pos4"] == p
    r["exact2"] = r["pos2"] == r["true2"]
    r["x1_ok"] = -1 <= p - 4 * r["pos1"] <= 3  # the hysteresis band of enc_x1_hysteresis
    r["exact"] = r["exact4"] and r["exact2"] and r["x1_ok"]
    r["flagged"] = r["n_err4"] + r["n_glitch"] > 0
    return r


def bound_clocks(f: int) -> float:
    return max(1.0, f / 2)


@cocotb_test()
async def exact_at_bound(dut):
    """20,000 transitions with S = 1.05 x max(1, F/2): every decoder exact, no error pulse."""
    await start(dut)
    log_seed(dut)
    f = int(dut.FILTER_LEN.value)
    rng = random.Random(cocotb.RANDOM_SEED)
    r = await run_walk(dut, rng, 20000, 1.05 * bound_clocks(f))
    dut._log.info("F=%d S=%.3f: %s", f, r["s"], r)
    assert r["exact"], f"miscount at the contract's bound: {r}"
    assert r["n_err4"] == 0 and r["n_err2"] == 0 and r["n_err1"] == 0, f"error pulses: {r}"


@cocotb_test()
async def never_silent(dut):
    """Past the limit: states of 1.05 T with levels shorter than the filter, and states of 0.4 T to
    0.8 T (under the sampling limit). Each run is exact or flagged; the fastest is flagged."""
    await start(dut)
    log_seed(dut)
    rng = random.Random(cocotb.RANDOM_SEED + 1)
    for s in (1.05, 0.7, 0.4):
        r = await run_walk(dut, rng, 3000, s)
        dut._log.info("S=%.2f: %s", s, r)
        assert r["exact"] or r["flagged"], f"silent miscount at S = {s} clocks: {r}"
        if s < 1:
            assert r["flagged"], f"states under one clock but neither error nor glitch: {r}"


@cocotb_test()
async def sweep(dut):
    """Benchmark driver (scripts/count_rate.py): points from ENC_POINTS, results to ENC_RESULTS."""
    await start(dut)
    log_seed(dut)
    points = json.loads(os.environ["ENC_POINTS"])
    results = []
    for pt in points:
        rng = random.Random(pt["seed"])
        r = await run_walk(dut, rng, pt["n"], pt["s"])
        r["seed"] = pt["seed"]
        results.append(r)
        with open(os.environ["ENC_RESULTS"], "w") as fh:
            json.dump(results, fh)
