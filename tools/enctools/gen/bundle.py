# SPDX-License-Identifier: Apache-2.0
"""The register block's bundles, from the compiled RDL: ``reg2hw`` (what the registers give the
hardware: configuration, pulses, pending events, the count to load) and ``hw2reg`` (what the
hardware gives the registers: live values, event and counter strobes, hardware clears, the
count). OpenTitan's reg2hw / hw2reg structures, as Verilog-2005 vectors with fixed positions:
one pair for the global registers (``glb``) and one pair per channel (``chan``).

One entry per field, named ``<reg>_<field>`` in lower case (``ctrl_func``), with these merges:
- a register whose only field is VALUE gives ``<reg>`` (``snap_period``);
- a pair X_LO / X_HI of COUNT_W-sized values (``sized_by`` COUNT_W:0 and COUNT_W:1) gives one
  64-bit entry ``x`` (``preset``: bits 31:0 from X_LO, 63:32 from X_HI);
- the event register (``intr`` fields) gives ``<reg>`` (pending bits) and ``<reg>_set`` (set
  strobes), each as wide as the register's top event bit, bits at their register positions;
- a register of live fields with unused bits between them gives one entry ``<reg>``, the fields at
  their register positions;
- a live field with ``swacc`` (EFIFO_ENTRY.VALID) adds ``<reg>_rd`` (reg2hw): a one-clock strobe
  in the clock a read of that register takes its data (the read side effect: a FIFO pop);
- the coherent pair COUNT_LO / COUNT_HI (``coherent`` "lo" / "hi") gives ``count`` (hw2reg, the
  live count) and ``count_load`` / ``count_load_value`` (reg2hw).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..regmap import field_kind, nodes
from . import HEADER_V

GROUPS = ("glb", "chan")


@dataclass
class Entry:
    name: str
    width: int
    desc: str
    lsb: int = 0

    @property
    def rng(self) -> str:
        """The entry's bits in its bundle, as a Verilog range."""
        return f"[{self.lsb + self.width - 1}:{self.lsb}]" if self.width > 1 else f"[{self.lsb}]"


@dataclass
class Bundles:
    r2h: list = field(default_factory=list)
    h2r: list = field(default_factory=list)
    # (register, field) -> (side, entry, lsb inside the entry): where a field's value lives
    where: dict = field(default_factory=dict)

    @property
    def r2h_w(self) -> int:
        return max(1, sum(e.width for e in self.r2h))

    @property
    def h2r_w(self) -> int:
        return max(1, sum(e.width for e in self.h2r))

    def add(self, side: str, name: str, width: int, desc: str) -> Entry:
        lst = self.r2h if side == "r2h" else self.h2r
        found = next((e for e in lst if e.name == name), None)
        if found:
            return found
        e = Entry(name, width, desc, sum(x.width for x in lst))
        lst.append(e)
        return e

    def entry(self, side: str, name: str) -> Entry:
        return next(e for e in (self.r2h if side == "r2h" else self.h2r) if e.name == name)


def pair_base(reg) -> tuple[str, int] | None:
    """(base name, half) of a register of an X_LO / X_HI pair of COUNT_W-sized values."""
    fields = list(reg.fields())
    if len(fields) != 1 or fields[0].inst_name != "VALUE":
        return None
    sz = fields[0].get_property("sized_by")
    name = reg.inst_name
    if sz == "COUNT_W:0" and name.endswith("_LO"):
        return name[:-3].lower(), 0
    if sz == "COUNT_W:1" and name.endswith("_HI"):
        return name[:-3].lower(), 1
    return None


def gapped(reg) -> bool:
    """A register of live fields with unused bits between them (EFIFO_ENTRY): it gives one entry
    ``<reg>``, the fields at their register positions, so that a live bit i of the register is
    always bit (entry + i) of hw2reg (the register proof's tables need that)."""
    fs = [f for f in reg.fields() if field_kind(f) == "in"]
    if len(fs) < 2 or len(fs) != len(list(reg.fields())):
        return False
    return sum(f.width for f in fs) != max(f.msb for f in fs) - min(f.lsb for f in fs) + 1


def entry_name(reg, f) -> str:
    fields = list(reg.fields())
    if len(fields) == 1 and f.inst_name == "VALUE":
        return reg.inst_name.lower()
    return f"{reg.inst_name}_{f.inst_name}".lower()


