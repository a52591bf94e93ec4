# SPDX-License-Identifier: Apache-2.0
"""cocotb module of scripts/phase_adjust.py: a technician adjusting a modelled unit's phase on the
averaging phase meter (enc_phase_meter, Figure 11), read as the meter reports it."""

from __future__ import annotations

import os

from enctools.tb import cocotb_test
from enctools.tb.phase_models import CLK_PS, play_case, start_clock, window_log2


def adjust_waveform(cpc: float, phase_at, cycles: int, forward: bool, pulse_err=(6.0, -4.0),
                    t0_ns: float = 0.0):
    """A unit whose rise phase follows ``phase_at(k)`` (cycle k), i.e. the encoder body being
    turned while the shaft runs. Returns the waveform (events off the clock grid)."""
    from hedsmodel.waveform import Waveform
    period = cpc * CLK_PS / 1000.0
    pa, pb = pulse_err
    edges = []  # (t, channel, level)
    for k in range(cycles):
        ph = phase_at(k)
        # forward: A rise at 0, B rise at ph, A fall at 180 + pa, B fall at ph + 180 + pb (degrees
        # of this cycle); reverse plays the same angles backwards
        for ang, chan, lvl in ((0.0, 0, 1), (ph, 1, 1), (180.0 + pa, 0, 0), (ph + 180.0 + pb, 1, 0)):
            if forward:
                edges.append((t0_ns + (k + ang / 360.0) * period, chan, lvl))
            else:
                edges.append((t0_ns + (k + 1 - ang / 360.0) * period, chan, 1 - lvl))
    edges.sort()
    a, b = (0, 0) if forward else (0, 0)
    wf = Waveform()
    wf.append(t0_ns, None, (a, b))
    for t, chan, lvl in edges:
        if chan == 0:
            a = lvl
        else:
            b = lvl
        wf.append(max(t, wf.events[-1][0]), None, (a, b))
    return wf


@cocotb_test()
async def phase_adjust_sweep(dut):
    """scripts/phase_adjust.py: the technician turns the encoder body so that the phase moves
    slowly from 60 to 120 e-degrees (between the pulse centres) while the shaft runs forward, then runs the shaft in reverse
    at the 90 degree setting. Writes the readings and the true phases to $ENC_PHASE_ADJUST_OUT."""
    import json

    await start_clock(dut)
    w = 2 ** window_log2(dut)
    cpc = 109.618034
    per_window = w / cpc
    n_fwd = int(float(os.environ.get("ENC_PHASE_ADJUST_READINGS", "25")) * (per_window + 1.5))
    # rise phase such that the phase between pulse centres (what the meter reads) runs 60 -> 120
    phase_fwd = lambda k: 65.0 + 60.0 * k / n_fwd  # noqa: E731
    wf = adjust_waveform(cpc, phase_fwd, n_fwd, True)
    t_end = wf.events[-1][0]
    n_rev = int(2 * (per_window + 1.5)) + 2
    wf_rev = adjust_waveform(cpc, lambda k: 95.0, n_rev, False, t0_ns=t_end)
    wf.events += wf_rev.events[1:]
    wf.positions += wf_rev.positions[1:]
    items, start_ps = await play_case(dut, wf)
    period_ns = cpc * CLK_PS / 1000.0
    rows = []
    for t_ps, perr, a_l, b_l in items:
        t_ns = (t_ps - start_ps) / 1000.0
        # the window: 2^W clocks ending W + 18 clocks before the reading; its true phase is the
        # mean of the per-cycle phases (centres) over it
        t1 = t_ns - (window_log2(dut) + 18) * CLK_PS / 1000.0
        t0 = t1 - w * CLK_PS / 1000.0
        if t1 <= t_end:
            ks = [k for k in range(n_fwd) if t0 <= k * period_ns < t1]
            true = sum(phase_fwd(k) for k in ks) / len(ks) + (-4.0 - 6.0) / 2.0
        else:
            true = 95.0 + (-4.0 - 6.0) / 2.0
        rows.append({"t_ms": t_ns / 1e6, "phase_err": perr, "true_err": true - 90.0,
                     "a_leads": a_l, "b_leads": b_l, "forward": t1 <= t_end})
    with open(os.environ["ENC_PHASE_ADJUST_OUT"], "w") as f:
        json.dump({"window_log2": window_log2(dut), "clocks_per_cycle": cpc, "clk_ns": CLK_PS / 1000,
                   "readings": rows}, f, indent=1)
