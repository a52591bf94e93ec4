# SPDX-License-Identifier: Apache-2.0
"""Reference model of enc_qei's counting, written from the module contract, the Linux counter
subsystem's definitions and rtl/enc_qei.rdl -- not from the RTL.

The model sees the sequence of conditioned (A, B) states, one call of :meth:`QeiModel.sample`
per state change the peripheral samples (inside the count-rate rule every waveform event is one
such change; an illegal jump changes both channels in one). It keeps the count, the range state
and the events raised since :meth:`take_events`.
"""

from __future__ import annotations

from enctools.regmap import enum_names

# the names of the count functions and range modes (rtl/enc_qei.rdl's enums, in code order); what
# each one does is written below from the contract
FUNCS = enum_names("CTRL", "FUNC")
RANGES = enum_names("CTRL", "RANGE")
QUAD_FUNCS = ("x4", "x2a", "x2b", "x1a", "x1b", "x1_hyst")
EDGE_FUNCS = ("pulse_dir", "increase", "decrease")  # count on A rising edges
QUAD = ((0, 0), (1, 0), (1, 1), (0, 1))  # forward sequence (A leads B)
POS = {ab: p for p, ab in enumerate(QUAD)}


def quad_dir(prev, cur) -> int | None:
    """+1 forward, -1 backward, 0 unchanged, None for a two-channel change."""
    if prev == cur:
        return 0
    return {1: 1, 3: -1}.get((POS[cur] - POS[prev]) % 4)


class QeiModel:
    def __init__(self, count_w: int = 32):
        self.count_w = count_w
        self.max = (1 << count_w) - 1
        self.func = "x4"
        self.range = "free"
        self.en = True
        self.ceiling = self.max
        self.compare = None  # None: compare off (CTRL.CMP_EN = 0, the reset) or no compare unit
        self.count = 0
        self.stopped = False
        self.dir = 1
        self.events: set[str] = set()
        self.qerrs = 0
        self.delta = 0  # the function's steps while EN, the motion (for SNAP_DELTA)
        self.prev = None
        self.hyst_d = 0  # x1_hyst: d = p - 4n, in -1 .. 3
        self.cmp_hits = 0
        # index (INDEX_CTRL) and its latch
        self.preset = 0
        self.idx_action = "none"
        self.idx_oneshot = False
        self.idx_edge = "rising"
        self.idx_gate = None  # None, or the (A, B) gate state
        self.idx_arm = True
        self.idx_q = 0
        self.idx_latch = 0
        self.idx_hits = 0

    # ---- configuration -------------------------------------------------------------------------
    def set_func(self, func: str, state) -> None:
        """A FUNC change re-references the decoders at the present state."""
        if func not in QUAD_FUNCS + EDGE_FUNCS:
            raise ValueError(f"QeiModel: count function {func!r} has no model")
        self.func = func
        self.reference(state)

    def reference(self, state) -> None:
        self.prev = tuple(state)
        self.hyst_d = 0

    def write_count(self, value: int) -> None:
        self.count = value & self.max
        self.stopped = False
        self._changed()

    def take_events(self) -> set[str]:
        ev, self.events = self.events, set()
        return ev

    # ---- counting ---------------------------------------------------------------------------------
    def func_step(self, prev, cur) -> int:
        """Count step (+1, -1, 0) of the count function for one sampled change; records QERR."""
        (pa, pb), (a, b) = prev, cur
        f = self.func
        if f in QUAD_FUNCS:
            d = quad_dir(prev, cur)
            if d is None:
                self.events.add("QERR")
                self.qerrs += 1
                return 0
            if d == 0:
                return 0
            if f == "x4":
                return d
            if f == "x2a":
                return d if a != pa else 0
            if f == "x2b":
                return d if b != pb else 0
            if f == "x1a":
                if a != pa and ((d > 0 and a == 1) or (d < 0 and a == 0)):
                    return d
                return 0
            if f == "x1b":
                if b != pb and ((d > 0 and b == 1) or (d < 0 and b == 0)):
                    return d
                return 0
            # x1_hyst (Figure 14): d = p - 4n kept in -1 .. 3
            if d > 0:
                if self.hyst_d == 3:
                    self.hyst_d = 0
                    return 1
                self.hyst_d += 1
            else:
                if self.hyst_d == -1:
                    self.hyst_d = 2
                    return -1
                self.hyst_d -= 1
            return 0
        rise = (pa, a) == (0, 1)
        if not rise:
            return 0
        if f == "pulse_dir":
            return 1 if b else -1
        if f == "increase":
            return 1
        if f == "decrease":
            return -1
        return 0

    def sample(self, state, z: int = 0) -> None:
        """One sampled change of (A, B) and/or Z."""
        cur = tuple(state)
        prev, self.prev = self.prev, cur
        q = int(bool(z) and (self.idx_gate is None or self.idx_gate == cur))
        q_prev, self.idx_q = self.idx_q, q
        hit = (q_prev, q) == ((0, 1) if self.idx_edge == "rising" else (1, 0))
        preset = armed = False
        if hit:
            self.events.add("INDEX")
            self.idx_hits += 1
            armed = self.idx_arm and self.idx_action != "none"
            preset = armed and self.idx_action == "preset"
            if armed and self.idx_oneshot:
                self.idx_arm = False
        if prev is not None and prev != cur:
            step = self.func_step(prev, cur)
            if step and self.en:
                self.delta += step  # the motion: every step of the function while EN
                self.apply(step, no_load=not preset)
        if armed and self.idx_action == "latch":
            self.idx_latch = self.count
        if preset:
            self.count = self.preset & self.max
            self._changed()

    def apply(self, step: int, no_load: bool = True) -> None:
        if step != self.dir:
            self.events.add("DIR_CHANGE")
        self.dir = step
        if self.stopped:  # non_recycle stopped it: no step, in any range, until COUNT is written
            return
        c, r = self.count, self.range
        took = True
        if r == "free":
            if step > 0:
                if c == self.max:
                    self.events.add("OVERFLOW")
                c = (c + 1) & self.max
            else:
                if c == 0:
                    self.events.add("UNDERFLOW")
                c = (c - 1) & self.max
        elif r == "modulo":
            if step > 0:
                if c >= self.ceiling:
                    self.events.add("OVERFLOW")
                    c = 0
                else:
                    c += 1
            else:
                if c == 0:
                    self.events.add("UNDERFLOW")
                    c = self.ceiling
                else:
                    c -= 1
        else:  # limit, non_recycle
            if step > 0 and c >= self.ceiling:
                self.events.add("OVERFLOW")
                took = False
                self.stopped = r == "non_recycle"
            elif step < 0 and c == 0:
                self.events.add("UNDERFLOW")
                took = False
                self.stopped = r == "non_recycle"
            else:
                c += step
        if took:
            self.count = c
            if no_load:  # a step overridden by a load in the same clock is not a count change
                self._changed()

    def _changed(self) -> None:
        if self.compare is not None and self.count == self.compare:  # None: no compare unit
            self.events.add("CMP")
            self.cmp_hits += 1
