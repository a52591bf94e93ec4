# SPDX-License-Identifier: Apache-2.0
"""Parametric two-channel encoder waveforms and reference measurements for the phase meter and the
characterizer tests (and scripts/phase_adjust.py).

Waveforms are built from the shaft's electrical angle theta(t) (360 e-degrees per cycle), not from
a clock: the channel levels are functions of theta,

    A = 1  for  theta mod 360 in [0, 180 + pulse_err_a)
    B = 1  for  (theta - rise_phase) mod 360 in [0, 180 + pulse_err_b)

so a trajectory that runs forward, stops or reverses gives the right sequence of edges in every
case, at real-valued times (off any clock grid). Forward rotation (theta increasing) makes A lead
B: 00 -> 10 -> 11 -> 01, as in the module contracts. Each edge may then be moved by a random
timing jitter. The result is a ``hedsmodel.Waveform`` (events ``(t_ns, a, b)``), the format that
``cocotbext.quadrature.play`` drives and that ``hedsmodel`` also produces.

The measurements here work on the continuous event times (the "true" waveform), or on the clock
samples of it (``sample_index``), independently of the RTL.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time
from cocotbext.quadrature import play
from hedsmodel.waveform import STATE_TO_POS, Waveform

from enctools import tb as tbutil

CLK_PS = 10_000  # test clock period (10 ns); rising edges at multiples of it from time 0
LSB = 1.0 / 256.0  # degrees per phase_err LSB


@dataclass
class Channels:
    """Edge angles of one encoder, electrical degrees within a cycle."""

    rise_phase: float = 90.0  # B rising edge after A rising edge (forward), e-degrees
    pulse_err_a: float = 0.0  # A high for 180 + pulse_err_a
    pulse_err_b: float = 0.0  # B high for 180 + pulse_err_b

    def edges(self):
        """(angle, channel, level-after-crossing-forward) for the four edges of one cycle."""
        ph = self.rise_phase
        return [(0.0, 0, 1), ((180.0 + self.pulse_err_a) % 360.0, 0, 0),
                (ph % 360.0, 1, 1), ((ph + 180.0 + self.pulse_err_b) % 360.0, 1, 0)]

    def levels(self, theta: float) -> tuple[int, int]:
        a = 1 if (theta % 360.0) < 180.0 + self.pulse_err_a else 0
        b = 1 if ((theta - self.rise_phase) % 360.0) < 180.0 + self.pulse_err_b else 0
        return a, b

    def state_widths(self) -> tuple[float, float, float, float]:
        """Forward-order state widths 10, 11, 01, 00 in e-degrees (negative: states overlap)."""
        ph, pa, pb = self.rise_phase, self.pulse_err_a, self.pulse_err_b
        return (ph, 180.0 + pa - ph, ph + pb - pa, 180.0 - ph - pb)

    @property
    def true_phase(self) -> float:
        """Phase between pulse centres = mean of the rising-edge and falling-edge phases."""
        return self.rise_phase + (self.pulse_err_b - self.pulse_err_a) / 2.0


def waveform(ch: Channels, segments, theta0: float = -45.0, jitter_ns: float = 0.0,
             rng: random.Random | None = None, t0_ns: float = 0.0) -> Waveform:
    """Waveform for a piecewise-constant-speed trajectory.

    ``segments``: list of ``(duration_ns, speed)`` with ``speed`` in cycles per ns (negative =
    reverse, 0 = standing). ``theta0`` is the starting electrical angle. ``jitter_ns``: each edge
    moves by uniform(-jitter, +jitter) ns (kept small against the state widths).
    """
    rng = rng or random.Random(0)
    crossings = []  # (t_ns, channel)
    theta, t = theta0, t0_ns
    edges = ch.edges()
    for dur, speed in segments:
        if speed != 0.0:
            th_end = theta + 360.0 * speed * dur
            lo, hi = min(theta, th_end), max(theta, th_end)
            for ang, chan, _ in edges:
                k = math.ceil((lo - ang) / 360.0)
                while ang + 360.0 * k <= hi:
                    e = ang + 360.0 * k
                    if lo < e <= hi if speed > 0 else lo <= e < hi:
                        crossings.append((t + (e - theta) / (360.0 * speed), chan))
                    k += 1
            theta = th_end
        t += dur
    crossings.sort()
    if jitter_ns:
        crossings = sorted((tc + rng.uniform(-jitter_ns, jitter_ns), c) for tc, c in crossings)
    a, b = ch.levels(theta0)
    wf = Waveform()
    wf.append(t0_ns, STATE_TO_POS[(a, b)], (a, b))
    for tc, chan in crossings:
        if chan == 0:
            a ^= 1
        else:
            b ^= 1
        wf.append(max(tc, wf.events[-1][0]), None, (a, b))
    wf.append(max(t, wf.events[-1][0]), None, (a, b))  # hold to the end of the trajectory
    return wf


def steady(ch: Channels, clocks_per_cycle: float, cycles: float, forward: bool = True,
           **kw) -> Waveform:
    period_ns = clocks_per_cycle * CLK_PS / 1000.0
    return waveform(ch, [(cycles * period_ns, (1 if forward else -1) / period_ns)], **kw)


def off_grid(wf: Waveform, start_ps: int, clk_ps: int = CLK_PS) -> Waveform:
    """Round event times to 1 ps and move any that would land exactly on a rising clock edge by
    1 ps, so sampling is never a race. Playback starts at a falling edge of the clock (absolute
    time ``start_ps``), so the rising edges are at playback times clk/2 + m * clk."""
    out = Waveform()
    for (t, a, b), pos in zip(wf.events, wf.positions):
        t_ps = int(round(t * 1000.0))
        if (t_ps - clk_ps // 2) % clk_ps == 0:
            t_ps += 1
        if out.events:
            t_ps = max(t_ps, int(round(out.events[-1][0] * 1000.0)))
        out.append(t_ps / 1000.0, pos, (a, b))
    return out


# ----------------------------------------------------------------------------------------------
# Measurements on the continuous waveform
# ----------------------------------------------------------------------------------------------
def rises_of_a(wf: Waveform) -> list[float]:
    ev = wf.events
    return [ev[i][0] for i in range(1, len(ev)) if ev[i][1] == 1 and ev[i - 1][1] == 0]


def xor_time(wf: Waveform, t0: float, t1: float) -> float:
    """Time with A != B inside [t0, t1)."""
    ev = wf.events
    total = 0.0
    for i, (t, a, b) in enumerate(ev):
        t_next = ev[i + 1][0] if i + 1 < len(ev) else math.inf
        lo, hi = max(t, t0), min(t_next, t1)
        if hi > lo and a != b:
            total += hi - lo
    return total


def xor_phase(wf: Waveform, t0: float, t1: float) -> float:
    """What an ideal averaging meter on A xor B reads over [t0, t1): 180 * duty cycle."""
    return 180.0 * xor_time(wf, t0, t1) / (t1 - t0)


def sample_index(t_ns: float, start_ps: int = 0, clk_ps: int = CLK_PS) -> int:
    """Index m of the first rising clock edge strictly after the event at playback time ``t_ns``
    (rising edges at playback times clk/2 + m * clk, playback starting at a falling edge): the
    clock on which the DUT first sees the new level. ``start_ps`` is accepted for symmetry with
    off_grid and does not matter."""
    t_ps = int(round(t_ns * 1000.0))
    return (t_ps - clk_ps // 2) // clk_ps + 1


# ----------------------------------------------------------------------------------------------
# Figure 3 characterization of a window of whole cycles (reference for enc_characterizer)
# ----------------------------------------------------------------------------------------------
DEG = 256  # 1/256 e-degree per LSB


def cycles_of(times, levels, start: int = 0):
    """Split an event list into cycles from one A rise to the next: for each, the four state
    widths in forward order (S10, S11, S01, S00) and the widths of the A pulse and the B pulse
    that end (fall) in the cycle, from their rising edges (in reverse rotation the B pulse began
    in the previous cycle), using ``times`` (ns or sample indices). ``levels[i]`` is the (a, b)
    state entered at ``times[i]``; event 0 is the initial state, not an edge. Cycles begin at the
    first A rise at or after event ``start``."""
    rises = [i for i in range(max(1, start), len(levels)) if levels[i][0] == 1 and levels[i - 1][0] == 0]
    out = []
    for r0, r1 in zip(rises, rises[1:]):
        widths = {}
        for i in range(r0, r1):
            widths[levels[i]] = widths.get(levels[i], 0) + (times[i + 1] - times[i])
        if r1 - r0 != 4 or len(widths) != 4:
            raise ValueError(f"cycle at event {r0} is not a clean quadrature cycle")
        pulses = []
        for ch in (0, 1):
            fall = next(i for i in range(r0 + 1, r1 + 1)
                        if levels[i][ch] == 0 and levels[i - 1][ch] == 1)
            rise = max(i for i in range(1, fall) if levels[i][ch] == 1 and levels[i - 1][ch] == 0)
            pulses.append(times[fall] - times[rise])
        out.append((widths[(1, 0)], widths[(1, 1)], widths[(0, 1)], widths[(0, 0)], *pulses))
    return out


def figure3_stats(cycles):
    """min / max of period, pulse widths (both channels), 2 x phase (centres), state widths."""
    per = [sum(c[:4]) for c in cycles]
    h = [c[4] for c in cycles] + [c[5] for c in cycles]
    f = [c[0] + c[2] for c in cycles]
    s = [x for c in cycles for x in c[:4]]
    return {"p": (min(per), max(per)), "h": (min(h), max(h)), "f": (min(f), max(f)),
            "s": (min(s), max(s)), "total": sum(per), "n": len(cycles)}


def _worst(lo, hi, nominal):
    d_lo, d_hi = lo - nominal, hi - nominal
    return d_hi if abs(d_hi) >= abs(d_lo) else d_lo


def characterizer_expect(cycles):
    """What enc_characterizer reports for these cycles (sample counts), computed from the Figure 3
    definitions with the documented integer conversion floor(x * 92160 * n / total)."""
    st = figure3_stats(cycles)
    n, total = st["n"], st["total"]

    def deg(x):
        return min((x * 92160 * n) // total, (1 << 24) - 1)

    def sat(v):
        return max(-32768, min(32767, v))

    r = {k: (deg(st[k][0]), deg(st[k][1])) for k in ("p", "h", "f", "s")}
    return {
        "cycle_err": sat(_worst(*r["p"], 92160)),
        "pulse_err": sat(_worst(*r["h"], 46080)),
        "phase_err": sat(_worst(*r["f"], 46080) >> 1),
        "state_err": sat(_worst(*r["s"], 23040)),
        "state_min": min(r["s"][0], 0xFFFF),
    }


def figure3_degrees(cycles):
    """The same in (float) e-degrees against the mean period of the cycles: for each error the
    deviations of both extremes (lo, hi), and the narrowest state and the mean period."""
    st = figure3_stats(cycles)
    pm = st["total"] / st["n"]

    def dev(key, nominal, scale=1.0):
        return tuple(360.0 * x / pm * scale - nominal for x in st[key])

    return {
        "cycle_err": dev("p", 360.0),
        "pulse_err": dev("h", 180.0),
        "phase_err": dev("f", 90.0, 0.5),
        "state_err": dev("s", 90.0),
        "state_min": (360.0 * st["s"][0] / pm,),
        "period": pm,
    }


def sampled_meter_reading(wf: Waveform, window_log2: int, clk_ps: int = CLK_PS):
    """The XOR duty cycle over whole cycles as a clocked meter sees it: samples of ``wf`` (played
    from a falling clock edge, already ``off_grid``), span from the first sampled rise of A to the
    last one at most 2^W samples later; X = samples in (first, last] with A != B. Returns
    (phase_err in 1/256 degree = floor(46080 X / T) - 23040, X, T) or None if no whole cycle."""
    ev = wf.events
    k = [sample_index(t, 0, clk_ps) for t, _, _ in ev]
    rises = [k[i] for i in range(1, len(ev)) if ev[i][1] == 1 and ev[i - 1][1] == 0]
    if len(rises) < 2:
        return None
    s0 = rises[0]
    last = max(r for r in rises if r - s0 <= 2 ** window_log2)
    if last == s0:
        return None
    x = 0
    for i in range(len(ev)):
        lo = max(k[i], s0 + 1)
        hi = min(k[i + 1] if i + 1 < len(ev) else last + 1, last + 1)
        if hi > lo and ev[i][1] != ev[i][2]:
            x += hi - lo
    t = last - s0
    return (46080 * x) // t - 23040, x, t


# ---- driving the meter ----------------------------------------------------------------------
def window_log2(dut) -> int:
    return int(dut.WINDOW_LOG2.value)


async def start_clock(dut):
    await tbutil.start(dut, CLK_PS, {"a": 0, "b": 0}, do_reset=False)


async def reset(dut, clocks: int = 2):
    dut.rst.value = 1
    for _ in range(clocks):
        await FallingEdge(dut.clk)
    dut.rst.value = 0


class Readings:
    """Collects (time_ps, phase_err degrees - as read -, a_leads, b_leads) on every valid pulse."""

    def __init__(self, dut):
        self.dut = dut
        self.items = []
        self.task = cocotb.start_soon(self._run())

    async def _run(self):
        while True:
            await RisingEdge(self.dut.valid)
            await ReadOnly()
            self.items.append((get_sim_time("ps"), self.dut.phase_err.value.to_signed() * LSB,
                               int(self.dut.a_leads.value), int(self.dut.b_leads.value)))
            await RisingEdge(self.dut.clk)
            await ReadOnly()
            assert int(self.dut.valid.value) == 0, "valid is longer than one clock"

    def stop(self):
        self.task.cancel()


async def play_case(dut, wf):
    """Reset with the waveform's first levels on a/b (so the jump from the previous case's levels
    is not an edge), then play ``wf`` from a falling clock edge; returns (readings, start_ps)."""
    _, a0, b0 = wf.events[0]
    dut.a.value, dut.b.value = a0, b0
    await reset(dut)
    start_ps = get_sim_time("ps")
    rd = Readings(dut)
    await play(dut, off_grid(wf, start_ps), "a", "b")
    await FallingEdge(dut.clk)
    rd.stop()
    return rd.items, start_ps
