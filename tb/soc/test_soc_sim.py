# SPDX-License-Identifier: Apache-2.0
"""enc_qei in a simulated LiteX SoC, its firmware against the motion model (`make soc-sim`).

The SoC (VexRiscv, ROM, SRAM, UART, 4 full channels driven by tools/enctools/litex/motion.py)
runs sw/soc/main.c: discovery from ID and CAPS, the 1 kHz global snapshot, the interrupt
handler's positions and velocities. enctools.litex.check compares what it printed with the model
(its docstring states the velocity bound). The firmware built with FW_FAULT=page reads one
register from the wrong channel page, and the same check must fail on it.

Run by `make soc-sim` (ENC_SOC_SIM=1), after scripts/soc_sim.py has built the simulator; the
builds and runs are cached, so this reuses them. Skipped by `make test`.
"""

from __future__ import annotations

import os

import pytest

if os.environ.get("ENC_SOC_SIM") != "1":
    pytest.skip("the LiteX SoC simulation runs under `make soc-sim`", allow_module_level=True)

from enctools.litex import check, simsoc  # noqa: E402

CFG = simsoc.SocConfig()


def _run(fault=None):
    simsoc.build_gateware(CFG)
    fw = simsoc.build_firmware(CFG, fault)
    out, _ = simsoc.run(CFG, fw)
    run = check.parse(out)
    return run, check.check(CFG.motions(), run)


@pytest.fixture(scope="module")
def good():
    return _run()


def _fails(res, what):
    return [m for w, m in res.failures if w == what]


def test_firmware_finds_the_build(good):
    run, res = good
    assert run.done, "the firmware did not print DONE"
    assert run.build == {"channels": CFG.channels, "profile": 2, "count_w": 32, "ts_w": 32,
                         "clk_hz": CFG.clk_hz, "period": CFG.clk_hz // 1000}
    assert len(run.rows) == CFG.snapshots


def test_no_missed_snapshot(good):
    run, res = good
    assert not _fails(res, "snapshots")
    assert run.misses == (0, 0, 0)


def test_positions_exact(good):
    run, res = good
    assert not _fails(res, "positions")
    assert res.delay is not None and res.positions == CFG.snapshots * CFG.channels


def test_velocity_estimator_and_bound(good):
    run, res = good
    assert not _fails(res, "velocity")
    assert res.bounded > CFG.channels * CFG.snapshots // 2, res.summary
    assert res.worst <= 1.0


def test_index_latch_and_error_counters(good):
    assert not _fails(good[1], "index")


def test_handler_cycles_reported(good):
    run, _ = good
    assert sorted(run.cycles) == list(range(1, CFG.channels + 1))
    means = [run.cycles[k][1] for k in sorted(run.cycles)]
    assert means == sorted(means)
    assert run.cycles[CFG.channels][2] < CFG.clk_hz // 1000   # the handler fits in the period


def test_wrong_page_fails_the_check():
    run, res = _run("page")
    assert run.done
    assert not res.ok
    assert _fails(res, "positions"), res.failures
