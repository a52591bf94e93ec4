# SPDX-License-Identifier: Apache-2.0
"""enc_qei in a simulated LiteX SoC, its firmware against the motion model (`make soc-sim`).

The SoC (VexRiscv, ROM, SRAM, UART, 4 full channels driven by tools/enctools/litex/motion.py)
runs sw/soc/main.c: discovery from ID and CAPS through the driver API, the 1 kHz global
snapshot, the interrupt handler's positions and velocities, a command snapshot at the end.
enctools.litex.check compares what it printed with the model (its docstring states the velocity bound); the firmware
runs twice, with the fixed-point estimator (the default: its readings within one unit of the
double estimator on the model's registers, in fewer than 500 cycles a channel, no floating point
linked) and with the double one (FW_VEL=double). The firmware built with FW_FAULT=page reads one
register from the wrong channel page, and the same check must fail on it. The edge-FIFO build
(simsoc.EFIFO: 3 channels, 256 entries each) runs the same firmware, which drains the FIFOs;
check.check_efifo compares the entries with the model's steps, and must fail on the firmware
built with FW_FAULT=efifo (an entry's direction from the wrong bit). Two more builds
(simsoc.ENGINE and simsoc.ENGINE_FULL: lean and full channels sharing one engine) run the same
firmware, and simsoc.ENGINE_EFIFO (the edge-FIFO build's channels on the engine) drains its FIFOs
with the same checks. The main and the
edge-FIFO builds read one unmapped offset: on VexRiscv it stalls for LiteX's bus timeout and
reads all ones.

Run by `make soc-sim` (ENC_SOC_SIM=1), after scripts/soc_sim.py has built the simulator; the
builds and runs are cached, so this reuses them. Skipped by `make test`.
"""

from __future__ import annotations

import copy
import os

import pytest

if os.environ.get("ENC_SOC_SIM") != "1":
    pytest.skip("the LiteX SoC simulation runs under `make soc-sim`", allow_module_level=True)

from enctools.litex import check, cli, simsoc  # noqa: E402

CFG = simsoc.MAIN
ECFG = simsoc.EFIFO
BUS_TIMEOUT = 10**6   # LiteX's Wishbone timeout (SoCCore bus_timeout), in clocks


def _run(fault=None, cfg=CFG, vel="fixed"):
    simsoc.build_gateware(cfg)
    fw = simsoc.build_firmware(cfg, fault, vel)
    out, _ = simsoc.run(cfg, fw)
    run = check.parse(out)
    return (run, *check.check_run(cfg.motions(), run))


@pytest.fixture(scope="module")
def good():
    return _run()[:2]


def _fails(res, what):
    return [m for w, m in res.failures if w == what]


def test_firmware_finds_the_build(good):
    run, res = good
    assert run.done, "the firmware did not print DONE"
    assert run.build == {"channels": CFG.channels, "profile": 2, "count_w": 32, "ts_w": 32,
                         "clk_hz": CFG.clk_hz, "period": CFG.clk_hz // 1000, "efifo_log2": 0,
                         "engine": 0, "vel": "fx8"}
    assert len(run.rows) == CFG.snapshots


def test_no_missed_snapshot(good):
    run, res = good
    assert not _fails(res, "snapshots")
    assert run.misses == (0, 0, 0, 0)


def test_command_snapshot(good):
    """enc_qei_drv_gsnap_take() after the timer stopped: every position the model's."""
    run, res = good
    assert run.gsnap and run.gsnap[0] == 0
    assert not _fails(res, "gsnap")


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


def test_fixed_point_readings_held_to_one_unit(good):
    """The check holds the fixed-point readings to one unit (2^-8 count/s) of the estimator on
    the model's registers: a reading moved by 1.5 units fails it, one moved by 0.4 does not."""
    run, res = good
    assert check.resolution(run) == 2.0**-8
    for du, ok in ((0.4, True), (1.5, False)):
        r2 = copy.deepcopy(run)
        i = len(r2.rows) // 2
        n, t, lat, cyc, pos, vel = r2.rows[i]
        vel = [v + du / 256 if k == 1 else v for k, v in enumerate(vel)]
        r2.rows[i] = (n, t, lat, cyc, pos, vel)
        assert check.check(CFG.motions(), r2, delay=res.delay).ok is ok, du


