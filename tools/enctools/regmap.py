# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei.rdl, compiled once: the one reader of the register map for every Python consumer
(the generators, the tests, the benches and the demo).

``compile_rdl()`` gives the systemrdl-compiler node tree; ``regmap()`` a plain view of it
(registers by name with offset and fields: position, access, reset, size property, enum
members); helpers pack and unpack register words by field and enum member names.
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
    if f.get_property("coherent"):
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

    @property
    def mask(self) -> int:
        return ((1 << self.width) - 1) << self.lsb


@dataclass(frozen=True)
class Reg:
    name: str
    offset: int
    feature: str | None
    fields: dict  # name -> Field, in bit order

    @property
    def coherent(self) -> bool:
        """COUNT_LO / COUNT_HI: the count's halves (a read latches, a write stages or loads)."""
        return any(f.kind == "coherent" for f in self.fields.values())


@lru_cache(maxsize=None)
def regmap() -> dict[str, Reg]:
    """Registers by name, in address order. Kept in sim/build/ (keyed by the RDL, this reader and
    the compiler's version), so that a process that only reads the map (a simulation's Python)
    does not load the compiler."""
    key = hashlib.sha256(RDL.read_bytes() + Path(__file__).read_bytes()
                         + metadata.version("systemrdl-compiler").encode()).hexdigest()[:16]
    cache = SIM / "build" / f"regmap-{key}.json"
    try:
        return {r["name"]: Reg(r["name"], r["offset"], r["feature"],
                               {f["name"]: Field(**f) for f in r["fields"]})
                for r in json.loads(cache.read_text())}
    except (OSError, ValueError, KeyError, TypeError):
        pass
    regs = _compile_regmap()
    cache.parent.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps([dict(name=r.name, offset=r.offset, feature=r.feature,
                                    fields=[asdict(f) for f in r.fields.values()])
                               for r in regs.values()]))
    os.replace(tmp, cache)  # atomic: parallel processes may write it at once
    return regs


def _compile_regmap() -> dict[str, Reg]:
    regs = {}
    for r in compile_rdl().registers():
        fields = {}
        for f in r.fields():
            enc = f.get_property("encode")
            fields[f.inst_name] = Field(
                f.inst_name, f.lsb, f.width, f.get_property("sw").name, f.get_property("hw").name,
                f.get_property("reset"), f.get_property("sized_by"),
                {m.name: m.value for m in enc} if enc is not None else None, field_kind(f))
        regs[r.inst_name] = Reg(r.inst_name, r.address_offset, r.get_property("feature"), fields)
    return regs


def addr(reg: str) -> int:
    return regmap()[reg].offset


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


def size_mask(sized_by: str | None, count_w: int, ts_w: int) -> int:
    """The bits of a 32-bit register word that a field sized by ``sized_by`` holds in a build."""
    if sized_by == "COUNT_W:0":
        return (1 << min(32, count_w)) - 1
    if sized_by == "COUNT_W:1":
        return (1 << max(0, count_w - 32)) - 1
    if sized_by == "TS_W":
        return (1 << ts_w) - 1
    return 0xFFFFFFFF
