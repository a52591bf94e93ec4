# SPDX-License-Identifier: Apache-2.0
"""The firmware documentation of enc_qei cannot go stale silently.

- sw/examples/enc_qei_example.c compiles as C99 with gcc -Wall -Wextra -Werror.
- Linked with a small host harness (written to the test's tmp dir) that points it at a register
  block in memory, it computes the right values (64-bit combine, sign extension, latch offset) and
  writes the right words: every expected word is built here from the field positions and enum
  values of the compiled rtl/enc_qei.rdl, not from the generated header the example uses. A plain
  struct in memory has none of the hardware's side effects (the COUNT_LO read latch, write-1-to-
  clear): the harness checks what the example writes and computes, the cocotb tests in
  tb/enc_qei/ check the hardware.
- Every register, field and enum member that doc/enc_qei.md and the example name exists in
  rtl/enc_qei.rdl, and the doc's relative links point at files that exist.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from functools import lru_cache
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[2]
EXAMPLE_DIR = TOP / "sw" / "examples"
EXAMPLE_C = EXAMPLE_DIR / "enc_qei_example.c"
EXAMPLE_H = EXAMPLE_DIR / "enc_qei_example.h"
DOC = TOP / "doc" / "enc_qei.md"
GCC = shutil.which("gcc")
needs_gcc = pytest.mark.skipif(GCC is None, reason="gcc not installed")


@lru_cache(maxsize=None)
def rdl():
    """{register: {field: (lsb, width, {member: value} or None)}}: a view of enctools.regmap."""
    from enctools.regmap import regmap

    return {r.name: {f.name: (f.lsb, f.width, f.enum) for f in r.fields.values()}
            for r in regmap().values()}


def fv(reg: str, field: str, value) -> int:
    """A field's value in place; value may be an enum member name."""
    lsb, width, enum = rdl()[reg][field]
    if isinstance(value, str):
        value = enum[value]
    assert 0 <= value < 1 << width
    return value << lsb


def bit(reg: str, field: str) -> int:
    return fv(reg, field, 1)


# ---- compile ------------------------------------------------------------------------------------------
@needs_gcc
def test_example_compiles_as_c99(tmp_path):
    cmd = [GCC, "-std=c99", "-Wall", "-Wextra", "-Werror", f"-I{TOP / 'sw'}", f"-I{EXAMPLE_DIR}",
           "-c", str(EXAMPLE_C), "-o", str(tmp_path / "enc_qei_example.o")]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"


