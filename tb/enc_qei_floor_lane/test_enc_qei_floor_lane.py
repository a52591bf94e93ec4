# SPDX-License-Identifier: Apache-2.0
"""enc_qei_floor_lane, the measurement model of `make synth`'s lane floor (not part of the IP):
it must do what its header says, or its LUT4 count is no floor. Against a Python model, clock by
clock: a random walk (states of 3 .. 9 clocks at FILTER_LEN 2) with one-clock glitches, reads at
random clocks (the accumulator's difference between two reads is the walk's steps between them),
index pulses of either EDGE, gated or not, and snapshot requests while the shaft rests (the latch and the capture
hold the accumulator then, `since` the clocks since the last step), illegal jumps counted; `since`
to its saturation."""

from __future__ import annotations

from cocotb.triggers import FallingEdge, RisingEdge, Timer

from enctools.harness import run
from enctools.paths import TOP
from enctools.tb import cocotb_test, start

QUAD = ((0, 0), (0, 1), (1, 1), (1, 0))  # forward: the floor lane's s = {A, A ^ B} counts 0, 1, 2, 3
ACC_W, ERR_W, TIME_W = 6, 5, 5
FIELDS = (("acc", ACC_W), ("since", TIME_W), ("qcnt", ERR_W), ("gcnt", ERR_W), ("lcap", ACC_W),
          ("lpend", 1), ("scap", ACC_W), ("ssince", TIME_W), ("spend", 1), ("a", 1), ("b", 1),
          ("z", 1), ("dir", 1), ("eidx", 1), ("edch", 1))


UNRESET = ("lcap", "scap", "ssince")  # captures without a reset: unknown until the first


def unpack(bits: str) -> dict:
    """The record's fields from its bits (MSB first); an unknown bit only in a capture that has
    none yet (read as 0)."""
    out, at = {}, 0
    for name, w in FIELDS:
        field = bits[at:at + w]
        at += w
        known = all(c in "01" for c in field)
        assert known or name in UNRESET, f"record field {name} is {field}"
        out[name] = int(field, 2) if known else 0
    return out


class Lane:
    """Drives the lane and reads its record."""

    def __init__(self, dut):
        self.dut, self.pos = dut, 0
        self.t = 0          # falling edges so far
        self.t_step = -99   # ... at the last step's input change

    async def clocks(self, n: int) -> None:
        for _ in range(n):
            await FallingEdge(self.dut.clk)
            self.t += 1

    def ab(self) -> None:
        """Drive the present position (a step: at a falling edge)."""
        self.dut.a_in.value, self.dut.b_in.value = QUAD[self.pos % 4]
        self.t_step = self.t

    async def read(self, cfg: int | None = None) -> dict:
        """The record in one clock with rd (cfg, if given, pushed in it); at a falling edge."""
        dut = self.dut
        dut.rd.value = 1
        if cfg is not None:
            dut.cfg_we.value, dut.cfg.value = 1, cfg
        await Timer(1, unit="ns")
        rec = unpack(str(dut.rec.value))
        await FallingEdge(dut.clk)
        self.t += 1
        dut.rd.value = dut.cfg_we.value = 0
        return rec

    async def rest(self) -> None:
        await self.clocks(12)  # (the filters and the decode settle)


INPUTS = {"a_in": 0, "b_in": 0, "z_in": 0, "tick": 1, "snap": 0, "rd": 0, "cfg_we": 0, "cfg": 0}


def cfg_word(last: int, edge_rising: int = 1, gate: tuple | None = None, arm: int = 1,
             oneshot: int = 0) -> int:
    """The configuration: FILTER_LEN - 1, EDGE, the gate ((A, B) or None: off), ARM, ONESHOT."""
    g = 0 if gate is None else 0b100 | (gate[0] << 1) | gate[1]
    return (oneshot << 9) | (arm << 8) | (edge_rising << 7) | (g << 4) | last


