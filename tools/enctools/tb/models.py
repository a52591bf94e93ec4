# SPDX-License-Identifier: Apache-2.0
"""Cycle-level Python reference models of the counting circuits, written from the module
contracts and the note, not from the RTL.

Each decoder model takes one (a, b) sample per clock and returns the outputs the circuit must show
for that sample (the RTL registers them, so they appear one clock later; the tests line that up).
"""

from __future__ import annotations

from hedsmodel.waveform import STATE_TO_POS


def quad_step(prev: tuple[int, int], cur: tuple[int, int]) -> int | None:
    """+1 forward, -1 reverse, 0 no change, None for an illegal (two-channel) change."""
    if prev == cur:
        return 0
    delta = (STATE_TO_POS[cur] - STATE_TO_POS[prev]) % 4
    return {1: 1, 3: -1}.get(delta)


class DecoderModel:
    """One (a, b) sample per clock. The first sample after reset is only the reference; after it,
    :meth:`decode` sees each (previous, present) pair. ``up`` is only defined in a clock with a
    count (the tests compare it only then), so the models report 0 otherwise."""

    outputs: tuple[str, ...] = ()

    def __init__(self):
        self.reset()

    def reset(self):
        self.prev = None

    def step(self, a: int, b: int) -> dict:
        out = dict.fromkeys(self.outputs, 0)
        if self.prev is not None:
            self.decode(self.prev, (a, b), out)
        self.prev = (a, b)
        return out

    def decode(self, prev: tuple[int, int], cur: tuple[int, int], out: dict) -> None:
        raise NotImplementedError


class X4Model(DecoderModel):
    """enc_x4_decoder: one count per valid transition, error on a two-channel change."""

    outputs = ("cnt_pulse", "up", "error")

    def decode(self, prev, cur, out):
        s = quad_step(prev, cur)
        if s is None:
            out["error"] = 1
        elif s:
            out.update(cnt_pulse=1, up=int(s > 0))


class X2Model(DecoderModel):
    """enc_x2_xor: one count per transition of A, direction from A xor B after the edge."""

    outputs = ("cnt_pulse", "up", "error")

    def decode(self, prev, cur, out):
        (pa, pb), (a, b) = prev, cur
        if a != pa:
            out.update(cnt_pulse=1, up=a ^ b, error=int(b != pb))


class X1Model(DecoderModel):
    """enc_x1_hysteresis, stated on the unbounded 4X position p and the net count n:
    an up pulse when p - 4n would reach +4, a down pulse when it would reach -2."""

    outputs = ("up_pulse", "dn_pulse", "error")

    def reset(self):
        super().reset()
        self.p = 0
        self.n = 0

    def decode(self, prev, cur, out):
        s = quad_step(prev, cur)
        if s is None:
            out["error"] = 1
        elif s:
            self.p += s
            if self.p - 4 * self.n == 4:
                self.n += 1
                out["up_pulse"] = 1
            elif self.p - 4 * self.n == -2:
                self.n -= 1
                out["dn_pulse"] = 1


class ConditionerModel:
    """enc_conditioner: two synchronizer stages, then a level is accepted after FILTER_LEN
    consecutive equal samples; a candidate that goes back early is a glitch."""

    def __init__(self, filter_len: int):
        self.f = filter_len
        self.reset()

    def reset(self):
        self.pipe = [(0, 0), (0, 0)]  # synchronizer stage 1, stage 2
        self.level = [0, 0]
        self.run = [0, 0]  # consecutive samples of the other level seen so far
        self.glitch = 0
        self.clocks = 0  # clocks since reset

    def clock(self, a_in: int, b_in: int) -> dict:
        """Advance one clock with the inputs as sampled at this edge; return the outputs after it."""
        synced = self.pipe[1]
        reject = False
        for ch in range(2):
            if synced[ch] != self.level[ch]:
                self.run[ch] += 1
                if self.run[ch] >= self.f:
                    self.level[ch] = synced[ch]
                    self.run[ch] = 0
            elif self.run[ch]:
                self.run[ch] = 0
                reject = True
        self.glitch = int(reject)
        self.pipe = [(a_in, b_in), self.pipe[0]]
        self.clocks += 1
        return {"a": self.level[0], "b": self.level[1], "glitch": self.glitch,
                "valid": int(self.clocks >= self.f + 2)}


def two_x_count(p: int) -> int:
    """Number of A transitions (signed) from position 0 to 4X position p: A toggles on the
    transitions 0->1 and 2->3 of every cycle."""
    return (p + 1) // 2
