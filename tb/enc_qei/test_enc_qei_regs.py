# SPDX-License-Identifier: Apache-2.0
"""The register map's generated outputs: committed files match rtl/enc_qei.rdl (and a stale one is
caught), the C header compiles cleanly and agrees with the RDL, and the RDL keeps the contract's
names (registers, fields, enum members). The register walk through the bus is the cocotb test
register_walk in test_bus.py."""

from __future__ import annotations

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


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
def test_c_header_compiles(tmp_path):
    header = TOP / "sw" / "enc_qei_regs.h"
    for std in ([], ["-std=c11"], ["-std=gnu11"]):  # the header uses C11 static_assert
        proc = subprocess.run(["gcc", "-Wall", "-Werror", "-fsyntax-only", *std, "-x", "c",
                               str(header)], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
    # a user of the header: offsets, masks and enum values agree with the RDL
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
        for f in r.fields():
            m = ((1 << f.width) - 1) << f.lsb
            checks.append(f"_Static_assert(ENC_QEI__{r.inst_name}__{f.inst_name}_bm == {m:#x}u, \"m\");")
            enum = f.get_property("encode")
            for e in enum or ():
                checks.append(f"_Static_assert(ENC_QEI__{r.inst_name}__{f.inst_name}__{e.name.upper()}"
                              f" == {e.value}u, \"e\");")
    src = tmp_path / "use.c"
    src.write_text("#include <stddef.h>\n#include \"enc_qei_regs.h\"\n" + "\n".join(checks) + "\n")
    proc = subprocess.run(["gcc", "-Wall", "-Werror", "-std=c11", "-fsyntax-only",
                           f"-I{header.parent}", str(src)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


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
    for field in ("EN", "SWAP_AB", "INV_A", "INV_B", "INV_Z", "FILTER_LEN"):
        assert regs["CTRL"].get_child_by_name(field) is not None, field
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
    for name in ("COUNT_LO", "SNAP_COUNT_LO", "EVENTS", "IRQ_EN", "SNAP_CTRL"):
        assert groups.get(name) == "chan", f"{name} is not a channel register"


def _reg(name):
    return next(r for _, _, r in nodes() if r.inst_name == name)

