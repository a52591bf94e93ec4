# SPDX-License-Identifier: Apache-2.0
"""The cocotb side of `make demo` (scripts/demo.py): plays the modeled HEDS-5000 waveform into
tb/hdl/demo_top.v and records what the circuits did. No verdicts here: enctools.demo compares the
records with the model and prints the tables.

The bus peripheral enc_qei_wb is read as a host would, over Wishbone through enctools.qei.bus's
QeiBus (cocotbext-wishbone's WishboneMaster; register offsets and fields from the compiled
rtl/enc_qei.rdl): once the waveform starts, STALL_TIMEOUT and SNAP_CTRL.EDGE are written; at each
planned read time a snapshot is commanded (SNAP_CTRL.CMD) and SNAP_COUNT_LO, SNAP_TIME,
SNAP_EDGE_TIME, SNAP_DELTA, SNAP_EDGE_DELTA and STATUS are read; after the profile, COUNT.

Environment (set by enctools.demo.simulate):
  ENC_DEMO_PLAN      JSON: clk_ps, events [[t_ns, a, b]...], seg {name: [t0_ns, t1_ns]}, meas_rst_ns,
                 hold_test_ns, hold_test_clocks, back_mid_ns, qei {reads_ns [...], edge (an
                 SNAP_CTRL.EDGE member name), stall_ticks}
  ENC_DEMO_RESULT    JSON written at the end (see ``result`` below)
  ENC_DEMO_PROGRESS  a one-line file "<sim ns> <total ns> <segment>" rewritten as the run goes
"""

from __future__ import annotations

import json
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from cocotbext.quadrature import play

from enctools.tb import cocotb_test, until
from hedsmodel.waveform import Waveform
from enctools.qei.bus import QeiBus
from enctools.regmap import get_field, pack

QEI_READS = ("SNAP_COUNT_LO", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA", "SNAP_EDGE_DELTA",
             "STATUS")


def _int(sig) -> int:
    return int(sig.value)


def _signed(sig) -> int:
    return sig.value.to_signed()


async def _record_rises(sig, out: list) -> None:
    while True:
        await RisingEdge(sig)
        out.append(get_sim_time("ps"))


async def _record_pm(dut, out: list) -> None:
    while True:
        await RisingEdge(dut.pm_valid)
        await ReadOnly()
        out.append({"t_ps": get_sim_time("ps"), "phase_err": _signed(dut.pm_phase_err),
                    "a_leads": _int(dut.pm_a_leads), "b_leads": _int(dut.pm_b_leads)})


async def _record_ch(dut, out: list) -> None:
    while True:
        await RisingEdge(dut.ch_valid)
        await ReadOnly()
        out.append({"t_ps": get_sim_time("ps"),
                    **{k: _signed(getattr(dut, "ch_" + k))
                       for k in ("cycle_err", "pulse_err", "phase_err", "state_err")},
                    "state_min": _int(dut.ch_state_min), "pass": _int(dut.ch_pass)})


async def _progress(path: str, t0_ps: float, total_ns: float, seg: dict) -> None:
    step = total_ns / 100.0
    t = 0.0
    while True:
        label = next((n for n, (a, b) in seg.items() if a <= t < b), "")
        try:
            with open(path, "w") as f:
                f.write(f"{t:.0f} {total_ns:.0f} {label}\n")
        except OSError:
            pass
        t += step
        await until(t0_ps + t * 1000.0)


SNAP_SIGNALS = ("x1_count", "x2_count", "x4_count", "pm_a_leads", "pm_b_leads")


async def _snapshot(dut, t_ps: float, key: str, out: dict) -> None:
    """The counts and the phase meter's LEDs at ``t_ps``, as ``out[key]``."""
    await until(t_ps)
    await ReadOnly()
    out[key] = {n: _signed(getattr(dut, n)) if n.endswith("_count") and n.startswith("x")
                else _int(getattr(dut, n)) for n in SNAP_SIGNALS}


