# SPDX-License-Identifier: Apache-2.0
"""The iCEBreaker board top (icebreaker_top) in simulation: encoder in, UART report line out.

The top runs at its real 12 MHz clock with a fast UART (8 clocks per bit) and a report line every
0.5 ms, so a whole session fits in a few tens of milliseconds of simulated time. A Python UART
receiver decodes every line (framing checked), and the lines are checked against the stimulus:

- quiet spells in a random walk (bursts of valid transitions, both directions, going negative):
  `P` equals the true 4X position and `B` the 2X count (p + 1) // 2 modulo 10000 in BCD;
- flags: none during clean motion; a lone 100 ns glitch and a 3.5-clock one (rejected only at the
  board's FILTER_LEN = 5, counted at enc_qei's reset value 3) each give `G` in exactly one line,
  an index pulse `I`, an illegal transition (both channels change) `E`, each on the next line only;
- the position and the flags come from enc_qei over Wishbone: a monitor on the top's bus checks,
  against the register map compiled from rtl/enc_qei.rdl, one CTRL write after each reset (EN,
  FUNC = x4, RANGE = free, FILTER_LEN = the board's), then before every line a COUNT_LO read, an
  EVENTS read and an EVENTS write of exactly the QERR/GLITCH/INDEX bits read (write 1 to clear),
  and that the line shows that COUNT_LO (as a POS_WIDTH-bit signed number) and those bits;
- Figure 11: steady rotation at 90 degrees lights the red LED forward and the green LED in reverse,
  and the `PH` field reads the phase minus 90 degrees (0.00 at 90, +10.00 at 100 degrees) to the
  contract's 0.25 degree accuracy;
- the line cadence: one line per 0.5 ms.

It runs twice: at POS_WIDTH = 24 (the default) and at POS_WIDTH = 8, where the walk and a
monotone sweep of 4 x 70 counts wrap the counter, so `P` is checked as a POS_WIDTH-bit two's
complement number on both sides of the wrap (the sign bit of COUNT_LO matters).
"""

from __future__ import annotations

import os
import random
import re

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time

from enctools.core import board_files
from enctools.paths import TOP
from enctools.harness import run
from cocotbext.quadrature import play
from hedsmodel.waveform import QUAD, STATE_TO_POS, Waveform
from enctools.regmap import addr, event_bits, get_field, pack
from enctools.tb import cocotb_test, log_seed

CLK_HZ = 12_000_000
CLK_PS = 83_334  # 12 MHz (even, for cocotb's 50 % Clock)
CLKS_PER_BIT = 8
BAUD = CLK_HZ // CLKS_PER_BIT  # 1.5 Mbit/s: simulation speed, not a real serial port
LINE_HZ = 2000  # a line every 0.5 ms (6000 clocks; a line takes ~3000)
PHASE_WINDOW_LOG2 = 13  # 8192 clocks = 0.68 ms
WINDOW_NS = (1 << PHASE_WINDOW_LOG2) * CLK_PS / 1000.0
LINE_NS = 1e9 / LINE_HZ

POS_WIDTH = int(os.environ.get("IB_POS_WIDTH", "24"))  # set by the pytest entry point
FILTER_LEN = 5  # not enc_qei's CTRL.FILTER_LEN reset value (3): the top must write it
PARAMS = {"CLK_HZ": CLK_HZ, "BAUD": BAUD, "LINE_HZ": LINE_HZ, "PHASE_WINDOW_LOG2": PHASE_WINDOW_LOG2,
          "POS_WIDTH": POS_WIDTH, "FILTER_LEN": FILTER_LEN}
ND = len(str(1 << (POS_WIDTH - 1)))  # decimal digits of the largest magnitude (7 for 24 bits)
FLAG_EVENTS = {"E": "QERR", "G": "GLITCH", "I": "INDEX"}  # line flag -> enc_qei EVENTS field

LINE_RE = re.compile(r"^P=([+-]\d{%d}) B=(\d{4}) PH=([+-]\d{3}\.\d{2}) F=([E-])([G-])([I-])\r\n$" % ND)