def group_regs(group: str) -> list:
    """The register nodes of a group, in page-offset order."""
    return [r for g, _, r in nodes() if g == group]


def build(group: str) -> Bundles:
    b = Bundles()
    for reg in group_regs(group):
        rn = reg.inst_name
        intr_top = max((f.msb for f in reg.fields() if field_kind(f) == "intr"), default=-1)
        for f in reg.fields():
            kind, desc = field_kind(f), f"{rn}.{f.inst_name}"
            pair = pair_base(reg)
            if kind == "coherent":
                e = b.add("h2r", "count", 64, "the live count (COUNT_W bits, zero-extended)")
                b.where[(rn, f.inst_name)] = ("h2r", e, 32 if f.get_property("coherent") == "hi" else 0)
                if f.get_property("coherent") == "lo":
                    b.add("r2h", "count_load", 1, "load the count: a COUNT_LO write")
                    b.add("r2h", "count_load_value", 64,
                          "the value to load: {word staged by COUNT_HI, COUNT_LO word}")
                continue
            if kind == "const":
                continue
            if kind == "intr":
                e = b.add("r2h", rn.lower(), intr_top + 1, f"{rn}: pending bits")
                b.add("h2r", f"{rn.lower()}_set", intr_top + 1, f"{rn}: set strobes")
                b.where[(rn, f.inst_name)] = ("r2h", e, f.lsb)
                continue
            if kind == "counter":
                b.add("h2r", f"{entry_name(reg, f)}_incr", 1, f"{desc}: count one")
                continue
            side = "h2r" if kind == "in" else "r2h"
            if kind == "in" and gapped(reg):
                e = b.add("h2r", rn.lower(), max(x.msb for x in reg.fields()) + 1,
                          f"{rn}: the live fields at their register positions (other bits unused)")
                b.where[(rn, f.inst_name)] = ("h2r", e, f.lsb)
            if kind == "in" and f.get_property("swacc"):
                b.add("r2h", f"{rn.lower()}_rd", 1, f"{rn}: read (a one-clock strobe, for a read side effect)")
            if kind == "in" and gapped(reg):
                continue
            if pair:
                e = b.add(side, pair[0], 64, f"{pair[0].upper()}_LO / _HI (COUNT_W bits)")
                b.where[(rn, f.inst_name)] = (side, e, 32 * pair[1])
            else:
                e = b.add(side, entry_name(reg, f), f.width, desc)
                b.where[(rn, f.inst_name)] = (side, e, 0)
            if kind == "cfg" and f.get_property("hwclr"):
                b.add("h2r", f"{entry_name(reg, f)}_clr", 1, f"{desc}: hardware clear")
    return b


def render_fields(group: str) -> str:
    """The named wires over one group's bundles: rtl/enc_qei_regs_fields.vh (glb: for enc_qei,
    over its reg2hw_g / hw2reg_g) and rtl/enc_qei_chan_fields.vh (chan: for enc_qei_channel,
    over its reg2hw / hw2reg ports): r2h_<entry> to read, h2r_<entry> to drive."""
    b = build(group)
    r2h, h2r = ("reg2hw_g", "hw2reg_g") if group == "glb" else ("reg2hw", "hw2reg")
    what = ("the global registers' bundles, for enc_qei (declare reg2hw_g and hw2reg_g first)"
            if group == "glb" else
            "one channel's bundles, for enc_qei_channel (its ports reg2hw and hw2reg)")
    lines = [*HEADER_V, f"// The fields of {what}: read r2h_<name>,",
             "// drive every h2r_<name> (rtl/enc_qei_regs.v; tools/enctools/gen/bundle.py).",
             "// verilator lint_off UNUSEDSIGNAL"]
    for e in b.r2h:
        rng = f"[{e.width - 1}:0] " if e.width > 1 else ""
        lines.append(f"wire {rng}r2h_{e.name} = {r2h}{e.rng};  // {e.desc}")
    lines.append("// verilator lint_on UNUSEDSIGNAL")
    for e in b.h2r:
        rng = f"[{e.width - 1}:0] " if e.width > 1 else ""
        lines.append(f"wire {rng}h2r_{e.name};  // {e.desc}")
    lines.append(f"assign {h2r} = {{" + ", ".join(f"h2r_{e.name}" for e in reversed(b.h2r)) + "};")
    return "\n".join(lines) + "\n"
