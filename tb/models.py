"""Cycle-level Python reference models of the counting circuits, written from the module
contracts and the note, not from the RTL.

Each decoder model takes one (a, b) sample per clock and returns the outputs the circuit must show
for that sample (the RTL registers them, so they appear one clock later; the tests line that up).
"""

from __future__ import annotations

from quad import STATE_TO_POS


def quad_step(prev: tuple[int, int], cur: tuple[int, int]) -> int | None:
    """+1 forward, -1 reverse, 0 no change, None for an illegal (two-channel) change."""
    if prev == cur:
        return 0
    delta = (STATE_TO_POS[cur] - STATE_TO_POS[prev]) % 4
    return {1: 1, 3: -1}.get(delta)


class X4Model:
    """enc_x4_decoder: one count per valid transition, error on a two-channel change."""

    outputs = ("cnt_pulse", "up", "error")

    def __init__(self):
        self.reset()

    def reset(self):
        self.prev = None
        self.up = 0

    def step(self, a: int, b: int) -> dict:
        out = {"cnt_pulse": 0, "up": self.up, "error": 0}
        if self.prev is not None:
            s = quad_step(self.prev, (a, b))
            if s is None:
                out["error"] = 1
            elif s:
                self.up = 1 if s > 0 else 0
                out.update(cnt_pulse=1, up=self.up)
        self.prev = (a, b)
        return out


class X2Model:
    """enc_x2_xor: one count per transition of A, direction from A xor B after the edge."""

    outputs = ("cnt_pulse", "up", "error")

    def __init__(self):
        self.reset()

    def reset(self):
        self.prev = None
        self.up = 0

    def step(self, a: int, b: int) -> dict:
        out = {"cnt_pulse": 0, "up": self.up, "error": 0}
        if self.prev is not None:
            pa, pb = self.prev
            if a != pa:
                self.up = a ^ b
                out.update(cnt_pulse=1, up=self.up, error=int(b != pb))
        self.prev = (a, b)
        return out


class X1Model:
    """enc_x1_hysteresis, stated on the unbounded 4X position p and the net count n:
    an up pulse when p - 4n would reach +4, a down pulse when it would reach -2."""

    outputs = ("up_pulse", "dn_pulse", "error")

    def __init__(self):
        self.reset()

    def reset(self):
        self.prev = None
        self.p = 0
        self.n = 0

    def step(self, a: int, b: int) -> dict:
        out = {"up_pulse": 0, "dn_pulse": 0, "error": 0}
        if self.prev is not None:
            s = quad_step(self.prev, (a, b))
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
        self.prev = (a, b)
        return out


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
