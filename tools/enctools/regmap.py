# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei.rdl, compiled once: the one reader of the register map for every Python consumer
(the generators, the tests, the benches and the demo).

The map is paged: page k (0x100 bytes) holds channel k's registers (the RDL's regfile array
``ch.chan``), at the same offsets in every page; page 0 also holds the global registers
(``glb``), at offsets no channel register uses. ``compile_rdl()`` gives the systemrdl-compiler
node tree; ``nodes()`` every register node with its group ("glb" or "chan") and its offset in a
page; ``regmap()`` a plain view (registers by name with group, offset and fields: position,
access, reset, size property, enum members); ``addr(reg, chan)`` a register's byte address; the
helpers pack and unpack register words by field and enum member names. An RDL of an older
revision (one flat map) reads as one page of channel registers.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import asdict, dataclass
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from .paths import RDL, SIM


@lru_cache(maxsize=None)
def compile_rdl(path: Path = RDL):
    """Compile and elaborate the RDL; return the top addrmap node."""
    from systemrdl import RDLCompiler

    rdlc = RDLCompiler()
    rdlc.compile_file(str(path))
    return rdlc.elaborate().top


def field_kind(f) -> str:
    """What the register block makes of a field (rtl/enc_qei_regs.v's generator): const, in
    (live from the hardware), cfg (storage), pulse (write-1 single pulse), intr (event, write 1 to
    clear), counter (saturating, a write clears) or coherent (a half of the count)."""
    sw, hw = f.get_property("sw").name, f.get_property("hw").name
    onwrite = f.get_property("onwrite")
    ow = onwrite.name if onwrite is not None else None
    if _udp(f, "coherent"):
        return "coherent"
    if f.get_property("intr") and ow == "woclr" and sw == "rw":
        return "intr"
    if f.get_property("counter") and f.get_property("incrsaturate") and ow == "wclr" and sw == "rw":
        return "counter"
    if sw == "r" and hw == "na":
        return "const"
    if sw == "r" and hw == "w":
        return "in"
    if sw == "rw" and hw in ("r", "rw") and ow is None:
        return "cfg"
    if sw == "w" and f.get_property("singlepulse"):
        return "pulse"
    raise ValueError(f"regmap: field {f.get_path()} (sw={sw}, hw={hw}, onwrite={ow}) is a kind the "
                     "register-block generator does not handle")


@dataclass(frozen=True)
class Field:
    name: str
    lsb: int
    width: int
    sw: str
    hw: str
    reset: int | None
    sized_by: str | None
    enum: dict | None  # member name -> value
    kind: str
    feature: str | None = None  # the optional unit of the field or its register (reads 0 without it)

    @property
    def mask(self) -> int:
        return ((1 << self.width) - 1) << self.lsb


PAGE = 0x100  # bytes per channel page


@dataclass(frozen=True)
class Reg:
    name: str
    offset: int  # in its page (channel registers: the same in every page)
    feature: str | None
    fields: dict  # name -> Field, in bit order
    group: str = "chan"  # "glb": a global register (page 0 only); "chan": one per channel

    @property
    def coherent(self) -> bool:
        """COUNT_LO / COUNT_HI: the count's halves (a read latches, a write stages or loads)."""
        return any(f.kind == "coherent" for f in self.fields.values())


def _udp(node, name: str):
    """A user-defined property; None in an RDL (of an older revision) that does not define it."""
    try:
        return node.get_property(name)
    except LookupError:
        return None


def _feature(reg) -> str | None:
    return _udp(reg, "feature")


@lru_cache(maxsize=None)
def nodes(path: Path = RDL) -> list[tuple[str, int, object]]:
    """(group, offset in the page, register node) of every register, in page-offset order;
    raises ValueError when a global register shares an offset with a channel register."""
    top = compile_rdl(path)
    children = {c.inst_name: c for c in top.children()}
    if "glb" in children and "ch" in children:
        out = [("glb", r.address_offset, r) for r in children["glb"].registers()]
        chan = children["ch"].get_child_by_name("chan")
        out += [("chan", chan.raw_address_offset + r.address_offset, r) for r in chan.registers()]
    else:  # an older, flat map: one channel page
        out = [("chan", r.address_offset, r) for r in top.registers()]
    seen: dict[int, str] = {}
    for g, off, r in out:
        if off in seen:
            raise ValueError(f"{r.inst_name} at 0x{off:02X} collides with {seen[off]}")
        seen[off] = r.inst_name
    return sorted(out, key=lambda x: x[1])


def channels_max(path: Path = RDL) -> int:
    """The number of channel pages the map has room for (the regfile array's size)."""
    top = compile_rdl(path)
    names = [c.inst_name for c in top.children()]
    if "ch" not in names:
        return 1
    return top.get_child_by_name("ch").get_child_by_name("chan").array_dimensions[0]