# ---- run against a register block in memory -------------------------------------------------------------
HARNESS = r"""
#include <stdio.h>
#include <string.h>
#include "enc_qei_example.h"

static enc_qei_chan_t regs;  /* a channel's page, in memory */
static enc_qei_t all;        /* the whole address space (for the global CAPS) */
#define Q ((volatile enc_qei_chan_t *)&regs)
#define P(name, v) printf("%s %llu\n", name, (unsigned long long)(v))
#define PS(name, v) printf("%s %lld\n", name, (long long)(v))

int main(void)
{
    uint32_t qerr = 0, glitch = 0;
    int r;

    P("ctrl_word", enc_qei_ctrl_word(ENC_QEI__CTRL__FUNC__X2B_VAL, ENC_QEI__CTRL__RANGE__LIMIT_VAL, 7u));

    /* setup: garbage before, the example's writes after */
    memset(&regs, 0xA5, sizeof regs);
    enc_qei_setup_x4(Q, 5u, ENC_QEI__CTRL__RANGE__MODULO_VAL, 0x00000001000007CFull);
    P("setup.CTRL", regs.CTRL);
    P("setup.CEILING_LO", regs.CEILING_LO);
    P("setup.CEILING_HI", regs.CEILING_HI);
    P("setup.COUNT_LO", regs.COUNT_LO);
    P("setup.COUNT_HI", regs.COUNT_HI);
    P("setup.EVENTS", regs.EVENTS);
    P("setup.QERR_COUNT", regs.QERR_COUNT);
    P("setup.GLITCH_COUNT", regs.GLITCH_COUNT);

    memset(&regs, 0, sizeof regs);
    all.glb.CAPS = 0x00072040u; /* COUNT_W 64, TS_W 32, INDEX, PROBE, TIMING */
    P("count_w", enc_qei_count_width((volatile enc_qei_t *)&all));

    P("combine", enc_qei_combine64(0xFFFFFFF0u, 2u));
    regs.COUNT_LO = 0x89ABCDEFu;
    regs.COUNT_HI = 0x01234567u;
    P("read_count", enc_qei_read_count(Q));
    enc_qei_write_count(Q, 0x0000000500000007ull);
    P("write.COUNT_LO", regs.COUNT_LO);
    P("write.COUNT_HI", regs.COUNT_HI);

    PS("signed.ff_8", enc_qei_to_signed(0xFFu, 8u));
    PS("signed.80_8", enc_qei_to_signed(0x80u, 8u));
    PS("signed.7f_8", enc_qei_to_signed(0x7Fu, 8u));
    PS("signed.1ff_8", enc_qei_to_signed(0x1FFu, 8u));
    PS("signed.ffffffff_32", enc_qei_to_signed(0xFFFFFFFFu, 32u));
    PS("signed.fffffffe_48", enc_qei_to_signed(0xFFFFFFFEull, 48u));
    PS("signed.neg1_64", enc_qei_to_signed(0xFFFFFFFFFFFFFFFFull, 64u));
    PS("signed.min_64", enc_qei_to_signed(0x8000000000000000ull, 64u));
    PS("signed.min_64_plus1", enc_qei_to_signed(0x8000000000000001ull, 64u) + 1);

    /* compare: CTRL's other fields kept, CMP_EN set */
    memset(&regs, 0, sizeof regs);
    regs.CTRL = enc_qei_ctrl_word(ENC_QEI__CTRL__FUNC__X1A_VAL, ENC_QEI__CTRL__RANGE__MODULO_VAL, 9u);
    regs.IRQ_EN = ENC_QEI__EVENTS__INDEX_bm;
    enc_qei_compare_at(Q, 0x0000000300000010ull);
    P("cmp.COMPARE_LO", regs.COMPARE_LO);
    P("cmp.COMPARE_HI", regs.COMPARE_HI);
    P("cmp.CTRL", regs.CTRL);
    P("cmp.IRQ_EN", regs.IRQ_EN);
    P("cmp.EVENTS", regs.EVENTS);

    /* homing by preset, gated at (A, B) = (1, 0) */
    memset(&regs, 0, sizeof regs);
    regs.IRQ_EN = ENC_QEI__EVENTS__CMP_bm;
    regs.EVENTS = ENC_QEI__EVENTS__INDEX_bm | ENC_QEI__EVENTS__CMP_bm;
    enc_qei_home_preset(Q, 0x0000000A000003E8ull, 2);
    P("preset.PRESET_LO", regs.PRESET_LO);
    P("preset.PRESET_HI", regs.PRESET_HI);
    P("preset.INDEX_CTRL", regs.INDEX_CTRL);
    P("preset.IRQ_EN", regs.IRQ_EN);
    P("preset.EVENTS", regs.EVENTS);
    enc_qei_home_preset(Q, 0u, -1);
    P("preset_nogate.INDEX_CTRL", regs.INDEX_CTRL);

    /* index interrupt: not pending; pending but still armed; pending and disarmed */
    regs.EVENTS = ENC_QEI__EVENTS__CMP_bm;
    r = enc_qei_index_irq(Q);
    P("irq_none.ret", r);
    P("irq_none.EVENTS", regs.EVENTS);
    regs.EVENTS = ENC_QEI__EVENTS__INDEX_bm | ENC_QEI__EVENTS__CMP_bm | ENC_QEI__EVENTS__QERR_bm;
    r = enc_qei_index_irq(Q);
    P("irq_armed.ret", r);
    P("irq_armed.EVENTS", regs.EVENTS);
    P("irq_armed.IRQ_EN", regs.IRQ_EN);
    regs.EVENTS = ENC_QEI__EVENTS__INDEX_bm | ENC_QEI__EVENTS__CMP_bm;
    regs.INDEX_CTRL &= ~(uint32_t)ENC_QEI__INDEX_CTRL__ARM_bm; /* what the hardware does */
    r = enc_qei_index_irq(Q);
    P("irq_homed.ret", r);
    P("irq_homed.EVENTS", regs.EVENTS);
    P("irq_homed.IRQ_EN", regs.IRQ_EN);

    /* homing by latch */
    memset(&regs, 0, sizeof regs);
    enc_qei_home_latch(Q);
    P("latch.INDEX_CTRL", regs.INDEX_CTRL);
    P("latch.IRQ_EN", regs.IRQ_EN);
    regs.INDEX_LATCH_LO = 0xFFFFFFF0u; /* index at -16 */
    regs.COUNT_LO = 0x10u;             /* count at +16 */
    PS("latch.pos32", enc_qei_position_from_latch(Q, 32u));
    regs.INDEX_LATCH_LO = 100u;
    regs.COUNT_LO = 40u;
    PS("latch.pos16", enc_qei_position_from_latch(Q, 16u));

    /* error counters */
    regs.QERR_COUNT = 3u;
    regs.GLITCH_COUNT = 0xFFFFu;
    r = enc_qei_read_errors(Q, &qerr, &glitch, 0);
    P("err.ret", r);
    P("err.qerr", qerr);
    P("err.glitch", glitch);
    P("err.kept", regs.QERR_COUNT);
    r = enc_qei_read_errors(Q, &qerr, &glitch, 1);
    P("err.cleared", regs.QERR_COUNT | regs.GLITCH_COUNT);
    r = enc_qei_read_errors(Q, &qerr, &glitch, 0);
    P("err.ret0", r);
    return 0;
}
"""