@cocotb_test()
async def walk_reads_latches(dut):
    """Steps, glitches and illegal jumps between random reads; index latches and snapshots."""
    rng = await start(dut, 10_000, inputs=INPUTS)
    lane = Lane(dut)
    mask = (1 << ACC_W) - 1
    rec = await lane.read(cfg_word(last=1))
    await lane.rest()
    rec = await lane.read()
    base, gbase, qbase, moved, glitches = rec["acc"], rec["gcnt"], rec["qcnt"], 0, 0
    edge, gate = 1, None  # the trial's INDEX_CTRL.EDGE (1 rising) and gate, pushed by the read before
    for trial in range(40):
        for _ in range(rng.randint(1, 6)):  # a short walk: at most 6 steps, < 2^(ACC_W - 1)
            if rng.random() < 0.2:  # a one-clock pulse on A: rejected at FILTER_LEN 2
                a, b = QUAD[lane.pos % 4]
                dut.a_in.value = 1 - a
                await lane.clocks(1)
                dut.a_in.value = a
                glitches += 1
                await lane.clocks(3)
            s = rng.choice((1, -1))
            lane.pos += s
            moved += s
            lane.ab()
            await lane.clocks(rng.randint(3, 9))
        await lane.rest()
        late = False  # an index latch waits for the trial's last read
        if trial % 3 == 0:  # an index pulse while resting, a read while Z is high: a rising
            dut.z_in.value = 1  # EDGE has latched then, a falling one latches after it; the gate
            await lane.clocks(8)  # passes it in its (A, B) state only
            passed = gate is None or QUAD[lane.pos % 4] == gate
            mid = await lane.read()
            assert (mid["lpend"], mid["eidx"]) == (edge & passed, edge & passed), \
                f"trial {trial}: EDGE {edge}, gate {gate} at {QUAD[lane.pos % 4]}, Z high: " \
                f"lpend {mid['lpend']}, eidx {mid['eidx']}"
            if edge and passed:
                assert mid["lcap"] == (base + moved) & mask, f"trial {trial}: lcap {mid['lcap']}"
            dut.z_in.value = 0
            await lane.clocks(8)
            late = passed and not edge
        since = None
        if trial % 4 == 1:  # a snapshot request while resting
            # at FILTER_LEN 2 a step's input change at falling edge 0 steps the lane at rising
            # edge 5 (two synchronizer flops, two samples, the decode): since is 0 after it and
            # the capture at rising edge k + 1 of a request at falling edge k holds k - 4
            since = min(lane.t - lane.t_step - 4, (1 << TIME_W) - 1)
            dut.snap.value = 1
            await lane.clocks(1)
            dut.snap.value = 0
        next_edge = rng.randint(0, 1)
        next_gate = rng.choice((None, QUAD[lane.pos % 4], rng.choice(QUAD)))
        rec = await lane.read(cfg_word(last=1, edge_rising=next_edge, gate=next_gate))
        want = (base + moved) & mask
        assert rec["acc"] == want, f"trial {trial}: acc {rec['acc']}, want {want} ({moved:+d} steps)"
        assert rec["gcnt"] == (gbase + glitches) & ((1 << ERR_W) - 1), f"trial {trial}: gcnt"
        assert rec["qcnt"] == qbase, f"trial {trial}: a quadrature error counted"
        assert (rec["a"], rec["b"]) == QUAD[lane.pos % 4], f"trial {trial}: STATUS A, B"
        assert rec["lpend"] == int(late), f"trial {trial}: lpend {rec['lpend']}"
        assert rec["eidx"] == int(late), f"trial {trial}: eidx {rec['eidx']}"
        if rec["lpend"]:
            assert rec["lcap"] == want, f"trial {trial}: lcap {rec['lcap']}, want {want}"
        assert rec["spend"] == int(trial % 4 == 1), f"trial {trial}: spend {rec['spend']}"
        if rec["spend"]:
            assert rec["scap"] == want, f"trial {trial}: scap {rec['scap']}, want {want}"
            assert rec["ssince"] == since, f"trial {trial}: ssince {rec['ssince']}, want {since}"
        base, gbase, moved, glitches = want, rec["gcnt"], 0, 0
        edge, gate = next_edge, next_gate
    # an illegal jump (two states in one clock) is counted, not stepped
    lane.pos += 2
    lane.ab()
    await lane.rest()
    rec = await lane.read()
    assert rec["qcnt"] == (qbase + 1) & ((1 << ERR_W) - 1), f"qcnt {rec['qcnt']} after a jump"
    assert rec["acc"] == base, "an illegal jump stepped the accumulator"


@cocotb_test()
async def since_counts_clocks(dut):
    """`since` is 0 in the clock after a step and counts clocks (tick every clock) up to all
    ones; a snapshot request captures it and the accumulator."""
    await start(dut, 10_000, inputs=INPUTS)
    lane = Lane(dut)
    await lane.read(cfg_word(last=0))
    await lane.rest()
    for trial in range(6):
        lane.pos += 1
        lane.ab()
        k = (8, 20, 35, 36, 50, 70)[trial]  # (since saturates at 31 from k = 35 on)
        await lane.clocks(k)
        rec = await lane.read()
        # FILTER_LEN 1: an input change at falling edge 0 steps the lane at rising edge 4 (two
        # synchronizer flops, one sample, the decode); since counts the rising edges after it
        want = min(k - 4, (1 << TIME_W) - 1)
        assert rec["since"] == want, f"trial {trial}: since {rec['since']}, {k} clocks after the change, want {want}"
        dut.snap.value = 1
        await RisingEdge(dut.clk)
        await FallingEdge(dut.clk)
        dut.snap.value = 0
        rec2 = await lane.read()
        assert rec2["spend"] == 1 and rec2["scap"] == rec["acc"], f"trial {trial}: snapshot"
        want = min(rec["since"] + 2, (1 << TIME_W) - 1)  # (the request two rising edges later)
        assert rec2["ssince"] == want, f"trial {trial}: ssince {rec2['ssince']}, want {want}"


def test_enc_qei_floor_lane():
    floor = TOP / "tools" / "enctools" / "synth" / "floor"
    run("enc_qei_floor_lane", __name__, name="enc_qei_floor_lane",
        parameters={"ACC_W": ACC_W, "ERR_W": ERR_W, "TIME_W": TIME_W},
        extra_sources=(floor / "enc_qei_floor_lane.v",))