async def _pulse(dut, t_ps: float, sig_name: str) -> None:
    """One clock of ``sig_name`` high, from the first falling clock edge after ``t_ps``."""
    await until(t_ps)
    await FallingEdge(dut.clk)
    getattr(dut, sig_name).value = 1
    await FallingEdge(dut.clk)
    getattr(dut, sig_name).value = 0


async def _hold_test(dut, t_ps: float, clocks: int, out: dict) -> None:
    """Assert the buffer's read inhibit for `clocks` clocks: rd_data must not move while the
    count does, and must catch up within 2 clocks of release."""
    await until(t_ps)
    await FallingEdge(dut.clk)
    dut.hold.value = 1
    await RisingEdge(dut.clk)      # rd_data takes its last value on this edge at the latest
    await FallingEdge(dut.clk)
    rd0, c0 = _int(dut.bcd_rd), _int(dut.bcd_count)
    frozen, moved = True, 0
    prev = c0
    for _ in range(clocks):
        await FallingEdge(dut.clk)
        if _int(dut.bcd_rd) != rd0:
            frozen = False
        c = _int(dut.bcd_count)
        moved += c != prev
        prev = c
    dut.hold.value = 0
    caught = False
    for _ in range(2):
        await FallingEdge(dut.clk)
        if _int(dut.bcd_rd) == _int(dut.bcd_count):
            caught = True
            break
    out.update(frozen=frozen, moved=moved, caught_up=caught, clocks=clocks)


async def _qei_reads(bus: QeiBus, t0_ps: float, qei: dict, out: list) -> None:
    """Set up enc_qei_wb, then at each planned time command a snapshot and read its registers
    (``t_ack_ps``: when the SNAP_CTRL write was acknowledged, a clock or two after the latch)."""
    edge = qei["edge"]
    await bus.wr("STALL_TIMEOUT", int(qei["stall_ticks"]))
    await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", EDGE=edge))
    for r_ns in qei["reads_ns"]:
        await until(t0_ps + r_ns * 1000.0)
        await bus.wr("SNAP_CTRL", pack("SNAP_CTRL", CMD=1, EDGE=edge))
        t_ack = get_sim_time("ps")
        words = {n: await bus.rd(n) for n in QEI_READS}   # one bus cycle each, as a simple host
        words["stalled"] = get_field("STATUS", "STALLED", words["STATUS"])
        out.append({"t_ack_ps": t_ack, **words})


async def _start(dut, clk_ps: int, events: list) -> QeiBus:
    """Clock, reset with the waveform's first state at the inputs, the Wishbone master idle;
    returns the bus once reset is released."""
    cocotb.start_soon(Clock(dut.clk, clk_ps, unit="ps").start())
    dut.rst.value = 1
    dut.meas_rst.value = 0
    dut.hold.value = 0
    dut.a_in.value = events[0][1]
    dut.b_in.value = events[0][2]
    await FallingEdge(dut.clk)
    # the Wishbone inputs from a clock edge on (set at time 0, Icarus left wb_ack_o at X)
    for name in ("wb_cyc_i", "wb_stb_i", "wb_we_i", "wb_adr_i", "wb_dat_i", "wb_sel_i"):
        getattr(dut, name).value = 0
    bus = QeiBus(dut, random.Random(0))   # the bus master, idle, while rst is held
    for _ in range(3):
        await FallingEdge(dut.clk)
    dut.rst.value = 0
    return bus


async def _final(dut) -> dict:
    """The counters and error tallies once the circuits have settled."""
    for _ in range(50):
        await FallingEdge(dut.clk)
    await ReadOnly()
    return {n: (_signed(getattr(dut, n)) if n.startswith("x") else _int(getattr(dut, n)))
            for n in ("x1_count", "x2_count", "x4_count", "bcd_count", "bcd_rd", "n_glitch",
                      "n_x1_err", "n_x2_err", "n_x4_err", "n_bcd_flag")}