@pytest.fixture(scope="module")
def harness_out(tmp_path_factory):
    if GCC is None:
        pytest.skip("gcc not installed")
    tmp = tmp_path_factory.mktemp("enc_qei_example")
    src = tmp / "harness.c"
    src.write_text(HARNESS)
    exe = tmp / "harness"
    cmd = [GCC, "-std=c99", "-Wall", "-Wextra", "-Werror", f"-I{TOP / 'sw'}", f"-I{EXAMPLE_DIR}",
           str(src), str(EXAMPLE_C), "-o", str(exe)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    return {k: int(v) for k, v in (line.split() for line in run.stdout.splitlines())}


def test_configuration_words(harness_out):
    o = harness_out
    assert o["ctrl_word"] == (bit("CTRL", "EN") | fv("CTRL", "FUNC", "x2b") | fv("CTRL", "RANGE", "limit")
                              | fv("CTRL", "FILTER_LEN", 7))
    # x4, FILTER_LEN 5, modulo, EN; no swap, no inversion
    assert o["setup.CTRL"] == (bit("CTRL", "EN") | fv("CTRL", "FUNC", "x4") | fv("CTRL", "RANGE", "modulo")
                               | fv("CTRL", "FILTER_LEN", 5))
    assert (o["setup.CEILING_HI"], o["setup.CEILING_LO"]) == (1, 0x7CF)
    assert (o["setup.COUNT_HI"], o["setup.COUNT_LO"]) == (0, 0)
    every_event = sum(bit("EVENTS", f) for f in rdl()["EVENTS"])
    assert o["setup.EVENTS"] & every_event == every_event, "setup does not clear every event"
    assert o["setup.QERR_COUNT"] == 0 and o["setup.GLITCH_COUNT"] == 0


def test_count_arithmetic(harness_out):
    o = harness_out
    assert o["count_w"] == 64
    assert o["combine"] == 0x2FFFFFFF0
    assert o["read_count"] == 0x0123456789ABCDEF
    assert (o["write.COUNT_HI"], o["write.COUNT_LO"]) == (5, 7)
    assert o["signed.ff_8"] == -1
    assert o["signed.80_8"] == -128
    assert o["signed.7f_8"] == 127
    assert o["signed.1ff_8"] == -1  # bits above COUNT_W ignored
    assert o["signed.ffffffff_32"] == -1
    assert o["signed.fffffffe_48"] == 0xFFFFFFFE
    assert o["signed.neg1_64"] == -1
    assert o["signed.min_64"] == -(1 << 63)
    assert o["signed.min_64_plus1"] == -(1 << 63) + 2


def test_compare_on(harness_out):
    o = harness_out
    ctrl = (bit("CTRL", "EN") | fv("CTRL", "FUNC", "x1a") | fv("CTRL", "RANGE", "modulo")
            | fv("CTRL", "FILTER_LEN", 9))
    assert (o["cmp.COMPARE_HI"], o["cmp.COMPARE_LO"]) == (3, 0x10)
    assert o["cmp.CTRL"] == ctrl | bit("CTRL", "CMP_EN"), "CMP_EN not set, or CTRL's fields lost"
    assert o["cmp.IRQ_EN"] == bit("EVENTS", "INDEX") | bit("EVENTS", "CMP")
    assert o["cmp.EVENTS"] == bit("EVENTS", "CMP")


def test_homing_and_index_interrupt(harness_out):
    o = harness_out
    index, cmp_, qerr = bit("EVENTS", "INDEX"), bit("EVENTS", "CMP"), bit("EVENTS", "QERR")
    assert (o["preset.PRESET_HI"], o["preset.PRESET_LO"]) == (0xA, 1000)
    armed_preset = (fv("INDEX_CTRL", "ACTION", "preset") | bit("INDEX_CTRL", "ONESHOT")
                    | fv("INDEX_CTRL", "EDGE", "rising") | bit("INDEX_CTRL", "ARM"))
    gate_10 = bit("INDEX_CTRL", "GATE_EN") | bit("INDEX_CTRL", "GATE_A")
    assert o["preset.INDEX_CTRL"] == armed_preset | gate_10
    assert o["preset_nogate.INDEX_CTRL"] == armed_preset
    assert o["preset.IRQ_EN"] == cmp_ | index, "INDEX not enabled, or other enables lost"
    assert o["preset.EVENTS"] == index, "the stale INDEX event must be cleared alone (W1C)"
    # nothing pending: no write to EVENTS
    assert o["irq_none.ret"] == 0 and o["irq_none.EVENTS"] == cmp_
    # pending, still armed: INDEX cleared alone, not homed, interrupt kept
    assert o["irq_armed.ret"] == 0
    assert o["irq_armed.EVENTS"] == index, "the handler must write 1 to INDEX only"
    assert o["irq_armed.IRQ_EN"] & index
    # pending and disarmed by the one-shot: homed, INDEX interrupt off, others kept
    assert o["irq_homed.ret"] == 1 and o["irq_homed.EVENTS"] == index
    assert o["irq_homed.IRQ_EN"] == cmp_
    assert not qerr & index
    latch = fv("INDEX_CTRL", "ACTION", "latch") | bit("INDEX_CTRL", "ONESHOT") | bit("INDEX_CTRL", "ARM")
    assert o["latch.INDEX_CTRL"] == latch
    assert o["latch.IRQ_EN"] == index
    assert o["latch.pos32"] == 32
    assert o["latch.pos16"] == -60


def test_error_counters(harness_out):
    o = harness_out
    assert (o["err.ret"], o["err.qerr"], o["err.glitch"], o["err.kept"]) == (1, 3, 0xFFFF, 3)
    assert o["err.cleared"] == 0 and o["err.ret0"] == 0


# ---- names: doc and example against the RDL ---------------------------------------------------------------
# All-caps names in the doc's code spans that are not registers or fields.
NOT_REGISTERS = {"COUNT_W", "TS_W", "SLVERR", "BASE"}
SPAN = re.compile(r"`([^`\n]+)`")
REF = re.compile(r"^([A-Z][A-Z0-9_]*)(?:\.([A-Z][A-Z0-9_]*))?(?:\s*=\s*([a-z][a-z0-9_]*))?$")
PAIR = re.compile(r"^([A-Z][A-Z0-9_]*)_LO/([A-Z][A-Z0-9_]*)_HI$")


def check_ref(reg: str, field: str | None, member: str | None, where: str) -> str | None:
    regs = rdl()
    if field is None and member is None:
        if reg in regs or reg in NOT_REGISTERS or any(reg in f for f in regs.values()):
            return None
        return f"{where}: `{reg}` is neither a register nor a field of rtl/enc_qei.rdl"
    if reg not in regs:
        return f"{where}: register {reg} not in rtl/enc_qei.rdl"
    if field not in regs[reg]:
        return f"{where}: field {reg}.{field} not in rtl/enc_qei.rdl"
    if member is not None:
        enum = regs[reg][field][2]
        if enum is None or member not in enum:
            return f"{where}: {reg}.{field} has no enum member {member!r}"
    return None


def doc_refs(text: str):
    """(register, field, member, line) for every reference in a code span of the doc; code
    blocks are C and are checked like the example."""
    in_block = False
    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            in_block = not in_block
            continue
        if in_block:
            continue
        for span in SPAN.findall(line):
            if "ENC_QEI_" in span:  # a C name in running text
                yield from c_refs(span, f"doc/enc_qei.md:{n}")
                continue
            for part in re.split(r"\s*,\s*|\s+(?:and|or)\s+", span):
                m = REF.match(part.strip())
                if m:
                    yield m.group(1), m.group(2), m.group(3), f"doc/enc_qei.md:{n}"


def c_refs(text: str, where: str):
    """Register/field/enum names a C text uses: ENC_QEI__REG__FIELD[_bm|_bp|_bw|_reset|_SET|_GET|
    _UPDATE], ENC_QEI__REG__FIELD__MEMBER_VAL / _bm, ENC_QEI_REG_OFFSET / _RESET and ->REG / .REG
    struct members."""
    regs = rdl()
    for m in re.finditer(r"\bENC_QEI__([A-Za-z0-9_]+)", text):
        parts = m.group(1).split("__")
        if len(parts) < 2 or parts[0] == "":
            yield None, None, None, f"{where}: malformed {m.group(0)}"
            continue
        reg, field = parts[0], re.sub(r"_(bm|bp|bw|reset|SET|GET|UPDATE)$", "", parts[1])
        member = None
        if len(parts) > 2 and parts[2] not in ("", "*_VAL", "*_bm", "*"):  # `__*`: any member
            if not re.search(r"_(VAL|bm)$", parts[2]):
                yield None, None, None, f"{where}: {m.group(0)}: an enum member is _VAL or _bm"
                continue
            member = re.sub(r"_(VAL|bm)$", "", parts[2]).lower()
        yield reg, field, member, where
    for m in re.finditer(r"\bENC_QEI_([A-Z][A-Z0-9_]*)_(?:OFFSET|RESET)\b", text):
        yield m.group(1), None, None, where
    for m in re.finditer(r"(?:->|\bregs\.)([A-Z][A-Z0-9_]*)\b", text):
        if m.group(1) not in regs:
            yield None, None, None, f"{where}: struct member {m.group(1)} is not a register"


def test_doc_names_exist_in_rdl():
    text = DOC.read_text()
    refs = list(doc_refs(text))
    assert len(refs) > 100, "the doc's register references were not found; did the format change?"
    errors = [r[3] if r[0] is None else e for r in refs
              if r[0] is None or (e := check_ref(*r)) is not None]
    for n, line in enumerate(text.splitlines(), 1):
        for span in SPAN.findall(line):
            m = PAIR.match(span)
            if m and m.group(1) == m.group(2):
                for half in ("_LO", "_HI"):
                    e = check_ref(m.group(1) + half, None, None, f"doc/enc_qei.md:{n}")
                    if e:
                        errors.append(e)
    assert not errors, "\n".join(errors)
    # every FUNC and RANGE value and index action is described
    for reg, field in (("CTRL", "FUNC"), ("CTRL", "RANGE"), ("INDEX_CTRL", "ACTION")):
        described = {m for r, f, m, _ in refs if (r, f) == (reg, field) and m}
        missing = set(rdl()[reg][field][2]) - described
        assert not missing, f"doc/enc_qei.md does not describe {reg}.{field} = {sorted(missing)}"
    # every event has a row
    described = {f for r, f, m, _ in refs if r == "EVENTS" and f}
    assert set(rdl()["EVENTS"]) <= described, set(rdl()["EVENTS"]) - described


def test_c_code_names_exist_in_rdl():
    errors = []
    texts = [(p.read_text(), str(p.relative_to(TOP))) for p in (EXAMPLE_C, EXAMPLE_H)]
    blocks = re.findall(r"```c\n(.*?)```", DOC.read_text(), re.S)
    assert blocks, "no C code block in doc/enc_qei.md"
    texts += [(b, "doc/enc_qei.md (C block)") for b in blocks]
    seen = 0
    for text, where in texts:
        for r in c_refs(text, where):
            seen += 1
            if r[0] is None:
                errors.append(r[3])
            elif (e := check_ref(*r)) is not None:
                errors.append(e)
    assert seen > 30
    assert not errors, "\n".join(errors)


def test_doc_links_resolve():
    text = DOC.read_text()
    missing = []
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" in target:
            continue
        if not (DOC.parent / target).resolve().exists():
            missing.append(target)
    # the shared reference lives outside the repository; only the repository's links must resolve
    missing = [m for m in missing if "shared/reference" not in m]
    assert not missing, f"doc/enc_qei.md links to missing files: {missing}"
