# SPDX-License-Identifier: Apache-2.0
"""The register map's generated outputs: committed files match rtl/enc_qei.rdl (and a stale one is
caught), the C header compiles cleanly and agrees with the RDL, and the RDL keeps the contract's
names (registers, fields, enum members). The register walk through the bus is the cocotb test
register_walk in test_bus.py."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys

import pytest

from enctools.gen import cli as gen_regs
from enctools.regmap import PAGE, compile_rdl, nodes
from enctools.paths import TOP


def test_generated_outputs_are_current():
    proc = subprocess.run([sys.executable, str(TOP / "scripts" / "gen_regs.py"), "--check"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, f"stale generated files:\n{proc.stdout}{proc.stderr}"


def test_check_catches_a_stale_file(tmp_path):
    stale = tmp_path / "enc_qei_regs.h"
    text = gen_regs.OUT_H.read_text().replace("0x5145", "0x5146", 1)
    stale.write_text(text)
    names = gen_regs.check({gen_regs.OUT_H: stale})
    assert names == ["sw/enc_qei_regs.h"], names


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("g++") is None,
                    reason="gcc / g++ not installed")
def test_c_header_compiles(tmp_path):
    header = TOP / "sw" / "enc_qei_regs.h"
    for cc, std in (("gcc", ["-std=c99", "-pedantic"]), ("gcc", ["-std=c11", "-pedantic"]),
                    ("gcc", ["-std=gnu11"]), ("g++", ["-std=c++11", "-pedantic", "-x", "c++"])):
        proc = subprocess.run([cc, "-Wall", "-Wextra", "-Werror", "-fsyntax-only", *std,
                               *([] if cc == "g++" else ["-x", "c"]), str(header)],
                              capture_output=True, text=True)
        assert proc.returncode == 0, f"{cc} {std}: {proc.stderr}"


def header_checks() -> list[str]:
    """C11 static assertions of every name of the header against the compiled RDL: offsets,
    struct layout, masks, positions, the field helpers, enum members (_VAL unshifted, _bm in
    place, no bare member name) and whole-register reset values."""
    checks = []
    regs = nodes()
    assert len(regs) >= 30, "the register map reads as almost empty"
    for group, offset, r in regs:
        checks.append(f"_Static_assert(ENC_QEI_{r.inst_name}_OFFSET == {offset}u, \"{r.inst_name}\");")
        view = "glb" if group == "glb" else "chan[0]"
        checks.append(f"_Static_assert(offsetof(enc_qei_t, {view}.{r.inst_name}) == {offset}u, \"s\");")
        if group == "chan":  # channel k's register at k * PAGE + offset
            checks.append(f"_Static_assert(offsetof(enc_qei_t, chan[3].{r.inst_name}) == "
                          f"{3 * PAGE + offset}u, \"p\");")
        resets = [f.get_property("reset") for f in r.fields()]
        if None not in resets:
            value = sum(v << f.lsb for v, f in zip(resets, r.fields()))
            checks.append(f"_Static_assert(ENC_QEI_{r.inst_name}_RESET == {value:#x}u, \"r\");")
        else:
            checks += [f"#ifdef ENC_QEI_{r.inst_name}_RESET", "#error a reset value of a live field",
                       "#endif"]
        for f in r.fields():
            p = f"ENC_QEI__{r.inst_name}__{f.inst_name}"
            m = ((1 << f.width) - 1) << f.lsb
            top = (1 << f.width) - 1
            checks += [f"_Static_assert({p}_bm == {m:#x}u && {p}_bp == {f.lsb} && {p}_bw == {f.width}, \"m\");",
                       # _SET places and masks, _GET extracts, _UPDATE replaces only the field
                       f"_Static_assert({p}_SET({top}u) == {m:#x}u && {p}_SET({top + 1}u) == 0u, \"set\");",
                       f"_Static_assert({p}_GET(0xFFFFFFFFu) == {top:#x}u && {p}_GET(~{m:#x}u) == 0u, \"get\");",
                       f"_Static_assert({p}_UPDATE(0xFFFFFFFFu, 0u) == (~{m:#x}u & 0xFFFFFFFFu), \"u\");",
                       f"_Static_assert({p}_UPDATE(0u, {top}u) == {m:#x}u, \"u\");"]
            for e in f.get_property("encode") or ():
                name = f"{p}__{e.name.upper()}"
                checks += [f"_Static_assert({name}_VAL == {e.value}u, \"e\");",
                           f"_Static_assert({name}_bm == {e.value << f.lsb:#x}u, \"e\");",
                           f"_Static_assert({p}_GET({name}_bm) == {name}_VAL, \"e\");",
                           f"#ifdef {name}", f"#error {name}: a bare member name (shifted or not?)",
                           "#endif"]
    return checks


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_c_header_names_agree_with_the_rdl(tmp_path):
    header = TOP / "sw" / "enc_qei_regs.h"
    src = tmp_path / "use.c"
    src.write_text("#include <stddef.h>\n#include \"enc_qei_regs.h\"\n" + "\n".join(header_checks()) + "\n")
    proc = subprocess.run(["gcc", "-Wall", "-Werror", "-std=c11", "-fsyntax-only",
                           f"-I{header.parent}", str(src)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[:4000]


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_enum_member_written_into_its_register(tmp_path):
    """The firmware engineer's first line: an enum member written into its register sets that
    field, and nothing else (a value meant for SNAP_CTRL.EDGE must not take a snapshot)."""
    header = TOP / "sw" / "enc_qei_regs.h"
    edge = next(f for _, _, r in nodes() if r.inst_name == "SNAP_CTRL"
                for f in r.fields() if f.inst_name == "EDGE")
    a_rising = next(m.value for m in edge.get_property("encode") if m.name == "a_rising")
    src = tmp_path / "edge.c"
    src.write_text(
        "#include <stdio.h>\n#include \"enc_qei_regs.h\"\n"
        "int main(void) {\n    enc_qei_chan_t c = {0};\n"
        "    c.SNAP_CTRL = ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm;\n"
        "    printf(\"%lu %lu\\n\", (unsigned long)c.SNAP_CTRL,\n"
        "           (unsigned long)(ENC_QEI__SNAP_CTRL__EDGE_SET(ENC_QEI__SNAP_CTRL__EDGE__A_RISING_VAL)"
        " | ENC_QEI__SNAP_CTRL__IN_EN_bm));\n    return 0;\n}\n")
    exe = tmp_path / "edge"
    proc = subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", f"-I{header.parent}",
                           str(src), "-o", str(exe)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    word, word2 = (int(x) for x in subprocess.run([str(exe)], capture_output=True, text=True,
                                                  check=True).stdout.split())
    fields = {f.inst_name: f for _, _, r in nodes() if r.inst_name == "SNAP_CTRL" for f in r.fields()}
    assert word == a_rising << fields["EDGE"].lsb, f"SNAP_CTRL = {word:#x}"
    assert not word & (1 << fields["CMD"].lsb), "the EDGE value took a snapshot (CMD set)"
    assert word2 == word | (1 << fields["IN_EN"].lsb)


def test_rdl_has_the_contract_names():
    regs = {r.inst_name: r for _, _, r in nodes()}
    for name in ("ID", "CAPS", "CTRL", "STATUS", "COUNT_LO", "COUNT_HI", "PRESET_LO", "CEILING_LO",
                 "COMPARE_LO", "INDEX_CTRL", "INDEX_LATCH_LO", "PROBE_CTRL", "PROBE_LATCH_LO",
                 "EVENTS", "IRQ_EN", "QERR_COUNT", "GLITCH_COUNT", "TIMEBASE", "SNAP_CTRL",
                 "SNAP_COUNT_LO", "SNAP_COUNT_HI", "SNAP_TIME", "SNAP_EDGE_TIME", "SNAP_DELTA",
                 "PERIOD_CTRL", "PERIOD", "STALL_TIMEOUT"):
        assert name in regs, name

    def enum(reg, field):
        return {m.name for m in regs[reg].get_child_by_name(field).get_property("encode")}

    # the contract's functions (a build may add more)
    assert enum("CTRL", "FUNC") >= {"x4", "x2a", "x2b", "x1a", "x1b", "pulse_dir", "increase",
                                    "decrease", "x1_hyst"}
    assert enum("CTRL", "RANGE") == {"free", "modulo", "limit", "non_recycle"}
    assert enum("INDEX_CTRL", "ACTION") == {"none", "preset", "latch"}
    # the fields the contract names (STATUS: filtered A, B, Z, direction, index armed, stalled;
    # INDEX_CTRL: one-shot, edge, the gate; PROBE_CTRL: the edge, optionally once)
    for reg, fields in (("CTRL", ("EN", "SWAP_AB", "INV_A", "INV_B", "INV_Z", "FILTER_LEN")),
                        ("STATUS", ("A", "B", "Z", "DIR", "INDEX_ARMED", "STALLED")),
                        ("INDEX_CTRL", ("ACTION", "ONESHOT", "EDGE", "GATE_EN", "GATE_A", "GATE_B", "ARM")),
                        ("PROBE_CTRL", ("EN", "EDGE", "ONCE"))):
        for field in fields:
            assert regs[reg].get_child_by_name(field) is not None, f"{reg}.{field}"
    assert {m.name for m in regs["INDEX_CTRL"].get_child_by_name("EDGE").get_property("encode")} \
        == {"rising", "falling"}
    events = {f.inst_name for f in regs["EVENTS"].fields()}
    # the contract's events, and the edge FIFO's (a build without it: they never fire)
    assert events == {"OVERFLOW", "UNDERFLOW", "INDEX", "PROBE", "CMP", "QERR", "GLITCH",
                      "DIR_CHANGE", "STALL", "SNAP_READY", "PERIOD_READY", "PERIOD_OVF",
                      "EFIFO_THRESH", "EFIFO_OVF"}


def test_rdl_has_the_multi_axis_names():
    """The contract's multi-axis part: the channel registers a regfile array named chan, the global
    registers beside it, CAPS.PROFILE an enum with full and lean."""
    top = compile_rdl()
    chan = [n for n in top.descendants() if n.inst_name == "chan"]
    assert len(chan) == 1 and chan[0].is_array, "no regfile array named chan"
    assert chan[0].array_dimensions == [16]
    groups = {r.inst_name: g for g, _, r in nodes()}
    for name in ("ID", "CAPS", "TIMEBASE", "TB_PRESCALE", "GSNAP_CTRL", "GSNAP_PERIOD",
                 "GSNAP_TIME", "IRQ_SUMMARY"):
        assert groups.get(name) == "glb", f"{name} is not a global register"
    assert {f.inst_name for f in _reg("GSNAP_CTRL").fields()} >= {"CMD", "IN_EN", "PERIOD_EN"}
    profile = _reg("CAPS").get_child_by_name("PROFILE").get_property("encode")
    assert {m.name for m in profile} >= {"full", "lean"}
    assert _reg("CAPS").get_child_by_name("CHANNELS") is not None
    # the shared engine's part: CAPS.ENGINE an enum with exactly per_channel and shared
    engine = _reg("CAPS").get_child_by_name("ENGINE").get_property("encode")
    assert {m.name: m.value for m in engine} == {"per_channel": 0, "shared": 1}
    for name in ("COUNT_LO", "SNAP_COUNT_LO", "EVENTS", "IRQ_EN", "SNAP_CTRL"):
        assert groups.get(name) == "chan", f"{name} is not a channel register"


def _reg(name):
    return next(r for _, _, r in nodes() if r.inst_name == name)



def offset_mentions(text: str, names: list[str]):
    """(register, offset) for every place a text gives a register next to an offset: `REG` then
    0xNN within a few characters of the same table cell or sentence, `0xNN | REG` in a table row,
    `uint32_t REG;  /* 0xNN */` in a struct, `// reg - REG (0xNN` and ENC_QEI_REG_OFFSET 0xNN."""
    alt = "|".join(sorted(names, key=len, reverse=True))
    pats = [rf"\b({alt})\b(?!_)[^|\n0-9]{{0,14}}?\b0x([0-9A-Fa-f]{{1,2}})\b(?![0-9A-Fa-f])",
            rf"\b0x([0-9A-Fa-f]{{1,2}})\s*\|\s*\[?`?({alt})\b(?!_)",
            rf"\bENC_QEI_({alt})_OFFSET\s+0x([0-9A-Fa-f]+)u"]
    for k, pat in enumerate(pats):
        for m in re.finditer(pat, text):
            reg, off = (m.group(2), m.group(1)) if k == 1 else (m.group(1), m.group(2))
            yield reg, int(off, 16)


def test_one_offset_per_register():
    """Every register is given at the offset the bus sees (its offset in page 0) in the register
    reference, the C header and the docs: never at the RDL regfile's relative offset."""
    regs = {r.inst_name: off for _, off, r in nodes()}
    files = [TOP / "doc" / "enc_qei_regs.md", TOP / "sw" / "enc_qei_regs.h", TOP / "README.md",
             *sorted((TOP / "doc").glob("*.md"))]
    seen, wrong = {}, []
    for path in dict.fromkeys(files):
        for reg, off in offset_mentions(path.read_text(), list(regs)):
            seen.setdefault(path.name, set()).add(reg)
            if off != regs[reg]:
                wrong.append(f"{path.relative_to(TOP)}: {reg} at 0x{off:02X}, the bus offset is "
                             f"0x{regs[reg]:02X}")
    assert not wrong, "\n".join(wrong)
    # the reference and the header give every register's offset
    for name in ("enc_qei_regs.md", "enc_qei_regs.h"):
        assert seen.get(name, set()) == set(regs), f"{name}: no offset for {set(regs) - seen.get(name, set())}"
    text = (TOP / "doc" / "enc_qei_regs.md").read_text()
    assert "Base Offset" not in text, "the reference gives a second, relative offset"


def test_offset_mentions_finds_a_relative_offset():
    regs = ["CTRL", "COUNT_LO", "COUNT_HI"]
    assert list(offset_mentions("| 0x00 |      CTRL     |", regs)) == [("CTRL", 0)]
    assert list(offset_mentions("| 0x10 | [COUNT_LO](#count_lo) |", regs)) == [("COUNT_LO", 0x10)]
    assert list(offset_mentions("`COUNT_HI` (0x0C)", regs)) == [("COUNT_HI", 0x0C)]
    assert list(offset_mentions("    uint32_t COUNT_LO;  /* 0x10 */", regs)) == [("COUNT_LO", 0x10)]
    assert list(offset_mentions("#define ENC_QEI_CTRL_OFFSET 0x08u", regs)) == [("CTRL", 8)]
    assert list(offset_mentions("CTRL_HI 0x10, COUNT_W 8", regs)) == []