def _dither(snaps: dict, pulses: dict, window_ps: tuple) -> dict:
    """Pulses inside the dither (up to 20 clocks after it) and the counts' net change across it."""
    def inside(ts):
        return len([t for t in ts if window_ps[0] <= t <= window_ps[1]])

    ds, de = snaps.get("dither_start", {}), snaps.get("dither_end", {})
    return {"x4_pulses": inside(pulses["x4"]),
            "x1_pulses": inside(pulses["x1_up"]) + inside(pulses["x1_dn"]),
            "x4_net": de["x4_count"] - ds["x4_count"],
            "x2_net": de["x2_count"] - ds["x2_count"],
            "x1_net": de["x1_count"] - ds["x1_count"]}


@cocotb_test()
async def demo(dut):
    plan = json.loads(open(os.environ["ENC_DEMO_PLAN"]).read())
    clk_ps = int(plan["clk_ps"])
    events = [tuple(e) for e in plan["events"]]
    wf = Waveform(events=events, positions=[0] * len(events))
    seg = plan["seg"]
    total_ns = max(b for _, b in seg.values())
    bus = await _start(dut, clk_ps, events)
    await Timer(clk_ps // 3, unit="ps")  # start the waveform off the clock grid
    t0 = get_sim_time("ps")

    a_rises, pm, ch = [], [], []
    pulses = {"x1_up": [], "x1_dn": [], "x4": []}
    for coro in (_record_rises(dut.a, a_rises), _record_rises(dut.x1_up, pulses["x1_up"]),
                 _record_rises(dut.x1_dn, pulses["x1_dn"]), _record_rises(dut.x4_pulse, pulses["x4"]),
                 _record_pm(dut, pm), _record_ch(dut, ch)):
        cocotb.start_soon(coro)
    if os.environ.get("ENC_DEMO_PROGRESS"):
        cocotb.start_soon(_progress(os.environ["ENC_DEMO_PROGRESS"], t0, total_ns, seg))
    cocotb.start_soon(_pulse(dut, t0 + plan["meas_rst_ns"] * 1000, "meas_rst"))
    hold_test: dict = {}
    cocotb.start_soon(_hold_test(dut, t0 + plan["hold_test_ns"] * 1000, plan["hold_test_clocks"],
                                 hold_test))
    snaps: dict = {}
    d0, d1 = seg["dither"]
    for key, t_ns in (("hold_end", seg["hold"][1] - 1000.0), ("back_mid", plan["back_mid_ns"]),
                      ("dither_start", d0), ("dither_end", d1 + 20 * clk_ps / 1000)):
        cocotb.start_soon(_snapshot(dut, t0 + t_ns * 1000, key, snaps))
    qei_reads: list = []
    qei_task = cocotb.start_soon(_qei_reads(bus, t0, plan["qei"], qei_reads))

    await play(dut, wf, "a_in", "b_in")
    await until(t0 + (total_ns + 1000.0) * 1000)
    await qei_task
    qei_count = await bus.count()
    final = await _final(dut)
    result = {
        "t0_ps": t0, "clk_ps": clk_ps, "final": final, "a_rises_ps": a_rises,
        "pm_readings": pm, "ch_readings": ch, "hold_test": hold_test,
        "leds": {"hold": [snaps["hold_end"]["pm_a_leads"], snaps["hold_end"]["pm_b_leads"]],
                 "back": [snaps["back_mid"]["pm_a_leads"], snaps["back_mid"]["pm_b_leads"]]},
        "dither": _dither(snaps, pulses, (t0 + d0 * 1000, t0 + d1 * 1000 + 20 * clk_ps)),
        "snaps": snaps,
        "qei": {"reads": qei_reads, "count": qei_count},
    }
    with open(os.environ["ENC_DEMO_RESULT"], "w") as f:
        json.dump(result, f)