@lru_cache(maxsize=None)
def regmap(path: Path = RDL) -> dict[str, Reg]:
    """Registers by name, in page-offset order (``path``: another RDL than rtl/enc_qei.rdl, e.g.
    the one of a git revision a bench simulates). Kept in sim/build/ as JSON (keyed by the RDL,
    this reader and the compiler's version), so that a process that only reads the map (a
    simulation's Python) does not load the compiler."""
    path = Path(path)
    key = hashlib.sha256(path.read_bytes() + Path(__file__).read_bytes()
                         + metadata.version("systemrdl-compiler").encode()).hexdigest()[:16]
    cache = SIM / "build" / f"regmap-{key}.json"
    try:
        return {r["name"]: Reg(r["name"], r["offset"], r["feature"],
                               {f["name"]: Field(**f) for f in r["fields"]}, r["group"])
                for r in json.loads(cache.read_text())}
    except (OSError, ValueError, KeyError, TypeError):
        pass
    regs = _compile_regmap(path)
    cache.parent.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps([dict(name=r.name, offset=r.offset, feature=r.feature,
                                    group=r.group, fields=[asdict(f) for f in r.fields.values()])
                               for r in regs.values()]))
    os.replace(tmp, cache)  # atomic: parallel processes may write it at once
    return regs


def _compile_regmap(path: Path) -> dict[str, Reg]:
    regs = {}
    for group, offset, r in nodes(path):
        fields = {}
        for f in r.fields():
            enc = f.get_property("encode")
            fields[f.inst_name] = Field(
                f.inst_name, f.lsb, f.width, f.get_property("sw").name, f.get_property("hw").name,
                f.get_property("reset"), f.get_property("sized_by"),
                {m.name: m.value for m in enc} if enc is not None else None, field_kind(f),
                _udp(f, "feature") or _feature(r))
        regs[r.inst_name] = Reg(r.inst_name, offset, _feature(r), fields, group)
    return regs


def addr(reg: str, chan: int = 0) -> int:
    """The byte address of a register: channel ``chan``'s (a channel register), or page 0's (a
    global register, chan 0)."""
    r = regmap()[reg]
    if r.group == "glb" and chan != 0:
        raise ValueError(f"{reg} is a global register (page 0 only)")
    return chan * PAGE + r.offset


def field(reg: str, name: str) -> Field:
    return regmap()[reg].fields[name]


def enum(reg: str, name: str) -> dict[str, int]:
    """The members of an enum-encoded field, name -> value."""
    e = field(reg, name).enum
    if e is None:
        raise KeyError(f"{reg}.{name} is not an enum field")
    return e


def enum_names(reg: str, name: str) -> tuple[str, ...]:
    """The members of an enum-encoded field, in value order."""
    return tuple(n for n, _ in sorted(enum(reg, name).items(), key=lambda kv: kv[1]))


def field_val(reg: str, name: str, value) -> int:
    """The register bits of field ``name`` = value (an int or an enum member name)."""
    f = field(reg, name)
    if isinstance(value, str):
        value = f.enum[value]
    if not 0 <= value < (1 << f.width):
        raise ValueError(f"{reg}.{name} = {value} does not fit {f.width} bits")
    return value << f.lsb


def get_field(reg: str, name: str, word: int) -> int:
    f = field(reg, name)
    return (word >> f.lsb) & ((1 << f.width) - 1)


def pack(reg: str, **fields) -> int:
    return sum(field_val(reg, k, v) for k, v in fields.items())


def event_names(word: int) -> set[str]:
    return {n for n, f in regmap()["EVENTS"].fields.items() if word & f.mask}


def event_bits(*names: str) -> int:
    return sum(regmap()["EVENTS"].fields[n].mask for n in names)


def units(caps: int) -> set[str]:
    """The optional units (the RDL's ``feature`` names) a build has, from its CAPS word."""
    profile = {v: k for k, v in enum("CAPS", "PROFILE").items()}.get(get_field("CAPS", "PROFILE", caps))
    out = {"RANGE", "PROBE"} if profile in ("full", "counting") else set()
    if get_field("CAPS", "TIMING", caps):
        out.add("TIMING")
    if profile == "full":
        out.add("PERIOD")
    if get_field("CAPS", "EFIFO_LOG2", caps):
        out.add("EFIFO")
    return out


def built_mask(f: Field, count_w: int, ts_w: int, have: set[str]) -> int:
    """The bits of field ``f`` a build holds: its size (size_mask) if its unit is in ``have``
    (units(CAPS)), else none (a field of a unit left out reads 0)."""
    if f.feature is not None and f.feature not in have:
        return 0
    return (size_mask(f.sized_by, count_w, ts_w) << f.lsb) & f.mask


def size_mask(sized_by: str | None, count_w: int, ts_w: int) -> int:
    """The bits of a 32-bit register word that a field sized by ``sized_by`` holds in a build."""
    if sized_by == "COUNT_W:0":
        return (1 << min(32, count_w)) - 1
    if sized_by == "COUNT_W:1":
        return (1 << max(0, count_w - 32)) - 1
    if sized_by == "TS_W":
        return (1 << ts_w) - 1
    return 0xFFFFFFFF
