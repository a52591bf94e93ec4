# SPDX-License-Identifier: Apache-2.0
"""The enc-qei Linux driver's register map cannot drift from rtl/enc_qei.rdl.

The driver (sw/linux/drivers/counter/enc-qei.c) defines its offsets, fields and enum values itself,
in the kernel's style (GENMASK, BIT), rather than including the generated header. Every one of
them is checked here against the compiled RDL: a register offset (ENC_QEI_<REG>), a field
(ENC_QEI_<REG>_<FIELD>, ENC_QEI_EV_<EVENT> for EVENTS), an enum value (ENC_QEI_FUNC_<MEMBER>,
ENC_QEI_RANGE_<MEMBER>, ENC_QEI_INDEX_ACTION_<MEMBER>, ENC_QEI_PROFILE_<MEMBER>), the ID magic
and the version the driver requires (ID.VERSION of the RDL must be one the driver accepts, or the
older 1.1 that `make linux-test` presents as 1.2 until the RTL reports it).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from enctools import regmap

TOP = Path(__file__).resolve().parents[2]
DRIVER = TOP / "sw" / "linux" / "drivers" / "counter" / "enc-qei.c"
# fields the driver is written for that the RDL may not have yet (they must match once it does)
PENDING = {("CTRL", "CMP_EN")}
NOT_REGMAP = {"PAGE_SIZE", "MAGIC", "VERSION_MAJOR", "VERSION_MINOR_MIN", "MAX_CHANNELS",
              "FILTER_LEN_MAX", "EV_ALL", "SIGNAL_A", "SIGNAL_B", "SIGNAL_INDEX",
              "ENGINE_VISIT_CLOCKS", "ENGINE_MIN_VISITS", "SNAPSHOT_TIMEOUT_US"}


def defines() -> dict[str, str]:
    return dict(re.findall(r"^#define ENC_QEI_(\w+)\s+(.+?)\s*$", DRIVER.read_text(), re.M))


def bits(value: str) -> tuple[int, int]:
    """(lsb, width) of GENMASK(h, l) or BIT(n)."""
    m = re.fullmatch(r"GENMASK\((\d+), (\d+)\)", value)
    if m:
        return int(m.group(2)), int(m.group(1)) - int(m.group(2)) + 1
    m = re.fullmatch(r"BIT\((\d+)\)", value)
    assert m, f"not a field mask: {value}"
    return int(m.group(1)), 1


def classify():
    regs = regmap.regmap()
    enums = {"FUNC": ("CTRL", "FUNC"), "RANGE": ("CTRL", "RANGE"),
             "INDEX_ACTION": ("INDEX_CTRL", "ACTION"), "PROFILE": ("CAPS", "PROFILE")}
    out = []
    for name, value in defines().items():
        if name in NOT_REGMAP or name.startswith("PAGE"):
            continue
        if name in regs:
            out.append(("reg", name, value, None))
        elif name.startswith("EV_"):
            out.append(("field", "EVENTS", value, name[3:]))
        elif any(name.startswith(p + "_") and name[len(p) + 1:].lower() in
                 regmap.enum(*enums[p]) for p in enums):
            p = next(p for p in enums if name.startswith(p + "_")
                     and name[len(p) + 1:].lower() in regmap.enum(*enums[p]))
            out.append(("enum", enums[p], value, name[len(p) + 1:].lower()))
        else:
            reg = max((r for r in regs if name.startswith(r + "_")), key=len, default=None)
            assert reg, f"ENC_QEI_{name}: no register of rtl/enc_qei.rdl starts its name"
            out.append(("field", reg, value, name[len(reg) + 1:]))
    return out


CASES = classify()


def test_every_define_is_checked():
    assert len(CASES) >= 50


@pytest.mark.parametrize("kind,where,value,what", CASES,
                         ids=[f"{c[0]}-{c[1]}-{c[3]}" for c in CASES])
def test_define_matches_rdl(kind, where, value, what):
    if kind == "reg":
        assert int(value, 0) == regmap.regmap()[where].offset
    elif kind == "enum":
        assert int(value, 0) == regmap.enum(*where)[what]
    else:
        fields = regmap.regmap()[where].fields
        if (where, what) in PENDING and what not in fields:
            pytest.skip(f"{where}.{what} is not in rtl/enc_qei.rdl yet")
        f = fields[what]
        assert bits(value) == (f.lsb, f.width), f"{where}.{what}"


def test_id_and_version():
    d = defines()
    assert int(d["MAGIC"], 0) == regmap.field("ID", "MAGIC").reset
    version = regmap.field("ID", "VERSION").reset
    assert version >> 8 == int(d["VERSION_MAJOR"])
    assert (version & 0xFF) >= int(d["VERSION_MINOR_MIN"]) or version == 0x0101