@pytest.fixture(scope="module")
def double():
    return _run(vel="double")[:2]


def test_double_estimator_build(double):
    """The same firmware with the double estimator passes the same checks."""
    run, res = double
    assert run.build["vel"] == "double"
    assert res.ok, res.failures


def test_handler_goal_per_channel(good, double):
    """The fixed point: at most 500 cycles a channel on average (snapshot read, position,
    velocity, record), 16 channels at 1 kHz in 20 % of the CPU by the worst case; the double
    estimator far slower."""
    fx, db = cli.PerChannel.of(good[0]), cli.PerChannel.of(double[0])
    period = CFG.clk_hz // 1000
    assert fx.mean <= cli.GOAL_PER_CHANNEL, fx
    assert fx.handler(cli.GOAL_CHANNELS) <= cli.GOAL_SHARE * period, fx
    assert db.mean > 5 * fx.mean, (db, fx)


def test_fixed_point_firmware_links_no_floating_point():
    fw = simsoc.build_firmware(CFG)
    assert simsoc.soft_float_symbols(fw) == []
    assert "__divdf3" in simsoc.soft_float_symbols(simsoc.build_firmware(CFG, vel="double"))


def test_wrong_page_fails_the_check():
    run, res, _ = _run("page")
    assert run.done
    assert not res.ok
    assert _fails(res, "positions"), res.failures


@pytest.fixture(scope="module")
def efifo_run():
    return _run(cfg=ECFG)


def test_efifo_build_positions_and_velocity(efifo_run):
    run, res, _ = efifo_run
    assert run.done and run.build["efifo_log2"] == ECFG.efifo_log2
    assert run.build["channels"] == ECFG.channels
    assert res.ok, res.failures


def test_efifo_entries_are_the_model_steps(efifo_run):
    run, res, fifo = efifo_run
    assert fifo.ok, fifo.failures
    assert fifo.offset == res.delay          # one time axis with the snapshots
    assert all(run.efifo[k]["entries"] > 100 for k in range(ECFG.channels)), run.efifo
    assert sum(run.efifo[k]["dir_changes"] for k in range(ECFG.channels)) >= 2
    assert sum(run.efifo[k]["idx"] for k in range(ECFG.channels)) >= 1


def test_wrong_efifo_field_fails_the_check():
    run, res, fifo = _run("efifo", ECFG)
    assert run.done
    assert not fifo.ok and [m for w, m in fifo.failures if w == "efifo"], fifo.failures


@pytest.mark.parametrize("cfg, profile", [(simsoc.ENGINE, 3), (simsoc.ENGINE_FULL, 2)],
                         ids=["lean", "full"])
def test_shared_engine_build(cfg, profile):
    """The same firmware on lean and on full channels sharing one engine (CAPS.ENGINE = shared):
    the driver's snapshots, positions and velocities pass every check there too."""
    run, res, _ = _run(cfg=cfg)
    assert run.build["engine"] == 1 and run.build["profile"] == profile
    assert run.build["channels"] == cfg.channels
    assert res.ok, res.failures


def test_engine_efifo_build():
    """The edge-FIFO build's channels and motions on the shared engine (its FIFOs beside the
    engine): the same firmware, the same checks of positions, velocities and FIFO entries."""
    cfg = simsoc.ENGINE_EFIFO
    run, res, fifo = _run(cfg=cfg)
    assert run.done and run.build["engine"] == 1 and run.build["efifo_log2"] == cfg.efifo_log2
    assert res.ok, res.failures
    assert fifo.ok, fifo.failures
    assert all(run.efifo[k]["entries"] > 100 for k in range(cfg.channels)), run.efifo


@pytest.mark.parametrize("which", ["main", "efifo"])
def test_unmapped_offset_on_vexriscv(which, good, efifo_run):
    """The peripheral answers wb_err_o; VexRiscv does not take it as an answer, so the access
    waits for LiteX's bus timeout, which answers all ones (and counts a bus error)."""
    run = (good if which == "main" else efifo_run)[0]
    u = run.unmapped
    assert u["value"] == 0xFFFFFFFF, u
    assert BUS_TIMEOUT <= u["cycles"] < BUS_TIMEOUT + 1000, u
    assert u["bus_errors"] == 1, u