QUIET_NS = 10_000.0  # the input was constant this long before a line: P and B must be exact


# ------------------------------------------------------------------------------------------------
# UART receiver
# ------------------------------------------------------------------------------------------------
async def uart_receiver(dut, lines: list) -> None:
    """Decode 8N1 bytes from dut.tx; append (start-bit time of the first byte in ns, text) per line."""
    bit_ps = CLKS_PER_BIT * CLK_PS
    buf = bytearray()
    t_line = 0.0
    while True:
        await FallingEdge(dut.tx)
        t0 = get_sim_time(unit="ns")
        await Timer(bit_ps // 2, unit="ps")
        assert int(dut.tx.value) == 0, f"UART: start bit not low at its middle ({t0:.0f} ns)"
        byte = 0
        for i in range(8):
            await Timer(bit_ps, unit="ps")
            byte |= int(dut.tx.value) << i
        await Timer(bit_ps, unit="ps")
        assert int(dut.tx.value) == 1, f"UART: framing error (stop bit low) at {t0:.0f} ns"
        if not buf:
            t_line = t0
        buf.append(byte)
        if byte == 0x0A:
            lines.append((t_line, buf.decode("ascii", errors="replace")))
            buf = bytearray()


def parse(text: str) -> dict:
    m = LINE_RE.match(text)
    assert m, f"malformed report line {text!r}"
    return {"p": int(m.group(1)), "b": int(m.group(2)), "ph": float(m.group(3)),
            "E": m.group(4) == "E", "G": m.group(5) == "G", "I": m.group(6) == "I"}


# ------------------------------------------------------------------------------------------------
# Wishbone monitor (the top's master and enc_qei_wb)
# ------------------------------------------------------------------------------------------------
async def wb_monitor(dut, txns: list) -> None:
    """Append (time in ns, write, byte address, data) for every access that ends; data is the
    written word for a write, the read word for a read. Asserts that none ends in wb_err."""
    while True:
        await RisingEdge(dut.clk)
        if not dut.wb_stb.value.is_resolvable:  # before the first clock of the power-on reset
            continue
        if int(dut.wb_stb.value) and (int(dut.wb_ack.value) or int(dut.wb_err.value)):
            adr = int(dut.wb_adr.value)
            assert not int(dut.wb_err.value), f"Wishbone error at offset {adr:#04x}"
            we = bool(int(dut.wb_we.value))
            data = int((dut.wb_wdat if we else dut.wb_rdat).value)
            txns.append((get_sim_time(unit="ns"), we, adr, data))


def check_bus(parsed: list, txns: list, t_base: float) -> int:
    """The firmware's part: one CTRL write after each reset, then per line COUNT_LO read, EVENTS
    read, EVENTS write of the flag bits read; the line shows what was read. Times in ``parsed``
    are from t_base (the start of playback), in ``txns`` absolute. Returns the lines checked."""
    flag_mask = event_bits(*FLAG_EVENTS.values())
    ctrl = pack("CTRL", EN=1, FUNC="x4", RANGE="free", FILTER_LEN=FILTER_LEN)
    pos_mask = (1 << POS_WIDTH) - 1
    t_ctrl = [t for t, we, a, _ in txns if we and a == addr("CTRL")]
    assert len(t_ctrl) == 2, f"CTRL written at {t_ctrl} ns: expected once after power-on and once " \
                             f"after the button reset"
    for t, we, a, d in txns:
        if we and a == addr("CTRL"):
            assert d == ctrl, f"CTRL written {d:#010x}, expected {ctrl:#010x} (EN, x4, free, FILTER_LEN={FILTER_LEN})"
    accesses = [x for x in txns if x[0] > t_ctrl[-1]]
    k = 0
    t_prev = t_ctrl[-1]
    for t_line, text, f in parsed:
        seq = [x for x in accesses if t_prev < x[0] < t_line + t_base]
        t_prev = t_line + t_base
        assert [(we, a) for _, we, a, _ in seq] == [(False, addr("COUNT_LO")), (False, addr("EVENTS")),
                                                    (True, addr("EVENTS"))], \
            f"line at {t_line:.0f} ns: bus accesses before it {[(hex(a), we) for _, we, a, _ in seq]}"
        cnt, ev, clr = seq[0][3], seq[1][3], seq[2][3]
        assert cnt & ~pos_mask == 0, f"COUNT_LO {cnt:#x} has bits above COUNT_W = {POS_WIDTH}"
        p = cnt - (1 << POS_WIDTH) if cnt >> (POS_WIDTH - 1) else cnt
        assert f["p"] == p, f"line at {t_line:.0f} ns: P={f['p']} but COUNT_LO read {cnt:#x} ({p}): {text!r}"
        for flag, field in FLAG_EVENTS.items():
            assert f[flag] == bool(get_field("EVENTS", field, ev)), \
                f"line at {t_line:.0f} ns: flag {flag} = {f[flag]} but EVENTS read {ev:#x}: {text!r}"
        assert clr == ev & flag_mask, f"line at {t_line:.0f} ns: EVENTS read {ev:#x}, cleared {clr:#x}, " \
                                      f"expected {ev & flag_mask:#x}"
        k += 1
    return k


# ------------------------------------------------------------------------------------------------
# stimulus
# ------------------------------------------------------------------------------------------------
class Session:
    """One waveform for the whole run, in ns from the start of playback, plus what happened when."""

    def __init__(self):
        self.wf = Waveform()
        self.t = 0.0
        self.pos = 0
        self.wf.append(0.0, 0)
        self.quiet = []  # (t_from, t_to, pos): the input holds `pos` all this time
        self.marks = []  # (flag, time) of each glitch / index / illegal transition
        self.steady = []  # (t_from, t_to, phase_deg, forward)

    def step(self, d: int, dur: float) -> None:
        self.t += dur
        self.pos += d
        self.wf.append(self.t, self.pos)

    def pause(self, dur: float) -> None:
        self.quiet.append((self.t, self.t + dur, self.pos))
        self.t += dur

    def burst(self, rng: random.Random, n: int, bias: int) -> None:
        for _ in range(n):
            self.step(bias if rng.random() < 0.8 else -bias, rng.uniform(500.0, 1500.0))

    def glitch(self, width_ns: float) -> None:
        """A lone pulse on A in the middle of a quiet spell; the position does not change."""
        a, b = QUAD[self.pos % 4]
        self.pause(50_000.0)
        self.marks.append(("G", self.t))
        self.wf.append(self.t, self.pos, (1 - a, b))
        self.wf.append(self.t + width_ns, self.pos, (a, b))
        self.t += width_ns
        self.pause(2 * LINE_NS)

    def steady_rotation(self, period_ns: float, phase_deg: float, forward: bool, cycles: int) -> None:
        """Square waves with 50 % duty; the lagging channel trails by phase_deg."""
        t_from = self.t
        a, b = QUAD[self.pos % 4]
        lag = period_ns * phase_deg / 360.0
        edges = []
        # align: both channels at 0 first (a few valid steps if needed)
        while (a, b) != (0, 0):
            self.step(-1 if forward else 1, 2_000.0)
            a, b = QUAD[self.pos % 4]
        t0 = self.t + 2_000.0
        lead, lagc = ("a", "b") if forward else ("b", "a")
        for k in range(cycles):
            base = t0 + k * period_ns
            edges += [(base, lead, 1), (base + period_ns / 2, lead, 0),
                      (base + lag, lagc, 1), (base + lag + period_ns / 2, lagc, 0)]
        edges.sort()
        lv = {"a": 0, "b": 0}
        for t, ch, v in edges:
            old = (lv["a"], lv["b"])
            lv[ch] = v
            new = (lv["a"], lv["b"])
            delta = (STATE_TO_POS[new] - STATE_TO_POS[old]) % 4
            assert delta in (1, 3)
            self.pos += 1 if delta == 1 else -1
            self.wf.append(t, self.pos)
        self.t = edges[-1][0]
        self.steady.append((t_from, self.t, phase_deg, forward))

    def illegal(self) -> None:
        self.pause(50_000.0)
        self.marks.append(("E", self.t))
        a, b = QUAD[self.pos % 4]
        self.wf.append(self.t, None, (1 - a, 1 - b))  # both channels at once: position unknown
        self.t += 2 * LINE_NS  # not a quiet spell to check: the 2X buffer counted the A edge


async def index_pulse(dut, at_ns: float, width_ns: float) -> None:
    await Timer(int(at_ns * 1000), unit="ps")
    dut.enc_i.value = 1
    await Timer(int(width_ns * 1000), unit="ps")
    dut.enc_i.value = 0


# ------------------------------------------------------------------------------------------------
# the test
# ------------------------------------------------------------------------------------------------
@cocotb_test()
async def board_session(dut):
    """Random walk with quiet spells, glitch, index, steady rotation at 90/100 degrees both ways,
    an illegal transition; every report line decoded and checked."""
    rng = random.Random(log_seed(dut))
    dut.enc_a.value = 0
    dut.enc_b.value = 0
    dut.enc_i.value = 0
    dut.btn_n.value = 1
    txns: list = []
    cocotb.start_soon(wb_monitor(dut, txns))
    cocotb.start_soon(Clock(dut.clk, CLK_PS, unit="ps").start())
    await ClockCycles(dut.clk, 30)  # power-on reset (16 clocks)
    assert int(dut.tx.value) == 1, "UART line not idle after power-on reset"
    dut.btn_n.value = 0  # the user button resets too
    await ClockCycles(dut.clk, 10)
    dut.btn_n.value = 1
    await ClockCycles(dut.clk, 10)

    s = Session()
    s.pause(LINE_NS * 1.2)
    for bias in (-1, -1, -1, 1, 1, 1, 1, 1, -1, 1, -1, 1):
        s.burst(rng, rng.randrange(60, 160), bias)
        s.pause(LINE_NS * 1.3 + rng.uniform(0, LINE_NS))
    for _ in range(4):  # quiet spells 70 counts apart: one is on each side of any sign boundary
        for _ in range(70):
            s.step(1, rng.uniform(500.0, 1500.0))
        s.pause(LINE_NS * 1.3 + rng.uniform(0, LINE_NS))
    s.glitch(100.0)  # 1.2 clocks: sampled once or twice, rejected at any FILTER_LEN >= 3
    s.glitch(3.5 * CLK_PS / 1000.0)  # sampled 3 or 4 times: rejected at 5, counted at 3
    s.pause(50_000.0)
    s.marks.append(("I", s.t))
    t_index = s.t
    s.pause(2 * LINE_NS)
    seg = []
    for phase, forward in ((90.0, True), (100.0, True), (90.0, False)):
        t = s.t
        s.steady_rotation(100.3 * CLK_PS / 1000.0, phase, forward, cycles=int(4 * WINDOW_NS / (100.3 * CLK_PS / 1000.0)))
        seg.append((t, s.t, phase, forward))
    s.illegal()

    lines: list = []
    cocotb.start_soon(uart_receiver(dut, lines))
    t_base = get_sim_time(unit="ns")
    cocotb.start_soon(index_pulse(dut, t_index, 2_000.0))

    # play the waveform, checking the LEDs at the end of each steady segment
    led_checks = []

    async def led_watch():
        for t_from, t_to, phase, forward in seg:
            now = get_sim_time(unit="ns") - t_base
            await Timer(int((t_to - now - 1_000.0) * 1000), unit="ps")
            led_checks.append((forward, int(dut.led_r_n.value), int(dut.led_g_n.value)))

    cocotb.start_soon(led_watch())
    await play(dut, s.wf, "enc_a", "enc_b")
    await Timer(int(s.t - s.wf.duration_ns) * 1000 + 1000, unit="ps")

    # ---- LEDs (Figure 11: red when A leads) --------------------------------------------------
    assert len(led_checks) == len(seg)
    for forward, r_n, g_n in led_checks:
        exp = (0, 1) if forward else (1, 0)
        assert (r_n, g_n) == exp, f"{'forward' if forward else 'reverse'}: LEDs (red_n, green_n) = " \
                                  f"{(r_n, g_n)}, expected {exp}"

    # ---- lines -----------------------------------------------------------------------------------
    parsed = [(t - t_base, text, parse(text)) for t, text in lines]
    dut._log.info("%d report lines; first: %r", len(parsed), parsed[0][1] if parsed else None)
    for t, text, _ in parsed:
        dut._log.debug("%12.0f ns  %s", t, text.rstrip())
    span = s.t
    assert len(parsed) >= int(span / LINE_NS) - 2, f"only {len(parsed)} lines in {span / 1e6:.1f} ms"
    gaps = [b[0] - a[0] for a, b in zip(parsed, parsed[1:])]
    assert all(abs(g - LINE_NS) < 2_000.0 for g in gaps), f"line cadence off: {min(gaps)}..{max(gaps)} ns"

    def wrap(p: int) -> int:  # the POS_WIDTH-bit counter's signed value
        half = 1 << (POS_WIDTH - 1)
        return (p + half) % (2 * half) - half

    checked = 0
    for t, text, f in parsed:
        for q_from, q_to, pos in s.quiet:
            if q_from + QUIET_NS <= t <= q_to:
                assert f["p"] == wrap(pos), f"line at {t:.0f} ns: P={f['p']} but the shaft is at {pos} " \
                                            f"({wrap(pos)} in {POS_WIDTH} bits): {text!r}"
                exp_b = ((pos + 1) // 2) % 10000
                assert f["b"] == exp_b, f"line at {t:.0f} ns: B={f['b']:04d}, expected {exp_b:04d} " \
                                        f"(2X count of 4X position {pos}): {text!r}"
                checked += 1
    assert checked >= 12, f"only {checked} lines fell in quiet spells"
    assert min(p for _, _, p in s.quiet) < 0, "the walk should have gone negative"
    if POS_WIDTH <= 8:
        assert any(wrap(p) != p for _, _, p in s.quiet), "the counter should have wrapped"

    # each flag: set on exactly one line per event, the first after it (or the second, if the
    # first started before the event reached EVENTS)
    for flag in FLAG_EVENTS:
        t_evs = [t for fl, t in s.marks if fl == flag]
        hits = [t for t, _, f in parsed if f[flag]]
        assert len(hits) == len(t_evs), \
            f"flag {flag}: set on {len(hits)} lines (at {hits}), expected one after each event at {t_evs}"
        for t_ev, hit in zip(t_evs, hits):
            after = [t for t, _, _ in parsed if t > t_ev]
            assert hit in after[:2] and (hit == after[0] or after[0] - t_ev < 5_000.0), \
                f"flag {flag} on the line at {hit:.0f} ns, its event was at {t_ev:.0f} ns"

    # ---- the readout is enc_qei's, over Wishbone -------------------------------------------------
    n_bus = check_bus(parsed, txns, t_base)

    # phase readings: lines at least two windows into a steady segment
    for t_from, t_to, phase, forward in seg:
        ph = [f["ph"] for t, _, f in parsed if t_from + 2 * WINDOW_NS + 50_000.0 <= t <= t_to]
        assert ph, f"no line during the steady {phase} degree segment"
        for v in ph:
            assert abs(v - (phase - 90.0)) <= 0.26, \
                f"steady {phase} deg {'forward' if forward else 'reverse'}: PH={v:+.2f}, expected {phase - 90.0:+.2f}"
    dut._log.info("checked %d exact position lines, flags G/I/E, %d phase segments, %d lines against "
                  "the bus", checked, len(seg), n_bus)


# ------------------------------------------------------------------------------------------------
# pytest entry point
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pos_width", [24, 8])
def test_icebreaker_top(pos_width):
    # enc_qei's files come from the core's rtl fileset; extra_sources() adds any it lacks
    run("icebreaker_top", __name__, name=f"icebreaker_top_w{pos_width}",
        parameters={**PARAMS, "POS_WIDTH": pos_width}, extra_env={"IB_POS_WIDTH": str(pos_width)},
        extra_sources=tuple(TOP / f for f in board_files("icebreaker")))
